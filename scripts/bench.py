#!/usr/bin/env python3
"""How fast beamstops runs the Dumont-Paoli scheme, measured side by side in one run.

    python scripts/bench.py                 # the full tables (a few minutes)
    python scripts/bench.py --quick         # the same tables, shorter runs (CI smoke use)
    python scripts/bench.py --out bench.md  # also write the markdown to a file

What it measures, on this machine, in one process (medians of --repeats repeats; every
ratio is computed from numbers of the same run):

- the ``beamstops`` program on the paper's scene (J = 19): Figure 4 (Signorini, beta = 1/2,
  dt = 1e-6, T = 2 s, two million steps, the tip recorded every step) and the same with
  normal compliance (1/eps = 1e8 per unit mass, beta = 1/4); the engine's own
  ``cpu_seconds`` attribute (time loop only) from the HDF5 output, and the wall time of the
  whole program (start-up and output included);
- the engine's loop alone (bench/bench_kernels: start_state + advance with a recorder that
  keeps nothing), on its fused path and on the LAPACK reference path (dpbtrs and one pass
  per operation, ``state%lapack_solve``);
- the same scheme in numpy/scipy, the way a user would write it (scripts/reference_scheme.py:
  ``cholesky_banded`` once, ``cho_solve_banded`` every step), and a loop driven from Python
  that calls the engine once per step through a small f2py module (scripts/bench_step.f90,
  built by scripts/bench_ext.py against the same build): the cost of crossing the
  language boundary at every step;
- the floor: the two triangular solves are a chain of 2n dependent multiply-adds (n = 2J
  unknowns); with the multiply-add latency measured here (the least of many short dependent
  chains, in thread CPU time: a chain is never faster than the latency, only slower when the
  core is shared), 2n latencies is a lower bound of
  any step that substitutes row by row. The operation count over the measured peak rate of
  independent multiply-adds, and (for large J) the bytes a step must move over the measured
  memory bandwidth, are the other two bounds; the floor is the largest of the three;
- scaling in J from 19 to 1e5 (time per step and per unknown, peak memory of the program),
  and in the number of records (record_every);
- lockstep ensembles (scripts/bench_lockstep.py): member-steps per second per core, one at a time
  against K = 1..16 members in lockstep, J = 19 and 100, with their floor;
- the paper's CPU-time table beside ours;
- the paper's Figure 4 run against issue 15's targets: the whole ``beamstops run`` process within
  1.15x the engine loop with nothing recorded, that loop within 2x the chain floor;
- a peer on the same scene (scripts/bench_peer.py under ``/usr/bin/python3``: Siconos from
  Debian's ``python3-siconos``), µs per step and its largest violation of the stops beside ours;
  skipped with a note when it does not import.

The build: --build DIR (a meson build directory; configured with -Dbench=true if needed),
else build/bench, configured and compiled here. The program: --program PATH, else the
build's ``beamstops``, else ``beamstops`` on PATH.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import scipy

SCRIPTS = Path(__file__).resolve().parent
sys.path.insert(0, str(SCRIPTS))

# The engine factors A once; a threaded BLAS under LAPACK (OpenBLAS, where Debian's
# liblapack.so.3 points to it) would start threads that spin after that call and take CPU time
# and a core from the measured process. One thread, for every program this script runs.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import bench_ext  # noqa: E402
import bench_lockstep  # noqa: E402
import reference_scheme  # noqa: E402

# The paper's CPU times (SPEC 2; Scilab on a 1.1 GHz PowerPC G4), its runs: figure ->
# (law, beta, dt, seconds). T = 2 s, J = 19 for all.
PAPER = {
    2: ("signorini", 0.5, 5e-5, 18.24),
    3: ("signorini", 0.5, 5e-6, 173.71),
    4: ("signorini", 0.5, 1e-6, 870.45),
    5: ("compliance", 0.25, 5e-6, 241.17),
    6: ("compliance", 0.25, 1e-6, 1187.9),
    7: ("compliance", 0.25, 5e-7, 2426.4),
    8: ("signorini", 0.25, 1e-6, 859.38),
}
STIFFNESS = 1e8  # the paper's 1/eps, per unit mass
BYTES = 8


# ----------------------------------------------------------------------------------- tools
def median(values: list[float]) -> float:
    return statistics.median(values)


def fmt(x: float, digits: int = 3) -> str:
    """Shortest readable number: 3 significant digits, no exponent between 1e-3 and 1e5."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e5:
        decimals = max(0, digits - 1 - int(math.floor(math.log10(abs(x)))))
        return f"{x:.{decimals}f}"
    return f"{x:.{digits - 1}e}"


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def kernels(binary: Path, *args: object) -> dict[str, float]:
    """Run bench_kernels and parse its `key value` lines."""
    out = subprocess.run([str(binary), *map(str, args)], check=True, capture_output=True, text=True).stdout
    return {k: float(v) for k, v in (line.split() for line in out.splitlines() if line.strip())}


@dataclass
class ProgramRun:
    cpu_seconds: float  # the engine's time loop (HDF5 attribute cpu_seconds)
    wall_seconds: float  # the whole program
    steps: int
    max_rss_mb: float  # peak resident memory of the program
    output_mb: float


def namelist(path: Path, out: Path, *, law="signorini", beta=0.5, dt=1e-6, t_end=2.0, elements=19,
             record_every=1, extra: str = "", stops_extra: str = "", mesh_extra: str = "") -> None:
    stops = f"law='{law}'" + (f", stiffness_per_mass={STIFFNESS:g}" if law == "compliance" else "") + stops_extra
    path.write_text(
        "&beam     length=1.501, k2=282.84, mass_per_length=0.11938 /\n"
        "&support  amplitude=0.2, omega=10.0 /\n"
        f"&stops    lower=-0.1, upper=0.1, {stops} /\n"
        f"&mesh     elements={elements}{mesh_extra} /\n"
        f"&time     dt={dt:g}, t_end={t_end:.12g}, beta={beta:g}, load_rule='paper', start='euler' /\n"
        f"&output   file='{out}', record_every={record_every}, snapshot_every=0, max_output_gb=100 /\n" + extra)


def peak_rss_mb(pid: int) -> float | None:
    """VmHWM of a running process (its peak resident memory so far), MB; None once it is gone."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    found = re.search(r"VmHWM:\s*(\d+)\s*kB", status)
    return int(found.group(1)) / 1024 if found else None


def run_program(program: Path, work: Path, **scene) -> ProgramRun:
    nml, out = work / "scene.nml", work / "out.h5"
    namelist(nml, out, **scene)
    start = time.perf_counter()
    proc = subprocess.Popen([str(program), "run", str(nml)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    # The peak resident memory of the program itself (the rusage of a child forked from
    # Python would count the interpreter's pages too): VmHWM, read until the process ends.
    peak = 0.0
    while proc.poll() is None:
        peak = max(peak, peak_rss_mb(proc.pid) or 0.0)
        time.sleep(0.002)
    wall = time.perf_counter() - start
    err = proc.stderr.read().decode()
    proc.stderr.close()
    if proc.returncode != 0:
        raise RuntimeError(f"{program} run failed: {err}")
    with h5py.File(out, "r") as f:
        cpu, steps = float(f.attrs["cpu_seconds"]), int(f.attrs["steps"])
    size = out.stat().st_size / 1e6
    out.unlink()
    return ProgramRun(cpu, wall, steps, peak, size)


def program_median(program: Path, work: Path, repeats: int, **scene) -> ProgramRun:
    runs = [run_program(program, work, **scene) for _ in range(repeats)]
    return ProgramRun(median([r.cpu_seconds for r in runs]), median([r.wall_seconds for r in runs]),
                      runs[0].steps, max(r.max_rss_mb for r in runs), runs[0].output_mb)


# ------------------------------------------------------------------------------- sections
def machine(build: Path, program: Path) -> str:
    cpu = platform.processor()
    try:
        info = Path("/proc/cpuinfo").read_text()
        cpu = re.search(r"model name\s*:\s*(.*)", info).group(1).strip()
        flags = set(re.search(r"flags\s*:\s*(.*)", info).group(1).split())
        # the widest vectors the native build's kernels use (the energy sums, the record's test)
        cpu += " (AVX-512)" if "avx512f" in flags else " (AVX2, no AVX-512)" if "avx2" in flags else ""
    except (OSError, AttributeError):
        pass
    fc = subprocess.run([os.environ.get("FC", "gfortran"), "--version"], capture_output=True, text=True).stdout
    lapack = "?"
    try:
        ldd = subprocess.run(["ldd", str(program)], capture_output=True, text=True).stdout
        lapack = ", ".join(sorted({Path(m).name for m in re.findall(r"=> (\S*(?:lapack|blas)\S*)", ldd)})) or "static"
    except OSError:
        pass
    options = ""
    intro = build / "meson-info" / "intro-buildoptions.json"
    if intro.exists():
        import json
        opts = {o["name"]: o["value"] for o in json.loads(intro.read_text())}
        options = f"buildtype={opts.get('buildtype')}, native={opts.get('native')}"
    return (f"Machine: {cpu}, {os.cpu_count()} logical CPUs, {platform.system()} {platform.release()}; "
            f"{fc.splitlines()[0] if fc else 'no gfortran'} ({options}); LAPACK/BLAS: {lapack} "
            f"(OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}); "
            f"Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}.")


def python_loops(ext, steps: int, repeats: int) -> dict[str, float]:
    """µs/step: numpy/scipy scheme, and the engine called once per step from Python."""
    numpy_us, crossing_us, one_call_us = [], [], []
    for _ in range(repeats):
        res = reference_scheme.run_reference(J=19, dt=1e-6, t_end=steps * 1e-6, beta=0.5,
                                             load_rule="paper", start="euler")
        numpy_us.append(1e6 * float(res["cpu_seconds"]) / int(res["steps"]))
        assert ext.init(19, 1e-6, 2.0, 0.5, 1, 0.0, 1, 0) == 0
        step = ext.step
        start = time.process_time()
        for _ in range(steps):
            step()
        crossing_us.append(1e6 * (time.process_time() - start) / steps)
        assert ext.init(19, 1e-6, 2.0, 0.5, 1, 0.0, 1, 0) == 0
        start = time.process_time()
        ext.steps(steps)
        one_call_us.append(1e6 * (time.process_time() - start) / steps)
    return {"numpy": median(numpy_us), "per_step_call": median(crossing_us), "one_call": median(one_call_us)}


def step_ops(n: int, record: bool) -> int:
    """Floating-point operations of one fused step (a multiply-add counts one): S u 7n,
    right-hand side 2n, forward substitution 3n + scaling n, back substitution 3n, update of
    d and u 3n, g.d n; recording adds M d 7n and three dot products 3n."""
    return (7 + 2 + 4 + 3 + 3 + 1) * n + ((7 + 3) * n if record else 0)


def step_bytes(n: int, record: bool) -> int:
    """Bytes one step must move when nothing stays in cache: read S (4n), the factor (3n
    multipliers + n scalings), g, z, u, d; write u, d, S u; w once out and back between the
    two sweeps (they run in opposite directions); recording reads M (4n)."""
    return BYTES * ((4 + 4 + 1 + 1 + 1 + 1) + 3 + 2 + (4 if record else 0)) * n


def machine_busy_seconds() -> tuple[float, float] | None:
    """(CPU seconds all CPUs have been busy since boot, of which the host's steal), from
    /proc/stat's first line (None where there is none): its resolution is a clock tick (10 ms)."""
    try:
        fields = [int(v) for v in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    except (OSError, ValueError):
        return None
    tick = os.sysconf("SC_CLK_TCK")
    user, nice, system, _idle, _iowait, irq, softirq, steal = (fields + [0] * 8)[:8]
    return (user + nice + system + irq + softirq + steal) / tick, steal / tick


@dataclass
class ProcessRun:
    """One ``beamstops run``: wall s, CPU s of the whole process (user + system, every thread),
    the engine's cpu_seconds, and the CPU s the machine's other processes (and the host's steal)
    took meanwhile (NaN where /proc/stat is not there)."""
    wall: float
    cpu: float
    cpu_loop: float
    others: float
    steal: float


def process_run(program: Path, work: Path, **scene) -> ProcessRun:
    """Run ``beamstops run`` once on the scene and time it."""
    nml, out = work / "scene.nml", work / "out.h5"
    namelist(nml, out, **scene)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    busy_before = machine_busy_seconds()
    start = time.perf_counter()
    subprocess.run([str(program), "run", str(nml)], check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    busy_after = machine_busy_seconds()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    with h5py.File(out, "r") as f:
        cpu_loop = float(f.attrs["cpu_seconds"])
    out.unlink()
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    others = steal = math.nan
    if busy_before is not None and busy_after is not None:
        others = max(0.0, busy_after[0] - busy_before[0] - cpu)
        steal = busy_after[1] - busy_before[1]
    return ProcessRun(wall, cpu, cpu_loop, others, steal)


def figure4_targets(program: Path, kernels_bin: Path, work: Path, quick: bool, repeats: int,
                    latency: float) -> str:
    """Issue 15's targets on the paper's Figure 4 run (J = 19, dt = 1e-6, 2,000,000 steps, tip and
    energies recorded every step): the whole process within 1.15x the engine loop with nothing
    recorded, that loop within 2x the chain floor. Each time is the least of the repeats (on a
    shared machine a run is only ever slowed down), the loop and the process interleaved."""
    t_end = 0.2 if quick else 2.0
    steps = int(round(t_end / 1e-6))
    runs, free, recorded, short = [], [], [], []
    for _ in range(max(repeats, 3)):
        runs.append(process_run(program, work, law="signorini", beta=0.5, dt=1e-6, t_end=t_end))
        short.append(process_run(program, work, law="signorini", beta=0.5, dt=1e-6, t_end=100e-6).wall)
        free.append(kernels(kernels_bin, "step", 19, "signorini", 0, steps, 1, "fused")["step_fused_ns"])
        recorded.append(kernels(kernels_bin, "step", 19, "signorini", 1, steps, 1, "fused")["step_fused_ns"])
    wall = min(r.wall for r in runs)
    cpu = min(r.cpu for r in runs)
    cpu_loop = min(r.cpu_loop for r in runs)
    others = sum(r.others for r in runs) / sum(r.wall for r in runs)
    steal = sum(r.steal for r in runs) / sum(r.wall for r in runs)
    loop_ns, recorded_ns, fixed = min(free), min(recorded), min(short)
    loop_s = loop_ns * 1e-9 * steps
    floor_ns = 2 * 38 * latency
    process_ratio, floor_ratio = wall / loop_s, loop_ns / floor_ns
    rows = [
        ["engine loop, nothing recorded (bench_kernels step, thread CPU)", fmt(loop_s), fmt(loop_ns), "1"],
        ["engine loop, every step recorded to a recorder that keeps nothing", fmt(recorded_ns * 1e-9 * steps),
         fmt(recorded_ns), fmt(recorded_ns / loop_ns)],
        ["`beamstops run`: its time loop (`cpu_seconds`: the loop's thread, records included; the HDF5 writes "
         "on the writer thread)", fmt(cpu_loop),
         fmt(1e9 * cpu_loop / steps), fmt(1e9 * cpu_loop / steps / loop_ns)],
        ["`beamstops run`: the whole process, CPU (user + system, all threads)", fmt(cpu), fmt(1e9 * cpu / steps),
         fmt(1e9 * cpu / steps / loop_ns)],
        ["**`beamstops run`: the whole process, wall**", fmt(wall), fmt(1e9 * wall / steps),
         f"**{process_ratio:.2f}**"],
        ["of which the fixed cost of a run: `beamstops run` of 100 steps of the scene, wall (start, input, "
         "file, end)", fmt(fixed), fmt(1e9 * fixed / steps), fmt(1e9 * fixed / steps / loop_ns)],
        ["chain floor: 2n = 76 dependent multiply-adds", fmt(floor_ns * 1e-9 * steps), fmt(floor_ns),
         fmt(floor_ns / loop_ns)],
    ]
    lines = [f"### The paper's Figure 4 run at the floor (issue 15; {steps:,} steps{', --quick' if quick else ''})\n",
             "Least of the repeats, loop and process interleaved; the scene of input/paper_fig4.nml (tip and "
             "energies recorded every step, HDF5).\n",
             table(["", "s", "ns per step", "× loop"], rows), "",
             f"- whole process / engine loop with nothing recorded: **{process_ratio:.2f}×** (target ≤ 1.15×: "
             f"{'met' if process_ratio <= 1.15 else 'NOT met'}); by the process's CPU time "
             f"{cpu / loop_s:.2f}× (load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs during the "
             "run: the wall time also counts the moments the process waits for a core)",
             f"- the second CPU: the HDF5 writes run on a thread of their own, beside the loop; while the program ran, "
             f"other processes took {others:.2f} CPUs on average and the host's steal {steal:.2f} (/proc/stat, "
             "10 ms ticks). With another process busy on the other CPU the loop and the writer share one, and the "
             "whole process's wall approaches its CPU time (the ratio above by CPU time)",
             f"- engine loop / chain floor ({fmt(latency)} ns a multiply-add): **{floor_ratio:.2f}×** (target ≤ 2×: "
             f"{'met' if floor_ratio <= 2 else 'NOT met'})", ""]
    return "\n".join(lines)


def peer_section(program: Path, work: Path, quick: bool) -> str:
    """The paper's scene at dt = 5e-5 in Siconos (scripts/bench_peer.py under /usr/bin/python3) beside
    the program: µs per step and the largest violation of the stops."""
    python = Path("/usr/bin/python3")
    head = "### A peer on the paper's scene: Siconos (dt = 5e-5 s, J = 19)\n"
    if not python.exists():
        return head + "\nSkipped: no /usr/bin/python3.\n"
    done = subprocess.run([str(python), str(SCRIPTS / "bench_peer.py"), *(["--quick"] if quick else [])],
                          capture_output=True, text=True)
    if done.returncode != 0:
        return head + f"\nSkipped: scripts/bench_peer.py failed: {done.stderr.strip().splitlines()[-1:]}\n"
    peer = json.loads(done.stdout)
    if not peer["available"]:
        return head + f"\nSkipped: {peer['note']}\n"
    nml, out = work / "scene.nml", work / "out.h5"
    namelist(nml, out, law="signorini", beta=0.5, dt=peer["dt"], t_end=peer["t_end"], record_every=1)
    # on one CPU, so that the program has no writer thread and its time loop's CPU time counts the
    # HDF5 writes too, as Siconos' loop does all its work in its own thread
    cpu = min(os.sched_getaffinity(0))
    subprocess.run([str(program), "run", str(nml)], check=True, stdout=subprocess.DEVNULL,
                   preexec_fn=lambda: os.sched_setaffinity(0, {cpu}))
    with h5py.File(out, "r") as f:
        ours_us = 1e6 * float(f.attrs["cpu_seconds"]) / int(f.attrs["steps"])
        ours_violation = float(f.attrs["max_violation"])
    out.unlink()
    rows = [
        ["`beamstops run` (Signorini projection, β = 1/2; tip recorded every step; `cpu_seconds`, on one CPU: "
         "the HDF5 writes in the loop's thread)",
         fmt(ours_us), fmt(ours_violation) if ours_violation > 0 else "0", "1"],
        [f"Siconos ({peer['version']}): MoreauJeanOSI θ = 1/2, LCP, two unilateral relations, "
         "its own C++ step (`computeOneStep`)", fmt(peer["us_per_step"]), fmt(peer["max_violation"]),
         f"{peer['us_per_step'] / ours_us:,.0f}"],
    ]
    return "\n".join([
        head,
        f"{peer['t_end']:g} s of the paper's scene ({peer['steps']:,} steps), the same finite elements (M, S and the "
        "support's load from scripts/reference_scheme.py; the load sin(ωt) g carried by one more degree of freedom, "
        "an oscillator, so that no Python runs inside Siconos' step); CPU time of the process. Siconos' loop "
        f"driven from Python, one call a step ({fmt(peer['us_per_step_watched'])} µs/step when it also reads the "
        "tip each step for the violation).\n",
        table(["", "µs per step", "largest violation of the stops (m)", "× beamstops"], rows), ""])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="short runs (a few seconds of measuring), for CI")
    parser.add_argument("--build", type=Path, help="meson build directory (default build/bench, made if missing)")
    parser.add_argument("--program", type=Path, help="the beamstops program (default: the build's, else PATH)")
    parser.add_argument("--baseline", type=Path,
                        help="another beamstops program (e.g. built from an older commit) to time beside this one")
    parser.add_argument("--repeats", type=int, default=None, help="repeats of every measurement (default 5, quick 3)")
    parser.add_argument("--out", type=Path, help="also write the markdown here")
    args = parser.parse_args()
    quick = args.quick
    repeats = args.repeats or (3 if quick else 5)

    build = bench_ext.meson_build(args.build, bench=True)
    kernels_bin = build / "bench" / "bench_kernels"
    program = args.program or (build / "beamstops" if (build / "beamstops").exists() else None)
    program = program or (Path(shutil.which("beamstops")) if shutil.which("beamstops") else None)
    if program is None:
        parser.error("no beamstops program: give --program or --build")
    ext = bench_ext.step_extension(build)
    t_end = 0.2 if quick else 2.0  # seconds of simulated time for the J = 19 program runs
    out: list[str] = []
    say = out.append

    # ------------------------------------------------------------ floor ingredients
    fma = kernels(kernels_bin, "fma", repeats)
    latency, rate = fma["fma_latency_ns"], fma["fma_per_ns"]
    triad = kernels(kernels_bin, "triad", 256_000, repeats)["triad_GBps"]  # memory (3 x 256 MB)
    solve = kernels(kernels_bin, "solve", 19, repeats)

    # ------------------------------------------------------------ J = 19, per step
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        fig4 = program_median(program, work, repeats, law="signorini", beta=0.5, dt=1e-6, t_end=t_end)
        comp = program_median(program, work, repeats, law="compliance", beta=0.25, dt=1e-6, t_end=t_end)
        if args.baseline:
            base_sig = program_median(args.baseline, work, repeats, law="signorini", beta=0.5, dt=1e-6, t_end=t_end)
            base_comp = program_median(args.baseline, work, repeats, law="compliance", beta=0.25, dt=1e-6,
                                       t_end=t_end)
        loop_steps = 200_000 if quick else 2_000_000
        loop = {law: kernels(kernels_bin, "step", 19, law, 1, loop_steps, repeats)
                for law in ("signorini", "compliance")}
        loop_free = {law: kernels(kernels_bin, "step", 19, law, 0, loop_steps, repeats)
                     for law in ("signorini", "compliance")}
        py = python_loops(ext, 2_000 if quick else 20_000, repeats)

        n = 38
        chain = 2 * n * latency
        ops_floor = {r: step_ops(n, r) / rate for r in (False, True)}
        floor = {r: max(chain, ops_floor[r]) for r in (False, True)}
        us = 1e-3
        sig_prog = 1e6 * fig4.cpu_seconds / fig4.steps
        comp_prog = 1e6 * comp.cpu_seconds / comp.steps
        sig_loop, comp_loop = loop["signorini"]["step_fused_ns"] * us, loop["compliance"]["step_fused_ns"] * us
        sig_free, comp_free = (loop_free["signorini"]["step_fused_ns"] * us,
                               loop_free["compliance"]["step_fused_ns"] * us)
        sig_lapack, comp_lapack = loop["signorini"]["step_lapack_ns"] * us, loop["compliance"]["step_lapack_ns"] * us

        say(f"## Speed (scripts/bench.py{' --quick' if quick else ''})\n")
        say(machine(build, program) + f" Medians of {repeats} repeats; ratios from the same run.\n")
        say(f"### Per step, the paper's scene (J = 19, n = 38 unknowns, dt = 1e-6 s, "
            f"{fig4.steps:,} steps)\n")
        rows = [
            ["`beamstops` program, tip recorded every step (HDF5), engine's `cpu_seconds` (the loop's thread; "
             "the HDF5 writes run on the writer thread)",
             fmt(sig_prog), fmt(comp_prog), "1"],
        ]
        if args.baseline:
            base_sig_us = 1e6 * base_sig.cpu_seconds / base_sig.steps
            rows.append([f"baseline program (`{args.baseline}`), same runs", fmt(base_sig_us),
                         fmt(1e6 * base_comp.cpu_seconds / base_comp.steps), fmt(base_sig_us / sig_prog)])
        rows += [
            ["engine loop alone, every step recorded (recorder keeps nothing)", fmt(sig_loop), fmt(comp_loop),
             fmt(sig_loop / sig_prog)],
            ["engine loop alone, nothing recorded", fmt(sig_free), fmt(comp_free), fmt(sig_free / sig_prog)],
            ["engine loop, LAPACK path (dpbtrs, one pass per operation), every step recorded",
             fmt(sig_lapack), fmt(comp_lapack), fmt(sig_lapack / sig_prog)],
            ["Python loop calling the engine once per step (f2py)", fmt(py["per_step_call"]), "—",
             fmt(py["per_step_call"] / sig_prog)],
            ["numpy/scipy loop (scripts/reference_scheme.py, cho_solve_banded per step)", fmt(py["numpy"]), "—",
             fmt(py["numpy"] / sig_prog)],
            ["floor: 2n dependent multiply-adds of the two solves", fmt(chain * us), fmt(chain * us),
             fmt(chain * us / sig_prog)],
        ]
        say(table(["µs per step", "Signorini, β = 1/2", "compliance, β = 1/4", "× program (Signorini)"], rows))
        say("")
        say(f"- numpy/scipy over the program: **{py['numpy'] / sig_prog:.0f}×** per step; over the engine loop "
            f"alone: {py['numpy'] / sig_loop:.0f}×. Crossing into Fortran and back at every step costs "
            f"{fmt(py['per_step_call'] - py['one_call'])} µs (the same steps in one call: "
            f"{fmt(py['one_call'])} µs/step).")
        say(f"- Figure 4 ({'0.2 s of it, ' if quick else ''}{fig4.steps:,} steps, tip recorded every step): "
            f"{fmt(fig4.cpu_seconds)} s of CPU in the time loop, {fmt(fig4.wall_seconds)} s for the whole "
            f"program ({fmt(fig4.output_mb)} MB of HDF5)" +
            ("." if quick else f"; target < 1 s: {'met' if fig4.wall_seconds < 1 else 'NOT met'}."))
        say(f"- Fused path over the LAPACK path (same loop, same records): {sig_lapack / sig_loop:.1f}× "
            f"(Signorini), {comp_lapack / comp_loop:.1f}× (compliance).")
        say("")

        # -------------------------------------------------------- the cost of each option
        off = "&statistics enabled = .false. /\n"
        options = [  # label, extra groups, extra &stops keys, extra &mesh keys
            ("none of them (`&statistics enabled = .false.`)", off, "", ""),
            ("shock log and statistics (the default)", "", "", ""),
            ("Rayleigh damping (`&damping ratio = 0.02`)", off + "&damping ratio = 0.02 /\n", "", ""),
            ("restitution (`&stops restitution = 0.5`)", off, ", restitution = 0.5", ""),
            ("mass redistribution (`&stops mass = 'redistributed'`)", off, ", mass = 'redistributed'", ""),
            ("reduced model (`&mesh modes = 8`)", off, "", ", modes = 8"),
        ]
        costs = [(label, program_median(program, work, repeats, law="signorini", beta=0.25, dt=1e-6, t_end=t_end,
                                        extra=extra, stops_extra=stops, mesh_extra=mesh))
                 for label, extra, stops, mesh in options]
        base = 1e6 * costs[0][1].cpu_seconds / costs[0][1].steps
        say("### The cost of each option (the program, paper's scene, J = 19, β = 1/4, dt = 1e-6 s)\n")
        say(table(["option", "µs per step", "× none"],
                  [[label, fmt(1e6 * r.cpu_seconds / r.steps), fmt(1e6 * r.cpu_seconds / r.steps / base)]
                   for label, r in costs]))
        say("")
        say("No option adds a banded solve: damping one product by C = aM + bS and two dot products, "
            "restitution a shifted projection, mass redistribution the massless rows' equilibria, the "
            "statistics a few compares and adds; a reduced model is a smaller step (O(r m + m²)).")
        say("")

        # -------------------------------------------------------- the floor
        say("### The floor (J = 19)\n")
        rows = [
            ["multiply-add latency (dependent chain, least of the probes)", f"{fmt(latency)} ns"],
            ["independent multiply-adds (vectorized peak)", f"{fmt(rate)} per ns"],
            ["chain of the two substitutions: 2n = 76 latencies", f"{fmt(chain)} ns"],
            [f"operations: {step_ops(n, False)} (nothing recorded), {step_ops(n, True)} (recorded) / peak rate",
             f"{fmt(ops_floor[False])} ns, {fmt(ops_floor[True])} ns"],
            ["floor = the largest", f"{fmt(floor[False])} ns, {fmt(floor[True])} ns"],
            ["one solve: LAPACK dpbtrs / fused / chain",
             f"{fmt(solve['solve_lapack_ns'])} / {fmt(solve['solve_fused_ns'])} / {fmt(chain)} ns"],
            ["engine step, nothing recorded / floor",
             f"{fmt(sig_free * 1e3)} ns = **{sig_free * 1e3 / floor[False]:.1f}×**"],
            ["engine step, every step recorded / floor",
             f"{fmt(sig_loop * 1e3)} ns = **{sig_loop * 1e3 / floor[True]:.1f}×**"],
            ["program step (HDF5 output every step) / floor", f"{fmt(sig_prog * 1e3)} ns = "
             f"{sig_prog * 1e3 / floor[True]:.1f}×"],
        ]
        say(table(["quantity", "value"], rows))
        say("")

        say(bench_lockstep.section(build, quick, repeats))

        # -------------------------------------------------------- scaling in J
        say("### Scaling in J (Signorini, β = 1/2, dt = 1e-6 s, tip recorded every step)\n")
        elements = [19, 100, 1000, 10_000] if quick else [19, 100, 1000, 10_000, 100_000]
        rows = []
        rss = {}
        for j in elements:
            n = 2 * j
            steps = max(20, int((2e6 if not quick else 2e5) * 38 / n / 10))
            run = program_median(program, work, repeats, elements=j, t_end=steps * 1e-6)
            step_us = 1e6 * run.cpu_seconds / run.steps
            chain_j = 2 * n * latency * 1e-3
            # the bandwidth of the cache level (or memory) that holds a step's data
            bandwidth = kernels(kernels_bin, "triad", max(1, step_bytes(n, True) // 3000), repeats)["triad_GBps"]
            mem_j = step_bytes(n, True) / (bandwidth * 1e3)
            floor_j = max(chain_j, mem_j, step_ops(n, True) / rate * 1e-3)
            rss[n] = run.max_rss_mb
            rows.append([f"{j:,}", f"{n:,}", f"{run.steps:,}", fmt(step_us), fmt(1e3 * step_us / n),
                         fmt(chain_j), fmt(step_bytes(n, True) / 1e6), fmt(bandwidth), fmt(mem_j),
                         fmt(step_us / floor_j), fmt(run.max_rss_mb)])
        say(table(["J", "n", "steps", "µs/step", "ns/(step·unknown)", "chain floor µs", "MB/step",
                   "bandwidth GB/s", "memory floor µs", "× floor", "peak RSS MB"], rows))
        (n1, r1), (n2, r2) = sorted(rss.items())[-2:]
        say(f"\nMB/step: the bytes a step must move, {step_bytes(1, True)} per unknown (S, M, the factor, g, z, "
            f"u, d, S u, w); bandwidth: a triad over the same amount of data (the cache level that holds it, "
            f"or memory: {fmt(triad)} GB/s). Peak RSS: the program's VmHWM (libraries and HDF5 buffers "
            f"dominate it for small J); from n = {n1:,} to {n2:,} it grows by {fmt(1e6 * (r2 - r1) / (n2 - n1))} "
            f"bytes per unknown.\n")

        # -------------------------------------------------------- scaling in records
        say(f"### Records (Figure 4 scene{', 0.2 s' if quick else ''}; `record_every`)\n")
        rows = []
        steps_total = int(round(t_end / 1e-6))
        for every in (1, 10, 100, 1000, steps_total):
            run = program_median(program, work, repeats, t_end=t_end, record_every=every)
            rows.append([f"{every:,}" + (" (none)" if every == steps_total else ""), fmt(1e6 * run.cpu_seconds / run.steps),
                         fmt(run.cpu_seconds), fmt(run.wall_seconds), fmt(run.output_mb)])
        say(table(["record_every", "µs/step", "cpu_seconds", "wall s", "output MB"], rows))
        say("")

        # -------------------------------------------------------- the paper's table
        say("### The paper's CPU times beside ours (T = 2 s, J = 19, tip recorded every step)\n")
        say("Different hardware: the paper used Scilab on a 1.1 GHz PowerPC G4; ours is the machine above.\n")
        rows = []
        for figure, (law, beta, dt, paper_s) in PAPER.items():
            if quick and figure not in (2, 4):
                continue
            run = program_median(program, work, repeats, law=law, beta=beta, dt=dt, t_end=2.0)
            rows.append([str(figure), law, f"{beta:g}", f"{dt:g}", f"{run.steps:,}", fmt(paper_s),
                         fmt(run.cpu_seconds), fmt(run.wall_seconds), f"{paper_s / run.cpu_seconds:,.0f}×"])
        say(table(["figure", "law", "β", "dt (s)", "steps", "paper CPU s", "beamstops cpu_seconds",
                   "beamstops wall s", "paper / beamstops"], rows))
        if quick:
            say("\n(--quick: figures 2 and 4 only.)")
        say("")
        say(figure4_targets(program, kernels_bin, work, quick, repeats, latency))
        say(peer_section(program, work, quick))
    import bench_sweep  # noqa: E402  (its own module: python scripts/bench_sweep.py runs it alone)

    say("")
    out.extend(bench_sweep.section(str(program), quick))
    text = "\n".join(out) + "\n"
    print(text)
    if args.out:
        args.out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
