"""Catalogue of kinematic pairs (joints): class and freedoms of each kind.

A pair of class *i* lets one link move relative to the other with *i* freedoms (Bagci 1969,
Appendix B, below eq. B.1). Freedoms are named in the pair's own frame:

=====  ==================================================================================
label  freedom
=====  ==================================================================================
rx…rz  rotation about the pair-frame x, y or z axis (through the pair centre)
tx…tz  translation along x, y or z
hz     helical: rotation about z coupled to a translation p·θ along z (pitch p)
sz     spiral: rotation about z coupled to a translation along x, normal to the axis
=====  ==================================================================================

Symbols R, P, H, C, S, S_s, H_s, S_a, S_p are Bagci's (List of Symbols). U and E are the
usual symbols for the universal (Hooke) joint and the planar pair. S_c, C_e and S_e are
screwkit's symbols for three higher pairs Bagci does not name (sphere in cylinder, cylinder
on plane, sphere on plane); the underscore keeps compact strings such as ``"RSRC"``
unambiguous.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from screwkit.mobility.errors import MobilityInputError, check_count

#: What each freedom label means; see the module table.
FREEDOM_MEANINGS: dict[str, str] = {
    "rx": "rotation about x",
    "ry": "rotation about y",
    "rz": "rotation about z",
    "tx": "translation along x",
    "ty": "translation along y",
    "tz": "translation along z",
    "hz": "rotation about z with translation along z (helical, fixed pitch)",
    "sz": "rotation about z with translation along x (spiral / planar screw)",
}


@dataclass(frozen=True)
class PairKind:
    """One kind of kinematic pair.

    Attributes
    ----------
    name:
        Canonical name in words (``"revolute"``).
    symbol:
        Short symbol used in mechanism names (``"R"`` as in R-S-R-C).
    freedoms:
        Freedom labels in the pair frame (see :data:`FREEDOM_MEANINGS`).
    aliases:
        Other accepted names (looked up case-insensitively, ignoring spaces, ``-`` and ``_``
        and a trailing "pair" or "joint").
    description:
        One line: what the pair is and what it allows.
    source:
        Where the name comes from (Bagci's List of Symbols, or "standard").
    """

    name: str
    symbol: str
    freedoms: tuple[str, ...]
    aliases: tuple[str, ...]
    description: str
    source: str

    @property
    def pair_class(self) -> int:
        """Class *i* = number of freedoms (Bagci 1969, Appendix B)."""
        return len(self.freedoms)

    @property
    def rotary_freedoms(self) -> int:
        """Pure rotation freedoms (Bagci's N_R counts these over a mechanism)."""
        return sum(f.startswith("r") for f in self.freedoms)

    @property
    def translatory_freedoms(self) -> int:
        """Pure translation freedoms (Bagci's N_T)."""
        return sum(f.startswith("t") for f in self.freedoms)

    @property
    def screw_freedoms(self) -> int:
        """Coupled rotation–translation freedoms (Bagci's N_S): helical and spiral."""
        return sum(f in ("hz", "sz") for f in self.freedoms)

    def as_dict(self) -> dict[str, object]:
        """Plain JSON-able description."""
        return {
            "name": self.name,
            "symbol": self.symbol,
            "class": self.pair_class,
            "freedoms": list(self.freedoms),
            "aliases": list(self.aliases),
            "description": self.description,
            "source": self.source,
        }


_BAGCI = "Bagci 1969, List of Symbols and Appendix B"
_STANDARD = "standard (not named by Bagci)"

#: Every pair kind, ordered by class.
PAIR_KINDS: tuple[PairKind, ...] = (
    PairKind("revolute", "R", ("rz",), ("revolute", "turning", "hinge", "pin"),
             "rotation about the pair axis (screw of zero pitch)", _BAGCI),
    PairKind("prism", "P", ("tz",), ("prism", "prismatic", "slider", "sliding"),
             "translation along the pair axis (screw of infinite pitch)", _BAGCI),
    PairKind("helical", "H", ("hz",), ("helical", "screw", "axial screw", "S_a"),
             "rotation about the axis with a translation of fixed pitch along it "
             "(Bagci's axial screw pair S_a is the same pair)", _BAGCI),
    PairKind("spiral", "H_s", ("sz",), ("spiral", "planar screw", "S_p"),
             "rotation about the axis coupled to a translation normal to it; Bagci's "
             "planar screw pair S_p is read as the same pair (Appendix B, Fig. 29g: "
             "RH_sP has m(101,110) = 4, a rotation and a translation on different axes)",
             _BAGCI),
    PairKind("cylinder", "C", ("rz", "tz"), ("cylinder", "cylindrical", "cylindric"),
             "rotation about and translation along the pair axis, independently", _BAGCI),
    PairKind("universal", "U", ("rz", "rx"),
             ("universal", "hooke", "hookes", "hooke's", "cardan"),
             "two rotations about intersecting perpendicular axes (Hooke joint)", _STANDARD),
    PairKind("slotted sphere", "S_s", ("rx", "rz"), ("slotted sphere", "sphere with pin"),
             "sphere whose pin (x) slides in a slot of plane xy: rotation about the pin and "
             "about the slot normal z; rotation about y is blocked", _BAGCI),
    PairKind("spherical", "S", ("rx", "ry", "rz"),
             ("spherical", "sphere", "ball", "ball and socket", "globular"),
             "any rotation about the pair centre", _BAGCI),
    PairKind("planar", "E", ("tx", "ty", "rz"), ("planar", "plane", "flat"),
             "plane on plane: two translations in the plane, rotation about its normal z",
             _STANDARD),
    PairKind("sphere in cylinder", "S_c", ("rx", "ry", "rz", "tz"),
             ("sphere in cylinder", "ball in cylinder", "ball in bore"),
             "sphere in a cylindrical bore of axis z: any rotation and a translation along z",
             _STANDARD),
    PairKind("cylinder on plane", "C_e", ("tx", "ty", "rx", "rz"),
             ("cylinder on plane", "line contact"),
             "cylinder of axis x lying on a plane of normal z: two translations in the plane, "
             "rolling about x, turning about z", _STANDARD),
    PairKind("sphere on plane", "S_e", ("tx", "ty", "rx", "ry", "rz"),
             ("sphere on plane", "point contact", "ball on plane"),
             "point contact (sphere on a plane of normal z): two translations in the plane and "
             "any rotation", _STANDARD),
)


_SYMBOL_FORM = re.compile(r"^[a-z](_[a-z])?$")


def _symbol_key(name: str) -> str:
    return name.strip().lower()


def _name_key(name: str) -> str:
    k = re.sub(r"[\s_\-']", "", name.strip().lower())
    for suffix in ("pair", "joint"):
        if k.endswith(suffix) and len(k) > len(suffix):
            k = k[: -len(suffix)]
    return k


# Symbols ("R", "S_s") match exactly, ignoring case; names and aliases match ignoring case,
# spaces, '-', '_' and a trailing "pair"/"joint". Keeping the two apart stops "SC" (a sphere
# then a cylinder) from reading as the sphere-in-cylinder S_c.
_BY_SYMBOL: dict[str, PairKind] = {}
_BY_NAME: dict[str, PairKind] = {}
for _kind in PAIR_KINDS:
    for _alias in (_kind.symbol, _kind.name, *_kind.aliases):
        _table, _k = (
            (_BY_SYMBOL, _symbol_key(_alias))
            if _SYMBOL_FORM.match(_symbol_key(_alias))
            else (_BY_NAME, _name_key(_alias))
        )
        if _table.get(_k, _kind) is not _kind:  # pragma: no cover - catalogue self-check
            raise RuntimeError(f"pair alias {_alias!r} is used twice")
        _table[_k] = _kind


def _lookup(name: str) -> PairKind | None:
    return _BY_SYMBOL.get(_symbol_key(name)) or _BY_NAME.get(_name_key(name))


def pair_kind_names() -> tuple[str, ...]:
    """Every valid pair name as ``"symbol (name)"``, for messages and help texts."""
    return tuple(f"{k.symbol} ({k.name})" for k in PAIR_KINDS)


def pair_kind(name: str | PairKind) -> PairKind:
    """Look a pair kind up by symbol, name or alias, case-insensitively.

    ``pair_kind("S_s")``, ``pair_kind("s_s")`` and ``pair_kind("Slotted-sphere pair")`` give
    the slotted-sphere pair. An unknown name raises :class:`MobilityInputError` listing the
    valid names.
    """
    if isinstance(name, PairKind):
        return name
    if not isinstance(name, str):
        raise MobilityInputError(f"a pair kind is named by a string; got {name!r}")
    kind = _lookup(name)
    if kind is None:
        raise MobilityInputError(
            f"unknown pair kind {name!r}; valid pairs are: " + ", ".join(pair_kind_names())
        )
    return kind


_SYMBOLS = sorted((k.symbol for k in PAIR_KINDS), key=len, reverse=True)
_TOKEN = re.compile(r"(\d*)(" + "|".join(re.escape(s) for s in _SYMBOLS) + ")", re.IGNORECASE)
_SYMBOL_OF = {s.lower(): pair_kind(s) for s in _SYMBOLS}


def _parse_compact(chunk: str, whole: str) -> list[PairKind]:
    out: list[PairKind] = []
    pos = 0
    while pos < len(chunk):
        m = _TOKEN.match(chunk, pos)
        if m is None:
            raise MobilityInputError(
                f"cannot read the pair list {whole!r} at {chunk[pos:]!r}; write symbols such "
                "as 'RSRC', 'RS_sRC' or '4P', or names separated by commas ('revolute, "
                "spherical'); valid pairs are: " + ", ".join(pair_kind_names())
            )
        repeat = int(m.group(1)) if m.group(1) else 1
        if repeat < 1:
            raise MobilityInputError(f"pair count {m.group(0)!r} in {whole!r} must be ≥ 1")
        out.extend([_SYMBOL_OF[m.group(2).lower()]] * repeat)
        pos = m.end()
    return out


def parse_pairs(pairs: str | Iterable[str | PairKind]) -> tuple[PairKind, ...]:
    """The pairs of a mechanism, in order.

    ``pairs`` is a compact string of symbols (``"RSRC"``, ``"RS_sRC"``, ``"R-S-S-R"``,
    ``"4P"`` for four prisms), a comma- or space-separated list of names
    (``"revolute, spherical, revolute, cylinder"``), or a sequence of names / kinds.
    """
    if isinstance(pairs, str):
        out: list[PairKind] = []
        for chunk in re.split(r"[,;]", pairs):
            chunk = chunk.strip()
            if not chunk:
                continue
            whole_chunk = _lookup(chunk)
            if whole_chunk is not None:
                out.append(whole_chunk)
                continue
            for word in chunk.split():
                kind = _lookup(word)
                if kind is not None:
                    out.append(kind)
                else:
                    out.extend(_parse_compact(word.replace("-", ""), pairs))
        if not out:
            raise MobilityInputError(f"the pair list {pairs!r} names no pair")
        return tuple(out)
    return tuple(pair_kind(p) for p in pairs)


def count_pairs_by_class(
    pairs: str | Iterable[str | PairKind] | Mapping[str, int],
) -> tuple[tuple[int, ...], dict[str, int]]:
    """(N_1 … N_5, {symbol: count}) of a pair list or a ``{name: count}`` mapping.

    N_i is the number of class-*i* pairs of Bagci's eq. (B.1).
    """
    counts: dict[str, int] = {}
    if isinstance(pairs, Mapping):
        for name, n in pairs.items():
            kind = pair_kind(name)
            n = check_count(n, f"number of {kind.name} pairs ({name!r})")
            counts[kind.symbol] = counts.get(kind.symbol, 0) + n
    else:
        for kind in parse_pairs(pairs):
            counts[kind.symbol] = counts.get(kind.symbol, 0) + 1
    by_class = [0] * 5
    for symbol, n in counts.items():
        by_class[pair_kind(symbol).pair_class - 1] += n
    return tuple(by_class), counts


def freedom_names(pairs: Sequence[tuple[str, str | PairKind]]) -> tuple[str, ...]:
    """Column names ``"<pair>.<freedom>"`` for pairs given as (label, kind) tuples.

    ``freedom_names([("A", "R"), ("B", "S")])`` gives ``("A.rz", "B.rx", "B.ry", "B.rz")``,
    the naming :func:`screwkit.mobility.mobility_from_jacobian` groups by.
    """
    return tuple(f"{label}.{f}" for label, kind in pairs for f in pair_kind(kind).freedoms)
