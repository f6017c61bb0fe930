!> Named values of a run (the scene's keys, the model's limits, the summary's results) as one
!> list that every consumer reads: the canonical namelist text of a scene, the HDF5 root
!> attributes, the attribute lines handed to Python and the checkpoint's scene signature.
module beamstops_attributes
   use beamstops_kinds, only: wp, ik
   use beamstops_strings, only: real_literal, fmt_int, quoted
   implicit none
   private
   public :: attribute_type, attribute_list, kind_real, kind_int, kind_logical, kind_text
   public :: namelist_text, attribute_lines

   !> Kinds of value.
   integer, parameter :: kind_real = 1, kind_int = 2, kind_logical = 3, kind_text = 4

   !> One named value: a real, an integer or a logical (scalars or lists), or a text.
   type :: attribute_type
      !> Namelist group of an input key; '' for a value that is not read (derived or a result).
      character(len=:), allocatable :: group
      !> Key or attribute name.
      character(len=:), allocatable :: name
      !> kind_real, kind_int, kind_logical or kind_text.
      integer :: kind = kind_real
      !> Whether the value is a list (a namelist list; not a root attribute).
      logical :: list = .false.
      !> Whether it is written as a root attribute of the output (and handed to Python).
      logical :: attribute = .true.
      !> Whether a restart must find the same value (the checkpoint's scene signature).
      logical :: signature = .true.
      !> Values of kind_real.
      real(wp), allocatable :: reals(:)
      !> Values of kind_int, and kind_logical as 0 or 1.
      integer(ik), allocatable :: ints(:)
      !> Value of kind_text.
      character(len=:), allocatable :: text
   end type attribute_type

   !> A growing list of named values, in the order they were added.
   type :: attribute_list
      !> The values; the first `count` are used.
      type(attribute_type), allocatable :: items(:)
      !> Number of values.
      integer :: count = 0
   contains
      !> Add a real (or a list of reals).
      procedure :: add_real
      !> Add an integer (or a list of integers).
      procedure :: add_int
      !> Add a logical.
      procedure :: add_logical
      !> Add a text.
      procedure :: add_text
      !> Add every value of another list.
      procedure :: extend
   end type attribute_list

contains

   !> Add a real scalar, or a list with `values`.
   subroutine add_real(self, group, name, value, values, attribute, signature)
      !> List.
      class(attribute_list), intent(inout) :: self
      !> Namelist group ('' when not an input).
      character(len=*), intent(in) :: group
      !> Name.
      character(len=*), intent(in) :: name
      !> Scalar value (ignored when `values` is present).
      real(wp), intent(in) :: value
      !> List value.
      real(wp), intent(in), optional :: values(:)
      !> Root attribute (default .true.).
      logical, intent(in), optional :: attribute
      !> Part of the signature (default .true.).
      logical, intent(in), optional :: signature
      type(attribute_type) :: item
      call start(item, group, name, kind_real, attribute, signature)
      if (present(values)) then
         item%reals = values
         item%list = .true.
      else
         item%reals = [value]
      end if
      call push(self, item)
   end subroutine add_real

   !> Add an integer scalar, or a list with `values`.
   subroutine add_int(self, group, name, value, values, attribute, signature)
      !> List.
      class(attribute_list), intent(inout) :: self
      !> Namelist group ('' when not an input).
      character(len=*), intent(in) :: group
      !> Name.
      character(len=*), intent(in) :: name
      !> Scalar value (ignored when `values` is present).
      integer(ik), intent(in) :: value
      !> List value.
      integer(ik), intent(in), optional :: values(:)
      !> Root attribute (default .true.).
      logical, intent(in), optional :: attribute
      !> Part of the signature (default .true.).
      logical, intent(in), optional :: signature
      type(attribute_type) :: item
      call start(item, group, name, kind_int, attribute, signature)
      if (present(values)) then
         item%ints = values
         item%list = .true.
      else
         item%ints = [value]
      end if
      call push(self, item)
   end subroutine add_int

   !> Add a logical (an attribute 0 or 1).
   subroutine add_logical(self, group, name, value, attribute, signature)
      !> List.
      class(attribute_list), intent(inout) :: self
      !> Namelist group ('' when not an input).
      character(len=*), intent(in) :: group
      !> Name.
      character(len=*), intent(in) :: name
      !> Value.
      logical, intent(in) :: value
      !> Root attribute (default .true.).
      logical, intent(in), optional :: attribute
      !> Part of the signature (default .true.).
      logical, intent(in), optional :: signature
      type(attribute_type) :: item
      call start(item, group, name, kind_logical, attribute, signature)
      item%ints = [merge(1_ik, 0_ik, value)]
      call push(self, item)
   end subroutine add_logical

   !> Add a text.
   subroutine add_text(self, group, name, value, attribute, signature)
      !> List.
      class(attribute_list), intent(inout) :: self
      !> Namelist group ('' when not an input).
      character(len=*), intent(in) :: group
      !> Name.
      character(len=*), intent(in) :: name
      !> Value.
      character(len=*), intent(in) :: value
      !> Root attribute (default .true.).
      logical, intent(in), optional :: attribute
      !> Part of the signature (default .true.).
      logical, intent(in), optional :: signature
      type(attribute_type) :: item
      call start(item, group, name, kind_text, attribute, signature)
      item%text = value
      call push(self, item)
   end subroutine add_text

   !> Add every value of `other`.
   subroutine extend(self, other)
      !> List.
      class(attribute_list), intent(inout) :: self
      !> Values to add.
      type(attribute_list), intent(in) :: other
      integer :: i
      do i = 1, other%count
         call push(self, other%items(i))
      end do
   end subroutine extend

   subroutine start(item, group, name, kind, attribute, signature)
      type(attribute_type), intent(out) :: item
      character(len=*), intent(in) :: group, name
      integer, intent(in) :: kind
      logical, intent(in), optional :: attribute, signature
      item%group = group
      item%name = name
      item%kind = kind
      if (present(attribute)) item%attribute = attribute
      if (present(signature)) item%signature = signature
   end subroutine start

   subroutine push(self, item)
      type(attribute_list), intent(inout) :: self
      type(attribute_type), intent(in) :: item
      type(attribute_type), allocatable :: grown(:)
      if (.not. allocated(self%items)) allocate (self%items(16))
      if (self%count == size(self%items)) then
         allocate (grown(2*size(self%items)))
         grown(:self%count) = self%items(:self%count)
         call move_alloc(grown, self%items)
      end if
      self%count = self%count + 1
      self%items(self%count) = item
   end subroutine push

   !> The value of an item as namelist text: reals that read back exactly, lists separated by
   !> commas, logicals .true./.false. (`as_namelist`) or 1/0, texts quoted.
   function value_text(item, as_namelist) result(s)
      type(attribute_type), intent(in) :: item
      logical, intent(in) :: as_namelist
      character(len=:), allocatable :: s
      integer :: i
      s = ''
      select case (item%kind)
      case (kind_real)
         do i = 1, size(item%reals)
            if (i > 1) s = s//', '
            s = s//real_literal(item%reals(i))
         end do
      case (kind_int)
         do i = 1, size(item%ints)
            if (i > 1) s = s//', '
            s = s//fmt_int(item%ints(i))
         end do
      case (kind_logical)
         if (as_namelist) then
            s = merge('.true. ', '.false.', item%ints(1) /= 0)
            s = trim(s)
         else
            s = fmt_int(item%ints(1))
         end if
      case (kind_text)
         s = quoted(item%text)
      end select
   end function value_text

   !> The inputs of a list as namelist text, one group after the other in the order of their
   !> first key, one `key = value` per line; only items for which `keep` (if given) is true.
   function namelist_text(list, keep) result(text)
      !> List.
      type(attribute_list), intent(in) :: list
      !> Which items to write (default: all inputs).
      logical, intent(in), optional :: keep(:)
      character(len=:), allocatable :: text
      character(len=:), allocatable :: group
      logical :: done(list%count)
      integer :: i, j
      character, parameter :: nl = new_line('a')
      text = ''
      done = .false.
      do i = 1, list%count
         if (done(i) .or. list%items(i)%group == '') cycle
         group = list%items(i)%group
         text = text//'&'//group//nl
         do j = i, list%count
            if (list%items(j)%group /= group) cycle
            done(j) = .true.
            if (present(keep)) then
               if (.not. keep(j)) cycle
            end if
            text = text//'  '//list%items(j)%name//' = '//value_text(list%items(j), .true.)//nl
         end do
         text = text//'/'//nl
      end do
   end function namelist_text

   !> The root attributes of a list as lines `name = value` (logicals as 1 or 0, as written to
   !> the output file).
   function attribute_lines(list) result(text)
      !> List.
      type(attribute_list), intent(in) :: list
      character(len=:), allocatable :: text
      integer :: i
      text = ''
      do i = 1, list%count
         if (.not. list%items(i)%attribute) cycle
         text = text//list%items(i)%name//' = '//value_text(list%items(i), .false.)//new_line('a')
      end do
   end function attribute_lines
end module beamstops_attributes
