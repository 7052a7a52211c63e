"""The planar graph examples against an independent solution (issue 26): the Watt I six-bar and
Jansen's leg dyad by dyad, the Stephenson III six-bar by its triad, all by circle intersections
in numpy from the joint points of the spec file (read with tomllib, not screwkit). The branch of
every intersection is the drawn one at the drawing and is kept by continuity; every joint centre
and point path must match the graph solver to 1e-9 of the mechanism's size at every sample."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

import screwkit as sk
from screwkit.kinematics.graph import solve_mechanism

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
MM = 1e-3


class Drawing:
    """The drawn joint and point positions (x, y in mm) of a planar spec, by name."""

    def __init__(self, name: str) -> None:
        self.path = EXAMPLES / f"{name}.toml"
        data = tomllib.loads(self.path.read_text())
        self.at = {j["name"]: np.array(j["at"], dtype=float) for j in data["joints"]}
        self.at.update({p["name"]: np.array(p["at"], dtype=float) for p in data["points"]})
        assert all(v[2] == 0.0 for v in self.at.values())
        assert all(j["axis"] == [0.0, 0.0, 1.0] for j in data["joints"])
        m = data["motion"]
        self.angles = np.radians(np.arange(m["start"], m["stop"] + 0.5 * m["step"], m["step"]))
        self.order = [j["name"] for j in data["joints"]]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.at[name][:2]

    def length(self, a: str, b: str) -> float:
        return float(np.linalg.norm(self[a] - self[b]))


def _circles(p: np.ndarray, r1: float, q: np.ndarray, r2: float) -> list[np.ndarray]:
    """Both intersections of the circles (p, r1) and (q, r2)."""
    d = q - p
    L = float(np.hypot(*d))
    a = (r1 * r1 - r2 * r2 + L * L) / (2 * L)
    h2 = r1 * r1 - a * a
    assert h2 > 1e-6 * r1 * r1, "the dyad reached a dead centre"
    e = d / L
    n = np.array([-e[1], e[0]])
    return [p + a * e + s * np.sqrt(h2) * n for s in (1.0, -1.0)]


def _nearest(cands: list[np.ndarray], prev: np.ndarray) -> np.ndarray:
    return min(cands, key=lambda x: float(np.linalg.norm(x - prev)))


def _carried(p0: np.ndarray, q0: np.ndarray, x0: np.ndarray, p: np.ndarray, q: np.ndarray
             ) -> np.ndarray:
    """Point x of the rigid body through p, q (drawn at p0, q0, x0)."""
    u0 = (q0 - p0) / np.linalg.norm(q0 - p0)
    n0 = np.array([-u0[1], u0[0]])
    u = (q - p) / np.linalg.norm(q - p)
    n = np.array([-u[1], u[0]])
    return p + ((x0 - p0) @ u0) * u + ((x0 - p0) @ n0) * n


def _turned(c: np.ndarray, x0: np.ndarray, t: float) -> np.ndarray:
    ct, st = np.cos(t), np.sin(t)
    v = x0 - c
    return c + np.array([ct * v[0] - st * v[1], st * v[0] + ct * v[1]])


def _compare(name: str, paths: dict[str, list[np.ndarray]]) -> None:
    spec = sk.load_spec(EXAMPLES / f"{name}.toml")
    md = solve_mechanism(spec.mechanism, spec.inputs).modes[0]
    assert md.assembles.all()
    size = spec.mechanism.length_scale
    order = [j.name for j in spec.mechanism.joints]
    for key, xy in paths.items():
        mine = np.array(xy) * MM
        got = md.points[key] if key in md.points else md.joint_centres[:, order.index(key)]
        assert got.shape[0] == mine.shape[0]
        np.testing.assert_allclose(got[:, :2], mine, rtol=0, atol=1e-9 * size, err_msg=key)
        np.testing.assert_allclose(got[:, 2], 0.0, rtol=0, atol=1e-12 * size, err_msg=key)


def test_watt_sixbar_equals_dyad_by_dyad() -> None:
    d = Drawing("watt_sixbar")
    OA, OB = d["OA"], d["OB"]
    lAB, lOB, lEG, lGF = d.length("A", "B"), d.length("B", "OB"), d.length("E", "G"), \
        d.length("G", "F")
    B, G = d["B"], d["G"]
    paths: dict[str, list[np.ndarray]] = {k: [] for k in ("A", "B", "E", "F", "G", "P")}
    for t in d.angles:
        A = _turned(OA, d["A"], t)
        B = _nearest(_circles(A, lAB, OB, lOB), B)  # the four-bar's dyad
        E = _carried(OB, d["B"], d["E"], OB, B)  # on the rocker
        F = _carried(d["A"], d["B"], d["F"], A, B)  # on the coupler
        G = _nearest(_circles(E, lEG, F, lGF), G)  # the second dyad
        P = _carried(d["G"], d["F"], d["P"], G, F)
        for k, v in zip(paths, (A, B, E, F, G, P), strict=True):
            paths[k].append(v)
    assert np.linalg.norm(paths["P"][-1] - d["P"]) < 1e-9  # a full crank turn closes the path
    _compare("watt_sixbar", paths)


def _triad(d: Drawing, x: float, psi: float, b: np.ndarray
           ) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """The Stephenson III triad for crank angle x (from the drawing): Newton on the angle psi
    of link K (Q1-a) until the coupler pin c lies at the rod length from the crank pin d."""
    Q1, Q2 = d["Q1"], d["Q2"]
    lK, lab, lR, lD = d.length("Q1", "a"), d.length("a", "b"), d.length("b", "Q2"), \
        d.length("c", "d")
    pin = _turned(d["Q3"], d["d"], x)

    def place(angle: float, near: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        a = Q1 + lK * np.array([np.cos(angle), np.sin(angle)])
        bb = _nearest(_circles(a, lab, Q2, lR), near)
        return a, bb, _carried(d["a"], d["b"], d["c"], a, bb)

    for _ in range(60):
        a, b2, c = place(psi, b)
        miss = float(np.linalg.norm(c - pin)) - lD
        step = 1e-7
        slope = (float(np.linalg.norm(place(psi + step, b2)[2] - pin)) - lD - miss) / step
        assert abs(slope) > 1.0  # mm/rad: far from the triad's singularity
        psi -= miss / slope
        if abs(miss) < 1e-13 * lD:
            break
    else:
        raise AssertionError(f"the triad did not converge at x = {x}")
    a, b, c = place(psi, b2)
    return psi, a, b, c


def test_stephenson3_sixbar_equals_its_triad_solved_by_circles() -> None:
    d = Drawing("stephenson3_sixbar")
    psi = float(np.arctan2(*(d["a"] - d["Q1"])[::-1]))
    b = d["b"]
    paths: dict[str, list[np.ndarray]] = {k: [] for k in ("d", "a", "b", "c", "P")}
    for x in d.angles:
        psi, a, b, c = _triad(d, float(x), psi, b)
        P = _carried(d["a"], d["b"], d["P"], a, b)
        for k, v in zip(paths, (_turned(d["Q3"], d["d"], x), a, b, c, P), strict=True):
            paths[k].append(v)
    assert np.linalg.norm(paths["P"][0] - d["P"]) < 1e-9  # the drawn branch at the drawing
    assert np.linalg.norm(paths["P"][-1] - d["P"]) < 1e-9
    _compare("stephenson3_sixbar", paths)


def _dyad_by_dyad(name: str) -> set[str]:
    """The bodies left unplaced when bodies are placed a dyad at a time from the ground and
    the crank: two unplaced bodies joined to each other and each to a placed body, or one
    unplaced body joined to placed bodies at two different points."""
    mech = sk.load_spec(EXAMPLES / f"{name}.toml").mechanism
    placed = {"ground", mech.joint(mech.inputs[0].split(".")[0]).bodies[1]}
    rest = set(mech.body_names) - placed

    def anchors(body: str) -> list[tuple[float, ...]]:
        return [tuple(j.at) for j in mech.joints if body in j.bodies
                and (set(j.bodies) - {body}) <= placed]

    while rest:
        single = {u for u in rest if len(set(anchors(u))) >= 2}
        pairs = {x for j in mech.joints if set(j.bodies) <= rest
                 and all(anchors(u) for u in j.bodies) for x in j.bodies}
        if not single | pairs:
            break
        placed |= single | pairs
        rest -= single | pairs
    return rest


def test_only_the_stephenson3_needs_a_triad() -> None:
    assert _dyad_by_dyad("watt_sixbar") == set()
    assert _dyad_by_dyad("jansen_leg") == set()
    assert _dyad_by_dyad("stephenson3_sixbar") == {"rod", "coupler", "link_k", "link_r"}


HOLY = {"a": 38.0, "b": 41.5, "c": 39.3, "d": 40.1, "e": 55.8, "f": 39.4, "g": 36.7,
        "h": 65.7, "i": 49.0, "j": 50.0, "k": 61.9, "l": 7.8, "m": 15.0}


def test_jansen_drawing_has_the_holy_numbers() -> None:
    d = Drawing("jansen_leg")
    sides = {"m": ("O", "Cj"), "j": ("Cj", "B"), "k": ("Ck", "Dk"), "b": ("Ab", "B"),
             "c": ("Ac", "Dk"), "d": ("Ab", "E"), "e": ("B", "E"), "f": ("E", "F"),
             "g": ("Dg", "F"), "h": ("F", "foot"), "i": ("Dg", "foot")}
    for key, (p, q) in sides.items():
        assert abs(d.length(p, q) - HOLY[key]) < 1e-12 * HOLY[key], key
    assert np.allclose(d["Ab"] - d["O"], [-HOLY["a"], -HOLY["l"]], rtol=0, atol=1e-12)
    for p, q in (("Cj", "Ck"), ("Ab", "Ac"), ("Dk", "Dg")):
        assert np.array_equal(d[p], d[q])  # a pin shared by three links


def test_jansen_foot_equals_dyad_by_dyad() -> None:
    d = Drawing("jansen_leg")
    O, A = d["O"], d["Ab"]
    L = HOLY
    B, D, E, F, foot = d["B"], d["Dk"], d["E"], d["F"], d["foot"]
    paths: dict[str, list[np.ndarray]] = {k: [] for k in ("Cj", "B", "Dk", "E", "F", "foot")}
    for t in d.angles:
        C = _turned(O, d["Cj"], t)
        B = _nearest(_circles(C, L["j"], A, L["b"]), B)
        D = _nearest(_circles(C, L["k"], A, L["c"]), D)
        E = _nearest(_circles(A, L["d"], B, L["e"]), E)
        F = _nearest(_circles(E, L["f"], D, L["g"]), F)
        foot = _nearest(_circles(F, L["h"], D, L["i"]), foot)
        for k, v in zip(paths, (C, B, D, E, F, foot), strict=True):
            paths[k].append(v)
    assert np.linalg.norm(paths["foot"][-1] - d["foot"]) < 1e-9  # a full turn closes the path
    _compare("jansen_leg", paths)
