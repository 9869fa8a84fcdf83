"""Compare what is drawn with what pybullet says, returning plain result records (no pytest here).

The pytest checks turn records into pass/fail; the command line and reports print the same records.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from conformance import backends
from conformance.bullet import poses, shapes, truth
from conformance.backends.common import Drawing
from conformance.judge.tolerances import DEFAULT, Tolerance

__all__ = [
    "BoundsResult",
    "GeometryResult",
    "NormalResult",
    "VertexResult",
    "VertexResults",
    "compare_bounds",
    "compare_collision_geometry",
    "compare_normals",
    "compare_vertices",
    "drawn_overlap",
    "link_poses",
]


@dataclass(frozen=True)
class VertexResult:
    """The worst vertex of one target at one frame: drawn (``actual``) vs pybullet (``expected``)."""

    scene: str
    target: str
    body: int
    link: int
    frame: int
    error: float
    tolerance: float
    vertex: int
    expected: tuple[float, float, float]
    actual: tuple[float, float, float]

    @property
    def ok(self) -> bool:
        return self.error <= self.tolerance  # False for NaN as well

    @property
    def where(self) -> str:
        part = f"link {self.link} of body {self.body}" if self.link >= 0 else f"body {self.body}"
        return f"{self.target!r} ({part})"

    def describe(self) -> str:
        def fmt(v):
            return "(" + ", ".join(f"{c:.6g}" for c in v) + ")"

        if not np.isfinite(self.actual).all():
            return (f"{self.where} is drawn at non-finite coordinates {fmt(self.actual)} (vertex {self.vertex}), "
                    f"but should be at {fmt(self.expected)}")
        return (f"{self.where} vertex {self.vertex} is drawn at {fmt(self.actual)}, but should be at "
                f"{fmt(self.expected)}: error {self.error:.3g} m {'<=' if self.ok else '>'} tolerance {self.tolerance:.3g} m")


class _Layout:
    """A drawing's targets grouped by vertex count, with what does not change between frames: the
    stacked reference geometry and normals, and each target's extent (for its tolerance). Built
    once per drawing, so a frame's comparison is a few array operations per group, not per target."""

    def __init__(self, drawing: Drawing):
        by_count: dict[int, list[int]] = {}
        #: Soft bodies' targets: drawn at their nodes, read each frame, not at a pose (``Target.nodes``).
        self.soft = {i for i, t in enumerate(drawing.targets) if t.nodes is not None}
        for i, local in enumerate(drawing.local):
            if i not in self.soft:
                by_count.setdefault(len(local), []).append(i)
        self.groups = [(np.array(rows), np.stack([drawing.local[i] for i in rows])) for rows in by_count.values()]
        # A node has no size: its vertex is a point (its tolerance is the float32 rounding of where it is).
        self.extents = np.array([float(np.max(np.linalg.norm(local, axis=1))) if len(local) and i not in self.soft else 0.0
                                 for i, local in enumerate(drawing.local)])
        lit = [i for i, normals in enumerate(drawing.local_normals) if normals is not None]
        by_count = {}
        for i in lit:
            by_count.setdefault(len(drawing.local_normals[i]), []).append(i)
        self.normal_groups = [(np.array(rows), np.stack([drawing.local_normals[i] for i in rows]))
                              for rows in by_count.values()]


_layouts: "weakref.WeakKeyDictionary[Drawing, _Layout]" = weakref.WeakKeyDictionary()


def _layout(drawing: Drawing) -> _Layout:
    layout = _layouts.get(drawing)
    if layout is None:
        layout = _layouts[drawing] = _Layout(drawing)
    return layout


def _gather(drawing: Drawing, rows, read) -> np.ndarray:
    """The drawn data of targets ``rows`` (equal vertex counts), stacked: ``read(actor)`` once per actor."""
    cache = {}
    parts = []
    for i in rows:
        t = drawing.targets[i]
        if id(t.actor) not in cache:
            cache[id(t.actor)] = read(t.actor)
        part = cache[id(t.actor)][t.start:t.stop]
        if len(part) != t.stop - t.start:  # the sync shrank the actor: its missing vertices are drawn nowhere
            part = np.concatenate([part, np.full((t.stop - t.start - len(part), 3), np.nan)])
        parts.append(part)
    return np.stack(parts)


def link_poses(drawing: Drawing) -> tuple[np.ndarray, np.ndarray]:
    """pyBullet's link-frame pose of every target now: positions ``(n, 3)`` and rotation matrices
    ``(n, 3, 3)``. A caller comparing vertices and normals at one frame reads them once and passes them
    to both (``frames=``): reading them is most of a frame's comparison."""
    positions, orientations = truth.link_frames(drawing.world.p, truth.items_of(drawing.targets))
    return positions, poses.matrices(orientations)


class VertexResults(Sequence):
    """:func:`compare_vertices`' records, one :class:`VertexResult` per target, kept as arrays and made
    into records only when read: a frame's check reads the worst and the failures (:meth:`worst`,
    :meth:`failures`), and making a record of each of a brick wall's hundred targets was most of a
    frame's comparison."""

    def __init__(self, drawing: Drawing, frame: int, error, tolerance, vertex, expected, actual):
        self._drawing, self._frame = drawing, frame
        self.error, self.tolerance, self._vertex, self._expected, self._actual = error, tolerance, vertex, expected, actual

    def __len__(self) -> int:
        return len(self.error)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(len(self)))]
        i = range(len(self))[i]
        t = self._drawing.targets[i]
        return VertexResult(scene=self._drawing.world.scene, target=t.name, body=t.body, link=t.link, frame=self._frame,
                            error=float(self.error[i]), tolerance=float(self.tolerance[i]), vertex=int(self._vertex[i]),
                            expected=tuple(map(float, self._expected[i])), actual=tuple(map(float, self._actual[i])))

    def worst(self) -> VertexResult | None:
        """The largest error in tolerances, a NaN error first (the first of equals, as ``max`` picks)."""
        if not len(self):
            return None
        nan = np.isnan(self.error)
        if nan.any():
            return self[int(np.argmax(nan))]
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(self.tolerance != 0, self.error / np.where(self.tolerance != 0, self.tolerance, 1.0), self.error)
        return self[int(np.argmax(ratio))]

    def failures(self) -> list[VertexResult]:
        """The records of the targets drawn outside their tolerance (or at NaN), in target order."""
        return [self[int(i)] for i in np.flatnonzero(~(self.error <= self.tolerance))]


def compare_vertices(drawing: Drawing, frame: int, tolerance: Tolerance = DEFAULT, *,
                     frames: tuple[np.ndarray, np.ndarray] | None = None) -> VertexResults:
    """One record per target: the worst vertex of what the renderer draws vs pybullet's pose
    (``frames``: :func:`link_poses` read at this frame, else read here)."""
    n = len(drawing.targets)
    positions, rotations = frames if frames is not None else link_poses(drawing)
    layout = _layout(drawing)
    drawn = {}

    def read(actor):
        if id(actor) not in drawn:
            drawn[id(actor)] = backends.world_vertices(actor)
        return drawn[id(actor)]

    error, vertex = np.zeros(n), np.zeros(n, dtype=int)
    expected_at, actual_at = np.zeros((n, 3)), np.zeros((n, 3))
    for rows, local in layout.groups:
        if not local.shape[1]:  # targets without vertices: error 0 at vertex 0, drawn and expected at the origin
            continue
        actual = _gather(drawing, rows, read)
        expected = np.einsum("nij,nkj->nki", rotations[rows], local) + positions[rows][:, None, :]
        errors = np.linalg.norm(actual - expected, axis=2)
        errors = np.where(np.isfinite(errors), errors, np.inf)
        worst = np.argmax(errors, axis=1)
        k = np.arange(len(rows))
        error[rows], vertex[rows] = errors[k, worst], worst
        expected_at[rows], actual_at[rows] = expected[k, worst], actual[k, worst]
    tolerances = tolerance.for_extents(layout.extents, positions)
    for i, expected in truth.soft_vertices(drawing.world.p, drawing.targets).items():
        actual = _gather(drawing, [i], read)[0]
        errors = np.linalg.norm(actual - expected, axis=1)
        errors = np.where(np.isfinite(errors), errors, np.inf)
        worst = int(np.argmax(errors)) if len(errors) else 0
        if len(errors):
            error[i], vertex[i], expected_at[i], actual_at[i] = errors[worst], worst, expected[worst], actual[worst]
        # each node's vertex is held to the float32 rounding of its own place: the farthest node's
        tolerances[i] = tolerance.for_extents(np.zeros(1), np.abs(expected).max(axis=0, initial=0.0)[None])[0]
    return VertexResults(drawing, frame, error, tolerances, vertex, expected_at, actual_at)


@dataclass(frozen=True)
class GeometryResult:
    """Whether one target's drawn vertices are its collision shape (as pybullet reports the shape)."""

    scene: str
    target: str
    kind: str
    problems: tuple[str, ...]

    @property
    def ok(self) -> bool:
        return not self.problems


def compare_collision_geometry(drawing: Drawing, frame: int, tolerance: Tolerance = DEFAULT) -> list[GeometryResult]:
    """Check the drawn vertices of every target against ``getCollisionShapeData``.

    The vertices read back from the renderer are brought into the collision shape's frame using
    pybullet alone (centre-of-mass pose composed with the shape's local frame, which
    ``getCollisionShapeData`` gives relative to the centre of mass); there every vertex must lie on
    the shape's surface and together they must span the shape along each axis.
    """
    p = drawing.world.p
    results = []
    drawn = {}
    for i, t in enumerate(drawing.targets):
        if t.nodes is not None:
            continue  # a soft body has no collision shape to draw: its vertices are its nodes (compare_vertices)
        if id(t.actor) not in drawn:
            drawn[id(t.actor)] = backends.world_vertices(t.actor)
        data = p.getCollisionShapeData(t.body, t.link)
        if len(data) != 1:
            results.append(GeometryResult(drawing.world.scene, t.name, "?", (f"pybullet reports {len(data)} collision shapes, expected 1",)))
            continue
        _, _, geometry, dimensions, _, local_pos, local_orn = data[0]
        if t.link == -1:
            com_pos, com_orn = p.getBasePositionAndOrientation(t.body)
        else:
            com_pos, com_orn = p.getLinkState(t.body, t.link, computeForwardKinematics=1)[:2]
        shape_pos, shape_orn = shapes.compose(com_pos, com_orn, local_pos, local_orn)
        in_shape = shapes.to_frame(shape_pos, shape_orn, drawn[id(t.actor)][t.start:t.stop])
        tol = tolerance.for_geometry(drawing.local[i], shape_pos)
        results.append(GeometryResult(drawing.world.scene, t.name, shapes.kind_name(geometry),
                                      tuple(shapes.problems(geometry, dimensions, in_shape, tol))))
    return results


@dataclass(frozen=True)
class NormalResult:
    """The worst vertex normal of one target: the angle between how it is lit and how it should be."""

    scene: str
    target: str
    frame: int
    angle: float
    tolerance: float
    vertex: int

    @property
    def ok(self) -> bool:
        return self.angle <= self.tolerance

    def describe(self) -> str:
        return (f"{self.target!r} vertex {self.vertex} normal is turned {self.angle:.3g} rad from the body's "
                f"rotated normal, but should be within {self.tolerance:.3g} rad (lighting would be wrong)")


def compare_normals(drawing: Drawing, frame: int, tolerance: Tolerance = DEFAULT, *,
                    frames: tuple[np.ndarray, np.ndarray] | None = None) -> list[NormalResult]:
    """Targets whose actor stores vertex normals: they must turn with the body (``frames`` as for
    :func:`compare_vertices`)."""
    layout = _layout(drawing)
    if not layout.normal_groups:
        return []
    _, rotations = frames if frames is not None else link_poses(drawing)
    lit = {}

    def read(actor):
        if id(actor) not in lit:
            lit[id(actor)] = backends.world_normals(actor)
        return lit[id(actor)]

    results = {}
    for rows, local in layout.normal_groups:
        stored = np.array([read(drawing.targets[i].actor) is not None for i in rows])
        for i in rows[~stored]:  # the actor stores no normals (any more): nothing turns with the body
            results[int(i)] = NormalResult(drawing.world.scene, drawing.targets[i].name, frame, float("inf"),
                                           tolerance.normal_angle, 0)
        rows, local = rows[stored], local[stored]
        if not len(rows):
            continue
        actual = _gather(drawing, rows, read)
        expected = np.einsum("nij,nkj->nki", rotations[rows], local)
        cosines = np.einsum("nkj,nkj->nk", actual, expected / np.linalg.norm(expected, axis=2, keepdims=True))
        angles = np.arccos(np.clip(np.nan_to_num(cosines, nan=-1.0), -1.0, 1.0))
        worst = np.argmax(angles, axis=1)
        for k, i in enumerate(rows):
            results[int(i)] = NormalResult(drawing.world.scene, drawing.targets[i].name, frame,
                                           float(angles[k, worst[k]]), tolerance.normal_angle, int(worst[k]))
    return [results[i] for i in sorted(results)]


@dataclass(frozen=True)
class BoundsResult:
    """A target's drawn world bounding box against pybullet's ``getAABB``."""

    scene: str
    target: str
    frame: int
    problems: tuple[str, ...]

    @property
    def ok(self) -> bool:
        return not self.problems


def compare_bounds(drawing: Drawing, frame: int, tolerance: Tolerance = DEFAULT) -> list[BoundsResult]:
    """Each target's drawn box lies inside ``getAABB`` and reaches it on every side within the margin
    stated in :mod:`conformance.judge.tolerances`."""
    p = drawing.world.p
    drawn = {}
    positions, orientations = truth.link_frames(p, truth.items_of(drawing.targets))
    results = []
    for i, t in enumerate(drawing.targets):
        if t.nodes is not None:
            # A soft body's getAABB is its nodes' box grown by a collision margin and the last step's motion,
            # 0.016-0.027 m on the cloth scene, unevenly by side (measured): no tighter than the vertex check,
            # which holds every vertex to its node.
            continue
        if id(t.actor) not in drawn:
            drawn[id(t.actor)] = backends.world_vertices(t.actor)
        vertices = drawn[id(t.actor)][t.start:t.stop]
        low, high = (np.asarray(v, dtype=np.float64) for v in p.getAABB(t.body, t.link))
        size = float(np.max(np.linalg.norm(drawing.local[i] - drawing.local[i].mean(axis=0), axis=1)))
        posed = truth.expected_vertices(drawing.local[i], positions[i], orientations[i])
        # How much larger than the shape pybullet's box is, along each axis (0 for a box).
        looseness = np.maximum(truth.aabb_half_extents(p, t.body, t.link) - np.ptp(posed, axis=0) / 2, 0.0)
        slack = tolerance.for_geometry(drawing.local[i], positions[i])
        margin = looseness + tolerance.bounds_rtol * size + slack
        found = []
        if not np.isfinite(vertices).all():
            found.append("drawn vertices are not finite")
        else:
            v_low, v_high = vertices.min(axis=0), vertices.max(axis=0)
            outside = np.maximum(low - v_low, v_high - high)
            short = np.maximum(v_low - low, high - v_high)
            for axis in range(3):
                if outside[axis] > slack:
                    found.append(f"drawn box sticks out of getAABB by {outside[axis]:.3g} m along {'xyz'[axis]} "
                                 f"(tolerance {slack:.3g} m)")
                elif short[axis] > margin[axis]:
                    found.append(f"drawn box falls {short[axis]:.3g} m short of getAABB along {'xyz'[axis]} "
                                 f"(margin {margin[axis]:.3g} m)")
        results.append(BoundsResult(drawing.world.scene, t.name, frame, tuple(found)))
    return results


def drawn_overlap(drawing, names: tuple[str, str] = ("a", "b")) -> tuple[dict[str, bool], float]:
    """Read back what the renderer draws for the two bodies: whether each one's drawn centre (the
    mean of its drawn vertices) lies inside the other's drawn shape (the convex hull of its drawn
    vertices), and the distance between the drawn centres."""
    from scipy.spatial import ConvexHull, QhullError

    drawn = {}
    for target in drawing.targets:
        if target.name in names:
            drawn[target.name] = backends.world_vertices(target.actor)[target.start:target.stop]
    centres = {name: points.mean(axis=0) for name, points in drawn.items()}
    inside = {}
    for name, other in (names, names[::-1]):
        if not (np.isfinite(drawn[other]).all() and np.isfinite(centres[name]).all()):
            inside[name] = False
            continue
        try:
            hull = ConvexHull(drawn[other])
        except QhullError:  # drawn flat or as one point: nothing lies inside
            inside[name] = False
            continue
        scale = float(np.ptp(drawn[other], axis=0).max())
        margin = hull.equations[:, :3] @ centres[name] + hull.equations[:, 3]
        inside[name] = bool((margin <= 1e-9 * scale).all())
    return inside, float(np.linalg.norm(centres[names[0]] - centres[names[1]]))
