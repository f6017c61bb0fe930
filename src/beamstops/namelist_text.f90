!> The text of a namelist group as the reader sees it, before gfortran reads it: the groups
!> and their keys, where each `key = value` starts and what its value text holds (items, nulls,
!> sections, logicals, whole numbers, the length of a quoted word). Pure scanning, no scene:
!> beamstops_namelist decides with it what a text may say.
module beamstops_namelist_text
   use beamstops_scene, only: max_stops
   use beamstops_strings, only: itoa, lower
   implicit none
   private
   public :: group_names, group_keys, text_len, word_len
   public :: next_item, whole_numbers_text, clamped_list, beyond_integer, whole_number_text, without_bom
   public :: assignment_text, value_count, list_key, section_of, outside_list, has_null, logical_text, key_at, all_groups
   public :: known_key, text_capacity, text_length, value_kind, group_body, assignment_starts

   !> Groups a scene file may hold, each at most once.
   character(len=*), parameter :: group_names(9) = [character(len=10) :: 'beam', 'support', 'stops', 'damping', &
      & 'mesh', 'time', 'output', 'statistics', 'ensemble']
   !> Keys of each group, for messages.
   character(len=*), parameter :: group_keys(9) = [character(len=140) :: &
      & 'length, k2, mass_per_length, youngs_modulus, density, outer_diameter, wall_thickness', &
      & 'amplitude, omega', 'lower, upper, nodes, x, law, stiffness, stiffness_per_mass, restitution, mass', &
      & 'mass_coefficient, stiffness_coefficient, ratio, modes', 'elements, modes', &
      & 'dt, t_end, beta, load_rule, start, allow_unstable', 'file, record_every, snapshot_every, checkpoint_every, max_output_gb', &
      & 'enabled, transient, batches, bins, rest_time, histogram_lower, histogram_upper', 'members, perturbation, seed']
   !> Length of the variable of &output file (a path of at most text_len - 1 characters).
   integer, parameter :: text_len = 4096
   !> Length of the variables of the word keys (law, mass, load_rule, start).
   integer, parameter :: word_len = 64

contains

   !> The next item of a list's text (separated by commas or blanks) at or after `pos`:
   !> text(first:last), `pos` moved past it; first = 0 when there is none.
   pure subroutine next_item(text, pos, first, last)
      character(len=*), intent(in) :: text
      integer, intent(inout) :: pos
      integer, intent(out) :: first, last
      first = 0
      last = 0
      do while (pos <= len(text))
         if (text(pos:pos) /= ',' .and. text(pos:pos) /= ' ') exit
         pos = pos + 1
      end do
      if (pos > len(text)) return
      first = pos
      do while (pos <= len(text))
         if (text(pos:pos) == ',' .or. text(pos:pos) == ' ') exit
         pos = pos + 1
      end do
      last = pos - 1
   end subroutine next_item

   !> Whether a list's text holds whole numbers only (at least one), one of them beyond the
   !> default integer kind.
   logical function whole_numbers_text(text)
      character(len=*), intent(in) :: text
      integer :: pos, first, last, count
      logical :: beyond
      pos = 1
      count = 0
      beyond = .false.
      whole_numbers_text = .false.
      do
         call next_item(text, pos, first, last)
         if (first == 0) exit
         if (.not. whole_number_text(text(first:last))) return
         beyond = beyond .or. beyond_integer(text(first:last))
         count = count + 1
      end do
      whole_numbers_text = count > 0 .and. beyond
   end function whole_numbers_text

   !> The list with each whole number beyond the default integer kind replaced by the kind's
   !> extreme of its sign, the items separated by commas.
   function clamped_list(text) result(list)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: list
      integer :: pos, first, last
      pos = 1
      list = ''
      do
         call next_item(text, pos, first, last)
         if (first == 0) exit
         if (len(list) > 0) list = list//', '
         if (.not. beyond_integer(text(first:last))) then
            list = list//text(first:last)
         else if (text(first:first) == '-') then
            list = list//'-'//itoa(huge(1))
         else
            list = list//itoa(huge(1))
         end if
      end do
   end function clamped_list

   !> Whether a whole number's text (an optional sign and digits) is beyond the default integer kind.
   logical function beyond_integer(text)
      character(len=*), intent(in) :: text
      integer :: value, stat
      beyond_integer = .false.
      if (.not. whole_number_text(text)) return
      read (text, *, iostat=stat) value
      beyond_integer = stat /= 0
   end function beyond_integer

   !> Whether a value's text is one whole number (an optional sign and digits; blanks and a
   !> trailing comma aside).
   pure logical function whole_number_text(text)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: t
      t = assignment_text(text)
      if (len(t) > 0) then
         if (t(1:1) == '+' .or. t(1:1) == '-') t = t(2:)
      end if
      whole_number_text = len(t) > 0 .and. verify(t, '0123456789') == 0
   end function whole_number_text

   !> The text without the UTF-8 byte order mark some editors put at its start.
   pure function without_bom(text) result(rest)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: rest
      character(len=*), parameter :: bom = char(239)//char(187)//char(191)
      rest = text
      if (len(text) >= len(bom)) then
         if (text(:len(bom)) == bom) rest = text(len(bom) + 1:)
      end if
   end function without_bom

   !> An assignment of a group's body as shown in a message: without the blanks and the comma after it.
   pure function assignment_text(text) result(shown)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: shown
      shown = trim(adjustl(text))
      do while (len(shown) > 0)
         if (shown(len(shown):) /= ',') exit
         shown = trim(shown(:len(shown) - 1))
      end do
   end function assignment_text

   !> Number of values in the value text of a list key: items separated by commas or blanks,
   !> `r*value` counting r.
   function value_count(text) result(count)
      character(len=*), intent(in) :: text
      integer :: count
      integer :: pos, first, last, star, r, stat
      character(len=:), allocatable :: item
      count = 0
      pos = 1
      do
         call next_item(text, pos, first, last)
         if (first == 0) exit
         item = text(first:last)
         star = index(item, '*')
         r = 1
         if (star > 1) then
            read (item(:star - 1), *, iostat=stat) r
            if (stat /= 0 .or. r < 1) r = 1
         end if
         count = count + r
      end do
   end function value_count

   !> Where a list key of a group is kept among the group's lists (slot 1, 2, ...) and how many
   !> values it holds (capacity); capacity 0 for a key of one value.
   pure subroutine list_key(group, key, slot, capacity)
      !> Group name.
      character(len=*), intent(in) :: group
      !> Key (lower case).
      character(len=*), intent(in) :: key
      !> Its list among the group's.
      integer, intent(out) :: slot
      !> Values it holds.
      integer, intent(out) :: capacity
      slot = 0
      capacity = 0
      select case (group)
      case ('stops')
         slot = findloc([character(len=5) :: 'lower', 'upper', 'nodes', 'x'], key, dim=1)
         if (slot > 0) capacity = max_stops
      case ('damping')
         slot = findloc([character(len=5) :: 'ratio', 'modes'], key, dim=1)
         if (slot > 0) capacity = 2
      end select
   end subroutine list_key

   !> The elements of a list of `capacity` values that a subscript gives, from `first` toward
   !> `final` by `step`: `(i)` starts a run of values at i (to the end of the list), `(i:j)` and
   !> `(i:j:s)` a section, any part left out taking its default (1, capacity, 1). ok = .false.
   !> when a part is not a whole number or the step is 0 (gfortran tells such a subscript).
   subroutine section_of(subscript, capacity, first, final, step, ok)
      !> The subscript with its parentheses.
      character(len=*), intent(in) :: subscript
      !> Values the list holds.
      integer, intent(in) :: capacity
      !> First element, the one not passed, and the step.
      integer, intent(out) :: first, final, step
      !> Whether the subscript is read.
      logical, intent(out) :: ok
      character(len=:), allocatable :: inner
      integer :: colon, second
      first = 1; final = capacity; step = 1
      inner = subscript(2:len(subscript) - 1)
      colon = index(inner, ':')
      if (colon == 0) then
         ok = part(inner, first)
         return
      end if
      second = index(inner(colon + 1:), ':')
      if (second == 0) then
         ok = part(inner(:colon - 1), first) .and. part(inner(colon + 1:), final)
      else
         second = colon + second
         ok = part(inner(:colon - 1), first) .and. part(inner(colon + 1:second - 1), final) .and. &
            & part(inner(second + 1:), step)
         ok = ok .and. step /= 0
      end if

   contains

      !> A part of the subscript into `value` (kept when the part is blank); whether it is read.
      !> A whole number beyond the integer kind is read as a quarter of the kind's largest, of its
      !> sign: outside every list (so out of range, not malformed), and no overflow in outside_list.
      logical function part(text, value)
         character(len=*), intent(in) :: text
         integer, intent(inout) :: value
         integer :: stat
         part = .true.
         if (len_trim(text) == 0) return
         part = whole_number_text(text)
         if (.not. part) return
         read (text, *, iostat=stat) value
         if (stat /= 0) value = sign(huge(value)/4, merge(-1, 1, index(text, '-') > 0))
      end function part
   end subroutine section_of

   !> Whether a subscript's elements fall outside a list of `capacity` values: `(i)`, whose
   !> `values` values run from element i, past either end; a section `(i:j:s)` that selects an
   !> element outside 1 .. capacity (an empty section selects none).
   pure logical function outside_list(first, final, step, values, capacity, section)
      !> The subscript's first element, its bound and step (section_of).
      integer, intent(in) :: first, final, step
      !> Values the assignment gives, and values the list holds.
      integer, intent(in) :: values, capacity
      !> Whether the subscript is a section (has a colon).
      logical, intent(in) :: section
      integer :: reached
      if (.not. section) then
         outside_list = first < 1 .or. first > capacity .or. first - 1 > capacity - max(values, 1)
         return
      end if
      outside_list = .false.
      if ((step > 0 .and. first > final) .or. (step < 0 .and. first < final)) return
      reached = first + ((final - first)/step)*step
      outside_list = min(first, reached) < 1 .or. max(first, reached) > capacity
   end function outside_list

   !> Whether the value text of an assignment holds a null value, one Fortran's namelist leaves
   !> as it was: an `r*` with nothing after the star, nothing (or blanks) between two commas, or
   !> a comma before the first value. (A comma after the last value only separates it from the
   !> next key or the /.)
   pure logical function has_null(text)
      !> Value text of the assignment (after its =).
      character(len=*), intent(in) :: text
      integer :: i, first
      logical :: expecting, quoted
      character :: quote
      has_null = .true.
      expecting = .true.
      quote = ' '
      i = 1
      do while (i <= len(text))
         if (text(i:i) == ' ' .or. text(i:i) == achar(9)) then
            i = i + 1
         else if (text(i:i) == ',') then
            if (expecting) return
            expecting = .true.
            i = i + 1
         else
            ! an item: up to a blank or a comma outside quotes
            first = i
            quoted = .false.
            do while (i <= len(text))
               if (quoted) then
                  if (text(i:i) == quote) quoted = .false.
               else if (text(i:i) == '"' .or. text(i:i) == "'") then
                  quoted = .true.
                  quote = text(i:i)
               else if (text(i:i) == ' ' .or. text(i:i) == ',' .or. text(i:i) == achar(9)) then
                  exit
               end if
               i = i + 1
            end do
            if (i - 1 > first .and. text(i - 1:i - 1) == '*') then
               if (verify(text(first:i - 2), '0123456789') == 0) return
            end if
            expecting = .false.
         end if
      end do
      has_null = .false.
   end function has_null

   !> Whether the value text of a logical key is a logical as a user means it: .true., .false.,
   !> T, F, .t., .f., true or false, in any case (blanks and a trailing comma aside). gfortran
   !> reads any word by its first letter after an optional dot (`trash` is .true., `.false.xyz`
   !> .false.); the reader refuses every other word.
   pure logical function logical_text(text)
      !> Value text of the assignment.
      character(len=*), intent(in) :: text
      character(len=*), parameter :: forms(8) = [character(len=7) :: '.true.', '.false.', 't', 'f', '.t.', '.f.', &
         & 'true', 'false']
      character(len=:), allocatable :: v
      integer :: star
      v = lower(assignment_text(text))
      ! a repeat count before it (1*T) is Fortran's, as for any other value
      star = index(v, '*')
      if (star > 1) then
         if (verify(v(:star - 1), '0123456789') == 0) v = v(star + 1:)
      end if
      logical_text = len(v) > 0 .and. len(v) <= len(forms) .and. any(forms == v)
   end function logical_text

   !> The key (lower case) that starts at position `start` of a group's body.
   function key_at(body, start) result(key)
      character(len=*), intent(in) :: body
      integer, intent(in) :: start
      character(len=:), allocatable :: key
      integer :: past
      ! (not verify(body(start:)//'=', ...): a copy of the rest of the body for every key)
      past = verify(body(start:), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_')
      if (past == 0) past = len(body) - start + 2
      key = lower(body(start:start + past - 2))
   end function key_at

   !> The groups as `&beam, &support, ...`.
   function all_groups() result(text)
      character(len=:), allocatable :: text
      integer :: g
      text = '&'//trim(group_names(1))
      do g = 2, size(group_names)
         text = text//', &'//trim(group_names(g))
      end do
   end function all_groups

   !> Whether a key belongs to group g.
   logical function known_key(g, key)
      integer, intent(in) :: g
      character(len=*), intent(in) :: key
      known_key = index(', '//trim(group_keys(g))//',', ', '//key//',') > 0
   end function known_key

   !> The characters a text key holds: a path for &output file, a word for the others.
   pure integer function text_capacity(key)
      character(len=*), intent(in) :: key
      text_capacity = merge(text_len, word_len, key == 'file') - 1
   end function text_capacity

   !> The length of a text value as gfortran reads it: between its quotes ('' or "" inside
   !> counting one) up to its last character not a blank, or up to a blank, comma or / when it
   !> has none.
   pure integer function text_length(value)
      character(len=*), intent(in) :: value
      integer :: first, i, count
      character :: quote
      first = verify(value, ' ')
      text_length = 0
      if (first == 0) return
      quote = value(first:first)
      if (quote /= "'" .and. quote /= '"') then
         text_length = scan(value(first:)//' ', ' ,/') - 1
         return
      end if
      ! blanks at its end do not count: the reader drops them (trim), and so may gfortran
      i = first + 1
      count = 0
      do while (i <= len(value))
         if (value(i:i) == quote) then
            if (i == len(value)) exit
            if (value(i + 1:i + 1) /= quote) exit
            i = i + 1
         end if
         count = count + 1
         if (value(i:i) /= ' ') text_length = count
         i = i + 1
      end do
   end function text_length

   !> The kind of value a key takes, for messages.
   function value_kind(key, group) result(kind)
      !> Key (lower case).
      character(len=*), intent(in) :: key
      !> Index of its group in group_names (&mesh modes is a whole number, &damping modes a list).
      integer, intent(in), optional :: group
      character(len=:), allocatable :: kind
      if (present(group)) then
         if (trim(group_names(group)) == 'mesh' .and. key == 'modes') then
            kind = 'a whole number'
            return
         end if
      end if
      select case (key)
      case ('elements', 'record_every', 'snapshot_every', 'checkpoint_every', 'batches', 'bins', 'members', 'seed')
         kind = 'a whole number'
      case ('nodes')
         kind = 'whole numbers separated by commas (one per stop, at most '//itoa(max_stops)//' stops)'
      case ('modes')
         kind = 'whole numbers separated by commas'
      case ('ratio')
         kind = 'one or two real numbers separated by commas'
      case ('lower', 'upper', 'x')
         kind = 'real numbers separated by commas (one per stop, at most '//itoa(max_stops)//' stops)'
      case ('law', 'load_rule', 'start', 'file', 'mass')
         kind = "a quoted text, e.g. 'name'"
      case ('allow_unstable', 'enabled')
         kind = '.true. or .false.'
      case default
         kind = 'a real number, e.g. 1e-5'
      end select
   end function value_kind

   !> The text of a group in `cleaned` after its name, up to its closing / (outside quotes). The
   !> group's name is looked for outside quotes too: a quoted value of another group holding
   !> `&name` (`file = 'x &time dt = 1 /'`) is not the group.
   function group_body(cleaned, name) result(body)
      character(len=*), intent(in) :: cleaned, name
      character(len=:), allocatable :: body, low
      integer :: start, i
      logical :: quoted
      character :: quote
      low = lower(cleaned)
      body = ''
      start = 0
      quoted = .false.
      quote = ' '
      do i = 1, len(low) - len(name)
         if (quoted) then
            if (low(i:i) == quote) quoted = .false.
         else if (low(i:i) == '"' .or. low(i:i) == "'") then
            quoted = .true.
            quote = low(i:i)
         else if ((low(i:i) == '&' .or. low(i:i) == '$') .and. low(i + 1:i + len(name)) == name) then
            if (scan(low(i + len(name) + 1:i + len(name) + 1), 'abcdefghijklmnopqrstuvwxyz0123456789_') == 0) then
               start = i + len(name) + 1
               exit
            end if
         end if
      end do
      if (start == 0) return
      quoted = .false.
      quote = ' '
      do i = start, len(cleaned)
         if (quoted) then
            if (cleaned(i:i) == quote) quoted = .false.
         else if (cleaned(i:i) == '"' .or. cleaned(i:i) == "'") then
            quoted = .true.
            quote = cleaned(i:i)
         else if (scan(cleaned(i:i), '/&$') > 0) then
            exit
         end if
      end do
      body = cleaned(start:i - 1)
   end function group_body

   !> Where each `key = ` (or `key(i) = `) of a group's body starts, outside quotes.
   function assignment_starts(body) result(starts)
      character(len=*), intent(in) :: body
      integer, allocatable :: starts(:), found(:)
      integer :: i, j, count
      logical :: quoted
      character :: quote
      ! grown by doubling: one element at a time, 200,000 assignments took 3 s
      allocate (found(16))
      count = 0
      quoted = .false.
      quote = ' '
      do i = 1, len(body)
         if (quoted) then
            if (body(i:i) == quote) quoted = .false.
            cycle
         end if
         if (body(i:i) == '"' .or. body(i:i) == "'") then
            quoted = .true.
            quote = body(i:i)
            cycle
         end if
         if (body(i:i) /= '=') cycle
         j = i - 1
         do while (j >= 1)
            if (body(j:j) /= ' ') exit
            j = j - 1
         end do
         if (j >= 1) then
            if (body(j:j) == ')') then
               j = index(body(:j), '(', back=.true.) - 1
               do while (j >= 1)
                  if (body(j:j) /= ' ') exit
                  j = j - 1
               end do
            end if
         end if
         do while (j >= 1)
            if (scan(body(j:j), 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_') == 0) exit
            j = j - 1
         end do
         if (j + 1 <= i - 1) then
            if (count == size(found)) found = [found, found]
            count = count + 1
            found(count) = j + 1
         end if
      end do
      starts = found(:count)
   end function assignment_starts
end module beamstops_namelist_text
