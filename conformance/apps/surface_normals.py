"""Stored normals of a surface that deforms: are they the normals of the surface drawn now?

A soft body's node has a position and no turn, so the normals of a surface that follows nodes cannot be
judged by a frame's rotation, as a rigid body's are (:meth:`conformance.apps.judge.Judgement.normals`). They
are judged against the drawn surface itself instead: whatever smoothing a program chooses (area-, angle- or
uniformly weighted, or each face's own normal on a surface whose corners are not shared), a vertex's normal is
a non-negative mix of the normals of the triangles that meet at its point, so it lies within the smallest
spherical cap about their sum that holds them all. A normal outside that cap by more than :data:`ANGLE` was
made for another shape: a program that computed its normals once, on the shape it was built with, and never
since (FURY shades the deformed surface by them).

The faces are the drawn triangles, as the recording's pictures keep them (each face's first three corners);
the triangles that meet at a point are those with a corner on a vertex that follows the same node, so a
surface drawn with its corners unshared (one vertex per corner) may be shaded smooth. The sign of a normal is
not judged: VTK lights both sides of a face.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ANGLE", "beyond", "triangles"]

#: How far outside the cap of its faces a stored normal may point: 15° changes a lit pixel by up to a quarter
#: of its diffuse light (2 sin 7.5° = 0.26), twice the golden check's 32 of 255 levels. Measured on the soft ball
#: and jelly examples: a right program's normals are inside the cap (0.0° to print precision, both FURYs); the
#: same programs with their normals computed once are 35° (soft ball) and 57-74° (jelly) outside it.
ANGLE = math.radians(15.0)


def triangles(pictures, offsets: list[int], actor: int, count: int) -> np.ndarray | None:
    """The triangles of actor ``actor`` (``count`` vertices, the first at app-wide vertex ``offsets[actor]``)
    as its own vertex indices ``(m, 3)``, from the first picture that kept faces; None when no picture did."""
    shot = next((s for s in pictures if "corners" in s), None)
    if shot is None:
        return None
    corners = np.asarray(shot["corners"], dtype=np.int64).reshape(-1, 3) - offsets[actor]
    mine = np.all((corners >= 0) & (corners < count), axis=1)
    found = corners[mine]
    # a point or a line repeats its last corner: no face, no normal
    return found[(found[:, 0] != found[:, 1]) & (found[:, 1] != found[:, 2]) & (found[:, 0] != found[:, 2])]


def beyond(vertices: np.ndarray, normals: np.ndarray, faces: np.ndarray, points: np.ndarray) -> np.ndarray:
    """``(T, n)`` radians by which each stored normal points outside the cap of the faces meeting at its point
    (``-inf`` for a vertex on no face); ``vertices`` and ``normals`` ``(T, n, 3)``, ``faces`` ``(m, 3)`` vertex
    indices, ``points`` ``(n,)`` which point each vertex is at (vertices at one point share their faces)."""
    ticks, count = vertices.shape[:2]
    _, point = np.unique(points, return_inverse=True)
    groups = int(point.max(initial=-1)) + 1
    a, b, c = (vertices[:, faces[:, k]] for k in range(3))
    face = np.cross(b - a, c - a)
    unit = face / np.maximum(np.linalg.norm(face, axis=-1, keepdims=True), 1e-300)
    corner_points = point[faces]  # (m, 3)
    total = np.zeros((ticks, groups, 3))
    for k in range(3):
        np.add.at(total, (slice(None), corner_points[:, k]), unit)
    total /= np.maximum(np.linalg.norm(total, axis=-1, keepdims=True), 1e-300)
    # the cap's radius: the widest angle from a point's sum to one of its faces
    least = np.ones((groups, ticks))
    flat = np.linalg.norm(face, axis=-1) == 0  # a face of no area has no normal to bound the cap with
    for k in range(3):
        cos = np.where(flat, 1.0, np.einsum("tfi,tfi->tf", unit, total[:, corner_points[:, k]]))
        np.minimum.at(least, corner_points[:, k], cos.T)
    radius = np.arccos(np.clip(least.T, -1.0, 1.0))
    stored = normals / np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), 1e-300)
    off = np.arccos(np.clip(np.abs(np.einsum("tvi,tvi->tv", stored, total[:, point])), 0.0, 1.0))
    on_face = np.zeros(count, dtype=bool)
    on_face[faces.ravel()] = True
    return np.where(on_face, off - radius[:, point], -np.inf)
