"""Output files written safely: the one rule of ``plot``, ``plan`` and the studies.

:func:`check` refuses, before anything runs, a name whose file would be lost or that cannot be
written: a symbolic link (nothing is written through one, nor over it), a folder, a FIFO, a
device or a socket, an HDF5 file (a run's output) and any existing file that is not of the
:class:`Kind` written there (an image for an image, a scene beamstops wrote for a scene, a
study's own table for that table); an empty file is written over. It also makes sure the folder
can take the file (a temporary file is created there and removed). :func:`write` then writes the
output to a temporary file in the same folder and renames it into place only once it is
complete, so a failed write (a full disk) leaves what was there before and no half-written file;
a failure is one :class:`WriteError`, ``cannot write FILE: REASON``.
"""

from __future__ import annotations

import hashlib
import os
import secrets
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Optional, Union

__all__ = ["Kind", "IMAGE", "WriteError", "check", "write", "write_text", "save_figure", "text_kind", "is_image",
           "names_no_file", "HDF5_SIGNATURE", "file_sha256"]

PathLike = Union[str, "os.PathLike[str]"]

#: The first bytes of an HDF5 file.
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"

#: The first bytes of the images and animations matplotlib writes: PostScript, PNG, PDF, JPEG, GIF,
#: TIFF, EPS with a preview (SVG, text, is told apart by its first tag; WebP and MP4 by their boxes).
_IMAGE_SIGNATURES = (b"%!PS", b"\x89PNG\r\n\x1a\n", b"%PDF", b"\xff\xd8\xff", b"GIF87a", b"GIF89a", b"II*\x00",
                     b"MM\x00*", b"\xc5\xd0\xd3\xc6")

#: How many first bytes of an existing file its kind is told from.
HEAD = 4096


def is_image(head: bytes) -> bool:
    """Whether a file starting with ``head`` is an image or an animation matplotlib writes."""
    if head.startswith(_IMAGE_SIGNATURES) or (head[:4] == b"RIFF" and head[8:12] == b"WEBP") or head[4:8] == b"ftyp":
        return True
    text = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    return text.startswith((b"<?xml", b"<svg", b"<!DOCTYPE svg"))


@dataclass(frozen=True)
class Kind:
    """What is written at a name, and how an existing file is told to be one (and so may be replaced)."""

    noun: str
    """The output, in messages: 'an image', 'the chosen scene'."""
    expected: str
    """What an existing file must be, in the refusal 'exists and is not EXPECTED'."""
    recognise: Callable[[Path, bytes], bool]
    """Whether the existing (regular, non-empty) file at a path, starting with these bytes, is one."""


IMAGE = Kind("an image", "an image (not PNG, PDF, SVG, PostScript, JPEG, GIF, TIFF, WebP or MP4)",
             lambda path, head: is_image(head))


def first_line(head: bytes) -> str:
    """The first line of a text starting with ``head`` (a UTF-8 byte order mark and the line end left out)."""
    line = head.split(b"\n", 1)[0].removeprefix(b"\xef\xbb\xbf").rstrip(b"\r")
    return line.decode("utf-8", "replace")


def text_kind(noun: str, line: str, expected: str) -> Kind:
    """A text whose first line is ``line`` (the marker its writer puts there)."""
    return Kind(noun, expected, lambda path, head: first_line(head) == line)


class WriteError(OSError):
    """A write that failed, named: ``cannot write FILE: REASON`` (``errno``, ``strerror``, ``filename``)."""

    def __str__(self) -> str:
        return f"cannot write {self.filename}: {self.strerror}"


def _named(exc: OSError, path: PathLike) -> WriteError:
    if isinstance(exc, WriteError):
        return exc
    return WriteError(exc.errno, exc.strerror or str(exc), os.fspath(path))


def check(path: PathLike, kind: Kind, advice: str = "name another file or remove it", probe: bool = True) -> Path:
    """Refuse a name whose existing file is not one of ``kind`` or that cannot take a file (see the
    module); give it as a Path. ``advice`` ends the refusal of an existing file; ``probe``: create
    and remove a temporary file beside it (the folder exists and can be written to)."""
    raw = os.fspath(path)
    if not isinstance(raw, str):
        raise TypeError(f"file name {path!r}: a str or a path, not bytes")
    if raw == "":
        raise ValueError("an empty file name: name the file to write")
    if raw.endswith(("/", os.sep)):
        raise IsADirectoryError(f"{raw}: names a folder; name the file to write")
    out = Path(raw)
    try:
        status: Optional[os.stat_result] = os.lstat(out)
    except FileNotFoundError:
        status = None
    except OSError as exc:
        raise _named(exc, out) from None
    if status is not None:
        _refuse_existing(out, status, kind, advice)
    if probe:
        os.remove(_temporary(out))
    return out


def _refuse_existing(out: Path, status: os.stat_result, kind: Kind, advice: str) -> None:
    mode = status.st_mode
    if stat.S_ISLNK(mode):
        raise FileExistsError(f"{out}: is a symbolic link; refusing to write {kind.noun} through it or over it; "
                              f"name the file itself, or remove the link")
    if stat.S_ISDIR(mode):
        raise IsADirectoryError(f"{out}: is a folder; name the file to write")
    if not stat.S_ISREG(mode):  # a FIFO or a terminal would hang the read, a device take the output
        raise FileExistsError(f"{out}: exists and is not a regular file (a FIFO, a device or a socket); refusing "
                              f"to write {kind.noun} there; name another file")
    if status.st_size == 0:
        return
    try:
        fd = os.open(out, os.O_RDONLY | os.O_NONBLOCK | os.O_NOFOLLOW)
        try:
            head = os.read(fd, HEAD)
        finally:
            os.close(fd)
    except OSError as exc:
        raise FileExistsError(f"{out}: exists and cannot be read ({exc.strerror}), so it cannot be told to be "
                              f"{kind.noun}; refusing to overwrite it; {advice}") from None
    if head.startswith(HDF5_SIGNATURE):
        raise FileExistsError(f"{out}: exists and is an HDF5 file (a run's output?); refusing to overwrite it "
                              f"with {kind.noun}; name another file")
    if head and not kind.recognise(out, head):
        raise FileExistsError(f"{out}: exists and is not {kind.expected}; refusing to overwrite it with "
                              f"{kind.noun}; {advice}")


def _temporary(out: Path) -> Path:
    """A new empty file beside ``out`` (its extension kept: writers tell the format from it), made
    with the permissions a new file gets (0666 less the umask); WriteError naming ``out``."""
    for _ in range(100):
        tmp = out.with_name(f".{out.name[:40]}.{secrets.token_hex(4)}.tmp{out.suffix[:16]}")
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o666))
            return tmp
        except FileExistsError:
            continue
        except OSError as exc:
            raise _named(exc, out) from None
    raise WriteError(17, "no free temporary name beside it", os.fspath(out))  # pragma: no cover


def _remove(path: Path) -> None:
    try:
        os.remove(path)
    except OSError:
        pass


def write(path: PathLike, kind: Kind, produce: Callable[[Path], Any], advice: str = "name another file or remove it") -> Path:
    """Check ``path`` (:func:`check`), let ``produce(tmp)`` write the whole output to a temporary
    file beside it, and rename that onto ``path``; give ``path``. On any failure the temporary
    file is removed and ``path`` is left as it was; an OSError becomes a :class:`WriteError`
    naming ``path``."""
    out = check(path, kind, advice, probe=False)
    tmp = _temporary(out)
    try:
        try:
            produce(tmp)
        except OSError as exc:
            raise _named(exc, out) from None
        check(out, kind, advice, probe=False)  # what is there now: it may have changed while the output was made
        try:
            os.replace(tmp, out)
        except OSError as exc:
            raise _named(exc, out) from None
    except BaseException:
        _remove(tmp)
        raise
    return out


def write_text(path: PathLike, kind: Kind, text: str, advice: str = "name another file or remove it") -> Path:
    """:func:`write` of a text (UTF-8)."""
    return write(path, kind, lambda tmp: tmp.write_text(text, encoding="utf-8"), advice)


def save_figure(fig: Any, path: PathLike, dpi: float, advice: str = "name another file or remove it") -> Path:
    """:func:`write` of a matplotlib figure, in the format of the name's extension."""
    out = Path(os.fspath(path))
    options: dict[str, Any] = {"format": out.suffix[1:].lower()} if out.suffix else {}
    return write(out, IMAGE, lambda tmp: fig.savefig(tmp, dpi=dpi, **options), advice)


def names_no_file(path: PathLike) -> bool:
    """Whether an input gives an output no name: read from a pipe, a FIFO or a device, or named by
    an open descriptor (/dev/stdin, /dev/fd/N, /proc/.../fd/N) — the engine's rule
    (``descriptor_path`` in src/beamstops/namelist.f90), applied to the name as given."""
    raw = os.fspath(path)
    if raw == "/dev/stdin" or raw.startswith("/dev/fd/") or (raw.startswith("/proc/") and "/fd/" in raw):
        return True
    try:
        return not stat.S_ISREG(os.stat(raw).st_mode)
    except OSError:
        return False


def file_sha256(path: PathLike) -> str:
    """The SHA-256 of a file's content, in hex (the studies' list of their tables, a sweep's
    program)."""
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()
