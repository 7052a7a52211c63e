"""``screwkit export`` of mechanism graphs (bodies and joints, docs/exchange.md): the DXF read back
with ezdxf and the glTF read back with pygltflib and trimesh hold the point paths, the body
frames and the bodies (through their joints) of an independent ``solve_mechanism`` of the
spec, to round-off (float32 round-off for glTF), in the spec's length unit (DXF) or metres."""

from pathlib import Path

import ezdxf
import numpy as np
import pygltflib
import trimesh
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app
from screwkit.kinematics.graph import solve_mechanism

MECHANISMS = Path(__file__).resolve().parents[2] / "examples" / "mechanisms"
WATT = MECHANISMS / "watt_sixbar.toml"  # mm, deg, 0…360° in 1° steps
STEWART = MECHANISMS / "stewart_platform_pose.toml"  # six inputs given as rows
Y_UP = Rotation.from_euler("x", -90, degrees=True).as_matrix()
MM = 1e-3
runner = CliRunner()


def _export(tmp_path: Path, spec: Path, fmt: str, name: str, *args: str) -> Path:
    out = tmp_path / name
    r = runner.invoke(app, ["export", str(spec), "--format", fmt, "-o", str(out), *args])
    assert r.exit_code == 0, r.output
    assert r.stdout.strip() == f"wrote {out}"
    return out


def _solve(path: Path, inputs: np.ndarray | None = None, every_mode: bool = True):
    spec = sk.load_spec(path)
    x = spec.inputs if inputs is None else inputs
    return spec, solve_mechanism(spec.mechanism, x, rates=spec.speed, every_mode=every_mode)


def _vertices(entity) -> np.ndarray:
    return np.array([tuple(v.dxf.location) for v in entity.vertices], dtype=float)


def test_dxf_of_a_six_bar_holds_its_point_path_and_bodies(tmp_path):
    """Every mode's path of P, in mm, is the solved path; the skeleton at 30.5° (between two
    samples: solved with the sweep) has one polyline per body and the ground, and each joint's
    centre, solved at 30.5° alone, is a vertex of the polylines of both its bodies."""
    doc = ezdxf.readfile(_export(tmp_path, WATT, "dxf", "watt.dxf", "--at", "30.5"))
    assert doc.header["$INSUNITS"] == 4  # millimetres
    spec, motion = _solve(WATT)
    layers: dict[str, list] = {}
    for e in doc.modelspace():
        layers.setdefault(e.dxf.layer, []).append(e)
    assert len(motion.modes) >= 2  # the closed-form dyads give more than the drawn mode
    for md in motion.modes:
        want = md.points["P"][md.assembles] / MM  # a curve is cut where it does not assemble
        got = np.vstack([_vertices(e) for e in layers[f"mode{md.index} P"]])
        assert got.shape == want.shape
        assert np.abs(got - want).max() < 1e-9 * np.abs(want).max()
    mech = spec.mechanism
    _, at = _solve(WATT, np.radians(np.linspace(0.0, 30.5, 62))[:, None], every_mode=False)
    skeleton = layers["mode0 skeleton at 30.5 deg"]
    assert len(skeleton) == len(mech.bodies) + 1
    polylines = [_vertices(e) for e in skeleton]
    names = [*mech.body_names, "ground"]
    for j, joint in enumerate(mech.joints):
        centre = at.modes[0].joint_centres[-1, j] / MM
        for body in joint.bodies:
            gap = np.linalg.norm(polylines[names.index(body)] - centre, axis=1).min()
            assert gap < 1e-9 * 100, (joint.name, body, gap)


def test_dxf_of_a_graph_driven_by_rows_refuses_at(tmp_path):
    out = tmp_path / "stewart.dxf"
    r = runner.invoke(app, ["export", str(STEWART), "-f", "dxf", "-o", str(out), "--at", "1"])
    assert r.exit_code == 2
    assert "--at needs a graph with one input" in " ".join(r.output.split())
    assert not out.exists()
    doc = ezdxf.readfile(_export(tmp_path, STEWART, "dxf", "stewart.dxf"))
    spec, motion = _solve(STEWART, every_mode=False)
    first = "mode0 skeleton at row 1"  # a graph driven by rows is drawn at its first row
    assert len([e for e in doc.modelspace() if e.dxf.layer == first]) == len(
        spec.mechanism.bodies) + 1


def _read(gltf: pygltflib.GLTF2, accessor: int) -> np.ndarray:
    """An accessor's values, decoded from the buffer by hand (float32 / uint32)."""
    acc = gltf.accessors[accessor]
    view = gltf.bufferViews[acc.bufferView]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc.type]
    dtype = np.float32 if acc.componentType == 5126 else np.uint32
    start = view.byteOffset + (acc.byteOffset or 0)
    data = np.frombuffer(gltf.binary_blob(), dtype=dtype, count=acc.count * width,
                         offset=start)
    return data.reshape(acc.count, width).astype(float)


def test_glb_of_a_six_bar_animates_every_body(tmp_path):
    """Each body's translation and rotation channel is its solved frame at every sample; the
    path of P is the solved path; keyframe times follow the spec's input speed."""
    out = _export(tmp_path, WATT, "gltf", "watt.glb")
    gltf = pygltflib.GLTF2().load(str(out))
    spec, motion = _solve(WATT, every_mode=False)
    md = motion.modes[0]
    names = list(spec.mechanism.body_names)
    (anim,) = gltf.animations
    assert anim.name == "mode 0"
    scale = np.abs(md.link_origin).max()
    checked = set()
    for ch in anim.channels:
        values = _read(gltf, anim.samplers[ch.sampler].output)
        b = names.index(gltf.nodes[ch.target.node].name)
        if ch.target.path == "translation":
            assert np.abs(values - md.link_origin[:, b]).max() < 1e-6 * scale
        else:
            R = Rotation.from_quat(values).as_matrix()
            assert np.abs(R - md.link_rotation[:, b]).max() < 1e-6
        checked.add((b, ch.target.path))
    assert checked == {(b, p) for b in range(len(names)) for p in ("translation", "rotation")}
    times = _read(gltf, anim.samplers[0].input)[:, 0]
    x = spec.inputs[:, 0]
    assert np.allclose(times, (x - x[0]) / spec.speed[0], atol=1e-5)
    (node,) = [n for n in gltf.nodes if n.name == "path P"]
    (strip,) = gltf.meshes[node.mesh].primitives
    want = md.points["P"]
    assert np.abs(_read(gltf, strip.attributes.POSITION) - want).max() < 1e-6 * scale


def test_trimesh_sees_each_body_through_its_joints(tmp_path):
    """Read by trimesh (its own GLB parser and scene graph): each body's mesh, placed by its
    node at the first sample and turned back to z-up, has a vertex on the centre of each of its
    joints (a cylinder's end-cap centre; a P, C or H joint's point is its first body's), to
    float32 round-off."""
    scene = trimesh.load(str(_export(tmp_path, STEWART, "gltf", "stewart.glb")),
                         file_type="glb", process=False)
    spec, motion = _solve(STEWART, every_mode=False)
    md = motion.modes[0]
    mech = spec.mechanism
    scale = np.abs(md.joint_centres).max()
    for name in [*mech.body_names, "ground"]:
        transform, geometry = scene.graph[name]
        vertices = scene.geometry[geometry].vertices
        world = (vertices @ transform[:3, :3].T + transform[:3, 3]) @ Y_UP
        for j, joint in enumerate(mech.joints):
            if name in joint.bodies:
                gap = np.linalg.norm(world - md.joint_centres[0, j], axis=1).min()
                assert gap < 1e-6 * scale, (name, joint.name, gap)
