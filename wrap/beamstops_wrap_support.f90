!> Helpers of the f2py routines (beamstops_wrap.f90): a scene from the text Python wrote,
!> and errors as a status and a message. f2py never sees this module.
module beamstops_wrap_support
   use beamstops, only: error_type, scene_type, scene_from_text
   implicit none
   private
   public :: scene_of, report

contains

   !> The scene of namelist `text` (Scene.to_namelist's text), read, derived and validated by the
   !> engine's one reader; `source` starts the messages; `carried`: the keys the text carries over
   !> from a scene being changed (scene_from_text).
   subroutine scene_of(text, source, scene, error, carried)
      !> Namelist text.
      character(len=*), intent(in) :: text
      !> Where the text came from ('scene', a file name).
      character(len=*), intent(in) :: source
      !> Scene read.
      type(scene_type), intent(out) :: scene
      !> Set on any bad input.
      type(error_type), allocatable, intent(out) :: error
      !> Keys carried over ('group:key' words).
      character(len=*), intent(in), optional :: carried
      call scene_from_text(text, trim(source), scene, error, carried=carried)
   end subroutine scene_of

   !> Turn an error object into status (0: none, 1: error) and a fixed-length message.
   subroutine report(error, status, message)
      !> Error, if any.
      type(error_type), allocatable, intent(in) :: error
      !> 0 without error, 1 with.
      integer, intent(out) :: status
      !> The error's message (truncated to the buffer), blank without error.
      character(len=*), intent(out) :: message
      status = 0
      message = ''
      if (.not. allocated(error)) return
      status = 1
      message = error%message
   end subroutine report
end module beamstops_wrap_support
