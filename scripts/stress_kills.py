"""SIGKILL at random moments: how often a killed run leaves a partial file HDF5 cannot read, and
whether the mend of `--restart` (raise_hdf5_eoa) resumes it to the uninterrupted output, bit for
bit. The figures of the README's "A SIGKILL inside HDF5's own flush" come from

    python scripts/stress_kills.py --kills 400

(the paper's scene, dt = 1e-6 s, t_end = 4 s, every step recorded, a snapshot every 997 steps, a
checkpoint every 40,000 steps: a flush every 6 ms or so; each run killed after a uniform random
0.05-0.55 s). Each kill: the partial file read whole with h5py, as written; where that fails, the
error, then `beamstops run --restart` and the resumed output against a run that was never
killed. Prints one line per unreadable file and a summary; asserts nothing."""

from __future__ import annotations

import argparse
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

SCENE = """&time dt=1e-6, t_end={t_end} /
&output file='{name}.h5', record_every=1, snapshot_every=997, checkpoint_every=40000 /
"""


def write(folder: Path, name: str, t_end: float) -> Path:
    path = folder / f"{name}.nml"
    path.write_text(SCENE.format(t_end=t_end, name=name))
    return path


def read_whole(path: Path) -> None:
    """Every dataset of the file, read (raises what h5py raises)."""
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: obj[()] if isinstance(obj, h5py.Dataset) else None)


def same_datasets(a: Path, b: Path) -> bool:
    """The two files hold the same datasets, bit for bit."""
    def datasets(path: Path) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        with h5py.File(path) as f:
            f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        return out
    x, y = datasets(a), datasets(b)
    return sorted(x) == sorted(y) and all(x[k].shape == y[k].shape and x[k].tobytes() == y[k].tobytes() for k in x)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--program", default=shutil.which("beamstops"), help="the beamstops program (default: PATH)")
    parser.add_argument("--kills", type=int, default=400, help="runs killed (default 400)")
    parser.add_argument("--t-end", type=float, default=4.0, help="simulated seconds of a run (default 4)")
    parser.add_argument("--window", type=float, nargs=2, default=(0.05, 0.55), metavar=("FROM", "TO"),
                        help="the kill comes after a uniform random wait in [FROM, TO] s (default 0.05 0.55)")
    parser.add_argument("--seed", type=int, default=None, help="random seed (default: the time)")
    args = parser.parse_args()
    if args.program is None:
        parser.error("no beamstops program: give --program")
    args.program = str(Path(args.program).resolve())  # the runs run in a folder of their own
    seed = args.seed if args.seed is not None else int(time.time())
    rng = random.Random(seed)
    unreadable = resumed = refused = 0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        reference = write(folder, "reference", args.t_end)
        subprocess.run([args.program, "run", str(reference)], cwd=folder, check=True, stdout=subprocess.DEVNULL)
        scene = write(folder, "cut", args.t_end)
        partial, checkpoint, output = (folder / f"cut.h5{end}" for end in (".partial", ".checkpoint", ""))
        for kill in range(args.kills):
            for stale in (partial, checkpoint, output):
                stale.unlink(missing_ok=True)
            process = subprocess.Popen([args.program, "run", str(scene)], cwd=folder, stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL)
            time.sleep(rng.uniform(*args.window))
            process.send_signal(signal.SIGKILL)
            process.wait()
            if not partial.exists():
                continue
            try:
                read_whole(partial)
                continue
            except Exception as exc:  # noqa: BLE001 - whatever h5py raises is the finding
                unreadable += 1
                print(f"kill {kill}: unreadable: {exc}", flush=True)
            if not checkpoint.exists():
                print("  no checkpoint to resume from", flush=True)
                continue
            done = subprocess.run([args.program, "run", str(scene), "--restart"], cwd=folder, capture_output=True,
                                  text=True)
            if done.returncode == 0 and same_datasets(output, folder / "reference.h5"):
                resumed += 1
                print("  --restart: resumed, the same bits as the run never killed", flush=True)
            else:
                refused += 1
                print(f"  --restart: exit {done.returncode}: {done.stderr.strip()}", flush=True)
    print(f"seed {seed}: {args.kills} kills, {unreadable} left a file HDF5 could not read; --restart resumed "
          f"{resumed} of them bit for bit, refused {refused}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
