"""Input fuzzing: valid namelists mutated thousands of times. Every case ends in either a
valid scene (and, when small, a valid run) or one clear message and a non-zero exit —
never a crash, a hang or a traceback; the Python Scene raises only ValueError/TypeError."""

from __future__ import annotations

import os
import random
import re
import shutil
import subprocess
from pathlib import Path

import pytest

import beamstops

PROGRAM = os.environ.get("BEAMSTOPS_PROGRAM") or shutil.which("beamstops")
INPUT = Path(__file__).resolve().parents[2] / "input"
CASES = int(os.environ.get("BEAMSTOPS_FUZZ_CASES", "1500"))
SEED = int(os.environ.get("BEAMSTOPS_FUZZ_SEED", "20261122"))

pytestmark = pytest.mark.skipif(PROGRAM is None, reason="the beamstops program is not on PATH")

NUMBERS = ["1e308", "1e400", "-1e400", "1e-320", "0", "-0.0", "nan", "NaN", "inf", "-Infinity", "1d3",
           "2147483648", "-2147483649", "99999999999999999999", "0.5", "-1", "3", "1e6", "+7", "1.e-2"]
WORDS = ["abc", ".true.", ".false.", "'x'", "\"signorini\"", "'compliance'", "'none'", "'paper'", "*", ",",
         "=", "&", "/", "!", "''", "3*1.0", "(1,2)", "T", "F"]
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?")


def seeds() -> list[str]:
    texts = [p.read_text() for p in sorted(INPUT.glob("*.nml"))]
    texts.append("&time dt=1e-4, t_end=0.01 /\n&output record_every=10 /\n")
    texts.append("&stops law='compliance', stiffness=1e7 /\n&time dt=1e-5, t_end=0.002, beta=0.25 /\n")
    return texts


def mutate(text: str, rng: random.Random) -> str:
    kind = rng.randrange(12)
    if kind == 0 and text:  # delete characters
        i = rng.randrange(len(text))
        return text[:i] + text[i + rng.randint(1, 4):]
    if kind == 1:  # insert a printable character
        i = rng.randrange(len(text) + 1)
        return text[:i] + rng.choice("&/=,'\"!*.-+eEdD0123456789 \nabcxyz$") + text[i:]
    if kind in (2, 3):  # replace a number by an extreme or odd one
        found = list(NUMBER.finditer(text))
        if found:
            m = rng.choice(found)
            return text[:m.start()] + rng.choice(NUMBERS) + text[m.end():]
    if kind == 4:  # replace a number by a value of another type
        found = list(NUMBER.finditer(text))
        if found:
            m = rng.choice(found)
            return text[:m.start()] + rng.choice(WORDS) + text[m.end():]
    if kind == 5:  # swap two keys
        keys = list(re.finditer(r"\b([a-z_]+)\s*=", text))
        if len(keys) >= 2:
            a, b = rng.sample(keys, 2)
            if a.start() > b.start():
                a, b = b, a
            return (text[:a.start(1)] + b.group(1) + text[a.end(1):b.start(1)] + a.group(1) + text[b.end(1):])
    if kind == 6:  # duplicate a group
        groups = re.findall(r"&[a-z]+[^/]*/", text)
        if groups:
            return text + "\n" + rng.choice(groups) + "\n"
    if kind == 7:  # binary garbage
        i = rng.randrange(len(text) + 1)
        return text[:i] + "".join(chr(rng.randrange(0, 32)) for _ in range(rng.randint(1, 6))) + text[i:]
    if kind == 8:  # truncate
        return text[:rng.randrange(len(text) + 1)]
    if kind == 9:  # an unknown key or group
        return text + rng.choice(["\n&time warp=9 /\n", "\n&gravity g=9.81 /\n", "\n&mesh elements=7, extra=1 /\n"])
    if kind == 10:  # change the case of a stretch
        i = rng.randrange(len(text) + 1)
        return text[:i] + text[i:i + 12].upper() + text[i + 12:]
    lines = text.splitlines(keepends=True)  # shuffle lines
    rng.shuffle(lines)
    return "".join(lines)


def one_clear_message(stderr: str, name: str) -> bool:
    lines = stderr.strip().splitlines()
    return len(lines) == 1 and lines[0].startswith("beamstops: error: ") and name in lines[0]


def cases() -> list[str]:
    rng = random.Random(SEED)
    base = seeds()
    out = []
    for _ in range(CASES):
        text = rng.choice(base)
        for _ in range(rng.randint(1, 3)):
            text = mutate(text, rng)
        out.append(text)
    return out


def test_mutated_namelists_end_in_a_scene_or_one_clear_message(tmp_path: Path) -> None:
    accepted = refused = ran = 0
    for k, text in enumerate(cases()):
        path = tmp_path / f"case{k}.nml"
        path.write_bytes(text.encode("utf-8", errors="surrogateescape"))
        done = subprocess.run([PROGRAM, "info", path.name], cwd=tmp_path, capture_output=True, text=True,
                              errors="replace", timeout=120)
        context = f"case {k} (seed {SEED}):\n{text}\nstdout: {done.stdout[-500:]}\nstderr: {done.stderr}"
        assert done.returncode in (0, 1), context
        if done.returncode == 1:
            assert one_clear_message(done.stderr, path.name), context
            refused += 1
        else:
            assert "kappa_h" in done.stdout and done.stderr == "", context
            accepted += 1
            steps = int(re.search(r"^steps\s+(\d+)", done.stdout, re.M).group(1))
            unknowns = int(re.search(r"^unknowns n\s+(\d+)", done.stdout, re.M).group(1))
            if steps * unknowns <= 2_000_000:
                out = tmp_path / f"case{k}.h5"
                run = subprocess.run([PROGRAM, "run", path.name, "-o", out.name], cwd=tmp_path, capture_output=True,
                                     text=True, errors="replace", timeout=120)
                assert run.returncode in (0, 3), context + f"\nrun: {run.stderr}"
                result = beamstops.load(out, allow_incomplete=True)
                assert result.status == ("complete" if run.returncode == 0 else "diverged"), context
                out.unlink()
                ran += 1
        path.unlink()
    # the mutations must exercise both outcomes
    assert accepted > CASES // 20 and refused > CASES // 4, (accepted, refused)
    assert ran > 10


def test_python_reads_every_mutated_namelist_exactly_as_the_program_does(tmp_path: Path) -> None:
    """One reader: Scene.from_namelist accepts what `beamstops info` accepts, and refuses what it
    refuses with the program's own message (a time step beyond the stability limit is refused by
    the program when the run is prepared; Python says so through engine.validate)."""
    agreed = 0
    for k, text in enumerate(cases()[: CASES // 2]):
        path = tmp_path / f"case{k}.nml"
        path.write_bytes(text.encode("utf-8", errors="surrogateescape"))
        done = subprocess.run([PROGRAM, "info", path.name], cwd=tmp_path, capture_output=True, text=True,
                              errors="replace", timeout=120)
        program = done.stderr.strip().removeprefix("beamstops: error: ")
        context = f"case {k} (seed {SEED}):\n{text}\nprogram: {program}"
        try:
            scene = beamstops.Scene.from_namelist(path)
        except (ValueError, OSError) as exc:
            assert done.returncode == 1, context + f"\npython: {exc}"
            assert str(exc).replace(str(path), path.name) == program, context + f"\npython: {exc}"
        else:
            assert beamstops.Scene.from_text(scene.to_text()) == scene, context
            if done.returncode != 0:
                with pytest.raises(ValueError) as caught:
                    beamstops.engine.validate(scene, path.name)
                assert str(caught.value) == program, context
        agreed += 1
        path.unlink()
    assert agreed == CASES // 2
