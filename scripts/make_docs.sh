#!/usr/bin/env bash
# Regenerate every figure and table the README shows, into docs/ (run after scripts/setup.sh).
# Each is the output of a script of this repository on this machine; nothing is typed in.
#   docs/paper/        scripts/paper_figures.py     the paper's Figures 2-8, report.md
#   docs/bench.md      scripts/bench.py             speed tables
#   docs/convergence/  scripts/convergence.py       convergence tables (markdown, CSV)
#   docs/work_precision/, docs/stability_map/, docs/compliance/, docs/contact_laws/   the studies
#   docs/work_precision_statistics/  the same two studies with --qoi: statistics under impacts
#   docs/bifurcation/  scripts/bifurcation.py       bifurcation diagram (sweep), and its periods table
#   docs/bifurcation_damped/  the same for the damped beam (input/sweeps/bifurcation_damped.toml)
#   docs/stops/        input/tube_supports.nml, scripts/bench_stops.py   stops along the span
#   docs/plan/         scripts/plan_chart.py        which model do I need (plan, stop power to 2 %)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export PATH="$PWD/.venv/bin:$PATH" MPLBACKEND=Agg
python scripts/paper_figures.py --out docs/paper
python scripts/convergence.py -o docs/convergence --quiet
python scripts/study_workprecision.py -o docs/work_precision --quiet
QOIS="stop_power impulse_rate shock_rate contact_fraction tip_rms"
python scripts/study_workprecision.py --qoi $QOIS -o docs/work_precision_statistics --quiet
python scripts/convergence.py --qoi $QOIS -o docs/work_precision_statistics --quiet
python scripts/study_stability.py -o docs/stability_map --quiet
python scripts/study_compliance.py -o docs/compliance --quiet
python scripts/study_contact_laws.py -o docs/contact_laws --quiet
python scripts/bifurcation.py -o out/bifurcation --png docs/bifurcation/bifurcation.png -q
python scripts/bifurcation.py --spec input/sweeps/bifurcation_damped.toml -o out/bifurcation_damped \
    --png docs/bifurcation_damped/bifurcation.png -q
python scripts/bench.py --out docs/bench.md
mkdir -p out docs/stops
beamstops run input/tube_supports.nml -o out/tube_supports.h5 >/dev/null
python -m beamstops plot out/tube_supports.h5 --kind stops -o docs/stops/tube_supports_stops.png >/dev/null
python scripts/bench_stops.py --out docs/stops/bench_stops.md
python scripts/plan_chart.py -o docs/plan --quiet
# keep the images and tables, not the HDF5 files of the runs
find docs -name '*.h5' -delete
