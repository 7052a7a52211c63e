"""Reading a spec file safely: the checks made before and while the TOML is parsed
(docs/reliability.md, "Spec files").

A spec file must be a regular file of at most :data:`MAX_SPEC_BYTES`, UTF-8 text (a leading
UTF-8 byte-order mark is accepted and dropped), with brackets nested at most
:data:`MAX_NESTING` deep (tomllib recurses once per level and would raise RecursionError
after about a thousand), no key longer than :data:`MAX_KEY_CHARS` and no string longer than
:data:`MAX_STRING_CHARS`. Every refusal is one sentence naming the file and, where there is one,
the key.
"""

from __future__ import annotations

import os
import re
import stat
import tomllib
from pathlib import Path
from typing import Any

from screwkit.errors import InputError
from screwkit.io.quantity import excerpt

#: largest spec file read (bytes); the biggest bundled example is under 4 kB
MAX_SPEC_BYTES = 1_000_000
#: deepest nesting of tables and arrays (the spec format needs 5: [balancing.bound.ellipsoids.
#: <link>] centre = [...])
MAX_NESTING = 10
#: longest key (characters)
MAX_KEY_CHARS = 100
#: longest string value (characters): descriptions and synthesis expressions; quantities have
#: their own, shorter limit (screwkit.io.quantity.MAX_QUANTITY_CHARS)
MAX_STRING_CHARS = 2000

_UTF8_BOM = b"\xef\xbb\xbf"
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
# strings and comments (skipped), and the brackets whose nesting is counted
_TOKENS = re.compile(
    r'"""[\s\S]*?"""(?!")|' r"'''[\s\S]*?'''(?!')|" r'"(?:[^"\\\n]|\\.)*"|' r"'[^'\n]*'|"
    r"#[^\n]*|[\[\]{}]"
)


class SpecFileError(InputError):
    """A spec file that cannot be read as TOML; the message names the file."""


def _file_kind(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def read_bytes(path: Path) -> bytes:
    """The bytes of a regular file of at most :data:`MAX_SPEC_BYTES` (clear refusals for a
    missing file, a folder, a FIFO or device, an unreadable or an oversized file)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise SpecFileError(f"{path}: no such spec file") from None
    except OSError as exc:
        raise SpecFileError(f"{path}: cannot read it ({exc.strerror})") from None
    if stat.S_ISDIR(st.st_mode):
        raise SpecFileError(f"{path}: this is a folder, not a spec file; give a .toml file")
    if not stat.S_ISREG(st.st_mode):
        raise SpecFileError(f"{path}: this is {_file_kind(st.st_mode)}, not a spec file")
    if st.st_size > MAX_SPEC_BYTES:
        raise SpecFileError(f"{path}: the file has {st.st_size} bytes; a spec file is at most "
                            f"{MAX_SPEC_BYTES} bytes (1 MB; see docs/reliability.md)")
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_SPEC_BYTES + 1)
    except OSError as exc:
        raise SpecFileError(f"{path}: cannot read it ({exc.strerror})") from None
    if len(data) > MAX_SPEC_BYTES:  # it grew after the stat
        raise SpecFileError(f"{path}: the file has over {MAX_SPEC_BYTES} bytes; a spec file is at most "
                            "1 MB")
    return data


def decode_text(path: Path, data: bytes) -> str:
    """UTF-8 text of ``data`` (a leading UTF-8 byte-order mark dropped); binary data, UTF-16 and
    other encodings are refused with a sentence saying so."""
    if not data.strip():
        raise SpecFileError(f"{path}: the file is empty; a spec file needs at least a [mechanism] table "
                            "with family = \"...\" (see docs/spec-format.md)")
    if data.startswith(_UTF16_BOMS):
        raise SpecFileError(f"{path}: starts with a UTF-16 byte-order mark; save it as UTF-8")
    if data.startswith(_UTF8_BOM):
        data = data[len(_UTF8_BOM):]  # a UTF-8 byte-order mark carries no meaning: drop it
    nul = data.find(b"\x00")
    if nul >= 0:
        raise SpecFileError(f"{path}: not a text file (binary data: a NUL byte at offset "
                            f"{nul}); a spec file is UTF-8 TOML text")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SpecFileError(f"{path}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
                            f"{exc.start}); save it as UTF-8") from None


def check_bracket_nesting(path: Path, text: str) -> None:
    """Refuse arrays and inline tables nested deeper than :data:`MAX_NESTING`, before parsing."""
    depth = 0
    for m in _TOKENS.finditer(text):
        tok = m.group(0)
        if tok in "[{":
            depth += 1
            if depth > MAX_NESTING:
                line = text.count("\n", 0, m.start()) + 1
                raise SpecFileError(f"{path}: arrays or inline tables are nested more than "
                                    f"{MAX_NESTING} deep (line {line}); a spec file needs at "
                                    "most 5 levels")
        elif tok in "]}":
            depth = max(depth - 1, 0)


def _key_path(parts: list[str | int]) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def check_document(path: Path, doc: dict[str, Any]) -> None:
    """Walk the parsed document (without recursion) checking nesting, key and string lengths."""
    stack: list[tuple[Any, list[str | int]]] = [(doc, [])]
    while stack:
        node, where = stack.pop()
        if len(where) > MAX_NESTING:
            raise SpecFileError(f"{path}: [{_key_path(where[:3])}…] is nested {len(where)} "
                                f"deep; a spec file needs at most 5 levels (limit {MAX_NESTING})")
        if isinstance(node, dict):
            for k, v in node.items():
                if len(k) > MAX_KEY_CHARS:
                    raise SpecFileError(f"{path}: the key {excerpt(k)} in "
                                        f"[{_key_path(where) or 'top level'}] is longer than "
                                        f"{MAX_KEY_CHARS} characters")
                stack.append((v, [*where, k]))
        elif isinstance(node, list):
            stack.extend((v, [*where, i]) for i, v in enumerate(node))
        elif isinstance(node, str) and len(node) > MAX_STRING_CHARS:
            raise SpecFileError(f"{path}: [{_key_path(where)}] is a string of {len(node)} "
                                f"characters ({excerpt(node)}); the limit is "
                                f"{MAX_STRING_CHARS}")


def read_toml(path: str | Path) -> dict[str, Any]:
    """Read and parse a spec file with the checks of the module docstring."""
    p = Path(path)
    text = decode_text(p, read_bytes(p))
    check_bracket_nesting(p, text)
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecFileError(f"{p}: not valid TOML: {exc}") from None
    except RecursionError:  # pragma: no cover - the bracket check comes first
        raise SpecFileError(f"{p}: nested too deeply to read (limit {MAX_NESTING})") from None
    check_document(p, doc)
    return doc
