!> The shock log and the statistics of a run in its HDF5 output:
!>
!>   /impacts/NAME       one row per shock: t_start, t_end, stop, side, velocity_in, velocity_out,
!>                       impulse, peak_reaction, energy_taken, contact_time, rebounds,
!>                       contact_steps, truncated (attribute units)
!>   /statistics/NAME    (count, 2): value and 95 % half-width of each entry (attributes units,
!>                       axis: 'stop', 'tip', 'run', 'bin' or 'edge'); group attributes
!>                       transient, batches, bins, rest_time
module beamstops_recorder_hdf5_observations
   use, intrinsic :: iso_c_binding, only: c_loc, c_ptr
   use hdf5
   use beamstops_kinds, only: wp, ik
   use beamstops_observe_shocks, only: n_shock_columns, shock_column_names, shock_column_units
   use beamstops_observe_statistics, only: statistics_table
   implicit none
   private
   public :: write_observations

contains

   !> Write /impacts and /statistics into an open file; `ok` false when a write failed.
   subroutine write_observations(file, shocks, table, transient, batches, bins, rest_time, ok, ensemble, members)
      !> Open HDF5 file.
      integer(hid_t), intent(in) :: file
      !> The shocks, one column each (n_shock_columns, shocks).
      real(wp), intent(in) :: shocks(:, :)
      !> The statistics.
      type(statistics_table), intent(in) :: table
      !> The statistics' settings, written as attributes of /statistics.
      real(wp), intent(in) :: transient, rest_time
      !> Batches and bins.
      integer, intent(in) :: batches, bins
      !> False when something could not be written.
      logical, intent(out) :: ok
      !> The statistics across the members of an ensemble (/ensemble, same layout as /statistics)
      !> and their number (written when > 1).
      type(statistics_table), intent(in), optional :: ensemble
      integer, intent(in), optional :: members
      integer(hid_t) :: group
      integer :: hdferr, i
      real(wp), allocatable :: pair(:, :)
      ok = .true.
      call h5gcreate_f(file, 'impacts', group, hdferr)
      if (hdferr /= 0) then
         ok = .false.
         return
      end if
      do i = 1, n_shock_columns
         call write_dataset(group, trim(shock_column_names(i)), [size(shocks, 2, hsize_t)], shocks(i, :), &
            & trim(shock_column_units(i)), '')
      end do
      call h5gclose_f(group, hdferr)
      if (.not. allocated(table%quantity)) return
      call write_table('statistics', table)
      if (present(ensemble) .and. present(members)) then
         if (members > 1 .and. allocated(ensemble%quantity)) call write_table('ensemble', ensemble, members)
      end if

   contains

      !> A group of one dataset (count, 2) per quantity of `t`, with the settings as attributes.
      subroutine write_table(name, t, members)
         character(len=*), intent(in) :: name
         type(statistics_table), intent(in) :: t
         integer, intent(in), optional :: members
         integer :: err
         call h5gcreate_f(file, name, group, err)
         if (err /= 0) then
            ok = .false.
            return
         end if
         call real_attribute(group, 'transient', transient)
         call real_attribute(group, 'rest_time', rest_time)
         call int_attribute(group, 'batches', int(batches, ik))
         call int_attribute(group, 'bins', int(bins, ik))
         if (present(members)) call int_attribute(group, 'members', int(members, ik))
         do i = 1, size(t%quantity)
            associate (q => t%quantity(i))
               pair = reshape([q%value, q%half_width], [size(q%value), 2])
               pair = transpose(pair)
               call write_dataset(group, q%name, [2_hsize_t, size(q%value, kind=hsize_t)], pair, q%unit, q%axis)
            end associate
         end do
         call h5gclose_f(group, err)
      end subroutine write_table

      !> A dataset of `dims` (Fortran order) from `values`, with attributes units (and axis).
      subroutine write_dataset(where, name, dims, values, units, axis)
         integer(hid_t), intent(in) :: where
         character(len=*), intent(in) :: name, units, axis
         integer(hsize_t), intent(in) :: dims(:)
         real(wp), intent(in), target, contiguous :: values(..)
         integer(hid_t) :: space, dset
         integer :: err
         type(c_ptr) :: buffer
         call h5screate_simple_f(size(dims), dims, space, err)
         call h5dcreate_f(where, name, H5T_NATIVE_DOUBLE, space, dset, err)
         if (err /= 0) then
            ok = .false.
            call h5sclose_f(space, err)
            return
         end if
         select rank (values)
         rank (1)
            buffer = c_loc(values)
         rank (2)
            buffer = c_loc(values)
         end select
         call h5dwrite_f(dset, H5T_NATIVE_DOUBLE, buffer, err)
         if (err /= 0) ok = .false.
         call text_attribute(dset, 'units', units)
         if (len(axis) > 0) call text_attribute(dset, 'axis', axis)
         call h5dclose_f(dset, err)
         call h5sclose_f(space, err)
      end subroutine write_dataset

      subroutine text_attribute(object, name, value)
         integer(hid_t), intent(in) :: object
         character(len=*), intent(in) :: name, value
         integer(hid_t) :: space, atype, attr
         integer(hsize_t) :: one(1) = 1
         integer :: err
         call h5screate_f(H5S_SCALAR_F, space, err)
         call h5tcopy_f(H5T_C_S1, atype, err)
         call h5tset_size_f(atype, int(max(1, len(value)), size_t), err)
         call h5acreate_f(object, name, atype, space, attr, err)
         call h5awrite_f(attr, atype, value, one, err)
         if (err /= 0) ok = .false.
         call h5aclose_f(attr, err)
         call h5tclose_f(atype, err)
         call h5sclose_f(space, err)
      end subroutine text_attribute

      subroutine real_attribute(object, name, value)
         integer(hid_t), intent(in) :: object
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: value
         integer(hid_t) :: space, attr
         integer(hsize_t) :: one(1) = 1
         integer :: err
         call h5screate_f(H5S_SCALAR_F, space, err)
         call h5acreate_f(object, name, H5T_NATIVE_DOUBLE, space, attr, err)
         call h5awrite_f(attr, H5T_NATIVE_DOUBLE, value, one, err)
         if (err /= 0) ok = .false.
         call h5aclose_f(attr, err)
         call h5sclose_f(space, err)
      end subroutine real_attribute

      subroutine int_attribute(object, name, value)
         integer(hid_t), intent(in) :: object
         character(len=*), intent(in) :: name
         integer(ik), intent(in) :: value
         integer(ik), target :: buffer
         integer(hid_t) :: space, attr
         integer :: err
         buffer = value
         call h5screate_f(H5S_SCALAR_F, space, err)
         call h5acreate_f(object, name, H5T_STD_I64LE, space, attr, err)
         call h5awrite_f(attr, h5kind_to_type(ik, H5_INTEGER_KIND), c_loc(buffer), err)
         if (err /= 0) ok = .false.
         call h5aclose_f(attr, err)
         call h5sclose_f(space, err)
      end subroutine int_attribute
   end subroutine write_observations
end module beamstops_recorder_hdf5_observations
