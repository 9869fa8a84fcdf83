"""What both backends share: the :class:`Drawing`, laying a scene's bodies out in actors, and the
colour code of the flat ID render. Nothing here touches VTK or pygfx; each backend hands in the
three things that differ (how an actor is made, and views of its vertex and normal arrays).
"""

from __future__ import annotations

import contextlib
from collections import defaultdict
from dataclasses import dataclass
from typing import Any, Callable, Iterator

import numpy as np

from conformance.bullet import poses, truth
from conformance.errors import SceneError
from conformance.world import Target, World

__all__ = ["Drawing", "decode_ids", "id_codes", "id_colors", "lay_out", "moved_range", "transformed", "turned_normals"]

IDENTITY_POSITION = np.zeros(3)
IDENTITY_ORIENTATION = np.array([0.0, 0.0, 0.0, 1.0])


@dataclass(frozen=True, eq=False)
class Drawing:
    """A scene's actors, the :class:`World` handed to the sync, and the kit's reference geometry.

    ``local[i]`` is target i's geometry in its link frame, float64, computed when the actor was built
    (before any float32 storage): the ground truth that read-back is compared against.
    ``local_normals[i]`` are its vertex normals in the link frame, or None where the actor stores none
    (flat-shaded boxes and cylinders: the renderer derives their normals from the faces).
    """

    world: World
    local: tuple[np.ndarray, ...]
    local_normals: tuple[np.ndarray | None, ...]

    @property
    def targets(self) -> tuple[Target, ...]:
        return self.world.targets

    @property
    def actors(self):
        return self.world.actors


def lay_out(scene, make_actor: Callable[[str, np.ndarray, np.ndarray, np.ndarray], Any], points: Callable[[Any], np.ndarray],
            normals: Callable[[Any], np.ndarray | None], announce: Callable[[Any], None], *,
            make_surface: Callable[[np.ndarray, np.ndarray, np.ndarray], Any]) -> Drawing:
    """Actors for every binding of ``scene``, drawn at the poses pybullet holds now.

    ``make_actor(kind, centers, colors, sizes)`` makes one actor drawing shapes of one kind at the
    origin (``centers`` all zero) in their canonical direction, the same number of vertices each
    (``colors`` and ``sizes`` float64 rows, one a shape); ``points``/``normals`` are writable views of its
    arrays; ``announce`` tells the renderer they changed.

    Whole actors are built at the origin with an identity transform (the guide: "Centers for the
    actor must be set to (0, 0, 0)"); shared actors have each vertex range written at its body's
    current link-frame pose (as the guide's single-actor example builds them from ``brick_centers``).

    A soft body (a :class:`~conformance.scenes.base.Surface` binding) is an actor of its own made by
    ``make_surface(vertices, faces, colors)``: one vertex per simulated node, at the nodes' positions now,
    its triangles as the scene gives them, no stored normals (flat shaded, so no normal goes stale).
    """
    groups: dict[str, list[int]] = defaultdict(list)
    for i, binding in enumerate(scene.bindings):
        groups[binding.actor].append(i)
    positions, orientations = truth.link_frames(scene.p, truth.items_of(scene.bindings))

    actors: dict[str, Any] = {}
    targets: list[Target | None] = [None] * len(scene.bindings)
    local: list[np.ndarray | None] = [None] * len(scene.bindings)
    local_normals: list[np.ndarray | None] = [None] * len(scene.bindings)
    for name, members in groups.items():
        if any(scene.bindings[i].soft for i in members):
            if len(members) != 1:
                raise SceneError(f"scene {scene.name!r}: actor {name!r} would draw a soft body with other bodies")
            i = members[0]
            actors[name], targets[i], local[i] = _soft_actor(scene, scene.bindings[i], make_surface, announce)
            continue
        shapes = [scene.bindings[i].shape for i in members]
        kinds = {s.kind for s in shapes}
        if len(kinds) != 1:
            raise SceneError(f"scene {scene.name!r}: actor {name!r} would draw several shape kinds {sorted(kinds)}")
        actor = make_actor(kinds.pop(), np.zeros((len(shapes), 3)), np.array([s.color for s in shapes], dtype=np.float64),
                           np.array([s.size for s in shapes], dtype=np.float64))
        vertices, stored_normals = points(actor), normals(actor)
        per_body, remainder = divmod(len(vertices), len(members))
        if remainder:
            raise SceneError(f"scene {scene.name!r}: actor {name!r} has {len(vertices)} vertices for {len(members)} bodies")
        shared = len(members) > 1
        for k, i in enumerate(members):
            start, stop = k * per_body, (k + 1) * per_body
            shape = scene.bindings[i].shape
            geometry = poses.apply(shape.position, shape.orientation, vertices[start:stop])
            if shared:
                drawn_pos, drawn_orn = positions[i], orientations[i]
            else:
                drawn_pos, drawn_orn = IDENTITY_POSITION, IDENTITY_ORIENTATION
            vertices[start:stop] = poses.apply(drawn_pos, drawn_orn, geometry)
            local[i] = geometry
            if stored_normals is not None:
                # Normals turn with the body, or a rotated sphere is shaded as if lit from elsewhere.
                local_normals[i] = np.asarray(stored_normals[start:stop], dtype=np.float64) @ poses.matrices(shape.orientation).T
                stored_normals[start:stop] = local_normals[i] @ poses.matrices(drawn_orn).T
            targets[i] = Target(
                name=scene.bindings[i].name, body=scene.bindings[i].body, link=scene.bindings[i].link,
                actor=actor, start=start, stop=stop, shared=shared,
                position=np.array(drawn_pos, dtype=np.float64), orientation=np.array(drawn_orn, dtype=np.float64),
            )
        announce(actor)
        actors[name] = actor

    world = World(scene=scene.name, p=scene.p, targets=tuple(targets), actors=actors)
    return Drawing(world=world, local=tuple(local), local_normals=tuple(local_normals))


def _soft_actor(scene, binding, make_surface, announce) -> tuple[Any, Target, np.ndarray]:
    """The actor, target and world geometry of one soft body: a surface through its drawn nodes as they are now
    (every node of a surface body; a volumetric body's boundary nodes)."""
    shape = binding.shape
    nodes = truth.nodes(scene.p, binding.body)
    drawn = np.arange(len(nodes)) if shape.nodes is None else np.asarray(shape.nodes, dtype=np.int64)
    faces = np.asarray(shape.faces, dtype=np.int64)
    # fancy indexing copies: FURY may keep the array it is given as the actor's vertices, which the sync rewrites
    actor = make_surface(nodes[drawn], faces, np.tile(np.asarray(shape.color, dtype=np.float64), (len(drawn), 1)))
    announce(actor)
    target = Target(name=binding.name, body=binding.body, link=-1, actor=actor, start=0, stop=len(drawn), shared=False,
                    position=IDENTITY_POSITION.copy(), orientation=IDENTITY_ORIENTATION.copy(), nodes=drawn)
    return actor, target, nodes[drawn]


@contextlib.contextmanager
def moved_range(target, transform: np.ndarray, points: np.ndarray, normals: np.ndarray | None,
                announce: Callable[[], None]) -> Iterator[None]:
    """Within the block, the vertices ``start:stop`` of a shared actor (and its normals) are moved by the
    world ``transform``, and announced; restored and announced on exit. The shared half of a backend's
    ``perturbed``: a shared actor draws with an identity matrix, so the body's own vertices move."""
    t = target
    saved_points = points[t.start:t.stop].copy()
    saved_normals = None if normals is None else normals[t.start:t.stop].copy()
    points[t.start:t.stop] = saved_points @ transform[:3, :3].T + transform[:3, 3]
    if normals is not None:
        normals[t.start:t.stop] = saved_normals @ transform[:3, :3].T
    announce()
    try:
        yield
    finally:
        points[t.start:t.stop] = saved_points
        if normals is not None:
            normals[t.start:t.stop] = saved_normals
        announce()


def transformed(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Row-vector ``points`` (n, 3) through the 4x4 ``matrix`` (acting on column vectors), with the
    perspective divide, so that whatever a sync put in the matrix is applied as the renderer applies it."""
    points = np.asarray(points, dtype=np.float64)
    homogeneous = points @ matrix[:3, :3].T + matrix[:3, 3]
    w = points @ matrix[3, :3] + matrix[3, 3]
    return homogeneous / w[:, None]


def turned_normals(normals: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Normals through the inverse transpose of ``matrix``'s linear part, unit length: how both
    renderers light stored normals under an actor's transform."""
    linear = matrix[:3, :3]
    # an actor drawn in world coordinates (a shared actor's matrix is the identity): nothing to invert, every frame
    turned = (np.array(normals, dtype=np.float64) if np.array_equal(linear, _IDENTITY)
              else np.asarray(normals, dtype=np.float64) @ np.linalg.inv(linear))
    return turned / np.linalg.norm(turned, axis=1, keepdims=True)


_IDENTITY = np.eye(3)


# -- the flat ID render (the silhouette check) ------------------------------------------------------

def id_colors(count: int) -> np.ndarray:
    """The ``(count, 3)`` uint8 colour of each target index in a backend's ``render_ids``: ``index + 1``
    times a stride spreading the codes over the 24-bit colour cube (black, code 0, is the background),
    so that no two are neighbours and a blended pixel is almost never another target's colour."""
    stride = max(1, (2**24 - 1) // (count + 1))
    values = (np.arange(count, dtype=np.int64) + 1) * stride
    return np.stack([(values >> 16) & 255, (values >> 8) & 255, values & 255], axis=1).astype(np.uint8)


def decode_ids(picture: np.ndarray, count: int, *, strict: bool = True) -> np.ndarray:
    """``(h, w)`` int32 target index of each pixel of an ID ``picture`` (-1 for the background).

    Raises ``RuntimeError`` if any pixel is neither the background nor exactly a target's colour:
    the renderer blended (anti-aliasing, lighting, translucency), and the picture cannot be trusted.
    With ``strict=False`` such pixels are -2 instead (an app's own actors may carry a shader or texture
    the kit cannot switch off: its pixels are then unknown, not the whole picture)."""
    stride = max(1, (2**24 - 1) // (count + 1))
    values = (picture[..., 0].astype(np.int64) << 16) | (picture[..., 1].astype(np.int64) << 8) | picture[..., 2]
    index, remainder = np.divmod(values, stride)
    bad = (remainder != 0) | (index > count)
    if bad.any() and strict:
        raise RuntimeError(f"ID render: {int(bad.sum())} pixels are not exactly a target's colour (blended?)")
    return np.where(bad, -2, index - 1).astype(np.int32)


def id_codes(drawing: Drawing, vertex_count: Callable[[Any], int]) -> list[tuple[Any, np.ndarray]]:
    """Each actor of the drawing with the ``(n, 3)`` uint8 ID colour of every vertex: each target's
    range ``start:stop`` in its own :func:`id_colors` colour, vertices of no target black."""
    colors = id_colors(len(drawing.targets))
    codes: dict[int, tuple[Any, np.ndarray]] = {}
    for i, target in enumerate(drawing.targets):
        if id(target.actor) not in codes:
            codes[id(target.actor)] = (target.actor, np.zeros((vertex_count(target.actor), 3), dtype=np.uint8))
        codes[id(target.actor)][1][target.start:target.stop] = colors[i]
    return list(codes.values())
