"""A run into an existing output against a run into a fresh folder: the paper's Figure 4 scene
(input/paper_fig4.nml, 145 MB of HDF5), `beamstops run` timed from outside, its output read
through pipes as `subprocess.run(capture_output=True)` does. The program moves an earlier output
aside and removes it in a process of its own (beamstops_replace_file in src/beamstops/files.c):
the README's figures for a re-run come from

    python scripts/bench_rerun.py --runs 8

Runs alternate (fresh, then a re-run over its output), 0.3 s apart so that the removal of the
one before is over; prints the least and median wall time of each and their differences.
--quick: 0.2 s of simulated time, 3 runs each (for the tests). Asserts nothing."""

from __future__ import annotations

import argparse
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SCENE = Path(__file__).resolve().parent.parent / "input" / "paper_fig4.nml"


def timed(program: str, scene: Path) -> float:
    start = time.perf_counter()
    subprocess.run([program, "run", str(scene)], cwd=scene.parent, capture_output=True, check=True)
    return time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--program", default=shutil.which("beamstops"), help="the beamstops program (default: PATH)")
    parser.add_argument("--runs", type=int, default=8, help="runs of each kind (default 8)")
    parser.add_argument("--quick", action="store_true", help="0.2 s of simulated time, 3 runs of each kind")
    args = parser.parse_args()
    if args.program is None:
        parser.error("no beamstops program: give --program")
    program = str(Path(args.program).resolve())  # the runs run in a folder of their own
    if not Path(program).is_file():
        parser.error(f"--program {args.program}: no such file")
    runs = 3 if args.quick else args.runs
    fresh: list[float] = []
    rerun: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        text = re.sub(r"file\s*=\s*'[^']*'", "file='out.h5'", SCENE.read_text())
        if args.quick:
            text = re.sub(r"t_end\s*=\s*[0-9.eE+-]+", "t_end=0.2", text)
        scene = folder / "scene.nml"
        scene.write_text(text)
        output = folder / "out.h5"
        for _ in range(runs):
            output.unlink(missing_ok=True)
            time.sleep(0.3)
            fresh.append(timed(program, scene))
            time.sleep(0.3)
            rerun.append(timed(program, scene))
        # the last re-run's earlier output is being removed by a process of its own: give it 10 s
        deadline = time.monotonic() + 10
        while (left := [p.name for p in folder.iterdir() if ".replaced-" in p.name]) and time.monotonic() < deadline:
            time.sleep(0.01)
    ms = 1e3
    print(f"fresh folder: least {min(fresh) * ms:.1f} ms, median {statistics.median(fresh) * ms:.1f} ms")
    print(f"re-run:       least {min(rerun) * ms:.1f} ms, median {statistics.median(rerun) * ms:.1f} ms")
    print(f"re-run - fresh: least {(min(rerun) - min(fresh)) * ms:.1f} ms, "
          f"median {(statistics.median(rerun) - statistics.median(fresh)) * ms:.1f} ms "
          f"({runs} runs each; earlier outputs left behind: {len(left)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
