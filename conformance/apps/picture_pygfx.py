"""FURY 2's side of an app's picture: the app's meshes as the GPU would hold them, each face in a code colour.

Under the kit an app's FURY 2 window never draws (its ticks only request a draw), so the picture is
drawn explicitly, on the kit's own off-screen canvas (:func:`conformance.backends.pygfx._draw`), with a
twin of each judged mesh: its index buffer, its world matrix, its visibility (and its parents') and its
face culling, unlit, each face flat in a code colour. Its positions are what the GPU would hold: pygfx
uploads only the chunks announced with ``update_range``/``update_full``, and the kit keeps a copy of
exactly those, tick by tick (``_Track.gpu``), so a change written but announced for the wrong range is
drawn where the GPU still has it, as the app's own window would draw it. A buffer the app itself put on
the GPU (it drew, or flushed as the kit's scene runner does) is shared instead: the kit uploads its
announced ranges after each tick as a window would, so it holds what the window would draw. The app's
meshes are not touched.
"""

from __future__ import annotations

import numpy as np

from conformance.apps import picture

__all__ = ["camera", "faces"]


def camera(showm):
    """``(Camera, app window size, "")`` from the first screen's camera, or ``(None, None, why)``."""
    screens = getattr(showm, "screens", None) or []
    cam = getattr(screens[0], "camera", None) if screens else None
    size = tuple(getattr(showm, "_kit_app_size", None) or (800, 800))
    if cam is None or not hasattr(cam, "fov"):
        return None, None, "the app's ShowManager has no perspective camera on its first screen"
    if not cam.fov:
        return None, None, "the app's camera is orthographic (fov 0); pyBullet's picture is drawn in perspective"
    matrix = np.asarray(cam.world.matrix, dtype=np.float64)
    position, up, forward = matrix[:3, 3], matrix[:3, 1], -matrix[:3, 2]
    aspect = size[0] / size[1]
    # pygfx spreads fov over the mean of width and height, and zoom narrows it (the inverse of
    # conformance.backends.pygfx._set_camera, which draws both pictures from the vertical angle)
    half = np.arctan(np.tan(np.radians(cam.fov) / 2) * 2 / (1 + aspect) / max(float(getattr(cam, "zoom", 1.0)), 1e-9))
    unit = forward / np.linalg.norm(forward)
    return picture.Camera(tuple(position), tuple(position + unit), tuple(up / np.linalg.norm(up)),
                          float(np.degrees(2 * half))), size, ""


def _alpha(actor) -> np.ndarray:
    """Each vertex's opacity: the material's, times the vertex colour's alpha where colours are per
    vertex with four components."""
    n = len(actor.geometry.positions.data)
    alpha = np.full(n, float(getattr(actor.material, "opacity", 1.0)))
    colours = getattr(actor.geometry, "colors", None)
    mode = str(getattr(actor.material, "color_mode", "auto"))
    if colours is not None and mode.split(".")[-1] in ("vertex", "auto"):
        data = np.asarray(colours.data)
        if data.ndim == 2 and data.shape == (n, 4):
            alpha = alpha * data[:, 3]
    return alpha


#: The twin of an impostor sphere: a UV sphere this fine (its outline lies at most 0.6 % of the radius
#: inside the true one, within the silhouettes' rounding allowance for FURY's side).
SPHERE_SEGMENTS = 32


def _spheres(centres: np.ndarray, radii: np.ndarray, faces_of: np.ndarray, codes: np.ndarray):
    """One mesh of a sphere per billboard of an impostor actor: billboard ``k`` is the vertices from its
    first face's first vertex; its sphere is centred there with its radius (local units), every face in
    the code colour of the billboard's first face."""
    import pygfx
    from fury import primitive

    unit, triangles = primitive.prim_sphere(phi=SPHERE_SEGMENTS, theta=SPHERE_SEGMENTS)
    unit = np.asarray(unit, dtype=np.float64)
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    triangles = np.asarray(triangles, dtype=np.int64)
    # The billboards: faces whose first vertex starts a run of six (two triangles each).
    firsts = faces_of[:, 0].astype(np.int64)
    starts = np.flatnonzero(firsts % 6 == 0)
    points, indices, colours = [], [], []
    for n, face in enumerate(starts):
        centre, radius = centres[firsts[face]], radii[firsts[face]]
        points.append(centre + radius * unit)
        indices.append(triangles + n * len(unit))
        colours.append(np.repeat(codes[face:face + 1], len(triangles), axis=0))
    if not points:
        return pygfx.Geometry(indices=np.zeros((0, 3), np.int32), positions=np.zeros((0, 3), np.float32))
    return pygfx.Geometry(indices=np.concatenate(indices).astype(np.int32),
                          positions=np.concatenate(points).astype(np.float32),
                          colors=pygfx.Buffer(np.ascontiguousarray(np.concatenate(colours), dtype=codes.dtype)))


def faces(showm, actors, cam, size, gpu) -> dict:
    """Draw twins of the app's ``actors`` from ``cam`` at ``size``; see :func:`picture.take`."""
    import pygfx

    from conformance.backends import pygfx as backend

    counts = [len(a.geometry.positions.data) for a in actors]
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(int)
    triangles = [np.asarray(a.geometry.indices.data) for a in actors]
    triangles = [t.reshape(len(t), -1) if t.ndim == 2 else t.reshape(-1, 3) for t in triangles]
    colours, owners = picture.face_codes([t.astype(np.int64) for t in triangles], list(offsets[:-1]))
    scene = pygfx.Scene()
    scene.add(pygfx.Background.from_color((0.0, 0.0, 0.0, 1.0)))
    stale, start = [], 0
    for actor, faces_of, held in zip(actors, triangles, gpu):
        data = np.asarray(actor.geometry.positions.data)
        # On the GPU already (drawn or flushed by the app): the buffer itself is what the GPU holds.
        live = held is None or held.shape != data.shape or actor.geometry.positions._wgpu_object is not None
        stale.append(np.zeros(len(data), bool) if live else np.any(held != data, axis=-1).reshape(-1))
        positions = actor.geometry.positions if live else pygfx.Buffer(np.ascontiguousarray(held, np.float32))
        codes = backend._linear(colours[start:start + len(faces_of)])
        start += len(faces_of)
        radii = backend.impostor_radii(actor)
        if radii is not None:
            # A shader draws each billboard as a sphere: its twin is that sphere, as a fine mesh, in the code
            # colour of the billboard's first face (the owner of its first vertex).
            centres = np.asarray(positions.data if live else held, dtype=np.float64)
            geometry = _spheres(centres, radii / max(np.linalg.norm(np.asarray(actor.world.matrix)[:3, :3], axis=0).max(), 1e-12),
                                faces_of, codes)
        else:
            geometry = pygfx.Geometry(indices=actor.geometry.indices, positions=positions, colors=pygfx.Buffer(codes))
        twin = pygfx.Mesh(geometry, pygfx.MeshBasicMaterial(color_mode="face", side=actor.material.side))
        twin.local.matrix = actor.world.matrix
        twin.visible = backend._visible(actor)
        scene.add(twin)
    view = pygfx.PerspectiveCamera(50, 1)
    backend._set_camera(view, cam, size)
    pixels = backend._draw(scene, view, size, "none")
    return {"faces": picture.decode(pixels, len(owners)), "corners": owners,
            "faint": np.concatenate([_alpha(a) < picture.FAINT for a in actors]) if actors else np.zeros(0, bool),
            "stale": np.concatenate(stale) if stale else np.zeros(0, bool),
            "hidden": [not backend._visible(a) for a in actors], "notes": []}
