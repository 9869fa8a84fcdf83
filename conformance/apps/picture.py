"""The pictures of an app's scene during a run, taken in the app's process: FURY's and pyBullet's.

At :data:`PICTURES` ticks of every run, evenly spaced, the last at its end (the app's own run and each
perturbed one, :func:`picture_ticks`), the kit draws the app's own actors, as
its own ShowManager holds them, from the app's own camera (:mod:`conformance.apps.picture_vtk`,
:mod:`conformance.apps.picture_pygfx`), each face flat in a colour that codes it, and pyBullet's tiny
renderer draws its segmentation mask on each of the app's clients from the same camera, put together by
its depth buffer
(:func:`conformance.rendering.silhouettes.pybullet_mask`, the scene checks' own). Which body a face
draws is not known here: the judgement (:mod:`conformance.apps.pictured`) labels each face by the frame
the attachment gives the first of its corners one frame alone holds. So the picture keeps, per pixel,
the index of the face seen (-1 for the background, -2 for a pixel whose colour is no code: a shader or
texture the kit could not switch off), and each face's first :data:`CORNERS` app-wide vertices (actors
in the recording's order).

What the picture shows that the recorded vertices do not: an actor hidden (``SetVisibility(0)``,
``visible = False``) or so transparent it changes no pixel by more than the golden check's 32 levels
(:data:`FAINT`: faces drawn fainter are kept, flagged per vertex), and on FURY 2 the vertices the GPU
holds: pygfx uploads only the ranges announced with ``update_range``, so the kit keeps, tick by tick,
a copy of what the renderer would have uploaded (``_Track.gpu`` in :mod:`conformance.apps.driver`) and
draws from it.

Both pictures share one camera: the app's position, focal point, view up and vertical view angle at
the aspect of the app's window, and a clipping range spanning every recorded vertex (so neither
renderer clips what the other shows). The size is the app's window scaled to :data:`SIDE` pixels on
its longer side, the scene checks' picture width, where their silhouette thresholds were measured.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from types import SimpleNamespace

import numpy as np

__all__ = ["FAINT", "PICTURES", "SIDE", "Camera", "picture_size", "picture_ticks", "take"]

#: The longer side of the picture, in pixels: the scene checks' 450×384 pictures, whose silhouette
#: thresholds (:data:`conformance.rendering.silhouettes.MIN_IOU`, ``MIN_PIXELS``) this reuses.
SIDE = 450
#: An opacity below this changes no pixel by more than 32 of 255 levels, the golden check's
#: other-renderer threshold (:data:`conformance.rendering.compare.OTHER_RENDERER`): not shown.
FAINT = 32 / 255
#: Pictures per run, evenly spaced, the last at its end: a mistake that shows only for a while (an actor
#: hidden or faded out, then shown again) is seen at another tick. Measured on the FURY 2 brick wall
#: example: the first picture of a run costs 2.1-2.4 s (the off-screen canvas), a second one almost
#: nothing more; on FURY 0.12 both together 0.14 s.
PICTURES = 4


@dataclass(frozen=True)
class Camera:
    """A perspective camera as :mod:`conformance.backends.projection` takes it (vertical view angle, degrees)."""

    position: tuple
    focal_point: tuple
    view_up: tuple
    view_angle: float
    clipping_range: tuple = (0.1, 100.0)

    def as_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}


def picture_ticks(ticks: int, pictures: int = PICTURES) -> list[int]:
    """The ticks of a run of up to ``ticks`` ticks at which pictures are taken: every ``ticks / pictures``
    (rounded up) ticks, and the run's end (an app that ends its run early has its last picture there)."""
    if ticks <= 0:
        return [0]
    period = -(-ticks // pictures)
    return sorted(set(range(period, ticks, period)) | {ticks})


def picture_size(app_size) -> tuple[int, int]:
    """The app's window ``(width, height)`` scaled to :data:`SIDE` pixels on its longer side."""
    width, height = (max(1, int(v)) for v in app_size)
    scale = SIDE / max(width, height)
    return max(1, round(width * scale)), max(1, round(height * scale))


def clipping_range(camera: Camera, points: np.ndarray) -> tuple[float, float]:
    """Near and far planes around ``points`` (n, 3) seen from ``camera``: 10 % beyond the farthest, and
    the nearest in front of the camera (at least 1/1000 of the far plane, a usable depth resolution)."""
    from conformance.backends import projection

    view = projection.view_matrix(camera)
    depth = -(points @ view[2, :3] + view[2, 3]) if len(points) else np.array([1.0])
    far = max(float(depth.max()) * 1.1, 1e-3)
    ahead = depth[depth > far * 1e-3]
    near = max(float(ahead.min()) * 0.9 if len(ahead) else far * 1e-3, far * 1e-3)
    return near, far


def touching(client: int, frames) -> list[list[int]]:
    """Pairs of frame indices pyBullet has within the silhouette check's
    :data:`~conformance.rendering.silhouettes.TOUCHING` of each other now: the pixels where two renderers
    may put either in front, which the comparison leaves out as the scene checks do. Candidates are the
    frames whose bounding boxes overlap (``getOverlappingObjects``), each pair then measured with
    ``getClosestPoints`` as :func:`~conformance.rendering.silhouettes.touching_pairs` does (contact points
    would miss a link and its parent, which pyBullet does not collide)."""
    import pybullet

    from conformance.rendering.silhouettes import TOUCHING

    index = {(f.body, f.link): i for i, f in enumerate(frames) if f.client == client and f.node < 0}
    pairs = set()
    for (body, link), i in index.items():
        low, high = pybullet.getAABB(body, link, physicsClientId=client)
        near = pybullet.getOverlappingObjects(np.subtract(low, TOUCHING).tolist(), np.add(high, TOUCHING).tolist(),
                                              physicsClientId=client) or []
        for other in {(b, l) for b, l in near}:
            j = index.get(other)
            if j is None or j <= i:
                continue
            if pybullet.getClosestPoints(body, other[0], TOUCHING, linkIndexA=link, linkIndexB=other[1],
                                         physicsClientId=client):
                pairs.add((i, j))
    return [list(p) for p in sorted(pairs)]


def take(source, tracks, frames, clients, tick: int) -> dict:
    """The pictures of the app's scene now (after tick ``tick``), as a dict the recording keeps: ``tick``,
    ``size``, ``camera``, ``faces`` (h, w) face index per pixel and ``corners`` (each face's first
    :data:`CORNERS` app-wide vertices: :func:`pixel_vertices`), ``bullet`` (h, w) frame index
    per pixel (-1 none), ``faint`` and ``stale`` (one bool per app-wide vertex: drawn fainter than
    :data:`FAINT`; held by the GPU elsewhere than its array), ``hidden`` (per actor), ``touching``,
    ``notes``; or only ``tick`` and ``skipped`` (why no picture was taken)."""
    from conformance.bullet.client import BoundClient
    from conformance.rendering import silhouettes

    viewed = getattr(source, "camera", None)
    if viewed is None:
        return {"tick": tick, "skipped": "the app's loop is its own function (--tick), with no ShowManager camera"}
    camera, app_size, why = viewed()
    if camera is None:
        return {"tick": tick, "skipped": why}
    size = picture_size(app_size)
    points = np.concatenate([t.vertices[-1] for t in tracks]) if tracks else np.zeros((0, 3))
    camera = replace(camera, clipping_range=clipping_range(camera, points))
    drawn = source.faces([t.actor for t in tracks], camera, size, [t.gpu for t in tracks])
    # Each client is a world of its own, which the app draws in one scene: pyBullet draws each from the
    # same camera, and the nearest drawing at each pixel (its depth buffer) is what the scene shows.
    bullet = np.full(size[::-1], -1, dtype=np.int32)
    nearest = np.full(size[::-1], np.inf)
    pairs = []
    for client in dict.fromkeys(clients):
        own = [i for i, f in enumerate(frames) if f.client == client]
        bound = [SimpleNamespace(body=frames[i].body, link=frames[i].link) for i in own]
        seen, depth = silhouettes.pybullet_mask(SimpleNamespace(p=BoundClient(client)), bound, camera, size, depth=True)
        depth = np.where(seen >= 0, depth, np.inf)
        front = depth < nearest
        bullet[front] = np.asarray(own + [-1], dtype=np.int32)[seen[front]]
        nearest[front] = depth[front]
        pairs += touching(client, frames)
    near, far = camera.clipping_range
    linear = np.where(np.isfinite(nearest), far * near / (far - (far - near) * np.where(np.isfinite(nearest), nearest, 0.0)),
                      np.inf)
    return {"tick": tick, "size": list(size), "camera": camera.as_dict(), "faces": drawn["faces"],
            "corners": drawn["corners"], "bullet": bullet, "faint": drawn["faint"], "stale": drawn["stale"], "hidden": drawn["hidden"],
            "touching": pairs, "notes": list(drawn.get("notes", [])),
            "bullet_depth": linear.astype(np.float32), **dict(zip(("fury_depth", "fury_back"), (
                a.astype(t) for a, t in zip(face_depth(drawn["faces"], drawn["corners"], points, camera, size),
                                            (np.float32, bool)))))}


def face_depth(faces, corners, points, camera, size) -> tuple[np.ndarray, np.ndarray]:
    """``(h, w)`` how far in front of the camera (along its direction of view) FURY's picture shows a surface
    at each pixel, inf where it shows none: where the pixel's ray meets the plane of the face seen there (its
    first three corners, ``points`` being every actor's world vertices in app-wide order); inf for a face
    that is a line, a point or seen edge-on. Beside pyBullet's depth buffer, it tells which of two things
    each renderer shows at a pixel is in front (:func:`conformance.apps.pictured.labels`). And ``(h, w)``
    whether the face seen there is seen from its back (its corners turn clockwise on the screen), which FURY 2
    draws and pyBullet's renderer does not."""
    faces = np.asarray(faces, dtype=np.int64)
    found = np.full(faces.shape, np.inf)
    back = np.zeros(faces.shape, dtype=bool)
    rows, cols = np.nonzero(faces >= 0)
    if not len(rows) or not len(points):
        return found, back
    from conformance.backends import projection

    width, height = size
    matrix = projection.projection_matrix(camera, size)
    # the pixel's ray in eye space (the eye at the origin looking down -z), scaled to z = -1
    ray = np.column_stack([((cols + 0.5) / width * 2 - 1) / matrix[0, 0], (1 - (rows + 0.5) / height * 2) / matrix[1, 1],
                           -np.ones(len(rows))])
    view = projection.view_matrix(camera)
    corner = np.asarray(corners, dtype=np.int64).reshape(-1, CORNERS)[faces[rows, cols]]
    eye = np.asarray(points, dtype=np.float64)[corner] @ view[:3, :3].T + view[:3, 3]   # (n, 3 corners, 3)
    normal = np.cross(eye[:, 1] - eye[:, 0], eye[:, 2] - eye[:, 0])
    facing = np.einsum("ij,ij->i", normal, ray)
    usable = np.abs(facing) > 1e-9 * np.linalg.norm(normal, axis=1)
    depth = np.full(len(rows), np.inf)
    depth[usable] = np.einsum("ij,ij->i", normal[usable], eye[usable, 0]) / facing[usable]
    found[rows, cols] = np.where(depth > 0, depth, np.inf)
    back[rows, cols] = usable & (np.einsum("ij,ij->i", normal, eye[:, 0]) > 0)  # its normal points away from the eye
    return found, back


def view_angle(vertical: float | None = None, *, horizontal: float | None = None, aspect: float = 1.0) -> float:
    """A vertical view angle in degrees, from itself or from a horizontal one at ``aspect`` = width / height."""
    if vertical is not None:
        return float(vertical)
    return math.degrees(2 * math.atan(math.tan(math.radians(horizontal) / 2) / aspect))


#: Corners of each face kept with a picture: a face is labelled by the first of them some frame alone holds
#: (:func:`conformance.apps.pictured.labels`).
CORNERS = 3


def face_codes(corners: list[np.ndarray], vertex_offsets: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Colours coding every face of every actor (:func:`conformance.backends.common.id_colors`), and the
    app-wide vertices of each face's first :data:`CORNERS` corners (``(faces, CORNERS)``; a point or line
    repeats its last), in code order."""
    from conformance.backends.common import id_colors

    rows = [np.asarray(c, dtype=np.int64).reshape(len(c), -1) + o for c, o in zip(corners, vertex_offsets)]
    rows = [np.concatenate([r, np.repeat(r[:, -1:], max(CORNERS - r.shape[1], 0), axis=1)], axis=1)[:, :CORNERS]
            for r in rows]
    owners = np.concatenate(rows) if rows else np.zeros((0, CORNERS), np.int64)
    return id_colors(len(owners)), owners.astype(np.int64)


def decode(picture: np.ndarray, count: int) -> np.ndarray:
    """``(h, w)`` int32 index of the face seen at each pixel of a face-coded ``picture`` of ``count`` faces:
    -1 for the background, -2 for a pixel that is no face's code colour."""
    from conformance.backends.common import decode_ids

    return decode_ids(picture, count, strict=False)


def pixel_vertices(shot: dict, usable: np.ndarray | None = None) -> np.ndarray:
    """``(h, w)`` the app-wide vertex that stands for the face seen at each pixel of ``shot`` (-1 background,
    -2 no face's code colour): the face's first corner, or the first of its corners ``usable`` marks (a
    mask over the app-wide vertices), where it has one. A picture recorded with a vertex per pixel
    (``vertices``) is read as it is."""
    if "faces" not in shot:
        return np.asarray(shot["vertices"], dtype=np.int64)
    corners = np.asarray(shot["corners"], dtype=np.int64).reshape(-1, CORNERS)
    pick = np.zeros(len(corners), dtype=np.int64)
    if usable is not None and len(corners):
        ok = np.asarray(usable, dtype=bool)[corners]
        pick = np.where(ok.any(axis=1), ok.argmax(axis=1), 0)
    table = np.concatenate([corners[np.arange(len(corners)), pick], [-2, -1]])  # faces -2 → -2, -1 → -1
    faces = np.asarray(shot["faces"], dtype=np.int64)
    return table[np.where(faces >= 0, faces, len(corners) + faces + 2)]
