#!/usr/bin/env bash
# Run every test: the Fortran unit tests (meson test, TAP) and the Python tests (pytest)
# against the package installed in .venv by scripts/setup.sh. The build (build/tests) also holds
# the microbenchmarks (-Dbench=true), which tests/python/test_bench_quick.py runs.
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export PATH="$PWD/.venv/bin:$PATH"
build=build/tests
if [ ! -f "$build/build.ninja" ]; then
  meson setup "$build" -Dpython=false -Dtests=true -Dbench=true --buildtype=release >/dev/null || exit 1
fi
meson compile -C "$build" >/dev/null || { meson compile -C "$build"; exit 1; }
meson test -C "$build" --print-errorlogs --num-processes 2
fortran=$?
MPLBACKEND=Agg python -m pytest tests/python -q -p no:cacheprovider "$@"
python_status=$?
if [ "$python_status" -eq 5 ]; then
  echo "test: pytest collected no tests" >&2
  python_status=1
fi
echo "test: meson test exit $fortran, pytest exit $python_status" >&2
[ "$fortran" -eq 0 ] && [ "$python_status" -eq 0 ]
