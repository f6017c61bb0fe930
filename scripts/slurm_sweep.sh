#!/usr/bin/env bash
# A beamstops sweep as a Slurm batch job, on MPI ranks (mpi4py.futures):
#
#   sbatch scripts/slurm_sweep.sh input/sweeps/bifurcation.toml out/bifurcation
#   sbatch --ntasks=129 --time=04:00:00 scripts/slurm_sweep.sh SPEC DIR [more sweep options]
#
# Rank 0 runs the sweep (it schedules and writes the summary), ranks 1..N-1 run the
# points, one `beamstops run` each at a time: ask for one task per core plus one. The
# command is the laptop's `python -m beamstops sweep` under `python -m mpi4py.futures`.
# A job stopped by its time limit (SIGTERM) keeps every finished point: submit the same
# job again and it resumes, skipping them.
#
# Run it from the repository (or set BEAMSTOPS_VENV) after `bash scripts/setup.sh`, which
# installs OpenMPI (Debian) and mpi4py into .venv; on a cluster, load the site's MPI module
# and `pip install mpi4py` against it instead.
#SBATCH --job-name=beamstops-sweep
#SBATCH --ntasks=33
#SBATCH --cpus-per-task=1
#SBATCH --time=01:00:00
#SBATCH --output=beamstops-sweep-%j.log
set -euo pipefail

if [ $# -lt 2 ]; then
  echo "usage: sbatch scripts/slurm_sweep.sh SPEC.toml OUTDIR [sweep options]" >&2
  exit 2
fi
spec=$1
out=$2
shift 2

venv=${BEAMSTOPS_VENV:-${SLURM_SUBMIT_DIR:-$PWD}/.venv}
python="$venv/bin/python"
[ -x "$python" ] || { echo "slurm_sweep: no Python at $python (run scripts/setup.sh or set BEAMSTOPS_VENV)" >&2; exit 1; }
export PATH="$venv/bin:$PATH"        # the beamstops program the points run
export OMP_NUM_THREADS=1             # one core per rank: no threaded BLAS inside a point

ranks=${SLURM_NTASKS:-2}
echo "slurm_sweep: $spec -> $out on $ranks ranks ($((ranks - 1)) workers), job ${SLURM_JOB_ID:-none}" >&2
# srun starts the ranks where Slurm placed them; mpiexec is the fallback outside Slurm.
if [ -n "${SLURM_JOB_ID:-}" ] && command -v srun >/dev/null; then
  launch=(srun -n "$ranks")
  # the site's default PMI, or the one named in BEAMSTOPS_SRUN_MPI (pmix, pmi2, ...)
  [ -z "${BEAMSTOPS_SRUN_MPI:-}" ] || launch+=(--mpi="$BEAMSTOPS_SRUN_MPI")
else
  launch=(mpiexec -n "$ranks")
fi
# --interval: one progress line a minute in the job's log.
exec "${launch[@]}" "$python" -m mpi4py.futures -m beamstops sweep "$spec" -o "$out" --interval 60 "$@"
