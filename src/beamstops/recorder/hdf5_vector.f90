!> Whole 1-D datasets of doubles in an open HDF5 file: write one, read one back.
!> Shared by the HDF5 writer (fixed datasets) and the checkpoints.
module beamstops_recorder_hdf5_vector
   use hdf5
   use beamstops_kinds, only: wp
   implicit none
   private
   public :: write_vector, read_vector

contains

   !> Create dataset `path` holding `values`; ok is false on any HDF5 failure.
   subroutine write_vector(file, path, values, ok)
      !> Open file (or group).
      integer(hid_t), intent(in) :: file
      !> Dataset path.
      character(len=*), intent(in) :: path
      !> Values to store.
      real(wp), intent(in) :: values(:)
      !> Whether it was written.
      logical, intent(out) :: ok
      integer(hid_t) :: space, dset
      integer(hsize_t) :: dims(1)
      integer :: hdferr, closing
      dims = size(values)
      call h5screate_simple_f(1, dims, space, hdferr)
      call h5dcreate_f(file, path, H5T_NATIVE_DOUBLE, space, dset, hdferr)
      ok = hdferr == 0
      if (ok) then
         call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, values, dims, hdferr)
         ok = hdferr == 0
         call h5dclose_f(dset, closing)
      end if
      call h5sclose_f(space, closing)
   end subroutine write_vector

   !> Read dataset `path` into `values`, which must have its exact size; ok is false otherwise.
   subroutine read_vector(file, path, values, ok)
      !> Open file (or group).
      integer(hid_t), intent(in) :: file
      !> Dataset path.
      character(len=*), intent(in) :: path
      !> Values read.
      real(wp), intent(out) :: values(:)
      !> Whether the dataset exists with that size and was read.
      logical, intent(out) :: ok
      integer(hid_t) :: space, dset
      integer(hsize_t) :: dims(1), maxdims(1)
      integer :: hdferr, rank, closing
      values = 0
      call h5dopen_f(file, path, dset, hdferr)
      ok = hdferr == 0
      if (.not. ok) return
      call h5dget_space_f(dset, space, hdferr)
      call h5sget_simple_extent_ndims_f(space, rank, hdferr)
      ok = rank == 1
      if (ok) then
         call h5sget_simple_extent_dims_f(space, dims, maxdims, hdferr)
         ok = dims(1) == size(values)
      end if
      if (ok) then
         call h5dread_f(dset, H5T_NATIVE_DOUBLE, values, dims, hdferr)
         ok = hdferr == 0
      end if
      call h5sclose_f(space, closing)
      call h5dclose_f(dset, closing)
   end subroutine read_vector
end module beamstops_recorder_hdf5_vector
