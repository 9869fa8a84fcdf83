"""Every frame pyBullet simulates on an app's clients: what exists, what it is called, and where it is.

An app is judged against *all* of its bodies, not a list it hands the kit: each base and each link of
each body on each client the app connected is a frame that drawn vertices may follow. A frame's pose
is its link frame (pybullet-facts.md, "Frames"): for a base, ``getBasePositionAndOrientation`` with the
inertial offset of ``getDynamicsInfo(body, -1)[3:5]`` undone; for a link,
``getLinkState(..., computeForwardKinematics=1)[4:6]`` (:func:`conformance.bullet.truth.link_frames`).

A frame's collision shape is described in its link frame (``getCollisionShapeData`` gives it in the
centre-of-mass frame, which is the link frame moved by the local inertial frame), so the kit can tell
where the app should have drawn it (:mod:`conformance.apps.placement`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pybullet

from conformance.bullet import poses, truth
from conformance.bullet.client import BoundClient

__all__ = ["Frame", "frames_of", "read_poses", "read_velocities"]

#: pybullet's shape type codes, by name, for the records
SHAPE_KINDS = {pybullet.GEOM_BOX: "box", pybullet.GEOM_SPHERE: "sphere", pybullet.GEOM_CYLINDER: "cylinder",
               pybullet.GEOM_CAPSULE: "capsule", pybullet.GEOM_MESH: "mesh", pybullet.GEOM_PLANE: "plane"}


@dataclass(frozen=True)
class Frame:
    """One base (``link == -1``) or link of one body on one client.

    ``shapes`` are its collision shapes as ``(kind, dims, position, orientation)`` in its link frame
    (``dims`` as ``getCollisionShapeData`` gives them: box full extents, sphere ``(r, ...)``, cylinder and
    capsule ``(height, radius, ...)``); ``mass`` 0 is a static base (or a fixed link)."""

    client: int
    body: int
    link: int
    name: str
    mass: float
    shapes: tuple
    inertial: tuple = (0.0, 0.0, 0.0)  # the centre of mass in the link frame (getDynamicsInfo()[3])
    #: the vertices of its mesh collision shapes in its link frame (``getMeshData``, which pyBullet gives in
    #: the centre-of-mass frame; URDF cylinders are meshes there too), at most :data:`MESH_VERTICES` of them
    mesh: tuple = ()
    #: its visual shapes as pyBullet holds them (``getVisualShapeData``), each ``(kind, dims, position,
    #: orientation, points)``: ``dims`` as pyBullet gives them (a mesh's: its scale), the shape's frame in the
    #: link frame, and ``points`` the shape's extreme points in its own frame, scaled (a mesh's convex hull,
    #: a box's corners, a cylinder's rims): what a drawing of it spans. pyBullet's own renderer draws these.
    visuals: tuple = ()
    #: a soft body's simulated node (its index in ``getMeshData(body, -1, flags=MESH_DATA_SIMULATION_MESH)``),
    #: else -1. A node is a frame with a position and no turn: what follows it moves with it; it has no
    #: collision shape, and pyBullet reports no mass for it (``mass`` is NaN).
    node: int = -1

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def label(self) -> str:
        """``body 3 link 1 (name)``; on a client other than 0, ``client 1 body 3 …`` (body ids restart on every client)."""
        where = f"node {self.node}" if self.node >= 0 else "base" if self.link == -1 else f"link {self.link}"
        client = f"client {self.client} " if self.client else ""
        return f"{client}body {self.body} {where}" + (f" ({self.name})" if self.name else "")


def _text(value) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


#: A frame keeps at most this many of its collision mesh's vertices (evenly picked): enough for the box
#: and the sphere around it, small in a recording.
MESH_VERTICES = 4096


def _mesh(p: BoundClient, body: int, link: int, shapes: tuple) -> tuple:
    """The frame's collision mesh vertices in its link frame, for a frame with a mesh shape; else ()."""
    if not any(kind == "mesh" for kind, *_ in shapes):
        return ()
    try:
        count, vertices = p.getMeshData(body, link)[:2]
    except pybullet.error:
        return ()
    if not count:
        return ()
    vertices = np.asarray(vertices, dtype=np.float64)
    if len(vertices) > MESH_VERTICES:
        vertices = vertices[np.linspace(0, len(vertices) - 1, MESH_VERTICES).round().astype(int)]
    inertial_pos, inertial_orn = p.getDynamicsInfo(body, link)[3:5]
    turned = poses.apply(inertial_pos, inertial_orn, vertices)
    return tuple(tuple(round(float(c), 9) for c in v) for v in turned)


#: Points around a cylinder's rims, for the box a drawing of it spans (0.2 % short of the radius at most).
RIM = 64


def _primitive_points(kind: str, dims) -> np.ndarray | None:
    """A primitive's extreme points in its own frame (pyBullet's dims: box full extents, sphere radius,
    cylinder and capsule length and radius along z)."""
    if kind == "box":
        half = np.asarray(dims[:3], dtype=np.float64) / 2
        return np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    if kind == "sphere":
        return np.concatenate([np.eye(3), -np.eye(3)]) * float(dims[0])
    if kind in ("cylinder", "capsule"):
        length, radius = float(dims[0]), float(dims[1])
        angle = np.linspace(0, 2 * np.pi, RIM, endpoint=False)
        rim = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), np.zeros(RIM)])
        ends = length / 2 + (radius if kind == "capsule" else 0.0)
        return np.concatenate([rim + [0, 0, length / 2], rim - [0, 0, length / 2], [[0, 0, ends], [0, 0, -ends]]])
    return None


def _mesh_points(path: str, scale) -> np.ndarray | None:
    """A visual mesh file's convex hull vertices, scaled (trimesh reads OBJ, STL, PLY; a file it cannot read: None)."""
    try:
        import trimesh

        mesh = trimesh.load(path, force="mesh", skip_materials=True)
        points = np.asarray(mesh.convex_hull.vertices if len(mesh.vertices) > 3 else mesh.vertices, dtype=np.float64)
    except Exception:  # a format or file trimesh cannot read: the shape is left out, not the run
        return None
    return points * np.asarray(scale, dtype=np.float64)[:3] if len(points) else None


def _visuals(p: BoundClient, body: int) -> dict[int, tuple]:
    """Each link's visual shapes (``getVisualShapeData``), by link index."""
    found: dict[int, list] = {}
    try:
        data = p.getVisualShapeData(body)
    except pybullet.error:
        return {}
    for shape in data:
        link, kind = shape[1], SHAPE_KINDS.get(shape[2], f"type {shape[2]}")
        dims, path = tuple(float(v) for v in shape[3]), _text(shape[4])
        points = _mesh_points(path, dims) if kind == "mesh" else _primitive_points(kind, dims)
        if points is None:
            continue
        found.setdefault(link, []).append((kind, dims, tuple(float(v) for v in shape[5]), tuple(float(v) for v in shape[6]),
                                           tuple(tuple(round(float(c), 9) for c in v) for v in points)))
    return {link: tuple(shapes) for link, shapes in found.items()}


def _shapes(p: BoundClient, body: int, link: int) -> tuple:
    inertial_pos, inertial_orn = p.getDynamicsInfo(body, link)[3:5]
    found = []
    for data in p.getCollisionShapeData(body, link):
        kind = SHAPE_KINDS.get(data[2], f"type {data[2]}")
        pos, orn = poses.compose(inertial_pos, inertial_orn, data[5], data[6])
        found.append((kind, tuple(float(v) for v in data[3]), tuple(float(v) for v in pos), tuple(float(v) for v in orn)))
    return tuple(found)


def _nodes(p: BoundClient, body: int) -> int:
    """How many simulated nodes ``body`` has if it is a soft body (``loadSoftBody``, ``loadURDF`` of a
    deformable), else 0. pyBullet has no call that says so: a soft body is one whose collision shapes it
    cannot report (``getCollisionShapeData`` raises) and whose simulation mesh it can."""
    try:
        p.getCollisionShapeData(body, -1)
        return 0
    except pybullet.error:
        pass
    try:
        return int(p.getMeshData(body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH)[0])
    except pybullet.error:
        return 0


def frames_of(clients) -> list[Frame]:
    """Every base and link of every rigid body and every node of every soft body on ``clients`` (ids), in
    client, body and link (node) order."""
    frames = []
    for client in clients:
        p = BoundClient(client)
        for index in range(p.getNumBodies()):
            body = p.getBodyUniqueId(index)
            base_name, body_name = (_text(v) for v in p.getBodyInfo(body))
            name = body_name if body_name and body_name != base_name else base_name
            nodes = _nodes(p, body)
            if nodes:
                frames.extend(Frame(client, body, -1, name, float("nan"), (), node=n) for n in range(nodes))
                continue
            visuals = _visuals(p, body)
            for link in range(-1, p.getNumJoints(body)):
                info = p.getDynamicsInfo(body, link)
                shapes = _shapes(p, body, link)
                label = name if link == -1 else _text(p.getJointInfo(body, link)[12])
                frames.append(Frame(client, body, link, label, float(info[0]), shapes, tuple(info[3]),
                                    _mesh(p, body, link, shapes), visuals.get(link, ())))
    return frames


def read_poses(frames: list[Frame]) -> tuple[np.ndarray, np.ndarray]:
    """Link-frame positions ``(F, 3)`` and quaternions ``(F, 4)`` of ``frames``, now."""
    positions = np.empty((len(frames), 3))
    orientations = np.empty((len(frames), 4))
    by_client: dict[int, list[int]] = {}
    soft: dict[tuple[int, int], list[int]] = {}
    for i, frame in enumerate(frames):
        if frame.node >= 0:
            soft.setdefault((frame.client, frame.body), []).append(i)
        else:
            by_client.setdefault(frame.client, []).append(i)
    for client, rows in by_client.items():
        pos, orn = truth.link_frames(BoundClient(client), [(frames[i].body, frames[i].link) for i in rows])
        positions[rows], orientations[rows] = pos, orn
    for (client, body), rows in soft.items():
        nodes = np.asarray(pybullet.getMeshData(body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH,
                                                physicsClientId=client)[1], dtype=np.float64)
        positions[rows] = nodes[[frames[i].node for i in rows]]
        orientations[rows] = (0.0, 0.0, 0.0, 1.0)
    return positions, orientations


def read_velocities(frames: list[Frame]) -> np.ndarray:
    """Linear and angular velocities ``(F, 6)`` of ``frames``' centres of mass, now (read only when the kit
    has to tell whether the app changed them: it costs one call per frame)."""
    velocities = np.zeros((len(frames), 6))
    for i, frame in enumerate(frames):
        if frame.node >= 0:
            continue  # pyBullet reports no node's velocity: the kit cannot tell whether the app set one
        if frame.link == -1:
            linear, angular = pybullet.getBaseVelocity(frame.body, physicsClientId=frame.client)
        else:
            state = pybullet.getLinkState(frame.body, frame.link, computeLinkVelocity=1,
                                          physicsClientId=frame.client)
            linear, angular = state[6], state[7]
        velocities[i, :3], velocities[i, 3:] = linear, angular
    return velocities
