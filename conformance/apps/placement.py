"""Where in its frame a drawing sits: on the body's collision shape, or off it.

Rigid attachment (:mod:`conformance.apps.attachment`) cannot see a drawing held by the right frame at
the wrong place in it: a base drawn at its centre of mass (``getBasePositionAndOrientation``) instead
of its link frame is rigid in the link frame, offset by the inertial position; a vertex range that
follows another body is rigid in that body's frame, far from its shape. What tells them apart is the
shape: when the vertices a frame holds in one actor span the same box, in the frame's axes, as the
frame's one collision shape (``getCollisionShapeData``, a box, sphere or cylinder), the drawn shape *is*
the collision shape, and its centre must then be the shape's centre. "The same box" allows
``bounds_rtol`` (2.5 %) of the shape's size, as the scene checks' bounds check does (FURY's sphere
tessellation reaches 98.1 % of the radius); so does "the centre".

When the extents differ (an app that draws a decoration, or a visual shape other than its collision
shape) the kit says the placement was not judged, and why: it never guesses an offset it cannot know —
unless some of those vertices lie far beyond the shape (more than twice its radius, and 1 cm): those are
drawn with this frame's pose at another body's place, the mistake of a vertex range paired with the wrong
link (FURY's wrecking-ball example), which attachment alone cannot see.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from conformance.tolerances import DEFAULT, Tolerance

__all__ = ["Placement", "bounding_radius", "bounding_sphere", "distance_to_shapes", "place", "shape_box"]

#: A drawing of another size than the collision shape is not judged, unless a vertex it holds lies further
#: from the shape's centre than REACH times the shape's radius plus REACH_MARGIN: no decoration of a body
#: reaches that far, while a vertex range paired with the wrong link of a chain does (a link's length away).
REACH = 2.0
REACH_MARGIN = 0.01  # metres


def shape_box(shapes) -> tuple[np.ndarray, np.ndarray] | None:
    """Centre and half extents, in the link frame's axes, of a frame's one box, sphere or cylinder
    collision shape; None for none, several, or other kinds."""
    if len(shapes) != 1:
        return None
    kind, dims, position, orientation = shapes[0]
    if kind == "box":
        half = np.asarray(dims[:3]) / 2
    elif kind == "sphere":
        half = np.full(3, float(dims[0]))
    elif kind == "cylinder":
        half = np.array([dims[1], dims[1], dims[0] / 2])
    else:
        return None
    turned = np.abs(Rotation.from_quat(orientation).as_matrix()) @ half
    if kind == "sphere":
        turned = half
    return np.asarray(position, dtype=np.float64), turned


def bounding_radius(shapes, default: float = 0.05) -> float:
    """How far from its frame's origin a frame's shapes reach (for telling whether it moved)."""
    radii = []
    for shape in shapes:
        box = shape_box([shape])
        if box is not None:
            radii.append(float(np.linalg.norm(box[0]) + np.linalg.norm(box[1])))
    return max(radii, default=default)


def bounding_sphere(shapes, mesh=()) -> tuple[np.ndarray, float]:
    """Centre (in the link frame) and radius of a sphere around a frame's collision shape: its one box,
    sphere or cylinder's; else around its collision ``mesh`` vertices (:attr:`~conformance.apps.bodies.Frame.mesh`);
    else one around the frame's origin."""
    box = shape_box(shapes)
    if box is None and len(mesh):
        points = np.asarray(mesh, dtype=np.float64)
        centre = (points.min(axis=0) + points.max(axis=0)) / 2
        return centre, float(np.linalg.norm(points - centre, axis=1).max())
    if box is None:
        return np.zeros(3), bounding_radius(shapes)
    return box[0], float(np.linalg.norm(box[1]))


def distance_to_shapes(points: np.ndarray, shapes, mesh=()) -> np.ndarray:
    """How far each of ``points`` ``(m, 3)`` (link-frame coordinates) lies outside a frame's collision
    shapes, 0 on or inside one: boxes, spheres, cylinders and capsules exactly, mesh shapes by the convex
    hull of ``mesh`` (pyBullet collides a mesh as its hull unless told otherwise); inf for a frame with
    none of them (a plane, say)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    best = np.full(len(points), np.inf)
    for kind, dims, position, orientation in shapes:
        local = (points - np.asarray(position)) @ Rotation.from_quat(orientation).as_matrix()
        if kind == "box":
            outside = np.maximum(np.abs(local) - np.asarray(dims[:3]) / 2, 0.0)
            distance = np.linalg.norm(outside, axis=1)
        elif kind == "sphere":
            distance = np.maximum(np.linalg.norm(local, axis=1) - dims[0], 0.0)
        elif kind in ("cylinder", "capsule"):
            height, radius = dims[0], dims[1]
            radial = np.linalg.norm(local[:, :2], axis=1)
            if kind == "cylinder":
                distance = np.hypot(np.maximum(radial - radius, 0.0), np.maximum(np.abs(local[:, 2]) - height / 2, 0.0))
            else:  # a segment of half length height/2 along z, swept by the radius
                along = np.clip(local[:, 2], -height / 2, height / 2)
                distance = np.maximum(np.hypot(radial, local[:, 2] - along) - radius, 0.0)
        elif kind == "mesh" and len(mesh) >= 4:
            distance = _outside_hull(points, np.asarray(mesh, dtype=np.float64))
        else:
            continue
        best = np.minimum(best, distance)
    return best


def _outside_hull(points: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """How far ``points`` lie outside the convex hull of ``vertices`` (the largest plane distance, 0 inside)."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        planes = ConvexHull(vertices).equations
    except (QhullError, ValueError):  # flat or degenerate: its bounding box
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        return np.linalg.norm(np.maximum(np.maximum(low - points, points - high), 0.0), axis=1)
    return np.maximum((points @ planes[:, :3].T + planes[:, 3]).max(axis=1), 0.0)


@dataclass
class Placement:
    """One actor's vertices held by one frame, against that frame's collision shape."""

    judged: bool
    ok: bool
    why: str
    offset: np.ndarray | None = None
    diagnosis: str = ""


def place(reference: np.ndarray, shapes, inertial_position, *, tolerance: Tolerance = DEFAULT) -> Placement:
    """Judge the link-frame coordinates ``reference`` ``(m, 3)`` of the vertices one frame holds in one
    actor against the frame's collision ``shapes``; ``inertial_position`` is the centre of mass in the
    link frame (``getDynamicsInfo(body, link)[3]``), to recognise a drawing made at the centre of mass."""
    box = shape_box(shapes)
    if box is None:
        kinds = ", ".join(s[0] for s in shapes) or "none"
        return Placement(False, True, f"not judged: the frame's collision shapes ({kinds}) are not one box, sphere or cylinder")
    centre, half = box
    low, high = reference.min(axis=0), reference.max(axis=0)
    drawn_centre, drawn_half = (low + high) / 2, (high - low) / 2
    allowance = tolerance.bounds_rtol * 2 * float(np.max(half)) + 1e-9
    if np.all(np.abs(drawn_half - half) <= allowance):
        offset = drawn_centre - centre
        if np.all(np.abs(offset) <= allowance):
            return Placement(True, True, "on its collision shape")
        diagnosis = ""
        inertial = np.asarray(inertial_position, dtype=np.float64)
        if np.linalg.norm(inertial) > allowance and np.all(np.abs(offset - inertial) <= allowance):
            diagnosis = "com-frame"
        return Placement(True, False, f"drawn {np.linalg.norm(offset):.4g} m off its collision shape (drawn centre "
                         f"{_v(drawn_centre)} in the link frame, the shape's {_v(centre)}; allowed {allowance:.3g} m)",
                         offset, diagnosis)
    if np.all(np.abs(np.sort(drawn_half) - np.sort(half)) <= allowance):
        return Placement(True, False, f"drawn turned in its frame: half extents {_v(drawn_half)} in the link frame's "
                         f"axes where the collision shape's are {_v(half)}", diagnosis="turned-shape")
    reach = float(np.max(np.linalg.norm(reference - centre, axis=1)))
    limit = REACH * float(np.linalg.norm(half)) + REACH_MARGIN
    if reach > limit:
        return Placement(True, False, f"reaches {reach:.3g} m from its collision shape's centre, more than {REACH:g} times "
                         f"the shape's radius ({float(np.linalg.norm(half)):.3g} m) and {REACH_MARGIN:g} m: drawn with this "
                         "frame's pose but elsewhere", drawn_centre - centre, "other-body")
    return Placement(False, True, f"not judged: the drawn shape (half extents {_v(drawn_half)}) is not the collision "
                     f"shape ({shapes[0][0]}, half extents {_v(half)})")


def _v(values) -> str:
    return "(" + ", ".join(f"{v:.4g}" for v in values) + ")"
