"""Every frame pyBullet simulates on an app's clients: what exists, what it is called, and where it is.

An app is judged against *all* of its bodies, not a list it hands the kit: each base and each link of
each body on each client the app connected is a frame that drawn vertices may follow. A frame's pose
is its link frame (pybullet-facts.md, "Frames"): for a base, ``getBasePositionAndOrientation`` with the
inertial offset of ``getDynamicsInfo(body, -1)[3:5]`` undone; for a link,
``getLinkState(..., computeForwardKinematics=1)[4:6]`` (:func:`conformance.bullet.truth.link_frames`).

A frame's collision shape is described in its link frame (``getCollisionShapeData`` gives it in the
centre-of-mass frame, which is the link frame moved by the local inertial frame), so the kit can tell
where the app should have drawn it (:mod:`conformance.apps.placement`).

Reading a body's shapes can crash pyBullet on a model it loaded itself (``getCollisionShapeData`` on an
MJCF ``fromto`` capsule), and the app's process with it. So :func:`frames_of` first makes every pyBullet
read of the bodies (:func:`_read`), then makes the frames of what it read; the reads of shapes, meshes and
visual shapes go through :mod:`conformance.apps.guarded`, which tries them in a forked copy of the process
first. A read that crashed the copy is never made in the app's process: the frame is recorded without
what it would have given, and the notes say which call, on which body and link, and what was left out.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
import pybullet

from conformance.apps import guarded
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
    #: how many of its visual shapes pyBullet's own renderer draws (``getVisualShapeData``: an extent, and not
    #: alpha 0); -1 where unknown (a recording made before the kit counted them). A frame pyBullet draws none of
    #: need not be drawn (:func:`conformance.apps.judge._shown`)
    shown: int = -1
    #: the centre-of-mass frame's turn in the link frame (``getDynamicsInfo()[4]``): a drawing made at the centre
    #: of mass is turned by it too (a bicycle's frame: its <inertial> turned 90° about x)
    inertial_turn: tuple = (0.0, 0.0, 0.0, 1.0)

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def label(self) -> str:
        """``body 3 link 1 (name)``; on a client other than 0, ``client 1 body 3 …`` (body ids restart on every client)."""
        where = f"node {self.node}" if self.node >= 0 else "base" if self.link == -1 else f"link {self.link}"
        return _label(self.client, self.body, where, self.name)


def _label(client: int, body: int, where: str, name: str) -> str:
    return f"{f'client {client} ' if client else ''}body {body}{f' {where}' if where else ''}" + (f" ({name})" if name else "")


def _text(value) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


#: A frame keeps at most this many of its collision mesh's vertices (evenly picked): enough for the box
#: and the sphere around it, small in a recording.
MESH_VERTICES = 4096


def _mesh(info, data) -> tuple:
    """The frame's collision mesh vertices in its link frame, from ``getMeshData``'s ``data`` (None: not read)
    and the frame's ``getDynamicsInfo``; else ()."""
    if data is None or not data[0]:
        return ()
    vertices = np.asarray(data[1], dtype=np.float64)
    if len(vertices) > MESH_VERTICES:
        vertices = vertices[np.linspace(0, len(vertices) - 1, MESH_VERTICES).round().astype(int)]
    turned = poses.apply(info[3], info[4], vertices)
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
    """A visual mesh file's convex hull vertices, scaled (trimesh reads OBJ, STL, PLY; a file it cannot read: None).
    A flat mesh has no hull (a cloth sheet, pybullet_data's cloth_z_up.obj): its own vertices stand for it, at most
    :data:`MESH_VERTICES` of them, so that a drawing of it is still judged against it (the zoo: drawn at the file's
    size, 1/1.6 of the scaled sheet, it was taken for a decoration)."""
    try:
        import trimesh

        mesh = trimesh.load(path, force="mesh", skip_materials=True)
    except Exception:  # a format or file trimesh cannot read: the shape is left out, not the run
        return None
    vertices = np.unique(np.asarray(mesh.vertices, dtype=np.float64), axis=0)
    try:
        points = np.asarray(mesh.convex_hull.vertices, dtype=np.float64) if len(vertices) > 3 else vertices
    except Exception:  # no hull: flat (or a line); its vertices are what a drawing of it spans
        points = vertices
    if len(points) > MESH_VERTICES:
        points = points[np.linspace(0, len(points) - 1, MESH_VERTICES).round().astype(int)]
    return points * np.asarray(scale, dtype=np.float64)[:3] if len(points) else None


def _visuals(data) -> dict[int, tuple]:
    """Each link's visual shapes, by link index, from ``getVisualShapeData``'s ``data``."""
    found: dict[int, list] = {}
    for shape in data:
        link, kind = shape[1], SHAPE_KINDS.get(shape[2], f"type {shape[2]}")
        dims, path = tuple(float(v) for v in shape[3]), _text(shape[4])
        points = _mesh_points(path, dims) if kind == "mesh" else _primitive_points(kind, dims)
        if points is None:
            continue
        found.setdefault(link, []).append((kind, dims, tuple(float(v) for v in shape[5]), tuple(float(v) for v in shape[6]),
                                           tuple(tuple(round(float(c), 9) for c in v) for v in points)))
    return {link: tuple(shapes) for link, shapes in found.items()}


def _shown(data) -> dict[int, int]:
    """How many of each link's visual shapes pyBullet draws, by link index, from ``getVisualShapeData``'s
    ``data``: those with an extent (a mesh's scale, a primitive's size; a plane's none, and it is drawn) and an
    alpha above 0 (pybullet 3.2.7 leaves both out of its pictures: 0 or 1 pixel of a segmentation mask)."""
    count: dict[int, int] = {}
    for shape in data:
        kind, dims, alpha = SHAPE_KINDS.get(shape[2], ""), shape[3], shape[7][3]
        extent = kind == "plane" or any(float(v) > 0 for v in dims[:3 if kind in ("box", "mesh") else 2])
        count[shape[1]] = count.get(shape[1], 0) + bool(extent and alpha > 0)
    return count


def _shapes(info, data) -> tuple:
    """The frame's collision shapes in its link frame, from ``getCollisionShapeData``'s ``data`` and the
    frame's ``getDynamicsInfo``."""
    found = []
    for shape in data:
        kind = SHAPE_KINDS.get(shape[2], f"type {shape[2]}")
        pos, orn = poses.compose(info[3], info[4], shape[5], shape[6])
        found.append((kind, tuple(float(v) for v in shape[3]), tuple(float(v) for v in pos), tuple(float(v) for v in orn)))
    return tuple(found)


@dataclass
class _Read:
    """What pyBullet said of one body, nothing made of it yet (:func:`_read`). ``nodes``: a soft body's
    simulated nodes (-1: unknown, the body is left out); ``links``: ``(link, name, getDynamicsInfo,
    getCollisionShapeData, getMeshData or None)`` each; ``refused``: ``(link or None for the whole body,
    Refused, what the kit did instead)`` for each read the guard did not make."""

    client: int
    body: int
    name: str
    nodes: int = 0
    #: per node, whether pyBullet draws it (:func:`_nodes_shown`)
    shown: tuple = ()
    visuals: tuple = ()
    links: list = field(default_factory=list)
    refused: list = field(default_factory=list)


#: What the kit does instead of each read pyBullet crashed on (the simulation mesh: getMeshData of a soft body's nodes).
INSTEAD = {
    "getCollisionShapeData": "recorded the frame without its collision shapes",
    "getMeshData": "recorded the frame without its collision mesh's vertices",
    "getVisualShapeData": "recorded every frame of the body without its visual shapes",
    "simulation mesh": "left the body out: its simulated nodes are unknown (getMeshData with MESH_DATA_SIMULATION_MESH)",
}


def _nodes(p: BoundClient, body: int, call, read: _Read) -> tuple[int, tuple]:
    """How many simulated nodes ``body`` has if it is a soft body (``loadSoftBody``, ``loadURDF`` of a
    deformable), else 0 (-1: its nodes could not be read), and the nodes. pyBullet has no call that says so: a
    soft body is one whose collision shapes it cannot report (``getCollisionShapeData`` raises) and whose
    simulation mesh it can."""
    try:
        call(pybullet.getCollisionShapeData, body, -1, physicsClientId=p.client)
        return 0, ()
    except guarded.Refused:
        return 0, ()  # a crash is no "cannot report": a rigid body, whose base read is refused again, and said, below
    except pybullet.error:
        pass
    try:
        count, nodes = call(pybullet.getMeshData, body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH, physicsClientId=p.client)
        return int(count), tuple(nodes)
    except guarded.Refused as refusal:
        read.refused.append((None, refusal, INSTEAD["simulation mesh"]))
        return -1, ()
    except pybullet.error:
        return 0, ()


def _nodes_shown(p: BoundClient, body: int, nodes: tuple, count: int, call) -> tuple:
    """For each of a soft body's ``count`` ``nodes``, whether pyBullet's own renderer draws it: 1 where a corner of
    the body's visual mesh (``getMeshData`` without ``MESH_DATA_SIMULATION_MESH``) lies on it, 0 where none does
    (a node inside a tetrahedral body: its visual mesh is the boundary's faces, each corner at a node, measured to
    the bit); -1 each where that cannot be told (no corner on any node: a surface body from an OBJ file before
    its first step, whose visual mesh is the file's vertices unmoved; or a read that failed)."""
    try:
        corners = set(map(tuple, call(pybullet.getMeshData, body, -1, physicsClientId=p.client)[1]))
    except (guarded.Refused, pybullet.error):
        return (-1,) * count
    shown = tuple(int(tuple(node) in corners) for node in nodes)
    return shown if len(shown) == count and any(shown) else (-1,) * count


def _read(p: BoundClient, body: int, call) -> _Read:
    """Every read :func:`frames_of` makes of ``body``; those that can crash pyBullet through ``call``."""
    base_name, body_name = (_text(v) for v in p.getBodyInfo(body))
    read = _Read(p.client, body, body_name if body_name and body_name != base_name else base_name)
    read.nodes, nodes = _nodes(p, body, call, read)
    if read.nodes > 0:
        read.shown = _nodes_shown(p, body, nodes, read.nodes, call)
    if read.nodes:
        return read
    try:
        read.visuals = call(pybullet.getVisualShapeData, body, physicsClientId=p.client)
    except pybullet.error:
        pass
    except guarded.Refused as refusal:
        read.refused.append((None, refusal, INSTEAD["getVisualShapeData"]))
    for link in range(-1, p.getNumJoints(body)):
        info = p.getDynamicsInfo(body, link)
        name = read.name if link == -1 else _text(p.getJointInfo(body, link)[12])
        try:
            shapes = call(pybullet.getCollisionShapeData, body, link, physicsClientId=p.client)
        except guarded.Refused as refusal:
            shapes = ()
            read.refused.append((link, refusal, INSTEAD["getCollisionShapeData"]))
        mesh = None
        if any(shape[2] == pybullet.GEOM_MESH for shape in shapes):
            try:
                mesh = call(pybullet.getMeshData, body, link, physicsClientId=p.client)[:2]
            except pybullet.error:
                pass
            except guarded.Refused as refusal:
                read.refused.append((link, refusal, INSTEAD["getMeshData"]))
        read.links.append((link, name, info, shapes, mesh))
    return read


def _read_all(call, clients: list[int]) -> list[_Read]:
    """The plan :func:`guarded.run` tries: every read of every body on ``clients``, in client and body order."""
    found = []
    for client in clients:
        p = BoundClient(client)
        found.extend(_read(p, p.getBodyUniqueId(index), call) for index in range(p.getNumBodies()))
    return found


def _note(read: _Read, link, refusal: guarded.Refused, instead: str) -> str:
    where = "" if link is None else "base" if link == -1 else f"link {link}"
    name = read.name if link in (None, -1) else next((n for k, n, *_ in read.links if k == link), "")
    return (f"{_label(read.client, read.body, where, name)}: pyBullet crashed on the kit's read {refusal.call}: it "
            f"ended the copy of the app's process the kit forks to try its reads first ({refusal.how}), so the kit "
            f"never made that call in the app's process and {instead}")


def frames_of(clients, notes: list | None = None) -> list[Frame]:
    """Every base and link of every rigid body and every node of every soft body on ``clients`` (ids), in
    client, body and link (node) order. A read pyBullet crashed on (:mod:`conformance.apps.guarded`) is
    left out of its frames, and said in ``notes`` (a list, appended to)."""
    frames = []
    for read in guarded.run(_read_all, clients):
        if notes is not None:
            notes.extend(_note(read, *refused) for refused in read.refused)
        if read.nodes:
            frames.extend(Frame(read.client, read.body, -1, read.name, float("nan"), (), node=n, shown=shown)
                          for n, shown in enumerate(read.shown))
            continue
        visuals, shown = _visuals(read.visuals), _shown(read.visuals)
        unknown = any(instead == INSTEAD["getVisualShapeData"] for *_, instead in read.refused)
        for link, name, info, shapes, mesh in read.links:
            shapes = _shapes(info, shapes)
            frames.append(Frame(read.client, read.body, link, name, float(info[0]), shapes, tuple(info[3]),
                                _mesh(info, mesh), visuals.get(link, ()), shown=-1 if unknown else shown.get(link, 0),
                                inertial_turn=tuple(info[4])))
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
