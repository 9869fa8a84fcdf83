"""Compare what is drawn with what pybullet says, returning plain result records (no pytest here).

The pytest checks turn records into pass/fail; the command line and reports print the same records.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from conformance import backends, shapes, truth
from conformance.backends import Drawing
from conformance.tolerances import DEFAULT, Tolerance

__all__ = ["GeometryResult", "VertexResult", "compare_collision_geometry", "compare_vertices"]


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
    drawn = {}
    results = []
    for i, t in enumerate(targets):
        if id(t.actor) not in drawn:
            drawn[id(t.actor)] = backends.world_vertices(t.actor)
        actual = drawn[id(t.actor)][t.start:t.stop]
        expected = truth.expected_vertices(drawing.local[i], positions[i], orientations[i])
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
