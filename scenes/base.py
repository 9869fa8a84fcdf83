"""What a reference scene is: physics in its own pybullet client, plus a description of how it is drawn.

A scene knows physics and bindings and nothing of checks or of FURY: the backend builds actors from
the :class:`Shape` of each :class:`Binding`. Scenes are objects built by a function from explicit
parameters (no globals, every random draw seeded), own one DIRECT client and always disconnect it
(:meth:`Scene.close`, or use the scene as a context manager).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import pybullet

from conformance.bullet.client import BoundClient
from conformance.errors import InvalidArgument, SceneError

__all__ = [
    "Binding",
    "Camera",
    "ExternalForce",
    "MovingPivot",
    "Scene",
    "Shape",
    "Surface",
    "IDENTITY",
]

IDENTITY = (0.0, 0.0, 0.0, 1.0)
SHAPE_KINDS = ("box", "sphere", "cylinder")


@dataclass(frozen=True)
class Shape:
    """A collision shape and the way it is drawn (the same thing, by construction).

    ``size`` is ``(hx, hy, hz)`` half extents for a box, ``(radius,)`` for a sphere and
    ``(radius, height)`` for a cylinder along the local z axis (pybullet's convention). ``position``
    and ``orientation`` place the shape in its body's link frame (pybullet's
    ``collisionFramePosition``/``collisionFrameOrientation``).
    """

    kind: str
    size: tuple[float, ...]
    color: tuple[float, float, float] = (0.8, 0.8, 0.8)
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = IDENTITY

    def __post_init__(self):
        expected = {"box": 3, "sphere": 1, "cylinder": 2}.get(self.kind)
        if expected is None:
            raise InvalidArgument(f"kind={self.kind!r} ({type(self.kind).__name__}), but should be one of {SHAPE_KINDS}")
        if len(self.size) != expected or not all(math.isfinite(s) and s > 0 for s in self.size):
            raise InvalidArgument(
                f"size={self.size!r} for a {self.kind}, but should be {expected} finite positive numbers"
            )

    def collision_shape(self, p: BoundClient) -> int:
        """Create this shape in pybullet and return its collision shape index."""
        frame = dict(collisionFramePosition=list(self.position), collisionFrameOrientation=list(self.orientation))
        if self.kind == "box":
            return p.createCollisionShape(pybullet.GEOM_BOX, halfExtents=list(self.size), **frame)
        if self.kind == "sphere":
            return p.createCollisionShape(pybullet.GEOM_SPHERE, radius=self.size[0], **frame)
        return p.createCollisionShape(pybullet.GEOM_CYLINDER, radius=self.size[0], height=self.size[1], **frame)


@dataclass(frozen=True)
class Surface:
    """How a soft body is drawn: triangles over its simulated nodes (``getMeshData(body, -1,
    flags=MESH_DATA_SIMULATION_MESH)``), flat shaded.

    ``nodes`` says which node each drawn vertex follows: None for every node in pyBullet's order (a surface
    body from an OBJ file, whose ``faces`` index the file's vertices, which :meth:`Scene.add_soft_body`
    checks pyBullet kept as its nodes, in order); for a volumetric body (tetrahedra, from a ``.vtk`` file or
    a ``<deformable>`` URDF) the nodes on its boundary, whose inside nodes are not drawn. ``faces`` index the
    drawn vertices."""

    faces: tuple[tuple[int, int, int], ...]
    color: tuple[float, float, float] = (0.8, 0.8, 0.8)
    #: the file's vertices as written, unscaled and unmoved: what pyBullet's visual mesh of a surface body
    #: holds until its first step (``getMeshData`` without ``MESH_DATA_SIMULATION_MESH``, one vertex per face corner)
    file_vertices: np.ndarray | None = field(default=None, compare=False, repr=False)
    #: the node of each drawn vertex (None: vertex k is node k, every node drawn)
    nodes: tuple[int, ...] | None = None
    #: a tetrahedral body: pyBullet's visual mesh is its boundary faces' corners at the nodes, from the start
    volumetric: bool = False
    kind = "surface"

    def __post_init__(self):
        if not self.faces or any(len(f) != 3 or min(f) < 0 for f in self.faces):
            raise InvalidArgument(f"faces={self.faces!r}, but should be triangles of vertex indices (three integers >= 0 each)")
        if self.nodes is not None and max(max(f) for f in self.faces) >= len(self.nodes):
            raise InvalidArgument(f"faces index {max(max(f) for f in self.faces) + 1} vertices, but nodes={len(self.nodes)} "
                                  f"nodes are drawn: give each drawn vertex its node")

    def node_faces(self) -> np.ndarray:
        """The faces as node indices, ``(n, 3)``: each face's corners as pyBullet's nodes."""
        faces = np.asarray(self.faces, dtype=np.int64)
        return faces if self.nodes is None else np.asarray(self.nodes, dtype=np.int64)[faces]


def obj_mesh(path: str) -> tuple[np.ndarray, tuple[tuple[int, int, int], ...]]:
    """The vertices ``(n, 3)`` and triangles of a Wavefront OBJ file, polygons split into fans, indices
    from 0: the mesh a soft body loaded from that file simulates (pyBullet keeps its vertices as nodes)."""
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == "v":
                vertices.append([float(w) for w in words[1:4]])
            elif words[0] == "f":
                corners = [int(w.split("/")[0]) for w in words[1:]]
                corners = [c - 1 if c > 0 else len(vertices) + c for c in corners]
                faces.extend((corners[0], corners[k], corners[k + 1]) for k in range(1, len(corners) - 1))
    return np.asarray(vertices, dtype=np.float64).reshape(-1, 3), tuple(faces)


def vtk_points(path: str) -> np.ndarray:
    """The points ``(n, 3)`` of a legacy ASCII VTK file (``POINTS n float``, then the coordinates): the nodes a
    soft body loaded from a tetrahedral ``.vtk`` file has, in order, before scaling and placing."""
    words = open(path, encoding="ascii").read().split()
    at = words.index("POINTS")
    count = int(words[at + 1])
    return np.asarray(words[at + 3:at + 3 + 3 * count], dtype=np.float64).reshape(count, 3)


def deformable_mesh(urdf: str) -> str:
    """The path of the mesh a ``<deformable>`` URDF names (its ``visual`` filename, beside the URDF)."""
    import xml.etree.ElementTree as ElementTree

    visual = ElementTree.parse(urdf).getroot().find("deformable/visual")
    if visual is None or not visual.get("filename"):
        raise SceneError(f"{urdf}: no <deformable><visual filename=…/> to load")
    return os.path.join(os.path.dirname(os.path.abspath(urdf)), visual.get("filename"))


@dataclass(frozen=True)
class Binding:
    """One drawn thing: body ``body`` (link ``link``, -1 for the base) is drawn by actor ``actor``.

    Bindings that name the same ``actor`` are drawn by one shared FURY actor (the guide's "rendering
    multiple objects by a single actor"), each by its own vertex range, in binding order; they must
    have the same shape kind. A binding alone in its actor is drawn by a whole actor.
    """

    name: str
    body: int
    link: int
    actor: str
    shape: Shape | Surface

    @property
    def soft(self) -> bool:
        """A soft body, drawn by its nodes (:class:`Surface`), not a rigid link."""
        return isinstance(self.shape, Surface)


@dataclass(frozen=True)
class Camera:
    """Where a scene is seen from, every number explicit so two renderers can be given the same view.

    ``view_angle`` is the vertical field of view in degrees (VTK's ``SetViewAngle`` with its default
    vertical convention; pyBullet's ``computeProjectionMatrixFOV(fov=…)``); ``clipping_range`` is
    ``(near, far)`` in metres from the camera, set explicitly rather than reset to the scene's bounds
    by the renderer, so a body moving away cannot change the depth precision of another's picture.
    """

    position: tuple[float, float, float]
    focal_point: tuple[float, float, float]
    view_up: tuple[float, float, float]
    view_angle: float = 30.0
    clipping_range: tuple[float, float] = (0.1, 100.0)

    def __post_init__(self):
        for name in ("position", "focal_point", "view_up"):
            value = getattr(self, name)
            if len(value) != 3 or not all(math.isfinite(v) for v in value):
                raise InvalidArgument(f"Camera {name}={value!r}, but should be three finite numbers")
        if not 0 < self.view_angle < 180:
            raise InvalidArgument(f"Camera view_angle={self.view_angle!r}, but should be in degrees, between 0 and 180")
        near, far = self.clipping_range
        if not 0 < near < far:
            raise InvalidArgument(f"Camera clipping_range={self.clipping_range!r}, but should be (near, far) with 0 < near < far")

    def as_dict(self) -> dict:
        return {"position": list(self.position), "focal_point": list(self.focal_point), "view_up": list(self.view_up),
                "view_angle": self.view_angle, "clipping_range": list(self.clipping_range)}


@dataclass(frozen=True)
class ExternalForce:
    """``applyExternalForce`` before the steps in ``steps`` (the guide's one-shot pushes).

    ``offset`` is added to the body's current centre of mass to give ``posObj`` in WORLD_FRAME,
    as the guide does with ``posObj=ball_pos``.
    """

    body: int
    force: tuple[float, float, float]
    steps: tuple[int, ...] = (0,)
    link: int = -1
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def apply(self, p: BoundClient, step: int, dt: float) -> None:
        if step not in self.steps:
            return
        if self.link == -1:
            centre = p.getBasePositionAndOrientation(self.body)[0]
        else:
            centre = p.getLinkState(self.body, self.link, computeForwardKinematics=1)[0]
        position = [c + o for c, o in zip(centre, self.offset)]
        p.applyExternalForce(self.body, self.link, forceObj=list(self.force), posObj=position, flags=pybullet.WORLD_FRAME)


@dataclass(frozen=True)
class MovingPivot:
    """Before every step, move a fixed constraint's pivot to ``centre + amplitude * sin(2π f t)``
    (the chain example's trajectory; t is the time after the step, as in the example)."""

    constraint: int
    centre: tuple[float, float, float]
    amplitude: tuple[float, float, float]
    frequency: float
    max_force: float

    def apply(self, p: BoundClient, step: int, dt: float) -> None:
        s = math.sin(2 * math.pi * self.frequency * (step + 1) * dt)
        pivot = [c + a * s for c, a in zip(self.centre, self.amplitude)]
        p.changeConstraint(self.constraint, pivot, jointChildFrameOrientation=list(IDENTITY), maxForce=self.max_force)


@dataclass
class Scene:
    """A reference scene: a live pybullet DIRECT client and what to draw.

    Create it with a scene builder (``scenes.build(name, **params)``); the constructor only connects
    (and, for a ``deformable`` scene, resets the world with ``RESET_USE_DEFORMABLE_WORLD``, which soft
    bodies need and which must come before anything else is set).
    """

    name: str
    params: Mapping[str, Any]
    camera: Camera
    image_size: tuple[int, int] = (450, 384)
    steps: int = 120
    dt: float = 1.0 / 240.0
    description: str = ""
    bindings: list[Binding] = field(default_factory=list)
    actions: list[Any] = field(default_factory=list)
    deformable: bool = False
    client: int = field(init=False, default=-1)

    def __post_init__(self):
        self.client = pybullet.connect(pybullet.DIRECT)
        if self.client < 0:
            raise SceneError(f"scene {self.name!r}: pybullet.connect(DIRECT) failed (returned {self.client})")
        self.p = BoundClient(self.client)
        if self.deformable:
            self.p.resetSimulation(pybullet.RESET_USE_DEFORMABLE_WORLD)
        self.p.setTimeStep(self.dt)

    # -- building -------------------------------------------------------------------------------
    def add_body(
        self,
        name: str,
        shape: Shape,
        *,
        mass: float,
        position: Sequence[float],
        orientation: Sequence[float] = IDENTITY,
        actor: str | None = None,
        friction: float | None = None,
        restitution: float | None = None,
        inertial_position: Sequence[float] = (0.0, 0.0, 0.0),
        inertial_orientation: Sequence[float] = IDENTITY,
    ) -> int:
        """Create a single-link body whose collision shape is ``shape`` and bind it for drawing.

        ``position``/``orientation`` place the body's link frame (where ``shape`` is drawn from);
        ``inertial_position``/``inertial_orientation`` place its centre of mass and principal axes in
        that frame (pybullet's ``baseInertialFramePosition``/``Orientation``). pybullet's base pose
        (``getBasePositionAndOrientation``) is the centre of mass's, not the link frame's."""
        body = self.p.createMultiBody(
            baseMass=mass,
            baseCollisionShapeIndex=shape.collision_shape(self.p),
            basePosition=list(position),
            baseOrientation=list(orientation),
            baseInertialFramePosition=list(inertial_position),
            baseInertialFrameOrientation=list(inertial_orientation),
        )
        dynamics = {}
        if friction is not None:
            dynamics["lateralFriction"] = friction
        if restitution is not None:
            dynamics["restitution"] = restitution
        if dynamics:
            self.p.changeDynamics(body, -1, **dynamics)
        self.bind(name, body, -1, shape, actor=actor)
        return body

    def add_soft_body(self, name: str, path: str, *, position: Sequence[float], color: tuple[float, float, float],
                      scale: float = 1.0, anchors: Sequence[int] = (), orientation: Sequence[float] = IDENTITY,
                      **soft: Any) -> int:
        """Load the mesh at ``path`` as a soft body (``loadSoftBody(path, basePosition=position,
        baseOrientation=orientation, scale=scale, **soft)``), pin ``anchors`` (node indices) to the world
        (``createSoftBodyAnchor``), and bind it for drawing as a :class:`Surface`: an OBJ file's triangles
        through every node, or a tetrahedral ``.vtk`` file's boundary (:meth:`add_deformable`). Needs a
        ``deformable`` scene."""
        self._needs_deformable_world(name)
        if str(path).endswith(".vtk"):
            body = self.p.loadSoftBody(path, basePosition=list(position), baseOrientation=list(orientation), scale=scale,
                                       **soft)
            self._loaded_as_written(name, body, path, position, orientation, scale)
            return self._bind_volumetric(name, body, path, color, anchors)
        if tuple(orientation) != IDENTITY:
            raise InvalidArgument(f"orientation={tuple(orientation)!r} for the OBJ soft body {name!r}, but should be the "
                                  f"identity: the file's faces are checked against its vertices where they were put")
        body = self.p.loadSoftBody(path, basePosition=list(position), scale=scale, **soft)
        vertices, faces = obj_mesh(path)
        nodes = np.asarray(self.p.getMeshData(body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH)[1], dtype=np.float64)
        if nodes.shape != vertices.shape or not np.allclose(nodes, vertices * scale + np.asarray(position), atol=1e-6):
            # the faces index the file's vertices: they draw the body only if pyBullet kept those as its nodes
            raise SceneError(f"scene {self.name!r}: soft body {name!r} from {path} has {len(nodes)} nodes that are not the "
                             f"file's {len(vertices)} vertices in order, so the file's faces cannot draw it")
        for node in anchors:
            self.p.createSoftBodyAnchor(body, int(node), -1, -1)
        self.bind(name, body, -1, Surface(faces=faces, color=color, file_vertices=vertices))
        return body

    def add_deformable(self, name: str, path: str, *, position: Sequence[float], color: tuple[float, float, float],
                       orientation: Sequence[float] = IDENTITY, anchors: Sequence[int] = ()) -> int:
        """Load the URDF at ``path``, a ``<deformable>`` body of a tetrahedral mesh (``loadURDF(path,
        basePosition=position, baseOrientation=orientation)``), and bind it for drawing by its boundary, as
        :meth:`add_soft_body` does a ``.vtk`` file. Needs a ``deformable`` scene."""
        self._needs_deformable_world(name)
        body = self.p.loadURDF(path, basePosition=list(position), baseOrientation=list(orientation))
        self._loaded_as_written(name, body, deformable_mesh(path), position, orientation, 1.0)
        return self._bind_volumetric(name, body, path, color, anchors)

    def _needs_deformable_world(self, name: str) -> None:
        if not self.deformable:
            raise SceneError(f"scene {self.name!r}: soft body {name!r} needs a deformable world (SceneSpec(deformable=True))")

    def _loaded_as_written(self, name: str, body: int, mesh: str, position, orientation, scale: float) -> None:
        """Check that the body's nodes are ``mesh``'s points, scaled and placed, in order. pyBullet looks for a
        URDF's mesh in the working directory before the URDF's own (measured: a ``jelly.vtk`` in the directory
        the kit ran from was loaded instead of the kit's, and blew up)."""
        nodes = np.asarray(self.p.getMeshData(body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH)[1], dtype=np.float64)
        points = vtk_points(mesh).astype(np.float32).astype(np.float64) * scale  # pyBullet reads them in single precision
        rotation = np.asarray(pybullet.getMatrixFromQuaternion(list(orientation))).reshape(3, 3)
        expected = points @ rotation.T + np.asarray(position, dtype=np.float64)
        if nodes.shape != expected.shape or not np.allclose(nodes, expected, atol=1e-6):
            raise SceneError(f"scene {self.name!r}: soft body {name!r} has {len(nodes)} nodes that are not the {len(points)} "
                             f"points of {mesh} in order (placed and scaled): pyBullet loaded another mesh; is there a "
                             f"file named {os.path.basename(mesh)!r} in the directory you run from ({os.getcwd()})? "
                             f"pyBullet looks there first")

    def _bind_volumetric(self, name: str, body: int, path: str, color, anchors: Sequence[int]) -> int:
        """Bind a tetrahedral soft body by its boundary, as pyBullet itself draws it: its visual mesh is the
        boundary faces' corners, each at a node (measured to the bit, tests/test_soft_bodies.py), so the
        faces are read from it, and each drawn vertex is a boundary node."""
        nodes = np.asarray(self.p.getMeshData(body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH)[1], dtype=np.float64)
        corners = np.asarray(self.p.getMeshData(body, -1)[1], dtype=np.float64).reshape(-1, 3)
        found = {tuple(v): k for k, v in enumerate(nodes)}
        at = [found.get(tuple(v), -1) for v in corners]
        if not nodes.size or not corners.size or len(corners) % 3 or min(at) < 0 or len(found) != len(nodes):
            raise SceneError(f"scene {self.name!r}: soft body {name!r} from {path}: pyBullet's visual mesh ({len(corners)} "
                             f"corners) is not faces through its {len(nodes)} distinct nodes, so the kit cannot say which "
                             f"node each drawn vertex follows")
        boundary = np.unique(at)
        faces = np.searchsorted(boundary, np.asarray(at)).reshape(-1, 3)
        for node in anchors:
            self.p.createSoftBodyAnchor(body, int(node), -1, -1)
        self.bind(name, body, -1, Surface(faces=tuple(map(tuple, faces.tolist())), color=color,
                                          nodes=tuple(boundary.tolist()), volumetric=True))
        return body

    def bind(self, name: str, body: int, link: int, shape: Shape | Surface, *, actor: str | None = None) -> Binding:
        binding = Binding(name=name, body=body, link=link, actor=actor or name, shape=shape)
        self.bindings.append(binding)
        return binding

    # -- running --------------------------------------------------------------------------------
    def act(self, step: int) -> None:
        """Apply this scene's actions that belong before ``stepSimulation`` number ``step`` (0-based)."""
        for action in self.actions:
            action.apply(self.p, step, self.dt)

    def advance(self, step: int) -> None:
        """One frame of the scene: its actions for ``step``, then one ``stepSimulation``."""
        self.act(step)
        self.p.stepSimulation()

    def run(self, steps: int, on_step: Callable[[int], None] | None = None) -> None:
        """Advance ``steps`` frames from the current state, calling ``on_step(n)`` after frame n (1-based)."""
        for step in range(steps):
            self.advance(step)
            if on_step is not None:
                on_step(step + 1)

    @property
    def rigid(self) -> list[Binding]:
        """The bindings of rigid bodies and links (every binding but soft bodies')."""
        return [b for b in self.bindings if not b.soft]

    def poses(self) -> np.ndarray:
        """Centre-of-mass pose of every binding, ``(n, 7)`` float64 = position + quaternion (x, y, z, w)."""
        rows = []
        for b in self.bindings:
            if b.link == -1:
                pos, orn = self.p.getBasePositionAndOrientation(b.body)
            else:
                pos, orn = self.p.getLinkState(b.body, b.link, computeForwardKinematics=1)[:2]
            rows.append((*pos, *orn))
        return np.asarray(rows, dtype=np.float64).reshape(-1, 7)

    def velocities(self) -> np.ndarray:
        """Linear and angular velocity of every binding, ``(n, 6)`` float64."""
        rows = []
        for b in self.bindings:
            if b.link == -1:
                lin, ang = self.p.getBaseVelocity(b.body)
            else:
                lin, ang = self.p.getLinkState(b.body, b.link, computeLinkVelocity=1, computeForwardKinematics=1)[6:8]
            rows.append((*lin, *ang))
        return np.asarray(rows, dtype=np.float64).reshape(-1, 6)

    def physics_state(self) -> bytes:
        """Every body's base pose and velocity, every joint's state, every link's dynamics, and the
        engine parameters, as bytes: equal bytes mean pybullet holds exactly the same state."""
        p = self.p
        parts = [repr(sorted(p.getPhysicsEngineParameters().items()))]
        soft = {b.body for b in self.bindings if b.soft}
        for i in range(p.getNumBodies()):
            body = p.getBodyUniqueId(i)
            if body in soft:
                # its nodes are its state; getDynamicsInfo of a soft body reports uninitialised memory (measured:
                # denormals that change from call to call), which would make every sync look like it touched it
                parts.append(repr((body, p.getMeshData(body, -1, flags=pybullet.MESH_DATA_SIMULATION_MESH)[1])))
                continue
            parts.append(repr((body, p.getBasePositionAndOrientation(body), p.getBaseVelocity(body),
                               p.getDynamicsInfo(body, -1))))
            joints = list(range(p.getNumJoints(body)))
            if joints:
                parts.append(repr(p.getJointStatesMultiDof(body, joints)))
                parts.append(repr([p.getDynamicsInfo(body, j) for j in joints]))
        # repr of a float is exact (shortest round-trip), so equal text is bit-identical state.
        return "\n".join(parts).encode()

    def reproduce(self) -> str:
        """A Python expression that rebuilds this scene."""
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        return f"scenes.build({self.name!r}{', ' + args if args else ''})"

    # -- lifetime -------------------------------------------------------------------------------
    @property
    def connected(self) -> bool:
        return self.client >= 0 and bool(pybullet.isConnected(physicsClientId=self.client))

    def close(self) -> None:
        """Disconnect the client; safe to call more than once."""
        if self.connected:
            pybullet.disconnect(physicsClientId=self.client)

    def __enter__(self) -> "Scene":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<Scene {self.reproduce()} client={self.client} bindings={len(self.bindings)}>"
