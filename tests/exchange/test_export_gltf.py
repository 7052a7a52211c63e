"""``screwkit export --format gltf``: the scene read back with pygltflib (animation channels,
line strips) and with trimesh (scene graph, meshes) holds the link frames of an independent
``solve_motion`` of the spec and the coupler curve of ``screwkit analyze --json``, to float32
round-off, in metres, under a root that turns z-up into glTF's y-up."""

import json
from pathlib import Path

import numpy as np
import pygltflib
import trimesh
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

import screwkit as sk
from screwkit.cli.main import app

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FIG7 = EXAMPLES / "bagci_fig7_rsrc.toml"
Y_UP = Rotation.from_euler("x", -90, degrees=True).as_matrix()  # glTF world from screwkit's
runner = CliRunner()


def _export(tmp_path: Path, name: str, *args: str) -> Path:
    out = tmp_path / name
    r = runner.invoke(app, ["export", str(FIG7), "--format", "gltf", "-o", str(out), *args])
    assert r.exit_code == 0, r.output
    return out


def _read(gltf: pygltflib.GLTF2, accessor: int) -> np.ndarray:
    """An accessor's values, decoded from the buffer by hand (float32 / uint32)."""
    acc = gltf.accessors[accessor]
    view = gltf.bufferViews[acc.bufferView]
    blob = gltf.binary_blob()
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc.type]
    dtype = np.float32 if acc.componentType == 5126 else np.uint32
    start = view.byteOffset + (acc.byteOffset or 0)
    data = np.frombuffer(blob, dtype=dtype, count=acc.count * width, offset=start)
    return data.reshape(acc.count, width).astype(float)


def _check_animation(gltf: pygltflib.GLTF2, mode: int) -> None:
    spec = sk.load_spec(FIG7)
    md = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed).mode(mode)
    (root,) = gltf.scenes[gltf.scene].nodes
    assert np.allclose(Rotation.from_quat(gltf.nodes[root].rotation).as_matrix(), Y_UP)
    (anim,) = gltf.animations
    assert anim.name == f"mode {mode}"
    names = [lk.name for lk in spec.linkage.links]
    by_name = {gltf.nodes[i].name: i for i in gltf.nodes[root].children}
    assert set(names) | {"ground"} <= set(by_name)
    times = None
    checked = set()
    for ch in anim.channels:
        sampler = anim.samplers[ch.sampler]
        t = _read(gltf, sampler.input)[:, 0]
        times = t if times is None else times
        assert np.array_equal(t, times)
        link = names.index(gltf.nodes[ch.target.node].name)
        values = _read(gltf, sampler.output)
        if ch.target.path == "translation":
            err = np.abs(values - md.link_origin[:, link]).max()
            assert err < 1e-6 * np.abs(md.link_origin).max()
        else:
            R = Rotation.from_quat(values).as_matrix()
            assert np.abs(R - md.link_rotation[:, link]).max() < 1e-6
            assert np.all(np.sum(values[1:] * values[:-1], axis=1) > 0)  # no sign flips
        checked.add((link, ch.target.path))
    assert checked == {(k, p) for k in range(3) for p in ("translation", "rotation")}
    # keyframe times: the input angle over the spec's 1 rad/s
    assert np.allclose(times, spec.inputs - spec.inputs[0], atol=1e-6)
    assert np.allclose(anim.extras["inputs"], spec.inputs, rtol=0, atol=1e-15)


def test_glb_link_frames_follow_the_motion(tmp_path):
    _check_animation(pygltflib.GLTF2().load(str(_export(tmp_path, "fig7.glb"))), mode=0)


def test_gltf_json_of_another_mode(tmp_path):
    out = _export(tmp_path, "fig7.gltf", "--mode", "1")
    doc = json.loads(out.read_text())  # a .gltf file is JSON, its buffer a data URI
    assert doc["buffers"][0]["uri"].startswith("data:application/octet-stream;base64,")
    gltf = pygltflib.GLTF2().load(str(out))
    gltf.convert_buffers(pygltflib.BufferFormat.BINARYBLOB)
    _check_animation(gltf, mode=1)


def test_coupler_path_is_the_analysis_json(tmp_path):
    gltf = pygltflib.GLTF2().load(str(_export(tmp_path, "fig7.glb")))
    r = runner.invoke(app, ["analyze", str(FIG7), "--json"])
    analysis = json.loads(r.stdout)
    name = analysis["coupler_points"][0]["name"]
    path = analysis["modes"][0]["coupler_points"][name]
    want = np.column_stack([path["x"], path["y"], path["z"]])
    (node,) = [n for n in gltf.nodes if n.name == f"path {name}"]
    (strip,) = gltf.meshes[node.mesh].primitives
    assert strip.mode == pygltflib.LINE_STRIP
    got = _read(gltf, strip.attributes.POSITION)
    assert np.abs(got - want).max() < 1e-6 * np.abs(want).max()


def test_trimesh_sees_each_link_at_its_first_pose(tmp_path):
    """Read by trimesh (its own GLB parser and scene graph): each link's mesh, placed by its
    node, puts its sphere (its first 9 × 12 vertices) on the centre of the joint the link leads
    to, and the ground's sphere on joint 0."""
    scene = trimesh.load(str(_export(tmp_path, "fig7.glb")), file_type="glb", process=False)
    spec = sk.load_spec(FIG7)
    md = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed).mode(0)
    names = [lk.name for lk in spec.linkage.links] + ["ground"]
    for k, name in enumerate(names):
        transform, geometry = scene.graph[name]
        vertices = scene.geometry[geometry].vertices
        world = vertices @ transform[:3, :3].T + transform[:3, 3]
        centre = (world[:108] @ Y_UP).mean(axis=0)  # back to z-up
        want = md.joint_centres[0, (k + 1) % 4]
        assert np.linalg.norm(centre - want) < 1e-6 * np.abs(md.joint_centres).max()


def test_animation_skips_samples_where_the_mode_does_not_assemble(tmp_path):
    spec_path = EXAMPLES / "bagci_example7_double_crank.toml"  # no assembly at sample 6
    out = tmp_path / "ex7.glb"
    r = runner.invoke(app, ["export", str(spec_path), "-f", "gltf", "-o", str(out)])
    assert r.exit_code == 0, r.output
    gltf = pygltflib.GLTF2().load(str(out))
    spec = sk.load_spec(spec_path)
    md = sk.solve_motion(spec.linkage, spec.inputs, rates=spec.speed).mode(0)
    keep = md.assembles
    assert int(keep.sum()) == 23
    (anim,) = gltf.animations
    times = _read(gltf, anim.samplers[0].input)[:, 0]
    assert np.allclose(times, (spec.inputs[keep] - spec.inputs[0]) / spec.speed, atol=1e-5)
    for ch in anim.channels:
        if ch.target.path == "translation":
            link = [lk.name for lk in spec.linkage.links].index(gltf.nodes[ch.target.node].name)
            values = _read(gltf, anim.samplers[ch.sampler].output)
            assert np.abs(values - md.link_origin[keep, link]).max() < 1e-6
