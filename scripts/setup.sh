#!/usr/bin/env bash
# Set up beamstops on a fresh Debian machine: the system packages it builds against
# (gfortran, LAPACK/BLAS, HDF5 with its Fortran API, pkg-config), then a Python
# virtual environment .venv with beamstops installed in it (`pip install .`), which
# puts the `beamstops` program in .venv/bin and the `beamstops` package in Python.
# Safe to run again: it installs only what is missing and rebuilds the package.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

python=${PYTHON:-python3}
missing=()
command -v gfortran >/dev/null || missing+=(gfortran)
command -v pkg-config >/dev/null || missing+=(pkg-config)
if command -v pkg-config >/dev/null; then
  pkg-config --exists lapack || missing+=(liblapack-dev libblas-dev)
  pkg-config --exists hdf5 || missing+=(libhdf5-dev)
else
  missing+=(liblapack-dev libblas-dev libhdf5-dev)
fi
command -v "$python" >/dev/null || missing+=(python3)
if command -v "$python" >/dev/null; then
  "$python" -c 'import venv, ensurepip' 2>/dev/null || missing+=(python3-venv)
  inc=$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
  [ -f "$inc/Python.h" ] || missing+=(python3-dev)
fi
# MPI, for sweeps on several ranks (python -m mpi4py.futures -m beamstops sweep): optional;
# installed when root, otherwise named below (the MPI tests then skip).
optional=()
command -v mpiexec >/dev/null || optional+=(openmpi-bin libopenmpi-dev)
if [ "$(id -u)" -eq 0 ] && [ ${#optional[@]} -gt 0 ]; then
  missing+=("${optional[@]}")
  optional=()
fi
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    echo "setup: installing Debian packages: ${missing[*]}" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}" build-essential >/dev/null
  else
    echo "setup: missing system packages; run as root:" >&2
    echo "  sudo apt-get install -y ${missing[*]} build-essential" >&2
    exit 1
  fi
fi
if [ ${#optional[@]} -gt 0 ]; then
  echo "setup: optional, for MPI sweeps: sudo apt-get install -y ${optional[*]}" >&2
fi

if [ ! -x .venv/bin/python ]; then
  "$python" -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip
# Build tools for the Fortran tests (meson test), then the package itself.
.venv/bin/python -m pip install -q 'meson>=1.1' ninja meson-python numpy pytest
.venv/bin/python -m pip install -q --no-build-isolation '.[test]'
# mpi4py (PyPI) over the system's MPI, for sweeps on MPI ranks.
if command -v mpiexec >/dev/null; then
  .venv/bin/python -m pip install -q mpi4py
fi
echo "setup: ready: $(.venv/bin/beamstops --version) in .venv (program .venv/bin/beamstops)" >&2
