"""The mechanism to **glTF 2.0** (binary GLB, pygltflib, MIT; docs/exchange.md), animated over
the spec's sweep, for Blender, three.js and CAD viewers.

Layout: one root node turns screwkit's z-up world into glTF's y-up (a −90° turn about x, as
Blender's exporter does); under it one node per link or body (moving ones, then ``ground``)
whose translation and rotation are its body frame (``ModeMotion.link_origin``,
``link_rotation``; the ground stays in the world frame) and one node per coupler point (a
graph's ``[[points]]`` point) holding its path as line strips. Each body's mesh is what the
report draws of it (:mod:`screwkit.exchange.geometry`): cylinders along its polyline and a
sphere at its last vertex (a loop's link: the centre of the joint it leads to), in its own
frame. One animation ("mode k") has a
translation and a rotation channel per moving link at the samples where the mode assembles;
keyframe times follow the spec's input speed (t = (x − x₀)/ẋ), or 24 frames per second when the
speed is zero. Lengths are metres (the glTF unit); geometry is float32.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from screwkit.exchange.geometry import ExportGeometry, ModeGeometry
from screwkit.exchange.samples import Array, ExportError, assembled_runs

#: z-up (screwkit) to y-up (glTF): −90° about x, as (x, y, z, w)
Z_UP_TO_Y_UP = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))
_SEGMENTS = 16  # sides of a cylinder
FLOAT, UINT32 = 5126, 5125  # glTF component types
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


def cylinder(a: Array, b: Array, radius: float) -> tuple[Array, NDArray[np.uint32]]:
    """Vertices and triangle indices of a closed cylinder of ``radius`` from ``a`` to ``b``."""
    d = b - a
    length = float(np.linalg.norm(d))
    w = d / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(w, helper)
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    t = np.linspace(0.0, 2 * np.pi, _SEGMENTS, endpoint=False)
    ring = radius * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v)
    verts = np.vstack([a + ring, b + ring, a, b])
    s = _SEGMENTS
    i = np.arange(s)
    j = (i + 1) % s
    side = np.concatenate([np.stack([i, j, s + i], 1), np.stack([j, s + j, s + i], 1)])
    caps = np.concatenate([np.stack([np.full(s, 2 * s), j, i], 1),
                           np.stack([np.full(s, 2 * s + 1), s + i, s + j], 1)])
    return verts, np.concatenate([side, caps]).astype(np.uint32)


def sphere(centre: Array, radius: float, rings: int = 8, sectors: int = 12
           ) -> tuple[Array, NDArray[np.uint32]]:
    """Vertices and triangle indices of a UV sphere."""
    phi = np.linspace(0.0, np.pi, rings + 1)
    theta = np.linspace(0.0, 2 * np.pi, sectors, endpoint=False)
    P, T = np.meshgrid(phi, theta, indexing="ij")
    unit = np.stack([np.sin(P) * np.cos(T), np.sin(P) * np.sin(T), np.cos(P)], axis=-1)
    verts = centre + radius * unit.reshape(-1, 3)
    r, c = np.meshgrid(np.arange(rings), np.arange(sectors), indexing="ij")
    a = r * sectors + c
    b = r * sectors + (c + 1) % sectors
    tris = np.concatenate([np.stack([a, a + sectors, b], -1).reshape(-1, 3),
                           np.stack([b, a + sectors, b + sectors], -1).reshape(-1, 3)])
    return verts, tris.astype(np.uint32)


def link_mesh(local: Array, radius: float) -> tuple[Array, NDArray[np.uint32]]:
    """One body's mesh from its polyline ``local`` (P, 3) in its own frame: a cylinder per
    segment longer than round-off, a sphere at the end (the next joint's centre)."""
    parts = [sphere(local[-1], 2 * radius)]
    for a, b in zip(local[:-1], local[1:], strict=True):
        if np.linalg.norm(b - a) > 1e-9 * max(radius, 1e-12):
            parts.append(cylinder(a, b, radius))
    verts, tris, offset = [], [], 0
    for v, t in parts:
        verts.append(v)
        tris.append(t + offset)
        offset += len(v)
    return np.vstack(verts), np.vstack(tris)


def quaternions(R: Array) -> Array:
    """(K, 4) unit quaternions (x, y, z, w) of rotation matrices (K, 3, 3), signs chosen so
    consecutive keyframes are within 90° (glTF interpolates them linearly)."""
    from scipy.spatial.transform import Rotation

    q = np.asarray(Rotation.from_matrix(R).as_quat())
    # flip q_k when it points away from the (already flipped) q_{k-1}: a running product of signs
    turn = np.where(np.sum(q[1:] * q[:-1], axis=1) < 0, -1.0, 1.0)
    q[1:] *= np.cumprod(turn)[:, None]
    return q


class _Buffer:
    """The GLB binary chunk, with one buffer view and accessor per array."""

    def __init__(self, gltf: Any) -> None:
        self.gltf = gltf
        self.data = bytearray()

    def add(self, array: NDArray[Any], kind: str, target: int | None = None,
            bounds: bool = False) -> int:
        import pygltflib as g

        arr = np.ascontiguousarray(array, dtype=np.uint32 if kind == "SCALAR_INDEX"
                                   else np.float32)
        while len(self.data) % 4:
            self.data.append(0)
        self.gltf.bufferViews.append(g.BufferView(buffer=0, byteOffset=len(self.data),
                                                  byteLength=arr.nbytes, target=target))
        self.data += arr.tobytes()
        flat = arr.reshape(arr.shape[0], -1)
        gtype = {1: "SCALAR", 3: "VEC3", 4: "VEC4"}[flat.shape[1]]
        acc = g.Accessor(bufferView=len(self.gltf.bufferViews) - 1,
                         componentType=UINT32 if arr.dtype == np.uint32 else FLOAT,
                         count=int(flat.shape[0]), type=gtype)
        if bounds:
            acc.min = flat.min(axis=0).astype(float).tolist()
            acc.max = flat.max(axis=0).astype(float).tolist()
        self.gltf.accessors.append(acc)
        return len(self.gltf.accessors) - 1


def keyframe_times(x: Array, speed: float) -> Array:
    """Seconds of each keyframe: (x − x₀)/speed, or 1/24 s apart when the speed is zero."""
    if speed != 0.0 and np.all(np.diff((x - x[0]) / speed) > 0):
        return np.asarray((x - x[0]) / speed)
    return np.arange(len(x)) / 24.0


def _body_poses(md: ModeGeometry, frames: NDArray[np.intp]) -> tuple[Array, Array, Array]:
    """Per body (moving, then ground): rotations (B+1, K, 3, 3), origins (B+1, K, 3) at the
    keyframes, and its polyline (B+1, P, 3) in its own frame (ground: the world)."""
    pts = md.skeleton[frames]  # (K, B+1, P, 3)
    R_all = md.rotations[frames].transpose(1, 0, 2, 3)
    o_all = md.origins[frames].transpose(1, 0, 2)
    local = np.einsum("lji,lpj->lpi", R_all[:, 0], pts[0] - o_all[:, 0, None, :])
    return R_all, o_all, local


def gltf_bytes(geometry: ExportGeometry, sweep: NDArray[np.intp], *, name: str,
               speed: float, binary: bool = True) -> bytes:
    """The glTF file (module docstring) of the first mode of ``geometry`` over the samples
    ``sweep``; ``speed`` is the first input's rate (rad/s or m/s) that sets the keyframe
    times. ``binary``: GLB; else glTF JSON with the buffer embedded as a data URI."""
    import pygltflib as g

    md = geometry.modes[0]
    mode = md.index
    frames = np.asarray(sweep)[md.assembles[sweep]]
    if len(frames) == 0:
        raise ExportError(f"assembly mode {mode} does not assemble anywhere on the sweep; "
                          "choose another mode (--mode)")
    R_all, o_all, local = _body_poses(md, frames)
    centres = np.stack(list(md.joints.values()), axis=1)[frames]
    size = float(np.linalg.norm(np.ptp(centres.reshape(-1, 3), axis=0))) or 1.0
    radius = 0.012 * size
    gltf = g.GLTF2(asset=g.Asset(generator="screwkit"), scene=0)
    buf = _Buffer(gltf)
    gltf.materials = [g.Material(name=n, pbrMetallicRoughness=g.PbrMetallicRoughness(
        baseColorFactor=c, metallicFactor=0.2, roughnessFactor=0.6))
        for n, c in (("link", [0.23, 0.45, 0.75, 1.0]), ("ground", [0.35, 0.35, 0.35, 1.0]),
                     ("path", [0.85, 0.3, 0.1, 1.0]))]
    names = list(md.bodies)
    children = []
    for li, link_name in enumerate(names):
        verts, tris = link_mesh(local[li], radius)
        pos = buf.add(verts, "VEC3", ARRAY_BUFFER, bounds=True)
        idx = buf.add(tris.reshape(-1), "SCALAR_INDEX", ELEMENT_ARRAY_BUFFER)
        ground = li == len(names) - 1
        gltf.meshes.append(g.Mesh(name=link_name, primitives=[g.Primitive(
            attributes=g.Attributes(POSITION=pos), indices=idx, material=1 if ground else 0)]))
        q = quaternions(R_all[li, :1])[0]
        gltf.nodes.append(g.Node(name=link_name, mesh=len(gltf.meshes) - 1,
                                 translation=o_all[li, 0].tolist(), rotation=q.tolist()))
        children.append(len(gltf.nodes) - 1)
    runs = assembled_runs(md.assembles[sweep])
    for point, whole in md.points.items():
        path = whole[sweep]
        strips = [g.Primitive(attributes=g.Attributes(
            POSITION=buf.add(path[a:b], "VEC3", ARRAY_BUFFER, bounds=True)),
            mode=g.LINE_STRIP, material=2) for a, b in runs if b - a > 1]
        if not strips:
            continue
        gltf.meshes.append(g.Mesh(name=point, primitives=strips))
        gltf.nodes.append(g.Node(name=f"path {point}", mesh=len(gltf.meshes) - 1))
        children.append(len(gltf.nodes) - 1)
    x = geometry.inputs[frames]
    times = buf.add(keyframe_times(x, speed), "SCALAR", bounds=True)
    samplers, channels = [], []
    for li in range(len(names) - 1):
        for target, values in (("translation", o_all[li]),
                               ("rotation", quaternions(R_all[li]))):
            kind = "VEC3" if target == "translation" else "VEC4"
            samplers.append(g.AnimationSampler(input=times, output=buf.add(values, kind),
                                               interpolation="LINEAR"))
            channels.append(g.AnimationChannel(sampler=len(samplers) - 1, target=g.AnimationChannelTarget(
                node=children[li], path=target)))
    gltf.animations = [g.Animation(name=f"mode {mode}", samplers=samplers, channels=channels,
                                   extras={"input_name": geometry.input_name,
                                           "inputs": x.tolist()})]
    gltf.nodes.append(g.Node(name=name, rotation=list(Z_UP_TO_Y_UP), children=children))
    gltf.scenes = [g.Scene(name=name, nodes=[len(gltf.nodes) - 1])]
    gltf.buffers = [g.Buffer(byteLength=len(buf.data))]
    gltf.set_binary_blob(bytes(buf.data))
    if not binary:
        gltf.convert_buffers(g.BufferFormat.DATAURI)
        return gltf.gltf_to_json().encode("utf-8")
    out: bytes = b"".join(gltf.save_to_bytes())
    return out
