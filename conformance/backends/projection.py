"""A scene :class:`~scenes.base.Camera` as view and projection matrices, for VTK and pyBullet alike.

Both renderers use the OpenGL conventions, so one pair of matrices describes both:

* the view matrix is the right-handed "look at" of ``position`` towards ``focal_point`` with
  ``view_up`` (VTK's ``vtkCamera::ComputeViewTransform``; pyBullet's
  ``computeViewMatrix(cameraEyePosition, cameraTargetPosition, cameraUpVector)``, pyBullet Quickstart
  Guide, "computeViewMatrix");
* the projection is the symmetric perspective frustum of vertical field of view ``view_angle`` (VTK's
  default: ``UseHorizontalViewAngle`` off), aspect ``width / height``, planes ``clipping_range``,
  depth mapped to [-1, 1] (VTK's ``GetProjectionTransformMatrix(aspect, -1, 1)``; pyBullet's
  ``computeProjectionMatrixFOV(fov, aspect, nearVal, farVal)``, Quickstart, "getCameraImage").

pyBullet wants each matrix as 16 floats in column-major order (the Quickstart: "4x4 view matrix,
stored as a list of 16 floats"; its own ``computeViewMatrix`` returns that order), and computes them
in float32, so they agree with these to about 1e-6 relative (``tests/test_silhouettes.py`` proves
the agreement against both VTK's and pyBullet's own functions).

No VTK and no pytest here.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["composite", "project", "projection_matrix", "pybullet_matrices", "view_matrix"]


def view_matrix(camera) -> np.ndarray:
    """The 4x4 world-to-eye matrix (acting on column vectors): the eye at the origin looking down -z,
    ``view_up`` projected orthogonal to the direction of view as +y."""
    eye = np.asarray(camera.position, dtype=np.float64)
    forward = np.asarray(camera.focal_point, dtype=np.float64) - eye
    forward /= np.linalg.norm(forward)
    side = np.cross(forward, np.asarray(camera.view_up, dtype=np.float64))
    norm = np.linalg.norm(side)
    if norm < 1e-12:
        raise ValueError(f"camera view_up={camera.view_up!r} is parallel to the direction of view")
    side /= norm
    up = np.cross(side, forward)
    matrix = np.eye(4)
    matrix[0, :3], matrix[1, :3], matrix[2, :3] = side, up, -forward
    matrix[:3, 3] = -matrix[:3, :3] @ eye
    return matrix


def projection_matrix(camera, size) -> np.ndarray:
    """The 4x4 eye-to-clip matrix: vertical field of view ``camera.view_angle`` degrees, aspect
    ``width / height`` of ``size = (width, height)``, depth from ``near`` ↦ -1 to ``far`` ↦ +1."""
    width, height = size
    near, far = camera.clipping_range
    y_scale = 1.0 / math.tan(math.radians(camera.view_angle) / 2)
    matrix = np.zeros((4, 4))
    matrix[0, 0] = y_scale * height / width
    matrix[1, 1] = y_scale
    matrix[2, 2] = (near + far) / (near - far)
    matrix[2, 3] = 2 * near * far / (near - far)
    matrix[3, 2] = -1.0
    return matrix


def composite(camera, size) -> np.ndarray:
    """Projection times view: world to clip coordinates (VTK's ``GetCompositeProjectionTransformMatrix``)."""
    return projection_matrix(camera, size) @ view_matrix(camera)


def pybullet_matrices(camera, size) -> tuple[list[float], list[float]]:
    """``(viewMatrix, projectionMatrix)`` for ``getCameraImage``: 16 floats each, column-major."""
    return (view_matrix(camera).T.ravel().tolist(), projection_matrix(camera, size).T.ravel().tolist())


def project(camera, size, points) -> tuple[np.ndarray, np.ndarray]:
    """Where world ``points`` (n, 3) land in a ``size = (width, height)`` picture.

    Returns ``(pixels, depth)``: ``pixels`` (n, 2) float64 in picture coordinates, x to the right and
    y down, the top-left corner of the picture at (0, 0) so that pixel (column i, row j) covers
    [i, i+1) × [j, j+1) and its centre is (i + 0.5, j + 0.5); ``depth`` (n,) the distance in front of
    the camera along its direction of view (negative behind it, where ``pixels`` mean nothing).
    """
    width, height = size
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    eye = points @ view_matrix(camera)[:3, :3].T + view_matrix(camera)[:3, 3]
    clip = eye @ projection_matrix(camera, size)[:, :3].T  # eye has w = 1; the projection has no translation in x, y, w
    clip[:, 2] += projection_matrix(camera, size)[2, 3]
    depth = -eye[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = clip[:, :2] / clip[:, 3:4]
    pixels = np.empty((len(points), 2))
    pixels[:, 0] = (ndc[:, 0] + 1) / 2 * width
    pixels[:, 1] = (1 - ndc[:, 1]) / 2 * height
    return pixels, depth
