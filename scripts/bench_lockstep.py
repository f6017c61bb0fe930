#!/usr/bin/env python3
"""The lockstep section of scripts/bench.py (SPEC 13, docs/lockstep.md): member-steps per second
per core, one scene at a time against K = 1, 2, 4, 8, 16 members in lockstep, at J = 19 and
J = 100, with the floor beside each; every ratio from one run of bench/bench_lockstep.

    python scripts/bench_lockstep.py [--quick] [--build DIR] [--repeats N]   # the section alone

bench/bench_lockstep does the measuring (its repeats interleave the variants; medians; times in
CPU seconds of the thread, so per core and not inflated by other work on a shared machine):
members are the paper's scene (Signorini, beta = 1/2, dt = 1e-6 s, the shock log and statistics
on: the default) with omega and amplitude varied, nothing recorded. One at a time: each member
alone on the fused one-scene path. The floor of a member-step is the larger of the chain of
the two substitutions shared by the K members of a group (2n dependent multiply-adds: 2n
latencies / K) and its operations over the peak rate (20n multiply-adds, 760 at J = 19), both
measured by the same program.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

SCRIPTS = Path(__file__).resolve().parent
sys.path.insert(0, str(SCRIPTS))

import bench_ext  # noqa: E402

GROUPS = (1, 2, 4, 8, 16)
OPS_PER_UNKNOWN = 20  # multiply-adds per member-step and unknown, nothing recorded (bench_lockstep.f90)


def run(binary: Path, elements: int, steps: int, repeats: int) -> dict[str, float]:
    """Run bench_lockstep and return its `key value` lines (its markdown table is skipped)."""
    out = subprocess.run([str(binary), str(elements), str(steps), str(repeats)], check=True,
                         capture_output=True, text=True).stdout
    return {m.group(1): float(m.group(2))
            for m in (re.match(r"^([a-z_0-9]+)\s+(\S+)$", line.strip()) for line in out.splitlines()) if m}


def fmt(x: float) -> str:
    """3 significant digits, no exponent between 1e-3 and 1e5."""
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e5:
        digits = max(0, 2 - int(f"{abs(x):e}".split("e")[1]))
        return f"{x:.{digits}f}"
    return f"{x:.2e}"


def table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows])


def floor_ns(n: int, k: int, latency: float, peak: float) -> float:
    """ns per member-step: the shared chain (2n latencies / K) or the operations over the peak."""
    return max(2 * n * latency / k, OPS_PER_UNKNOWN * n / peak)


def section(build: Path, quick: bool = False, repeats: int | None = None) -> str:
    """The markdown of the section, measured now with build's bench/bench_lockstep."""
    binary = build / "bench" / "bench_lockstep"
    if not binary.exists():
        raise FileNotFoundError(f"{binary}: build with -Dbench=true")
    repeats = repeats or (3 if quick else 5)
    out = ["### Lockstep ensembles: member-steps per second per core (bench/bench_lockstep)\n",
           "K members sharing A advance together, the member index innermost (docs/lockstep.md), each "
           "bit for bit the same scene run alone. Members: the paper's scene (Signorini, β = 1/2, "
           "dt = 1e-6 s, shock log and statistics on, the default) with ω and amplitude varied, nothing "
           "recorded. One at a time: each member alone on the one-scene fused path. Times: CPU seconds of "
           f"the thread (per core), medians of {repeats} interleaved repeats; ratios from the same run. "
           "Floor: the larger of the two substitutions' chain shared by the group (2n multiply-add "
           f"latencies / K) and the operations ({OPS_PER_UNKNOWN}n multiply-adds) over the peak rate, "
           "both measured by the same program.\n"]
    summary = []
    for elements in (19, 100):
        n = 2 * elements
        steps = (50_000 if quick else 200_000) * 19 // elements
        r = run(binary, elements, steps, repeats)
        latency, peak, alone = r["fma_latency_ns"], r["fma_per_ns"], r["alone_ns_per_member_step"]
        rows = [["one at a time", fmt(alone), fmt(1e9 / alone), "1", fmt(floor_ns(n, 1, latency, peak)),
                 fmt(alone / floor_ns(n, 1, latency, peak))]]
        for k in GROUPS:
            ns = r[f"lockstep_{k}_ns_per_member_step"]
            floor = floor_ns(n, k, latency, peak)
            rows.append([f"lockstep K = {k}", fmt(ns), fmt(1e9 / ns), f"**{alone / ns:.2f}**" if k == 8 else
                         f"{alone / ns:.2f}", fmt(floor), fmt(ns / floor)])
            if k == 8:
                least = r["alone_least_ns_per_member_step"] / r[f"lockstep_{k}_least_ns_per_member_step"]
                summary.append((elements, alone / ns, least))
        out.append(f"J = {elements} (n = {n}), {steps:,} steps; multiply-add latency {fmt(latency)} ns, "
                   f"peak {fmt(peak)} independent multiply-adds per ns, {OPS_PER_UNKNOWN * n} per member-step:\n")
        out.append(table(["", "ns per member-step", "member-steps per s per core", "× one at a time",
                          "floor ns", "× floor"], rows))
        out.append("")
    out.append("- K = 8 over one at a time, medians: " + ", ".join(f"J = {j}: **{x:.2f}×**" for j, x, _ in summary) +
               "; least of the repeats over least of the repeats (the run least slowed down by other work on "
               "the machine, as the floor's latency): " + ", ".join(f"J = {j}: {y:.2f}×" for j, _, y in summary) +
               " (goal of issue 15: ≥ 4× at J = 19).")
    out.append("")
    return "\n".join(out)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="four times fewer steps")
    parser.add_argument("--build", type=Path, help="meson build directory (default build/bench, made if missing)")
    parser.add_argument("--repeats", type=int, default=None, help="repeats (default 5, quick 3)")
    args = parser.parse_args()
    print(section(bench_ext.meson_build(args.build, bench=True), args.quick, args.repeats))
    return 0


if __name__ == "__main__":
    sys.exit(main())
