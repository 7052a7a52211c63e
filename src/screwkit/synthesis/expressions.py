"""Safe evaluation of user expressions for desired functions (never ``eval`` of user text).

A spec file may state a desired rotation or translation as text, e.g.
``"0.45*((1 - 2*theta/80)**2 - 1)"``.  The text is parsed with :mod:`ast` and only a small,
closed grammar is accepted: numbers, the variable ``theta`` and named parameters, the operators
``+ - * / **`` (unary and binary), and the functions of `FUNCTIONS`.  Anything else (attribute
access, calls of other names, subscripts, comparisons, lambdas, ...) raises `ExpressionError`
naming what was found.  The result is evaluated with numpy, vectorised over ``theta``.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from screwkit.errors import InputError

__all__ = ["FUNCTIONS", "Expression", "ExpressionError", "parse_expression"]

FloatArray = NDArray[np.float64]

#: Functions a desired-function expression may call (one argument each, angles in radians).
FUNCTIONS: dict[str, Callable[[Any], Any]] = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
    "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "exp": np.exp,
    "log": np.log, "sqrt": np.sqrt, "abs": np.abs, "sign": np.sign,
    "radians": np.radians, "degrees": np.degrees,
}
CONSTANTS: dict[str, float] = {"pi": math.pi, "e": math.e}
MAX_LENGTH = 2000
MAX_NODES = 500


class ExpressionError(InputError):
    """An expression that is not in the accepted grammar; the message says what and where."""


_BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide,
    ast.Pow: np.power,
}
_UNARY: dict[type[ast.unaryop], Callable[[Any], Any]] = {ast.UAdd: np.positive, ast.USub: np.negative}


def _check(node: ast.AST, names: frozenset[str], text: str) -> None:
    """Reject every node outside the grammar (before anything is evaluated)."""
    count = 0
    for sub in ast.walk(node):
        count += 1
        if isinstance(sub, ast.Expression | ast.Load):
            continue
        if isinstance(sub, ast.Constant):
            if isinstance(sub.value, bool) or not isinstance(sub.value, int | float):
                raise ExpressionError(f"in {text!r}: only numbers are allowed as constants, "
                                      f"got {sub.value!r}")
        elif isinstance(sub, ast.Name):
            if sub.id not in names and sub.id not in CONSTANTS and sub.id not in FUNCTIONS:
                raise ExpressionError(
                    f"in {text!r}: unknown name {sub.id!r}; use theta, "
                    f"{', '.join(sorted(names - {'theta'})) or '(no parameters)'}, pi, or one of "
                    f"the functions {', '.join(sorted(FUNCTIONS))}")
        elif isinstance(sub, ast.BinOp):
            if type(sub.op) not in _BINARY:
                raise ExpressionError(f"in {text!r}: operator {type(sub.op).__name__} is not "
                                      "allowed; use + - * / **")
        elif isinstance(sub, ast.UnaryOp):
            if type(sub.op) not in _UNARY:
                raise ExpressionError(f"in {text!r}: unary {type(sub.op).__name__} is not allowed")
        elif isinstance(sub, ast.Call):
            if not (isinstance(sub.func, ast.Name) and sub.func.id in FUNCTIONS):
                raise ExpressionError(f"in {text!r}: only the functions "
                                      f"{', '.join(sorted(FUNCTIONS))} may be called")
            if len(sub.args) != 1 or sub.keywords:
                raise ExpressionError(f"in {text!r}: {sub.func.id}() takes exactly one argument")
        elif isinstance(sub, ast.operator | ast.unaryop):
            continue
        else:
            raise ExpressionError(f"in {text!r}: {type(sub).__name__} is not allowed in a desired "
                                  "function (numbers, theta, parameters, + - * / ** and "
                                  "functions only)")
    if count > MAX_NODES:
        raise ExpressionError(f"expression {text[:40]!r}... is too long ({count} nodes)")


def _evaluate(node: ast.AST, env: Mapping[str, Any]) -> Any:
    if isinstance(node, ast.Expression):
        return _evaluate(node.body, env)
    if isinstance(node, ast.Constant):
        return float(node.value)  # type: ignore[arg-type]  # _check: numbers only
    if isinstance(node, ast.Name):
        if node.id in env:
            return env[node.id]
        return CONSTANTS[node.id]
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)](_evaluate(node.left, env), _evaluate(node.right, env))
    if isinstance(node, ast.UnaryOp):
        return _UNARY[type(node.op)](_evaluate(node.operand, env))
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        return FUNCTIONS[node.func.id](_evaluate(node.args[0], env))
    raise AssertionError(f"unchecked node {type(node).__name__}")  # _check rejects these


@dataclass(frozen=True)
class Expression:
    """A parsed, checked expression of ``theta`` and named parameters."""

    text: str
    parameters: Mapping[str, float]
    _tree: ast.Expression

    def __call__(self, theta: ArrayLike) -> FloatArray:
        """Evaluate at ``theta`` (any shape); raises ExpressionError where not finite."""
        t = np.asarray(theta, dtype=np.float64)
        env: dict[str, Any] = dict(self.parameters)
        env["theta"] = t
        with np.errstate(all="ignore"):
            raw = np.asarray(_evaluate(self._tree, env), dtype=np.float64)
            value: FloatArray = np.broadcast_to(raw, t.shape).copy()
        bad = ~np.isfinite(value)
        if bad.any():
            where = float(t.reshape(-1)[int(np.flatnonzero(bad.reshape(-1))[0])])
            raise ExpressionError(f"{self.text!r} is not finite at theta = {where!r}")
        return value


def parse_expression(text: str, parameters: Mapping[str, float] | None = None) -> Expression:
    """Parse and check ``text``; ``parameters`` are extra named numbers it may use."""
    if not isinstance(text, str) or not text.strip():
        raise ExpressionError(f"a desired function must be a non-empty text, got {text!r}")
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression is too long ({len(text)} > {MAX_LENGTH} characters)")
    params = {str(k): float(v) for k, v in (parameters or {}).items()}
    for name in params:
        if not name.isidentifier() or name in FUNCTIONS or name in ("theta",):
            raise ExpressionError(f"parameter name {name!r} is not allowed (reserved or invalid)")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"{text!r} is not a valid expression: {exc.msg}") from None
    _check(tree, frozenset(params) | {"theta"}, text)
    return Expression(text, params, tree)
