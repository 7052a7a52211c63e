"""Safe desired-function expressions: the accepted grammar evaluates with numpy, everything else
is rejected before evaluation with a message naming what was found."""

import math

import numpy as np
import pytest

from screwkit.synthesis.expressions import ExpressionError, parse_expression
from screwkit.synthesis.targets import expression_function, library_function


def test_expression_evaluates_vectorised() -> None:
    expr = parse_expression("0.45*((1 - 2*theta/80)**2 - 1) + sin(radians(theta))*k", {"k": 2.0})
    theta = np.array([0.0, 40.0, 80.0])
    expected = 0.45 * ((1 - 2 * theta / 80) ** 2 - 1) + np.sin(np.radians(theta)) * 2.0
    assert np.array_equal(expr(theta), expected)
    assert parse_expression("-pi + 2**3")(np.zeros(2)).tolist() == [8 - math.pi] * 2


@pytest.mark.parametrize("text, fragment", [
    ("__import__('os').system('true')", "only the functions"),
    ("theta.real", "Attribute"),
    ("open", "unknown name"),
    ("x + 1", "unknown name 'x'"),
    ("theta[0]", "Subscript"),
    ("theta if theta else 1", "IfExp"),
    ("lambda: 1", "Lambda"),
    ("theta > 1", "Compare"),
    ("'a' * 3", "only numbers"),
    ("sin(theta, 2)", "exactly one argument"),
    ("theta // 2", "FloorDiv"),
    ("1 +", "not a valid expression"),
    ("", "non-empty"),
])
def test_rejected(text: str, fragment: str) -> None:
    with pytest.raises(ExpressionError, match=None) as info:
        parse_expression(text)
    assert fragment in str(info.value)


def test_non_finite_value_is_reported() -> None:
    with pytest.raises(ExpressionError, match="not finite at theta = 0"):
        parse_expression("1/theta")(np.array([0.0, 1.0]))


def test_units_and_library() -> None:
    fn = expression_function("1.5*(1 - (1 - theta/80)**2)", angle_unit=math.radians(1.0),
                             value_unit=0.0254)
    lib = library_function("parabola_rise", amplitude=1.5 * 0.0254, span=math.radians(80))
    theta = np.radians(np.arange(0.0, 81.0, 5.0))
    # same function through two routes; only rounding of the degree conversion differs
    assert np.allclose(fn(theta), lib(theta), rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="unknown desired function"):
        library_function("nope")
    with pytest.raises(ValueError, match="unexpected keyword"):
        library_function("power", amplitude=1.0, span=1.0, wrong=2.0)
