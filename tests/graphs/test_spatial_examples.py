"""The spatial graph examples against independent solutions and their own invariants (issue 26).

- double wishbone: the upright placed in numpy from its three balls (the lower ball turned with
  its arm; the upper ball where its arm's circle meets the sphere about the lower ball; the tie
  rod's outer ball by trilateration), camber, toe and track change from that pose against the
  graph solver's, and every hardpoint distance held;
- Stewart-Gough platform: every leg's length between its U and S centres is its drawn length
  plus its input, and the platform follows the trajectory its inputs were made from;
- Delta robot: every rod keeps its length, the plate keeps its orientation and follows the
  trajectory its arm angles were made from.
Hardpoints are read from the spec files with tomllib (mm), the solver's results are in SI."""

from __future__ import annotations

import tomllib
from functools import cache
from pathlib import Path

import numpy as np

import screwkit as sk
from screwkit.kinematics.graph import MechanismMode, solve_mechanism

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
MM = 1e-3


@cache
def _solved(name: str) -> tuple[dict[str, np.ndarray], sk.Mechanism, np.ndarray, MechanismMode]:
    """Drawn joint points (m) by name, the mechanism, its inputs and its drawn mode."""
    data = tomllib.loads((EXAMPLES / f"{name}.toml").read_text())
    at = {j["name"]: np.array(j["at"], dtype=float) * MM for j in data["joints"]}
    at.update({p["name"]: np.array(p["at"], dtype=float) * MM for p in data["points"]})
    spec = sk.load_spec(EXAMPLES / f"{name}.toml")
    md = solve_mechanism(spec.mechanism, spec.inputs).modes[0]
    assert md.assembles.all() and not md.singular.any()
    return at, spec.mechanism, spec.inputs, md


def _centre(mech: sk.Mechanism, md: MechanismMode, joint: str) -> np.ndarray:
    return md.joint_centres[:, [j.name for j in mech.joints].index(joint)]


def _rotation(axis: np.ndarray, t: float) -> np.ndarray:
    u = axis / np.linalg.norm(axis)
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + np.sin(t) * K + (1.0 - np.cos(t)) * K @ K


def _frame(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """An orthonormal frame from three points (columns)."""
    e1 = (q - p) / np.linalg.norm(q - p)
    e2 = (r - p) - ((r - p) @ e1) * e1
    e2 /= np.linalg.norm(e2)
    return np.column_stack([e1, e2, np.cross(e1, e2)])


# --- double wishbone ---------------------------------------------------------------------
HARD = {"LF": [200.0, 350.0, 150.0], "LR": [-200.0, 360.0, 160.0],
        "UF": [120.0, 440.0, 440.0], "UR": [-150.0, 450.0, 455.0]}  # bushings (spec header)


def _upright_by_hand(at: dict[str, np.ndarray], theta: float) -> tuple[np.ndarray, np.ndarray]:
    """The upright's rotation and the lower ball for lower-arm angle ``theta`` (module doc)."""
    hard = {k: np.array(v) * MM for k, v in HARD.items()}
    la, ua = hard["LF"] - hard["LR"], hard["UF"] - hard["UR"]  # the hinge lines
    LB = at["L"] + _rotation(la, theta) @ (at["LB"] - at["L"])
    # the upper ball: on the circle of its arm about U, at |UB - LB| from the lower ball:
    # α cos φ + β sin φ = γ
    v0 = at["UB"] - at["U"]
    u = ua / np.linalg.norm(ua)
    par, perp = (v0 @ u) * u, v0 - (v0 @ u) * u
    w = np.cross(u, perp)
    c = at["U"] + par - LB
    r2 = float(np.sum((at["UB"] - at["LB"]) ** 2))
    alpha, beta = 2 * (c @ perp), 2 * (c @ w)
    gamma = r2 - c @ c - perp @ perp
    base = np.arctan2(beta, alpha)
    spread = np.arccos(gamma / np.hypot(alpha, beta))
    phi = min((base + spread, base - spread), key=lambda x: abs(np.angle(np.exp(1j * x))))
    UB = at["U"] + par + np.cos(phi) * perp + np.sin(phi) * w
    # the tie rod's outer ball: the spheres about TI, LB and UB, on the drawn side
    centres = (at["TI"], LB, UB)
    radii = [float(np.linalg.norm(at["TO"] - x)) for x in (at["TI"], at["LB"], at["UB"])]
    TO = _trilaterate(centres, radii, _side(at))
    R = _frame(LB, UB, TO) @ _frame(at["LB"], at["UB"], at["TO"]).T
    return R, LB


def _side(at: dict[str, np.ndarray]) -> float:
    return float(np.sign(np.cross(at["LB"] - at["TI"], at["UB"] - at["TI"])
                         @ (at["TO"] - at["TI"])))


def _trilaterate(c: tuple[np.ndarray, ...], r: list[float], side: float) -> np.ndarray:
    ex = (c[1] - c[0]) / np.linalg.norm(c[1] - c[0])
    i = ex @ (c[2] - c[0])
    ey = c[2] - c[0] - i * ex
    ey /= np.linalg.norm(ey)
    ez = np.cross(ex, ey)
    d = np.linalg.norm(c[1] - c[0])
    j = ey @ (c[2] - c[0])
    x = (r[0] ** 2 - r[1] ** 2 + d ** 2) / (2 * d)
    y = (r[0] ** 2 - r[2] ** 2 + i * i + j * j) / (2 * j) - i * x / j
    z2 = r[0] ** 2 - x * x - y * y
    assert z2 > 0
    return c[0] + x * ex + y * ey + side * np.sqrt(z2) * ez


def _camber_toe(R: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Camber (top out positive) and toe (toe-in positive) of the left wheel, whose spin axis
    is +y in the drawing, in radians, from the upright's rotation(s)."""
    s = R @ np.array([0.0, 1.0, 0.0])
    return -np.arcsin(s[..., 2]), np.arctan2(s[..., 0], s[..., 1])


def test_double_wishbone_upright_pose_and_bump_steer_curves() -> None:
    at, mech, X, md = _solved("double_wishbone")
    up = mech.body_index("upright")
    R = md.link_rotation[:, up]
    mine = [_upright_by_hand(at, float(x)) for x in X[:, 0]]
    np.testing.assert_allclose(R, np.array([m[0] for m in mine]), rtol=0, atol=1e-10)
    np.testing.assert_allclose(_centre(mech, md, "LB"), np.array([m[1] for m in mine]), rtol=0,
                               atol=1e-12)
    # the points carried by the upright follow its pose
    p = md.link_origin[:, up]
    for name in ("wheel_centre", "contact_patch"):
        np.testing.assert_allclose(md.points[name], np.einsum("nij,j->ni", R, at[name]) + p,
                                   rtol=0, atol=1e-12)
    camber, toe = _camber_toe(R)
    camber_hand, toe_hand = _camber_toe(np.array([m[0] for m in mine]))
    np.testing.assert_allclose(camber, camber_hand, rtol=0, atol=1e-10)
    np.testing.assert_allclose(toe, toe_hand, rtol=0, atol=1e-10)
    travel = md.points["wheel_centre"][:, 2] - at["wheel_centre"][2]
    track = 2 * (md.points["contact_patch"][:, 1] - at["contact_patch"][1])
    k0 = int(np.argmin(np.abs(X[:, 0])))
    assert X[k0, 0] == 0.0
    assert max(abs(camber[k0]), abs(toe[k0]), abs(track[k0]) / 0.3) < 1e-12  # the drawing
    assert np.all(np.diff(travel) > 0)  # the input lifts the wheel throughout
    assert travel[0] < -0.05 and travel[-1] > 0.05  # more than ±50 mm of wheel travel
    # a shorter upper arm: camber goes negative in bump and positive in rebound
    assert camber[-1] < 0 < camber[0]


def test_double_wishbone_keeps_every_hardpoint_distance() -> None:
    at, mech, _, md = _solved("double_wishbone")
    hard = {k: np.array(v) * MM for k, v in HARD.items()}
    # the R joints sit midway between their bushings, on the bushing line (spec header)
    for arm, front, rear in (("L", "LF", "LR"), ("U", "UF", "UR")):
        np.testing.assert_allclose(at[arm], 0.5 * (hard[front] + hard[rear]), rtol=0, atol=1e-15)
        axis = mech.joint(arm).axis
        assert np.linalg.norm(np.cross(axis, hard[front] - hard[rear])) < 1e-15
    now = {name: _centre(mech, md, name) for name in ("LB", "UB", "TI", "TO")}
    np.testing.assert_allclose(now["TI"], np.broadcast_to(at["TI"], now["TI"].shape), rtol=0,
                               atol=1e-15)  # the rack end is fixed
    pairs = [("LB", "LF"), ("LB", "LR"), ("UB", "UF"), ("UB", "UR"),  # arm to bushings
             ("TO", "TI"),  # the tie rod
             ("LB", "UB"), ("LB", "TO"), ("UB", "TO")]  # the upright's three balls
    for a, b in pairs:
        drawn = float(np.linalg.norm(at[a] - (hard[b] if b in hard else at[b])))
        other = hard[b] if b in hard else now[b]
        np.testing.assert_allclose(np.linalg.norm(now[a] - other, axis=-1), drawn, rtol=0,
                                   atol=1e-10, err_msg=f"{a}-{b}")


# --- Stewart-Gough platform --------------------------------------------------------------
def _stewart_pose(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The trajectory the rows were made from (spec header): centre offset (m), rotation."""
    two = 2 * np.pi * s
    d = np.stack([40 * np.sin(two), 30 * np.sin(2 * two), 25 * np.sin(np.pi * s)], -1) * MM
    yaw, pitch, roll = np.radians([6 * np.sin(two), 4 * np.sin(two), 5 * np.sin(2 * two)])
    R = np.array([_rotation(np.array([0, 0, 1.0]), a) @ _rotation(np.array([0, 1.0, 0]), b)
                  @ _rotation(np.array([1.0, 0, 0]), c) for a, b, c in zip(yaw, pitch, roll,
                                                                         strict=True)])
    return d, R


def test_stewart_leg_lengths_are_the_inputs() -> None:
    at, mech, X, md = _solved("stewart_platform")
    assert mech.inputs == tuple(f"P{k}.s" for k in range(1, 7))
    for k in range(1, 7):
        drawn = np.linalg.norm(at[f"S{k}"] - at[f"U{k}"])
        leg = np.linalg.norm(_centre(mech, md, f"S{k}") - _centre(mech, md, f"U{k}"), axis=1)
        np.testing.assert_allclose(leg, drawn + X[:, k - 1], rtol=0, atol=1e-10)
        np.testing.assert_allclose(md.variables[f"P{k}.s"], X[:, k - 1], rtol=0, atol=1e-12)


def test_stewart_platform_follows_its_trajectory() -> None:
    at, mech, X, md = _solved("stewart_platform")
    s = np.arange(X.shape[0]) / (X.shape[0] - 1)
    d, R = _stewart_pose(s)
    np.testing.assert_allclose(md.points["centre"], at["centre"] + d, rtol=0, atol=1e-11)
    np.testing.assert_allclose(md.link_rotation[:, mech.body_index("platform")], R, rtol=0,
                               atol=1e-10)


# --- Delta robot -------------------------------------------------------------------------
def test_delta_rods_keep_their_length_and_the_plate_only_translates() -> None:
    at, mech, X, md = _solved("delta_robot")
    rods = [(f"E{k}{t}", f"P{k}{t}") for k in (1, 2, 3) for t in "ab"]
    drawn = [np.linalg.norm(at[a] - at[b]) for a, b in rods]
    assert np.ptp(drawn) < 1e-12  # every rod of the drawing has the same length
    for (a, b), length in zip(rods, drawn, strict=True):
        got = np.linalg.norm(_centre(mech, md, a) - _centre(mech, md, b), axis=1)
        np.testing.assert_allclose(got, length, rtol=0, atol=1e-10, err_msg=a)
    plate = md.link_rotation[:, mech.body_index("plate")]
    np.testing.assert_allclose(plate, np.broadcast_to(np.eye(3), plate.shape), rtol=0,
                               atol=1e-10)
    s = np.arange(X.shape[0]) / (X.shape[0] - 1)
    two = 2 * np.pi * s
    path = np.stack([60 * np.sin(two), 60 * (1 - np.cos(two)), -40 * np.sin(np.pi * s) ** 2],
                    -1) * MM  # the trajectory the rows were made from (spec header)
    np.testing.assert_allclose(md.points["centre"], at["centre"] + path, rtol=0, atol=1e-11)
    for k in (1, 2, 3):
        np.testing.assert_allclose(md.variables[f"R{k}.theta"], X[:, k - 1], rtol=0,
                                   atol=1e-12)
