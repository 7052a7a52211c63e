"""Safe result files (docs/reliability.md, "Outputs").

An output path must be a new name or an existing *regular* file that is not an input of the
same command: screwkit never writes over its own spec, never replaces a symbolic link (the
link would silently become a file), and never opens a FIFO, a device or a socket. A result is
written to a temporary file in the destination's folder and renamed over the destination, so
an error or Ctrl-C leaves either the old file or the complete new one, never a partial file.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path

from screwkit.errors import InputError


class OutputPathError(InputError):
    """An output path that screwkit refuses to write; the message says why and what to do."""


def _label(option: str | None, path: Path) -> str:
    return f"{option} {path}" if option else str(path)


def _kind(mode: int) -> str | None:
    """What an existing non-regular file is, in words (None for a regular file)."""
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISLNK(mode):
        return ("a symbolic link (screwkit does not replace links; write to its target's path "
                "or another name)")
    if stat.S_ISDIR(mode):
        return "a folder; give a file name inside it"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file (resolved paths, or one inode for hard links)."""
    try:
        if os.path.realpath(a) == os.path.realpath(b):
            return True
        sa, sb = os.stat(a), os.stat(b)
    except OSError:
        return False
    return (sa.st_dev, sa.st_ino) == (sb.st_dev, sb.st_ino)


def check_output_path(path: str | Path, inputs: Iterable[str | Path] = (),
                      option: str | None = None) -> Path:
    """``path`` if screwkit may write a result there (module docstring); otherwise an
    :class:`OutputPathError` naming the option and the reason."""
    p = Path(path)
    where = _label(option, p)
    for source in inputs:
        if _same_file(p, Path(source)):
            raise OutputPathError(f"{where}: this is an input of the command ({source}); "
                                  "writing the result there would destroy it. Give another name")
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise OutputPathError(f"cannot write {where}: {exc.strerror}") from None
    if st is not None:
        kind = _kind(st.st_mode)
        if kind is not None:
            raise OutputPathError(f"cannot write {where}: it is {kind}")
    folder = p.parent
    if not folder.is_dir():
        raise OutputPathError(f"cannot write {where}: folder {folder} does not exist; create "
                              "it first")
    return p


def check_output_folder(folder: str | Path, option: str) -> Path:
    """A folder results are written into: an existing folder (or a link to one), or a new
    name, created later; an existing file or anything else is refused."""
    p = Path(folder)
    try:
        st = os.stat(p)
    except (FileNotFoundError, NotADirectoryError):
        if os.path.lexists(p):
            raise OutputPathError(f"{option} {p}: is a dangling symbolic link") from None
        if not _creatable(p.parent):
            raise OutputPathError(f"{option} {p}: cannot create it (a path above it is a file, "
                                  "not a folder)") from None
        return p
    except OSError as exc:
        raise OutputPathError(f"{option} {p}: {exc.strerror}") from None
    if not stat.S_ISDIR(st.st_mode):
        raise OutputPathError(f"{option} needs a folder: {p} is an existing "
                              f"{'file' if stat.S_ISREG(st.st_mode) else 'non-folder'}; give a "
                              "folder name (it is created if missing)")
    return p


def _creatable(folder: Path) -> bool:
    """Whether ``mkdir -p folder`` could work: the nearest existing ancestor is a folder."""
    for up in (folder, *folder.parents):
        if os.path.lexists(up):
            return up.is_dir()
    return True


def make_output_folder(folder: str | Path, option: str) -> Path:
    """Check (:func:`check_output_folder`) and create the folder; errors as
    :class:`OutputPathError`."""
    p = check_output_folder(folder, option)
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputPathError(f"{option} {p}: cannot create the folder ({exc.strerror})") from None
    return p


def check_outputs(inputs: Iterable[str | Path], files: Mapping[str, str | Path | None],
                  folders: Mapping[str, str | Path | None] | None = None) -> None:
    """Check every output of a command before any work: each file (option → path, ``None``
    for an option not given) with :func:`check_output_path`, no two outputs the same file, and
    each output folder with :func:`check_output_folder`."""
    sources = list(inputs)
    given = [(opt, Path(p)) for opt, p in files.items() if p is not None]
    for opt, p in given:
        check_output_path(p, sources, opt)
    for i, (opt, p) in enumerate(given):
        for opt2, p2 in given[:i]:
            if _same_file(p, p2) or os.path.abspath(p) == os.path.abspath(p2):
                raise OutputPathError(f"{opt2} and {opt} name the same file {p}; give two names")
    for opt, folder in (folders or {}).items():
        if folder is not None:
            check_output_folder(folder, opt)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path: str | Path, inputs: Iterable[str | Path] = (),
                option: str | None = None) -> Iterator[str]:
    """A temporary path in ``path``'s folder to write the result to; on success it gets the
    usual file mode (0666 less the umask) and is renamed over ``path`` (checked again just
    before, :func:`check_output_path`); on any error or Ctrl-C it is removed."""
    p = check_output_path(path, inputs, option)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name[:80]}.", suffix=p.suffix[:16] or ".tmp",
                                   dir=str(p.parent))
    except OSError as exc:
        raise OutputPathError(f"cannot write {_label(option, p)}: {exc.strerror}") from None
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; results are ordinary files
        check_output_path(p, inputs, option)  # nothing swapped in meanwhile
        os.replace(tmp, p)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_text_atomic(path: str | Path, text: str, inputs: Iterable[str | Path] = (),
                      option: str | None = None) -> None:
    """Write ``text`` (UTF-8) to ``path`` through :func:`atomic_path`."""
    with atomic_path(path, inputs, option) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)


def write_bytes_atomic(path: str | Path, data: bytes, inputs: Iterable[str | Path] = (),
                       option: str | None = None) -> None:
    """Write ``data`` to ``path`` through :func:`atomic_path`."""
    with atomic_path(path, inputs, option) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
