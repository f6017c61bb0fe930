"""Build helpers shared by scripts/bench.py and tests/python/test_speed_fused.py.

- ``meson_build(build_dir, bench=True)``: a meson build of the engine (configured with
  ``-Dpython=false -Dtests=false``, plus ``-Dbench=true`` for the Fortran microbenchmarks
  when asked), compiled; returns its directory.
- ``step_extension(build_dir)``: the f2py module ``_bench_step`` (scripts/bench_step.f90,
  plain subroutines; their derived types live in scripts/bench_step_state.f90, its recorder
  in bench/null_recorder.f90), compiled against the static library ``libbeamstops.a`` and
  the ``.mod`` files of that build, and imported. It drives the engine one step per call
  from Python, and exposes the fused and LAPACK band solves and whole runs on both paths
  for the tests.

Nothing here is installed: the package's own extension (``beamstops._engine``) has no
per-step entry point, so the per-step loop needs this small module of its own.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path
from types import ModuleType

REPO = Path(__file__).resolve().parent.parent
SCRIPTS = REPO / "scripts"
MODULE = "_bench_step"


def run(cmd: list[str], cwd: Path | None = None, quiet: bool = True) -> None:
    """Run a command; on failure raise with its output."""
    done = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"command failed ({done.returncode}): {' '.join(map(str, cmd))}\n{done.stdout}")
    if not quiet:
        print(done.stdout)


def existing_build(fallback: str) -> Path:
    """A meson build of the engine for the tests to reuse: $BEAMSTOPS_BUILD, else build/tests
    (scripts/test.sh) or build/bench (scripts/bench.py) when configured, else build/`fallback`."""
    if os.environ.get("BEAMSTOPS_BUILD"):
        return Path(os.environ["BEAMSTOPS_BUILD"])
    for name in ("tests", "bench"):
        candidate = REPO / "build" / name
        if (candidate / "build.ninja").exists():
            return candidate
    return REPO / "build" / fallback


def meson_build(build_dir: Path | None = None, bench: bool = True) -> Path:
    """Configure (if needed) and compile a meson build of the engine; return its directory."""
    build_dir = Path(build_dir) if build_dir else REPO / "build" / "bench"
    if not (build_dir / "build.ninja").exists():
        options = ["-Dpython=false", "-Dtests=false", "--buildtype=release"]
        if bench:
            options.append("-Dbench=true")
        run(["meson", "setup", str(build_dir), str(REPO), *options])
    elif bench and not (build_dir / "bench").is_dir():
        run(["meson", "configure", str(build_dir), "-Dbench=true"])
    run(["meson", "compile", "-C", str(build_dir)])
    return build_dir


def module_dir(build_dir: Path) -> Path:
    """The directory holding the engine's .mod files in a meson build."""
    candidates = sorted(Path(build_dir).glob("libbeamstops.a.p"))
    if not candidates or not (candidates[0] / "beamstops_scheme.mod").exists():
        raise FileNotFoundError(f"{build_dir}: no libbeamstops.a.p/beamstops_scheme.mod (not a compiled meson build?)")
    return candidates[0]


def step_extension(build_dir: Path) -> ModuleType:
    """Build (when older than its sources or the engine library) and import _bench_step."""
    build_dir = Path(build_dir).resolve()
    library = build_dir / "libbeamstops.a"
    mods = module_dir(build_dir)
    out = build_dir / "bench-step-ext"
    out.mkdir(exist_ok=True)
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    target = out / f"{MODULE}{suffix}"
    modules = [REPO / "bench" / "null_recorder.f90", SCRIPTS / "bench_step_state.f90"]  # users after what they use
    sources = [*modules, SCRIPTS / "bench_step.f90", library]
    if not target.exists() or target.stat().st_mtime < max(p.stat().st_mtime for p in sources):
        fc = os.environ.get("FC", "gfortran")
        objects = [out / f"{source.stem}.o" for source in modules]
        for source, obj in zip(modules, objects):
            run([fc, "-O2", "-fPIC", "-ffree-line-length-none", "-I", str(mods), "-J", str(out),
                 "-c", str(source), "-o", str(obj)])
        work = out / "f2py"
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir()
        shutil.copy(SCRIPTS / "bench_step.f90", work / "bench_step.f90")
        run([sys.executable, "-m", "numpy.f2py", "-c", "bench_step.f90", "-m", MODULE,
             "--build-dir", str(work / "build"), f"-I{out}", f"-I{mods}",
             *map(str, objects), str(library), "-llapack", "-lblas"], cwd=work)
        built = sorted(work.glob(f"{MODULE}*{suffix}"))
        if not built:
            raise RuntimeError(f"f2py produced no {MODULE}{suffix} in {work}")
        shutil.move(str(built[0]), target)
    spec = importlib.util.spec_from_file_location(MODULE, target)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
