"""Sweep pictures in reports: a picture written by ``screwkit sweep --plot`` carries PNG text
chunks (``Title``, ``Description``, ``Software = "screwkit sweep"``); :func:`sweep_pictures`
finds such pictures in a folder so the demo index (:func:`screwkit.report.html.write_index`)
shows them with their titles (docs/sweeps.md, "Plots")."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

#: the ``Software`` text chunk that marks a sweep picture
PICTURE_SOFTWARE = "screwkit sweep"

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_text(path: Path, limit: int = 1 << 20) -> dict[str, str]:
    """The text chunks (tEXt, zTXt, iTXt) of a PNG file read before its image data; an empty
    dict for a file that is not a PNG."""
    out: dict[str, str] = {}
    try:
        with open(path, "rb") as fh:
            if fh.read(8) != _PNG_SIGNATURE:
                return out
            while True:
                head = fh.read(8)
                if len(head) < 8:
                    return out
                size, kind = struct.unpack(">I4s", head)
                if kind == b"IDAT" or size > limit:
                    return out
                body = fh.read(size)
                fh.read(4)  # CRC
                if kind == b"tEXt" and b"\0" in body:
                    key, value = body.split(b"\0", 1)
                    out[key.decode("latin-1")] = value.decode("latin-1")
                elif kind == b"zTXt" and b"\0" in body:
                    key, rest = body.split(b"\0", 1)
                    out[key.decode("latin-1")] = zlib.decompress(rest[1:]).decode("latin-1")
                elif kind == b"iTXt" and b"\0" in body:
                    key, rest = body.split(b"\0", 1)
                    compressed = rest[0] == 1
                    text = rest[2:].split(b"\0", 2)[-1]
                    out[key.decode("utf-8")] = (zlib.decompress(text) if compressed
                                                else text).decode("utf-8")
    except (OSError, zlib.error, UnicodeDecodeError, struct.error):
        return {}
    return out


def sweep_pictures(folder: Path) -> list[dict[str, str]]:
    """The sweep pictures in ``folder`` (file name, title, description), by file name."""
    found = []
    for png in sorted(folder.glob("*.png")):
        text = png_text(png)
        if text.get("Software") == PICTURE_SOFTWARE:
            found.append({"file": png.name, "title": text.get("Title", png.stem),
                          "description": text.get("Description", "")})
    return found
