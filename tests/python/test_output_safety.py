"""The files a run writes beside its output (OUT.h5.partial, OUT.h5.checkpoint and its temporary
file OUT.h5.checkpoint.tmp, the hidden name an earlier output is moved aside to) never destroy
what is there: another run's live file, the input, what a symbolic link leads to, a foreign HDF5
file, a FIFO (which would block the run). Each is refused before anything is written, in one line,
exit status 4."""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import h5py
import pytest

from test_cli import PROGRAM, SHORT, complete_output, write

pytestmark = pytest.mark.skipif(PROGRAM is None, reason="the beamstops program is not on PATH")


def test_a_file_at_the_hidden_name_of_the_replaced_output_is_kept(tmp_path: Path) -> None:
    """The earlier output is moved aside to .OUT.h5.replaced-PID before it is removed; a file of
    that name (the shell's PID is the program's after exec) is not overwritten."""
    complete_output(tmp_path, "out.h5")
    scene = write(tmp_path, SHORT)
    done = subprocess.run(["sh", "-c", 'echo mine > ".out.h5.replaced-$$"; exec "$0" run scene.nml -o out.h5',
                           PROGRAM], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    hidden = [p for p in tmp_path.glob(".out.h5.replaced-*") if "-" not in p.name.rsplit("replaced-", 1)[1]]
    assert len(hidden) == 1 and hidden[0].read_text() == "mine\n"
    deadline = time.time() + 30  # the earlier output, moved aside under another name, is removed
    while len(list(tmp_path.glob(".out.h5.replaced-*"))) > 1 and time.time() < deadline:
        time.sleep(0.01)
    assert list(tmp_path.glob(".out.h5.replaced-*")) == hidden
    with h5py.File(tmp_path / "out.h5") as f:
        assert f.attrs["status"] == b"complete"
