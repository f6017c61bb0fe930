!> The root attributes of a run's output, from the one scene table: the scene's keys, its
!> canonical text (`scene`), the engine's version, the model's spectrum and limits, and at the
!> end the summary. The HDF5 writer writes them; the Python wrapper hands the same list over.
module beamstops_output_attributes
   use beamstops_kinds, only: ik
   use beamstops_scene, only: scene_type, scene_table, canonical_text
   use beamstops_model, only: model_type
   use beamstops_summary, only: run_summary
   use beamstops_version, only: version
   use beamstops_attributes, only: attribute_list
   implicit none
   private
   public :: run_attributes, summary_attributes

contains

   !> Attributes known before the run: version, the scene (keys and canonical text without the
   !> output file), the Rayleigh coefficients a and b in use (from the ratio form too) and the
   !> model's kappa_h, kappa_bound and time-step limits.
   function run_attributes(scene, model) result(list)
      !> Scene.
      type(scene_type), intent(in) :: scene
      !> Its model.
      type(model_type), intent(in) :: model
      type(attribute_list) :: list
      call list%add_text('', 'version', version)
      call list%extend(scene_table(scene))
      call list%add_text('', 'scene', canonical_text(scene, with_file=.false.))
      call list%add_real('', 'damping_a', model%damping_a)
      call list%add_real('', 'damping_b', model%damping_b)
      call list%add_real('', 'kappa_h', model%kappa_h)
      call list%add_real('', 'kappa_bound', model%kappa_bound)
      call list%add_real('', 'dt_limit_newmark', model%dt_newmark)
      call list%add_real('', 'dt_limit_paper', model%dt_paper_exact)
      call list%add_real('', 'dt_limit_paper_bound', model%dt_paper_bound)
   end function run_attributes

   !> Attributes of the outcome: steps, t_final, cpu_seconds, impacts, max_violation, the energy
   !> ledger (work, dissipated, damped, energy_residual; J) and (when not
   !> complete) message; the status is written last, by each consumer.
   function summary_attributes(summary) result(list)
      !> Outcome of the run.
      type(run_summary), intent(in) :: summary
      type(attribute_list) :: list
      call list%add_int('', 'steps', summary%steps)
      call list%add_real('', 't_final', summary%t_final)
      call list%add_real('', 'cpu_seconds', summary%cpu_seconds)
      call list%add_int('', 'impacts', summary%impacts)
      call list%add_int('', 'contact_phases', summary%contact_phases)
      call list%add_real('', 'max_violation', summary%max_violation)
      call list%add_real('', 'work', summary%work)
      call list%add_real('', 'dissipated', summary%dissipated)
      call list%add_real('', 'damped', summary%damped)
      call list%add_real('', 'energy_residual', summary%energy_residual)
      if (allocated(summary%message)) call list%add_text('', 'message', summary%message)
   end function summary_attributes
end module beamstops_output_attributes
