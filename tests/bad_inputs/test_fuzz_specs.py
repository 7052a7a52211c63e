"""Fuzzing the spec files: Hypothesis mutates the bundled examples — drops, duplicates and retypes
keys, perturbs numbers across magnitudes, swaps units, splices in random strings — and runs the
commands on them. Every command must exit 0 or 2 within a time bound, with no traceback and no
numpy warning; when it exits 0 its JSON is strict (no NaN/Infinity tokens) and every number is
finite except where a mask says the sample does not count.

A fast profile runs in ``make test``; ``SCREWKIT_FUZZ=long`` runs many more examples."""

from __future__ import annotations

import json
import os
import tomllib
from pathlib import Path
from typing import Any

import tomli_w
from cli_runner import invoke_bounded
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: small, fast examples of every family and table kind
FAST_EXAMPLES = ["bagci_fig7_rsrc", "bagci_example3_4r", "rahman_cssp_balance",
                 "fourbar_dynamics", "rsrc_fig7_dynamics", "bagci_example4_synthesis",
                 "rccc_loop", "rssr_spatial"]
LONG = os.environ.get("SCREWKIT_FUZZ") == "long"
TIMEOUT = 60.0
UNITS = ["mm", "in", "m", "deg", "rad", "kg", "lb", "lbf", "N", "rpm", "rad/s", "s",
         "kg*mm^2", "parsec", "", "furlong/fortnight", "deg/s^2"]
STRINGS = st.text(max_size=12) | st.sampled_from(["NaN", "inf", "-inf", "1e400", "10**10**10 m",
                                                  "true", "", " ", "💥", "1e-400 mm"])
SCALARS = (st.floats(allow_nan=True, allow_infinity=True) | st.integers(-10**20, 10**20)
           | st.booleans() | STRINGS)


def _paths(data: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every key path (dict keys and list indices) in a TOML document."""
    out = []
    if isinstance(data, dict):
        for k, v in data.items():
            out.append((*prefix, k))
            out += _paths(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            out.append((*prefix, i))
            out += _paths(v, (*prefix, i))
    return out


def _parent(data: Any, path: tuple[Any, ...]) -> Any:
    for p in path[:-1]:
        data = data[p]
    return data


def _mutate(data: dict[str, Any], draw: Any) -> dict[str, Any]:
    paths = _paths(data)
    if not paths:
        return data
    path = draw(st.sampled_from(paths))
    parent, key = _parent(data, path), path[-1]
    value = parent[key]
    op = draw(st.sampled_from(["drop", "duplicate", "retype", "scale", "unit", "splice"]))
    if op == "drop":
        if isinstance(parent, dict):
            del parent[key]
        elif len(parent) > 1:
            parent.pop(key)
    elif op == "duplicate" and isinstance(parent, dict):
        parent[f"{key}{draw(st.sampled_from(['_', '2', 's', 'X']))}"] = value
    elif op == "retype":
        parent[key] = draw(SCALARS | st.lists(SCALARS, max_size=3)
                           | st.dictionaries(st.text(max_size=4), SCALARS, max_size=2))
    elif op == "scale" and isinstance(value, int | float) and not isinstance(value, bool):
        exponent = draw(st.integers(-15, 15))
        parent[key] = draw(st.sampled_from([1.0, -1.0, 0.0])) * value * 10.0**exponent
    elif op == "unit":
        number = value if isinstance(value, int | float) and not isinstance(value, bool) else 1.0
        parent[key] = f"{number} {draw(st.sampled_from(UNITS))}".strip()
    elif op == "splice":
        parent[key] = f"{value}{draw(STRINGS)}"
    return data


def _drop_none(x: Any) -> Any:
    """TOML has no null: drop None values a retype may have made (keeps the document valid)."""
    if isinstance(x, dict):
        return {str(k): _drop_none(v) for k, v in x.items() if v is not None}
    if isinstance(x, list):
        return [_drop_none(v) for v in x if v is not None]
    return x


def _strict_and_finite(text: str) -> None:
    def refuse(token: str) -> None:
        raise AssertionError(f"non-strict JSON token {token}")

    json.loads(text, parse_constant=refuse)


@st.composite
def mutated_specs(draw: Any) -> tuple[str, str]:
    name = draw(st.sampled_from(FAST_EXAMPLES))
    data = tomllib.loads((EXAMPLES / f"{name}.toml").read_text(encoding="utf-8"))
    for _ in range(draw(st.integers(1, 3))):
        data = _mutate(data, draw)
    try:
        text = tomli_w.dumps(_drop_none(data))
    except (TypeError, ValueError):  # e.g. a float key; write what TOML can hold
        text = tomli_w.dumps(_drop_none(tomllib.loads((EXAMPLES / f"{name}.toml").read_text())))
    return name, text


def _commands(name: str) -> list[list[str]]:
    cmds = [["validate"], ["analyze", "--json"], ["mobility", "--json"]]
    if "dynamics" in name or "cssp" in name:
        cmds.append(["dynamics", "--json"])
    if name in ("bagci_fig7_rsrc", "bagci_example3_4r"):
        cmds.append(["limits", "--json"])
    if "balance" in name:
        cmds.append(["balance", "--json"])
    if "synthesis" in name:
        cmds.append(["synthesize", "--json", "--starts", "1"])
    return cmds


@settings(max_examples=400 if LONG else 25, deadline=None, derandomize=not LONG,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(case=mutated_specs())
def test_mutated_examples_exit_cleanly(case: tuple[str, str], tmp_path_factory: Any) -> None:
    name, text = case
    folder = tmp_path_factory.mktemp("fuzz")
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    for cmd in _commands(name):
        args = [cmd[0], str(path), *cmd[1:]]
        result, caught = invoke_bounded(args, TIMEOUT)
        where = f"screwkit {' '.join(args)}\n--- spec ---\n{text}\n--- output ---\n{result.output}"
        if result.exception is not None and not isinstance(result.exception, SystemExit):
            import traceback

            raise AssertionError("uncaught exception from " + where + "\n" + "".join(
                traceback.format_exception(result.exception)))
        assert result.exit_code in (0, 2), where
        assert "Traceback" not in result.output, where
        assert not caught, f"warnings {caught}: {where}"
        if result.exit_code == 0 and "--json" in cmd:
            _strict_and_finite(result.stdout)
