"""Compare what is drawn with what pybullet says, returning plain result records (no pytest here).

The pytest checks turn records into pass/fail; the command line and reports print the same records.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import pybullet

from conformance import backends, poses, shapes, truth
from conformance.backends import Drawing
from conformance.tolerances import DEFAULT, Tolerance

__all__ = [
    "BoundsResult",
    "GeometryResult",
    "NormalResult",
    "VertexResult",
    "compare_bounds",
    "compare_collision_geometry",
    "compare_normals",
    "compare_vertices",
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


def compare_vertices(drawing: Drawing, frame: int, tolerance: Tolerance = DEFAULT) -> list[VertexResult]:
    """One record per target: the worst vertex of what the renderer draws vs pybullet's pose."""
    targets = drawing.targets
    positions, orientations = truth.link_frames(drawing.world.p, [(t.body, t.link) for t in targets])
    rotations = poses.matrices(orientations)
    drawn = {}
    results = []
    for i, t in enumerate(targets):
        if id(t.actor) not in drawn:
            drawn[id(t.actor)] = backends.world_vertices(t.actor)
        actual = drawn[id(t.actor)][t.start:t.stop]
        expected = drawing.local[i] @ rotations[i].T + positions[i]
        errors = np.linalg.norm(actual - expected, axis=1)
        errors = np.where(np.isfinite(errors), errors, np.inf)
        worst = int(np.argmax(errors)) if len(errors) else 0
        results.append(VertexResult(
            scene=drawing.world.scene, target=t.name, body=t.body, link=t.link, frame=frame,
            error=float(errors[worst]) if len(errors) else 0.0,
            tolerance=tolerance.for_geometry(drawing.local[i], positions[i]),
            vertex=worst, expected=tuple(map(float, expected[worst])), actual=tuple(map(float, actual[worst])),
        ))
    return results


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


def compare_normals(drawing: Drawing, frame: int, tolerance: Tolerance = DEFAULT) -> list[NormalResult]:
    """Targets whose actor stores vertex normals: they must turn with the body."""
    results = []
    _, orientations = truth.link_frames(drawing.world.p, [(t.body, t.link) for t in drawing.targets])
    lit = {}
    for i, t in enumerate(drawing.targets):
        if drawing.local_normals[i] is None:
            continue
        if id(t.actor) not in lit:
            lit[id(t.actor)] = backends.world_normals(t.actor)
        actual = lit[id(t.actor)]
        if actual is None:
            results.append(NormalResult(drawing.world.scene, t.name, frame, float("inf"), tolerance.normal_angle, 0))
            continue
        expected = truth.expected_vertices(drawing.local_normals[i], np.zeros(3), orientations[i])
        cosines = np.einsum("ij,ij->i", actual[t.start:t.stop], expected / np.linalg.norm(expected, axis=1, keepdims=True))
        angles = np.arccos(np.clip(np.nan_to_num(cosines, nan=-1.0), -1.0, 1.0))
        worst = int(np.argmax(angles))
        results.append(NormalResult(drawing.world.scene, t.name, frame, float(angles[worst]), tolerance.normal_angle, worst))
    return results


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
    stated in :mod:`conformance.tolerances`."""
    p = drawing.world.p
    drawn = {}
    positions, orientations = truth.link_frames(p, [(t.body, t.link) for t in drawing.targets])
    results = []
    for i, t in enumerate(drawing.targets):
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
