"""The front door: ``import screwkit as sk`` offers every verb and type; one Motion type and one
mode numbering for every solver; every CLI job solves the motion exactly once."""

from __future__ import annotations

import inspect
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_every_front_door_name_resolves_and_documents_itself():
    for name in sk.__all__:
        obj = getattr(sk, name)
        assert name in dir(sk)
        doc = inspect.getdoc(obj)
        assert doc and len(doc) > 40, f"sk.{name} needs a docstring that says what it computes"
    for verb in ("load_spec", "solve_motion", "inverse_dynamics", "mobility", "balance",
                 "synthesize", "limit_positions"):
        doc = inspect.getdoc(getattr(sk, verb))
        # what it computes, where it comes from, and (for physical results) in which units
        assert any(k in doc for k in ("Bagci", "Rahman", "docs/", "eq.", "§")), verb
        if verb != "mobility":  # a count of freedoms
            assert any(k in doc for k in ("SI", "rad", "N·m", "(m)", "metres")), verb


def test_mobility_verb_survives_importing_the_mobility_package():
    """``screwkit.mobility`` is a package and the front-door verb: importing the package (as the
    docs do for the formula functions) must not replace the verb with an uncallable module."""
    import subprocess
    import sys

    code = ("{pre}\nimport screwkit as sk\nimport screwkit.mobility as m\n"
            "lk = sk.load_spec(r'{spec}').linkage\n"
            "assert m is sk.mobility\nprint(sk.mobility(lk).numeric.mobility)")
    for pre in ("", "import screwkit.mobility", "from screwkit.mobility import formula_mobility",
                "import screwkit.kinematics.analysis.loop_mobility"):
        out = subprocess.run([sys.executable, "-c", code.format(
            pre=pre, spec=EXAMPLES / "bagci_fig7_rsrc.toml")], capture_output=True, text=True,
            timeout=120)
        assert out.returncode == 0, (pre, out.stderr)
        assert out.stdout.strip() == "1", pre


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'solve'"):
        sk.solve  # noqa: B018


@pytest.mark.parametrize("example", ["bagci_fig7_rsrc", "bagci_example3_4r", "rahman_cssp"])
def test_closed_form_and_generic_give_the_same_motion_and_numbering(example):
    spec = sk.load_spec(EXAMPLES / f"{example}.toml")
    closed = sk.solve_motion(spec.linkage, spec.inputs, rates=1.3, accelerations=0.4)
    generic = sk.solve_motion(spec.linkage, spec.inputs, rates=1.3, accelerations=0.4,
                              method="generic")
    assert closed.method == "closed" and generic.method == "generic"
    assert isinstance(closed, sk.Motion) and isinstance(generic, sk.Motion)
    assert len(closed.modes) == len(generic.modes)
    L = spec.linkage.length_scale
    for k, (c, g) in enumerate(zip(closed.modes, generic.modes, strict=True)):
        assert c.index == g.index == k
        both = c.assembles & g.assembles
        assert both.sum() >= 0.9 * c.assembles.sum()
        np.testing.assert_allclose(c.joint_centres[both], g.joint_centres[both], atol=1e-9 * L)
        np.testing.assert_allclose(c.link_angular_velocity[both & ~c.singular & ~g.singular],
                                   g.link_angular_velocity[both & ~c.singular & ~g.singular],
                                   atol=1e-8)
        # the same variable names, joint freedoms and the seed's alike
        assert set(c.variables) == set(g.variables)


def test_motion_fields_and_named_access():
    spec = sk.load_spec(EXAMPLES / "bagci_fig7_rsrc.toml")
    m = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    n, L = len(spec.inputs), len(spec.linkage.links)
    md = m.mode(0)
    assert md.link_rotation.shape == (n, L, 3, 3) and md.joint_centres.shape == (n, 4, 3)
    assert m.solver.startswith("RSRC closed form")
    np.testing.assert_array_equal(m.variable("phi0", mode=0), md.variables["phi0"])
    np.testing.assert_array_equal(m.variable("phi0", mode=1, derivative=1),
                                  m.modes[1].velocities["phi0"])
    with pytest.raises(sk.AssemblyError, match=r"assembly mode 5 asked for.*0…1"):
        m.mode(5)
    with pytest.raises(KeyError, match="no variable 'psi'"):
        m.variable("psi")


def test_front_door_dynamics_equals_the_per_mode_form():
    spec = sk.load_spec(EXAMPLES / "rsrc_fig7_dynamics.toml")
    m = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed)
    a = sk.inverse_dynamics(m, 1, gravity=[0, 0, -9.80665])
    b = sk.inverse_dynamics(spec.linkage, m.mode(1), [0, 0, -9.80665], inputs=m.inputs)
    np.testing.assert_array_equal(a.shaking_force, b.shaking_force)
    r = a.reactions["sphere"]
    np.testing.assert_array_equal(r.force, r["force"])
    np.testing.assert_array_equal(r.point, m.mode(1).joint_centres[:, 1])


class _Counter:
    def __init__(self, fn):
        self.fn, self.calls = fn, 0

    def __call__(self, *args, **kwargs):
        self.calls += 1
        return self.fn(*args, **kwargs)


@pytest.mark.parametrize(("command", "example"), [
    ("dynamics", "rsrc_fig7_dynamics"), ("dynamics", "rahman_cssp"),
    ("balance", "rahman_cssp_balance"), ("analyze", "bagci_fig7_rsrc")])
def test_each_command_solves_the_motion_once(monkeypatch, command, example):
    import screwkit.kinematics.closed_forms.closed_form_motion as closed
    import screwkit.kinematics.solve_motion as solver
    import screwkit.pipeline as pipeline

    solve = _Counter(pipeline.solve_motion)
    generic = _Counter(solver.generic_motion)
    rsrc, cssp = _Counter(closed.rsrc_closed_motion), _Counter(closed.cssp_closed_motion)
    monkeypatch.setattr(pipeline, "solve_motion", solve)
    monkeypatch.setattr(solver, "generic_motion", generic)
    monkeypatch.setattr(closed, "rsrc_closed_motion", rsrc)
    monkeypatch.setattr(closed, "cssp_closed_motion", cssp)
    r = CliRunner().invoke(app, [command, str(EXAMPLES / f"{example}.toml"), "--json"])
    assert r.exit_code == 0, r.output
    assert solve.calls == 1
    assert rsrc.calls + cssp.calls == 1 and generic.calls == 0


@pytest.mark.parametrize("at", [[], ["40"], ["45", "90"]])
def test_export_solves_the_motion_once(monkeypatch, tmp_path, at):
    """An input between samples (45) is solved with the sweep, in the same single solve."""
    import screwkit.kinematics.closed_forms.closed_form_motion as closed
    import screwkit.pipeline as pipeline

    solve = _Counter(pipeline.solve_motion)
    rsrc = _Counter(closed.rsrc_closed_motion)
    monkeypatch.setattr(pipeline, "solve_motion", solve)
    monkeypatch.setattr(closed, "rsrc_closed_motion", rsrc)
    args = [a for x in at for a in ("--at", x)]
    r = CliRunner().invoke(app, ["export", str(EXAMPLES / "bagci_fig7_rsrc.toml"), "-f", "dxf",
                                 "-o", str(tmp_path / "f.dxf"), *args])
    assert r.exit_code == 0, r.output
    assert solve.calls == 1 and rsrc.calls == 1


def test_the_pipeline_reuses_its_motion():
    pipe = sk.Pipeline(sk.load_spec(EXAMPLES / "rahman_cssp_balance.toml"))
    first = pipe.motion
    pipe.dynamics()
    pipe.balance()
    assert pipe.motion is first
