"""The stored normals of a deforming surface (``conformance.apps.surface_normals``): whatever smoothing a
program chooses, a normal within the faces that meet at its point passes; a normal made for the shape the
surface had before it folded is outside them and is caught."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conformance.apps import surface_normals

# A sheet of two squares that folds like a book about its middle edge (vertices 2 and 3): each half turns
# by `fold`, so the normals at the middle edge are shared by both halves and those at the outer edges by one.
FACES = np.array([[0, 1, 3], [0, 3, 2], [2, 3, 5], [2, 5, 4]])


def _square(fold: float) -> np.ndarray:
    x = np.array([0.0, 1.0] * 3)
    y = np.repeat([-1.0, 0.0, 1.0], 2)
    return np.stack([x, y * math.cos(fold), np.abs(y) * math.sin(fold)], axis=1)


def _smooth(vertices: np.ndarray, faces: np.ndarray, weighted: bool) -> np.ndarray:
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    face = np.cross(b - a, c - a)
    if not weighted:
        face /= np.linalg.norm(face, axis=1, keepdims=True)
    normals = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(normals, faces[:, k], face)
    return normals / np.linalg.norm(normals, axis=1, keepdims=True)


def _beyond(vertices, normals, faces=FACES, points=None) -> float:
    points = np.arange(len(vertices)) if points is None else points
    return float(surface_normals.beyond(vertices[None], normals[None], faces, points).max())


@pytest.mark.parametrize("weighted", [True, False], ids=["area-weighted", "unweighted"])
def test_normals_of_the_surface_drawn_pass_however_they_are_smoothed(weighted):
    folded = _square(math.radians(60))
    normals = _smooth(folded, FACES, weighted)
    assert _beyond(folded, normals) <= 1e-12
    assert _beyond(folded, -normals) <= 1e-12  # VTK lights both sides: the sign is not judged


def test_normals_made_for_the_flat_square_are_caught_once_it_folds():
    flat, folded = _square(0.0), _square(math.radians(60))
    stale = _smooth(flat, FACES, True)
    assert _beyond(folded, stale) > surface_normals.ANGLE  # the outer edges turned 60°, their normals did not
    assert _beyond(_square(math.radians(5)), stale) < surface_normals.ANGLE  # folded 5°: the picture hardly shows it


def test_corners_drawn_unshared_may_be_shaded_smooth():
    """A surface drawn with one vertex per corner of each face (as pyBullet's visual mesh is): the vertices at
    one node are one point, so a smooth normal there is within the faces that meet at it, and a normal
    made for the flat square is not."""
    folded = _square(math.radians(60))
    corners = folded[FACES.ravel()]
    faces = np.arange(len(corners)).reshape(-1, 3)
    smooth = _smooth(folded, FACES, True)[FACES.ravel()]
    assert _beyond(corners, smooth, faces, points=FACES.ravel()) <= 1e-12
    # judged corner by corner, as if each were a point of its own, the smooth normals would be wrong
    assert _beyond(corners, smooth, faces) > surface_normals.ANGLE
    stale = _smooth(_square(0.0), FACES, True)[FACES.ravel()]
    assert _beyond(corners, stale, faces, points=FACES.ravel()) > surface_normals.ANGLE


def test_a_vertex_on_no_face_is_not_judged():
    folded = np.vstack([_square(math.radians(60)), [[5.0, 5.0, 5.0]]])
    normals = np.vstack([_smooth(folded[:6], FACES, True), [[1.0, 0.0, 0.0]]])
    found = surface_normals.beyond(folded[None], normals[None], FACES, np.arange(7))
    assert found[0, 6] == -np.inf and found.max() <= 1e-12


def test_the_faces_of_one_actor_are_read_from_a_picture():
    pictures = [{"tick": 1, "skipped": "no camera"},
                {"tick": 2, "corners": np.array([[0, 1, 2], [3, 4, 5], [5, 6, 7], [7, 7, 7]])}]
    assert surface_normals.triangles(pictures, [0, 3, 8], 1, 5).tolist() == [[0, 1, 2], [2, 3, 4]]
    assert surface_normals.triangles(pictures[:1], [0, 3, 8], 1, 5) is None
