"""Every refusal is one line: a control character in what a message quotes (a file name with a
newline or a tab, a key's text) is written as an escape, in the program and in Python alike."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from beamstops import Scene


def test_a_file_name_with_a_newline_is_told_on_one_line(program: str, tmp_path: Path) -> None:
    bad = tmp_path / "bad\nname.nml"
    bad.write_text("&time dt = -1 /\n")
    done = subprocess.run([program, "run", bad.name], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith("beamstops: error: bad\\nname.nml: &time dt = -1 is out of range")


def test_an_output_name_with_control_characters_is_told_on_one_line(program: str, tmp_path: Path) -> None:
    (tmp_path / "scene.nml").write_text("&time dt = 1e-4, t_end = 1e-3 /\n")
    done = subprocess.run([program, "run", "scene.nml", "-o", "no\tsuch\r/dir\n/out.h5"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode != 0 and done.stderr.count("\n") == 1, done.stderr
    assert "no\\tsuch\\r/dir\\n/out.h5" in done.stderr


def test_python_raises_the_same_one_line_message() -> None:
    with pytest.raises(ValueError) as caught:
        Scene.from_text("&output file = 'a\x01b.h5' /\n&time dt = -1 /\n", source="scene\nfrom text")
    message = str(caught.value)
    assert "\n" not in message and "\x01" not in message


def test_a_nul_in_python_text_is_refused_as_in_a_file() -> None:
    """Scene.from_text read a text only up to a NUL (the &mesh after it was dropped unsaid); the
    program refuses such a file as binary, and so does Python now."""
    with pytest.raises(ValueError, match="holds binary characters"):
        Scene.from_text("&time dt=1e-4 /\x00&mesh elements=5 /")


@pytest.mark.parametrize("capacity", [-1, 0, 2.5, True, 10**12])
def test_run_refuses_a_shock_capacity_out_of_range(capacity: object) -> None:
    """beamstops.run's room for the shock log: a whole number from 1 to 1e8 (10**12 had ended in
    numpy's MemoryError, -1 and 2.5 passed)."""
    import beamstops

    with pytest.raises(ValueError, match=r"shock_capacity = .* is out of range; allowed: a whole number"):
        beamstops.run(Scene(t_end=1e-3, dt=1e-4), shock_capacity=capacity)  # type: ignore[arg-type]


def test_a_name_not_in_utf8_is_escaped_and_utf8_is_kept(program: str, tmp_path: Path) -> None:
    """A file name in Latin-1 (bytes that are not UTF-8) reached the message raw, so the message
    itself was not valid UTF-8; a C1 control (NEL, U+0085) breaks the line on some terminals.
    Such bytes are escaped as \\xHH; a name in UTF-8 (é, 漢, 😀) is kept as it is."""
    names = {b"caf\xe9.nml": "caf\\xe9.nml", "a\u0085b.nml".encode(): "a\\xc2\\x85b.nml",
             b"x\xed\xa0\x80y.nml": "x\\xed\\xa0\\x80y.nml", "é漢😀.nml".encode(): "é漢😀.nml"}
    for raw, shown in names.items():
        path = bytes(tmp_path) + b"/" + raw
        with open(path, "wb") as f:
            f.write(b"&time dt = -1 /\n")
        done = subprocess.run([program.encode(), b"run", raw], cwd=tmp_path, capture_output=True, timeout=60)
        message = done.stderr.decode("utf-8")  # fails when the message is not valid UTF-8
        assert done.returncode == 1 and message.count("\n") == 1, message
        assert message.startswith(f"beamstops: error: {shown}: &time dt = -1 is out of range"), message
