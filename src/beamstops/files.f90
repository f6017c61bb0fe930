!> Files as the engine handles them: existence, identity (same file under two names),
!> atomic replacement by rename, removal. The C library and src/beamstops/files.c do the work.
module beamstops_files
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_int64_t, c_null_char, c_ptr, c_f_pointer, c_associated, &
      & c_size_t
   implicit none
   private
   public :: file_exists, is_directory, same_file, same_path, rename_file, replace_file, remove_file, creation_error
   public :: raise_hdf5_eoa
   public :: path_kind, kind_name, path_missing, path_regular, path_link, path_folder
   public :: lock_file, unlock_file, file_in_use, hdf5_locks, lock_busy, not_writable_here
   public :: read_whole_file, read_ok, read_missing, read_folder, read_too_big, read_unopened, read_failed

   !> Outcomes of read_whole_file: read, no such file, a folder, more bytes than allowed, not
   !> opened, not read (the last two with the system's words).
   integer, parameter :: read_ok = 0, read_missing = 1, read_folder = 2, read_too_big = 3, read_unopened = 4, &
      & read_failed = 5

   !> What is at a path (path_kind): nothing, a regular file, a symbolic link, a folder, a FIFO,
   !> a socket, a device, anything else.
   integer, parameter :: path_missing = 0, path_regular = 1, path_link = 2, path_folder = 3, path_fifo = 4, &
      & path_socket = 5, path_device = 6

   !> lock_file's result when another open file holds a lock on the file.
   integer, parameter :: lock_busy = -1

   interface
      function c_path_kind(path, follow) bind(c, name='beamstops_path_kind') result(kind)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: follow
         integer(c_int) :: kind
      end function c_path_kind
      function c_lock_file(path) bind(c, name='beamstops_lock_file') result(fd)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: fd
      end function c_lock_file
      subroutine c_unlock_file(fd) bind(c, name='beamstops_unlock_file')
         import :: c_int
         integer(c_int), value :: fd
      end subroutine c_unlock_file
      function c_file_in_use(path) bind(c, name='beamstops_file_in_use') result(busy)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: busy
      end function c_file_in_use
      function c_hdf5_locks() bind(c, name='beamstops_hdf5_locks') result(locks)
         import :: c_int
         integer(c_int) :: locks
      end function c_hdf5_locks
      function c_rename(from, to) bind(c, name='rename') result(status)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: status
      end function c_rename
      function c_replace_file(from, to) bind(c, name='beamstops_replace_file') result(status)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: status
      end function c_replace_file
      function c_remove(path) bind(c, name='remove') result(status)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: status
      end function c_remove
      function c_same_file(a, b) bind(c, name='beamstops_same_file') result(same)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: a(*), b(*)
         integer(c_int) :: same
      end function c_same_file
      function c_same_path(a, b) bind(c, name='beamstops_same_path') result(same)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: a(*), b(*)
         integer(c_int) :: same
      end function c_same_path
      function c_is_directory(path) bind(c, name='beamstops_is_directory') result(directory)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: directory
      end function c_is_directory
      function c_read_file(path, limit, data, size, regular, message, message_size) &
         & bind(c, name='beamstops_read_file') result(outcome)
         import :: c_char, c_int, c_int64_t, c_ptr
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int64_t), value :: limit
         type(c_ptr), intent(out) :: data
         integer(c_int64_t), intent(out) :: size
         integer(c_int), intent(out) :: regular
         character(kind=c_char), intent(inout) :: message(*)
         integer(c_int), value :: message_size
         integer(c_int) :: outcome
      end function c_read_file
      subroutine c_free(pointer) bind(c, name='free')
         import :: c_ptr
         type(c_ptr), value :: pointer
      end subroutine c_free
      function c_creation_errno(path) bind(c, name='beamstops_creation_errno') result(code)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: code
      end function c_creation_errno
      function c_raise_hdf5_eoa(path) bind(c, name='beamstops_raise_hdf5_eoa') result(outcome)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: outcome
      end function c_raise_hdf5_eoa
      subroutine c_errno_text(code, text, size) bind(c, name='beamstops_errno_text')
         import :: c_char, c_int, c_size_t
         integer(c_int), value :: code
         character(kind=c_char), intent(out) :: text(*)
         integer(c_size_t), value :: size
      end subroutine c_errno_text
   end interface

contains

   !> The whole content of a file, read to its end: a regular file, or a pipe, a FIFO or a
   !> device (`beamstops run <(...)`, /dev/stdin), whose size is known only once read.
   subroutine read_whole_file(path, limit, text, outcome, bytes, regular, why)
      !> File.
      character(len=*), intent(in) :: path
      !> Most bytes read.
      integer(c_int64_t), intent(in) :: limit
      !> Its content ('' unless read).
      character(len=:), allocatable, intent(out) :: text
      !> read_ok, or why it was not read: read_missing, read_folder, read_too_big, read_unopened,
      !> read_failed.
      integer, intent(out) :: outcome
      !> Bytes read; with read_too_big, the size a regular file reports (-1 for a stream).
      integer(c_int64_t), intent(out) :: bytes
      !> Whether the file is a regular file (not a pipe, a FIFO or a device).
      logical, intent(out) :: regular
      !> With read_unopened and read_failed, the system's words.
      character(len=:), allocatable, intent(out) :: why
      character(kind=c_char) :: message(256)
      character(kind=c_char), pointer :: chars(:)
      type(c_ptr) :: data
      integer(c_int) :: is_regular
      integer(c_int64_t) :: i
      message = c_null_char
      outcome = c_read_file(path//c_null_char, limit, data, bytes, is_regular, message, size(message, kind=c_int))
      regular = is_regular /= 0
      why = ''
      do i = 1, size(message)
         if (message(i) == c_null_char) exit
         why = why//message(i)
      end do
      allocate (character(len=max(0_c_int64_t, merge(bytes, 0_c_int64_t, outcome == read_ok))) :: text)
      if (.not. c_associated(data)) return
      call c_f_pointer(data, chars, [bytes])
      do i = 1, bytes
         text(i:i) = chars(i)
      end do
      call c_free(data)
   end subroutine read_whole_file

   !> Whether `path` exists (a file or a directory).
   function file_exists(path) result(exists)
      !> Path.
      character(len=*), intent(in) :: path
      logical :: exists
      inquire (file=path, exist=exists)
   end function file_exists

   !> Whether `path` is an existing directory.
   function is_directory(path) result(directory)
      !> Path.
      character(len=*), intent(in) :: path
      logical :: directory
      directory = c_is_directory(path//c_null_char) == 1
   end function is_directory

   !> What is at `path`: path_missing, path_regular, path_link, path_folder, or a FIFO, a socket, a
   !> device (kind_name names them); the link itself unless `follow` (then what it leads to).
   integer function path_kind(path, follow)
      !> Path.
      character(len=*), intent(in) :: path
      !> Whether a symbolic link is followed.
      logical, intent(in) :: follow
      path_kind = c_path_kind(path//c_null_char, merge(1_c_int, 0_c_int, follow))
   end function path_kind

   !> What a path_kind is, in words: 'a symbolic link', 'a FIFO (named pipe)', ...
   function kind_name(kind) result(name)
      !> A path_kind.
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      select case (kind)
      case (path_missing)
         name = 'nothing'
      case (path_regular)
         name = 'a regular file'
      case (path_link)
         name = 'a symbolic link'
      case (path_folder)
         name = 'a folder'
      case (path_fifo)
         name = 'a FIFO (named pipe)'
      case (path_socket)
         name = 'a socket'
      case (path_device)
         name = 'a device'
      case default
         name = 'not a regular file'
      end select
   end function kind_name

   !> Why a run must not write a file at `path` whatever it holds ('' when nothing is there, or a
   !> regular file that is not the input): 'is the input file IN.nml', 'is a symbolic link, which
   !> the run would write through', 'is a FIFO (named pipe), not a regular file', ... Nothing is
   !> opened (a FIFO would block the opening).
   function not_writable_here(path, input) result(why)
      !> File the run writes.
      character(len=*), intent(in) :: path
      !> Input file of the run ('' for none).
      character(len=*), intent(in) :: input
      character(len=:), allocatable :: why
      integer :: kind
      why = ''
      kind = path_kind(path, follow=.false.)
      if (kind == path_missing) return
      if (len(input) > 0) then
         if (same_file(path, input)) then
            why = 'is the input file '//input
            return
         end if
      end if
      if (kind == path_link) then
         why = 'is a symbolic link, which the run would write through'
      else if (kind /= path_regular) then
         why = 'is '//kind_name(kind)//', not a regular file'
      end if
   end function not_writable_here

   !> An exclusive lock (flock) on the regular file `path`, on a descriptor of its own, taken
   !> without waiting, never through a symbolic link, never creating nor truncating the file (files.c,
   !> beamstops_lock_file): the descriptor that holds it (>= 0, for unlock_file); lock_busy when
   !> another open file holds a lock on it (HDF5 locks the files it has open); another negative
   !> value when it cannot be locked otherwise (no lock held).
   integer function lock_file(path)
      !> File.
      character(len=*), intent(in) :: path
      lock_file = c_lock_file(path//c_null_char)
   end function lock_file

   !> Release a lock_file lock (nothing for a negative `fd`).
   subroutine unlock_file(fd)
      !> What lock_file gave.
      integer, intent(in) :: fd
      call c_unlock_file(int(fd, c_int))
   end subroutine unlock_file

   !> Whether another open file holds a lock on the existing file `path` (HDF5 locks every file it
   !> has open: another run writing it, or a program reading it). Nothing is written.
   logical function file_in_use(path)
      !> File.
      character(len=*), intent(in) :: path
      file_in_use = c_file_in_use(path//c_null_char) == 1
   end function file_in_use

   !> Whether HDF5 locks the files it opens (not when HDF5_USE_FILE_LOCKING is FALSE or 0).
   logical function hdf5_locks()
      hdf5_locks = c_hdf5_locks() == 1
   end function hdf5_locks

   !> Whether two existing paths name the same file (same device and inode), however spelt.
   function same_file(a, b) result(same)
      !> First path.
      character(len=*), intent(in) :: a
      !> Second path.
      character(len=*), intent(in) :: b
      logical :: same
      same = c_same_file(a//c_null_char, b//c_null_char) == 1
   end function same_file

   !> Whether two paths name one file, existing or not: the same existing file, or the same
   !> name in the same existing folder however spelt (`out.h5`, `./out.h5`, `sub/../out.h5`).
   function same_path(a, b) result(same)
      !> First path.
      character(len=*), intent(in) :: a
      !> Second path.
      character(len=*), intent(in) :: b
      logical :: same
      same = c_same_path(a//c_null_char, b//c_null_char) == 1
   end function same_path

   !> Rename `from` onto `to` (replacing `to` atomically when on the same file system).
   subroutine rename_file(from, to, ok)
      !> Existing file.
      character(len=*), intent(in) :: from
      !> New name.
      character(len=*), intent(in) :: to
      !> Whether the rename happened.
      logical, intent(out) :: ok
      ok = c_rename(from//c_null_char, to//c_null_char) == 0
   end subroutine rename_file

   !> Move the finished file `from` onto `to`, removing a regular file `to` first (not atomic:
   !> for outputs, not checkpoints; beamstops_replace_file in src/beamstops/files.c says why).
   subroutine replace_file(from, to, ok)
      !> Existing file.
      character(len=*), intent(in) :: from
      !> New name.
      character(len=*), intent(in) :: to
      !> Whether the file is now at `to`.
      logical, intent(out) :: ok
      ok = c_replace_file(from//c_null_char, to//c_null_char) == 0
   end subroutine replace_file

   !> Why a run could not write the file `path` (create it, or write it, and rename it in its
   !> folder): the system's reason, e.g. 'File name too long', 'No such file or directory',
   !> 'Permission denied', 'Read-only file system'; '' when it can. Nothing is left behind: a file
   !> created to find out is removed again.
   function creation_error(path) result(why)
      !> File.
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: why
      character(kind=c_char) :: text(256)
      integer(c_int) :: code
      integer :: i
      why = ''
      code = c_creation_errno(path//c_null_char)
      if (code == 0) return
      call c_errno_text(code, text, int(size(text), c_size_t))
      do i = 1, size(text)
         if (text(i) == c_null_char) exit
         why = why//text(i)
      end do
   end function creation_error

   !> Remove a file if it exists.
   subroutine remove_file(path)
      !> File.
      character(len=*), intent(in) :: path
      integer(c_int) :: status
      status = c_remove(path//c_null_char)
   end subroutine remove_file

   !> Raise the end-of-allocation address an HDF5 file's superblock records to the file's size
   !> when the file is longer (files.c, beamstops_raise_hdf5_eoa: a run killed while HDF5 flushed
   !> its file). True when it was raised.
   logical function raise_hdf5_eoa(path)
      !> The HDF5 file.
      character(len=*), intent(in) :: path
      raise_hdf5_eoa = c_raise_hdf5_eoa(path//c_null_char) == 1
   end function raise_hdf5_eoa
end module beamstops_files
