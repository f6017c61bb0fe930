!> Files as the engine handles them: existence, identity (same file under two names),
!> atomic replacement by rename, removal. The C library and src/beamstops/files.c do the work.
module beamstops_files
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char, c_size_t
   implicit none
   private
   public :: file_exists, is_directory, same_file, same_path, rename_file, replace_file, remove_file, creation_error

   interface
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
      function c_creation_errno(path) bind(c, name='beamstops_creation_errno') result(code)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: code
      end function c_creation_errno
      subroutine c_errno_text(code, text, size) bind(c, name='beamstops_errno_text')
         import :: c_char, c_int, c_size_t
         integer(c_int), value :: code
         character(kind=c_char), intent(out) :: text(*)
         integer(c_size_t), value :: size
      end subroutine c_errno_text
   end interface

contains

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
end module beamstops_files
