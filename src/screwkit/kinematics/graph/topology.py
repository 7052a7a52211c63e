"""Topology and mobility of a mechanism graph: its loops, the Grübler–Kutzbach count, the rank of
the stacked screw Jacobian, which constraints are redundant, idle freedoms and whether the inputs
drive it (docs/mechanisms.md).

The numeric mobility is m − rank J (m freedoms, J the stacked loop-closure Jacobian, six rows per
loop). Redundant constraints are the 6L − rank J rows that depend on the others: a column-pivoted
QR factorisation of Jᵀ picks an independent set of rows, and the rest are named as "loop k:
rotation about x" etc. (world axes). An idle freedom moves no joint centre: a null direction of
the passive block that leaves every joint centre still (a rod spinning between two balls).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from screwkit.kinematics.graph.closure import GraphLayout, graph_layout
from screwkit.kinematics.graph.newton import RANK_CUTOFF, linearise
from screwkit.kinematics.tracker.loop import Configuration
from screwkit.model.mechanism import GROUND, Mechanism
from screwkit.model.spin_groups import spin_groups

Array = NDArray[np.float64]

_ROW_NAMES = ("rotation about x", "rotation about y", "rotation about z",
              "translation along x", "translation along y", "translation along z")


@dataclass(frozen=True)
class MechanismTopology:
    """What :func:`mechanism_topology` reports (module docstring)."""

    mechanism: str
    bodies: int
    joints: int
    loops: list[list[str]]
    grubler: int
    freedoms: int
    rank: int
    mobility: int
    ranks_at_samples: list[int]
    redundant: list[str]
    idle: list[str]
    free: list[str]
    inputs: list[str]
    verdict: str

    @property
    def redundant_count(self) -> int:
        return len(self.redundant)

    def summary(self) -> list[str]:
        """The report in short lines (each under 80 columns but for long names)."""
        lines = [f"{self.bodies} moving bodies, {self.joints} joints, {len(self.loops)} "
                 f"independent loop(s)"]
        for k, loop in enumerate(self.loops):
            lines.append(f"loop {k + 1}: {' – '.join(loop)}")
        lines.append(f"Grübler–Kutzbach (spatial): M = 6·{self.bodies} − Σ(6 − f) = "
                     f"{self.grubler}")
        sampled = ", ".join(str(r) for r in sorted(set(self.ranks_at_samples)))
        lines.append(f"screw Jacobian: {self.freedoms} freedoms, rank {self.rank}, mobility "
                     f"{self.mobility}")
        lines.append(f"  (rank at the drawing and at sampled configurations: {sampled})")
        if self.redundant:
            lines.append(f"{len(self.redundant)} redundant constraint(s):")
            by_loop: dict[str, list[str]] = {}
            for r in self.redundant:
                where, what = r.split(": ", 1)
                by_loop.setdefault(where.split(" (")[0], []).append(what)
            lines += [f"  {where}: {', '.join(what)}" for where, what in by_loop.items()]
        if self.idle:
            lines.append(f"{len(self.idle)} idle freedom(s), moving no joint centre:")
            lines += [f"  {x}" for x in self.idle]
        lines.append(self.verdict)
        return lines

    def as_dict(self) -> dict[str, Any]:
        return {"mechanism": self.mechanism, "bodies": self.bodies, "joints": self.joints,
                "loops": self.loops, "grubler_kutzbach": self.grubler,
                "freedoms": self.freedoms, "jacobian_rank": self.rank,
                "mobility": self.mobility, "ranks_at_samples": self.ranks_at_samples,
                "redundant_constraints": self.redundant, "idle_freedoms": self.idle,
                "free_freedoms": self.free, "inputs": self.inputs,
                "drives": not self.free and "conflict" not in self.verdict,
                "verdict": self.verdict, "summary": self.summary()}


def _rank(s: Array) -> int:
    return int(np.sum(s > RANK_CUTOFF * max(float(s[0]) if s.size else 0.0, 1e-300)))


def mechanism_topology(mech: Mechanism, samples: Configuration | None = None
                       ) -> MechanismTopology:
    """The topology report at the drawn configuration, with the Jacobian's rank also at the
    configurations ``samples`` (e.g. every 10th sample of a solved motion)."""
    lay = graph_layout(mech)
    drawn = Configuration(np.zeros((1, lay.n_scalar)),
                          np.broadcast_to(np.eye(3), (1, lay.n_spherical, 3, 3)).copy())
    lin = linearise(mech, lay, drawn)
    J = lin.J[0]
    s = np.linalg.svd(J, compute_uv=False) if J.size else np.zeros(0)
    rank = _rank(s)
    ranks = [rank]
    if samples is not None and samples.size:
        Js = linearise(mech, lay, samples).J
        ranks += [_rank(x) for x in np.linalg.svd(Js, compute_uv=False)]
    m = lay.m
    grubler = 6 * len(mech.bodies) - sum(6 - len(j.freedoms) for j in mech.joints)
    redundant = _redundant_rows(mech, J, rank)
    idle, free = _null_freedoms(mech, lay, lin)
    if mech.drives:
        free, verdict = _driven_verdict(mech, m - rank, idle)
    else:
        verdict = _verdict(mech, lay, J, m - rank, idle, free)
    return MechanismTopology(mech.name, len(mech.bodies), len(mech.joints),
                             mech.loop_joint_names(), grubler, m, rank, m - rank, ranks,
                             redundant, idle, free, list(mech.driven_names), verdict)


def _redundant_rows(mech: Mechanism, J: Array, rank: int) -> list[str]:
    if J.shape[0] == rank:
        return []
    _, _, piv = scipy.linalg.qr(J.T, pivoting=True, mode="economic")
    dependent = sorted(int(r) for r in piv[rank:])
    names = mech.loop_joint_names()
    return [f"loop {r // 6 + 1} ({'-'.join(names[r // 6])}): {_ROW_NAMES[r % 6]}"
            for r in dependent]


def _null_freedoms(mech: Mechanism, lay: GraphLayout, lin: Any) -> tuple[list[str], list[str]]:
    """Null directions of the passive block: idle ones (no joint centre moves) and free ones
    (named by their largest components)."""
    passive = list(lay.passive)
    Jp = lin.J[0][:, passive]
    if Jp.shape[1] == 0:
        return [], []
    _, s, Vt = np.linalg.svd(Jp) if Jp.shape[0] else (None, np.zeros(0), np.eye(len(passive)))
    r = _rank(s)
    null = Vt[r:]
    if null.shape[0] == 0:
        return [], []
    # joint-centre velocities of each null direction: centre of joint i moves with the twist of
    # both its bodies; use the bodies' twists from the tree
    from screwkit.kinematics.graph.closure import body_twists
    from screwkit.kinematics.graph.newton import column_scale

    qd = np.zeros((null.shape[0], lay.m))
    qd[:, passive] = null * column_scale(lay)[passive]
    screws = np.broadcast_to(lin.frames.screws, (null.shape[0], *lin.frames.screws.shape[1:]))
    V, _ = body_twists(mech, lay, screws, qd)
    cols = []
    # a P joint inside a telescopic leg has no centre (its 'at' may be off the leg's line,
    # which its idle spin turns): the leg's balls and the bodies' other joints tell
    slides = {k for g in spin_groups(mech) for k in g.slides}
    for i, j in enumerate(mech.joints):
        if i in slides:
            continue
        c = lin.frames.centres[0, i]
        for body in j.bodies:
            if body != GROUND:
                Vb = V[:, lay.body_of[body]]
                cols.append((Vb[:, 3:] + np.cross(Vb[:, :3], c)) / lay.length)
    # centre velocities are linear in the null coordinates: the idle subspace is their kernel
    C = np.concatenate(cols, axis=1).T  # (3·k, n_null)
    _, sc, Wt = np.linalg.svd(C)
    rc = int(np.sum(sc > 1e-9 * max(1.0, float(sc[0]) if sc.size else 0.0)))
    idle_dirs = Wt[rc:] @ null
    free_dirs = Wt[:rc] @ null
    names = [lay.names[f] for f in passive]

    def pick(dirs: Array) -> list[str]:
        """One freedom per direction, all different: the column pivots of a QR factorisation
        of the directions (the freedoms that carry the subspace most independently)."""
        if dirs.shape[0] == 0:
            return []
        _, _, piv = scipy.linalg.qr(dirs, pivoting=True, mode="economic")
        return [names[k] for k in piv[: dirs.shape[0]]]

    rods = _rods(mech)
    d = idle_dirs.shape[0]
    if len(rods) > d:  # some rods cannot spin here (loaded by other constraints)
        return pick(idle_dirs), pick(free_dirs)
    idle = [f"{body} spin (about the line {a}–{b})" for body, a, b in rods]
    # an idle motion beyond the rods' spins is no structural freedom: the drawing is singular
    # there (a U joint with its rod in the plane of its axes …), so it counts as free
    balls = {j for _, a, b in rods for j in (a, b)}
    extra = [n for n in pick(idle_dirs) if n.split(".")[0] not in balls][:d - len(rods)]
    return idle, pick(free_dirs) + extra


def _rods(mech: Mechanism) -> list[tuple[str, str, str]]:
    """Rods: bodies held by exactly two ball joints and nothing else, and telescopic legs of
    bodies slid by P joints between two balls (model/spin_groups.py): each can spin about
    the line through its two ball centres, an idle freedom (a point it carries off that line
    turns with it, but no joint moves)."""
    return [(g.label, mech.joints[g.balls[0]].name, mech.joints[g.balls[1]].name)
            for g in spin_groups(mech)]


def _driven_verdict(mech: Mechanism, mobility: int, idle: list[str]) -> tuple[list[str], str]:
    """Free freedoms and the verdict of a mechanism with driven body freedoms: first the count
    (joint inputs + body drives = mobility, idle freedoms aside), then whether they fix it,
    from the mechanism with its drives' virtual chains (graph/drives.py)."""
    from screwkit.kinematics.graph.drives import augmented, rename_virtual

    effective = mobility - len(idle)
    names = mech.driven_names
    given = (f"{len(names)} driven freedom(s) ({len(mech.inputs)} joint input(s), "
             f"{len(mech.drives)} body freedom(s): {', '.join(names)})")
    whole = mechanism_topology(augmented(mech))
    free = [rename_virtual(mech, f) for f in whole.free]
    if len(names) > effective:
        return free, (f"the driven freedoms conflict: {given} for a mechanism of mobility "
                      f"{effective} (idle freedoms aside), which needs {effective}; remove "
                      f"{len(names) - effective} (a [[drives]] entry or an input = true)")
    if len(names) < effective:
        return free or ["(a freedom)"], (
            f"too few driven freedoms: {given} for a mechanism of mobility {effective} (idle "
            f"freedoms aside), which needs {effective}; add {effective - len(names)} (a "
            "[[drives]] entry or an input = true)"
            + (f"; free with these held: {', '.join(free)}" if free else ""))
    if whole.free or "conflict" in whole.verdict:
        return free or ["(a freedom)"], (
            f"the driven freedoms do not fix the mechanism: {given}, as many as its mobility "
            f"{effective}, but they leave a freedom free (a driven coordinate that cannot "
            "change here, or two that fix the same motion)"
            + (f"; free with these held: {', '.join(free)}" if free else "")
            + "; drive other freedoms (or draw it away from a singular configuration)")
    return [], (f"the driven freedom(s) drive the mechanism: mobility {effective}"
                + (f" + {len(idle)} idle" if idle else "") + f", {len(names)} driven")


def _verdict(mech: Mechanism, lay: GraphLayout, J: Array, mobility: int, idle: list[str],
             free: list[str]) -> str:
    n_in = len(mech.inputs)
    effective = mobility - len(idle)
    if free:
        return (f"the inputs do not drive the mechanism: mobility {effective} (idle freedoms "
                f"aside) needs {effective} input(s), {n_in} given; free with the inputs held: "
                + ", ".join(free) + " (if the mechanism has fewer freedoms, the drawing is at "
                "a dead centre or another singular configuration: draw it away from there)")
    if effective < n_in:
        return (f"the inputs conflict: mobility {effective} (idle freedoms aside) but {n_in} "
                f"inputs ({', '.join(mech.inputs)}); drive {effective}")
    return (f"the input(s) drive the mechanism: mobility {effective}"
            + (f" + {len(idle)} idle" if idle else "") + f", {n_in} input(s)")
