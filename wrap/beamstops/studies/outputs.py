"""Where a study writes: its folder (``-o DIR``) and the files it writes there, at fixed names.

:meth:`StudyFolder.prepare` makes the folder and checks every name the study will write before
anything runs (:func:`beamstops.output_files.check`): a file there is written over only when it
is what this study writes at that name — an image (or an empty file) for a chart, and for a table
the study's own earlier output. A study's Markdown starts with a marker line (an HTML comment,
invisible once rendered) naming the study; its CSV files stay plain tables (a first line of
column names, what pandas, numpy and ``csv.DictReader`` read), so the folder's manifest
:data:`MANIFEST` lists each CSV file a study wrote with the SHA-256 of its content: a CSV file is
the study's own when it is listed there for that study and unchanged since. Every file goes
through a temporary file renamed into place (:func:`beamstops.output_files.write`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Optional

from ..output_files import IMAGE, Kind, check, file_sha256, text_kind, write_text
from ..scene import NAMELIST_FILE, Scene

__all__ = ["StudyFolder", "MANIFEST", "marker", "study_folder"]

#: The folder's list of the CSV files the studies wrote there (hidden: a dot file).
MANIFEST = ".beamstops-study-outputs.json"
#: The manifest's own mark: a JSON object with this key and value.
_MARK = ("written_by", "beamstops studies")


def marker(study: str) -> str:
    """The first line of every Markdown file ``study`` writes."""
    return f"<!-- beamstops study {study}: rewritten when the study runs again into this folder -->"


def study_folder(path: Optional[os.PathLike[str] | str], study: str) -> Path:
    """The output folder of a study (default out/<study>), created; an empty name is refused."""
    if path is not None and os.fspath(path) == "":
        raise ValueError("an empty output folder name; name the folder (-o . is the current one)")
    folder = Path(path) if path is not None else Path("out") / study
    if folder.exists() and not folder.is_dir():
        raise NotADirectoryError(f"{folder}: exists and is not a folder (-o takes the study's output folder)")
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def _is_manifest(head: bytes) -> bool:
    try:
        content = json.loads(head.decode("utf-8"))
    except ValueError:
        return False
    return isinstance(content, dict) and content.get(_MARK[0]) == _MARK[1]


class StudyFolder:
    """The folder a study writes into, its names checked (:meth:`prepare`) and its files written
    whole (:meth:`markdown`, :meth:`csv`; charts through ``output_files.save_figure`` at
    :meth:`path`)."""

    def __init__(self, folder: Path, study: str) -> None:
        self.folder, self.study = folder, study
        self.advice = "move it away or choose another -o folder"

    @classmethod
    def prepare(cls, folder: Optional[os.PathLike[str] | str], study: str, names: Sequence[str]) -> StudyFolder:
        """Make the folder (default out/<study>) and refuse, before the study runs, any of ``names``
        it must not write (one line naming the file and how to proceed)."""
        out = cls(study_folder(folder, study), study)
        check(out.folder / MANIFEST, out._manifest_kind(), out.advice)  # also: the folder can take files
        for name in names:
            check(out.folder / name, out.kind(name), out.advice, probe=False)
        return out

    def path(self, name: str) -> Path:
        return self.folder / name

    def kind(self, name: str) -> Kind:
        """What the study writes at ``name``: by its extension, a table (.md, .csv), a scene (.nml) or a chart."""
        if name.endswith(".md"):
            return text_kind(f"a table of the study {self.study}", marker(self.study),
                             f"a table the study {self.study} wrote (its first line: {marker(self.study)})")
        if name.endswith(".nml"):
            return NAMELIST_FILE
        if name.endswith(".csv"):
            return Kind(f"a table of the study {self.study}",
                        f"a table the study {self.study} wrote, unchanged since ({MANIFEST} in the folder lists "
                        f"those)", lambda path, head: self._listed(path))
        return IMAGE

    def _manifest_kind(self) -> Kind:
        return Kind("the studies' list of their CSV files", f"that list ({_MARK[0]!r}: {_MARK[1]!r})",
                    lambda path, head: _is_manifest(path.read_bytes()))

    def _manifest(self) -> dict[str, Any]:
        try:
            content = json.loads(self.path(MANIFEST).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return {_MARK[0]: _MARK[1], "files": {}}
        files = content.get("files") if isinstance(content, dict) else None
        return {_MARK[0]: _MARK[1], "files": files if isinstance(files, dict) else {}}

    def _listed(self, path: Path) -> bool:
        entry = self._manifest()["files"].get(path.name)
        return isinstance(entry, dict) and entry.get("study") == self.study and entry.get("sha256") == file_sha256(path)

    def markdown(self, name: str, text: str) -> Path:
        """Write a Markdown file, its first line the study's marker."""
        return write_text(self.path(name), self.kind(name), marker(self.study) + "\n" + text, self.advice)

    def scene(self, name: str, scene: Scene) -> Path:
        """Write a scene as :meth:`Scene.to_namelist` does."""
        return write_text(self.path(name), self.kind(name), scene.namelist_file_text(), self.advice)

    def csv(self, name: str, text: str) -> Path:
        """Write a CSV file and list it, with the SHA-256 of its content, in the folder's manifest."""
        path = write_text(self.path(name), self.kind(name), text, self.advice)
        manifest = self._manifest()
        manifest["files"][name] = {"study": self.study, "sha256": file_sha256(path)}
        write_text(self.path(MANIFEST), self._manifest_kind(), json.dumps(manifest, indent=1, sort_keys=True) + "\n",
                   self.advice)
        return path
