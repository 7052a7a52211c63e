"""pydantic validation errors as short lines a user can act on: one line per key (the union
branches pydantic tries for a quantity — number, integer, string — are merged into one
"expected … ; got …"), at most :data:`MAX_LISTED_ERRORS` lines, the value echoed as a short
excerpt (docs/reliability.md)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import AfterValidator, ValidationError

from screwkit.errors import InputError
from screwkit.io.quantity import excerpt
from screwkit.tables import FORMULA_STARTS


def refuse_formula(name: str) -> str:
    """``name`` unless it starts as a spreadsheet formula would (``=``, ``+``, ``-``, ``@``):
    names become CSV and Parquet column headers, where ``=HYPERLINK(…)`` would run."""
    if name.startswith(FORMULA_STARTS):
        raise InputError(f"the name {excerpt(name)} starts with {name[0]!r}, which a spreadsheet "
                         "reads as a formula in the CSV headers; start it with a letter")
    return name


#: a joint, link, point or counterweight name of a spec file (see :func:`refuse_formula`)
Name = Annotated[str, AfterValidator(refuse_formula)]

#: validation errors listed in one message (the rest are counted)
MAX_LISTED_ERRORS = 12

_UNION_TAGS = {"float", "int", "str", "bool"}
_EXPECTED = {
    "float_type": "a number",
    "int_type": "an integer",
    "string_type": "a string with a unit (e.g. \"2.0 in\")",
    "list_type": "a list",
    "dict_type": "a table",
    "bool_type": "true or false (TOML booleans, without quotes)",
    "model_type": "a table",
}


def _key(loc: tuple[Any, ...]) -> str:
    """Dotted key of a pydantic location without its union-branch tags."""
    parts = [str(p) for p in loc if not (isinstance(p, str) and (p in _UNION_TAGS or "[" in p))]
    return ".".join(parts)[:120]


def _shown(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    if isinstance(value, str):
        return excerpt(value)
    text = repr(value)
    return text if len(text) <= 40 else text[:40] + "…"


def validation_lines(exc: ValidationError, prefix: str = "",
                     unknown_hint: str = "docs/spec-format.md") -> list[str]:
    """``[key] message`` lines for ``exc``; ``prefix`` goes before each key (e.g.
    ``"balancing."``)."""
    groups: dict[str, list[Any]] = {}
    for err in exc.errors():
        groups.setdefault(_key(tuple(err["loc"])), []).append(err)
    lines = []
    for key, errs in list(groups.items())[:MAX_LISTED_ERRORS]:
        types = [e["type"] for e in errs]
        if all(t in _EXPECTED for t in types):
            wanted = list(dict.fromkeys(_EXPECTED[t] for t in types))
            if "a number" in wanted and "an integer" in wanted:
                wanted.remove("an integer")
            expected = ", ".join(wanted[:-1]) + (" or " if len(wanted) > 1 else "") + wanted[-1]
            msg = f"expected {expected}; got {_shown(errs[0]['input'])}"
        elif types[0] == "extra_forbidden":
            msg = f"unknown key (check the spelling; see {unknown_hint})"
        else:
            msg = str(errs[0]["msg"]).removeprefix("Value error, ")
        lines.append(f"  [{prefix}{key}] {msg}")
    if len(groups) > MAX_LISTED_ERRORS:
        lines.append(f"  … and {len(groups) - MAX_LISTED_ERRORS} more")
    return lines
