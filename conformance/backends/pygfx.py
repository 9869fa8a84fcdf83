"""The FURY 2.0 / pygfx backend: build actors, read back what pygfx draws, render off-screen with wgpu.

FURY 2 actors are ``pygfx.Mesh`` objects. What they draw is ``geometry.positions`` (float32) through
``actor.world.matrix``; what the GPU holds of the positions is what was announced with the buffer's
``update_range``/``update_full``/``update_indices`` (the counterpart of VTK's ``Modified()``), each
of which bumps the buffer's revision counter. Pictures come from one off-screen wgpu canvas per
process (Mesa's lavapipe on a machine without a GPU); no X server is needed.

Spheres are real meshes (``actor.sphere(..., impostor=False)``): FURY 2's default impostor is six
vertices at the centre, which no vertex check could hold to a radius. A smooth mesh without a
``normals`` buffer is lit by normals pygfx computes once, when its pipeline is built, and never
again, so a sync turning its vertices would be lit as if unturned; the kit gives its spheres (the only
smooth actors: boxes and cylinders are flat-shaded) a ``normals`` buffer of radial unit normals, which
a sync turns with the vertices (and the normals check reads), as FURY 0.12 stores them.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import weakref
from typing import Any, Iterator

import numpy as np

from conformance.backends import cffi_types
from conformance.backends.common import Drawing, decode_ids, id_codes, lay_out, moved_range, transformed, turned_normals
from conformance.errors import BackendError
from conformance.backends.renderer_start import WGPU_VARIABLES, asked_for, set_among

__all__ = ["ANNOUNCE", "LIGHTING", "MULTISAMPLES", "NAME", "Drawing", "build", "content_state", "content_time", "flush", "hand_over", "mesh_signature", "perturbed", "render", "render_ids",
           "renderer_info", "world_normals", "world_vertices"]

NAME = "pygfx"

#: What tells the renderer that vertex data changed, as failure messages name it.
ANNOUNCE = "positions.update_range()/update_full()"

#: How every picture is lit, as the golden manifests say.
LIGHTING = "FURY 2's ambient light and a directional light riding on the camera"

#: Anti-aliasing of every picture unless a caller asks otherwise: 1 is pygfx's default post-processing
#: anti-aliasing (``ppaa="default"``) at one rendered pixel per picture pixel, 0 is none.
MULTISAMPLES = 1

#: Mesh resolution, FURY's defaults (FURY 0.12's sphere is 16 × 16 too), explicit so that goldens keep it.
SPHERE_PHI = SPHERE_THETA = 16
CYLINDER_SECTORS = 16


def _fury_actor(kind: str, centers: np.ndarray, colors: np.ndarray, sizes: np.ndarray):
    """One FURY 2 actor drawing one shape per row of ``sizes`` at the origin in its canonical direction."""
    from fury import actor as fury_actor

    n = len(centers)
    if kind == "box":
        # `scales` are full edge lengths; direction +x keeps the box's axes.
        made = fury_actor.box(centers=centers, directions=np.tile([1.0, 0, 0], (n, 1)), scales=2 * sizes, colors=colors)
    elif kind == "sphere":
        made = fury_actor.sphere(centers=centers, colors=colors, radii=sizes[:, 0], impostor=False,
                                 phi=SPHERE_PHI, theta=SPHERE_THETA)
    else:
        made = fury_actor.cylinder(centers=centers, directions=np.tile([0, 0, 1.0], (n, 1)), colors=colors,
                                   radii=sizes[:, 0], height=sizes[:, 1], sectors=CYLINDER_SECTORS, capped=True)
    if kind == "sphere":
        # Radial unit normals, as FURY 0.12's sphere stores them (pygfx's own, computed from the faces,
        # are not defined at the poles, where the faces are degenerate).
        import pygfx

        positions = made.geometry.positions.data.astype(np.float64)
        made.geometry.normals = pygfx.Buffer((positions / np.linalg.norm(positions, axis=1, keepdims=True)).astype(np.float32))
    return made


def _fury_surface(vertices: np.ndarray, faces: np.ndarray, colors: np.ndarray):
    """A FURY 2 surface through ``vertices`` (a soft body's nodes), its triangles ``faces``, flat shaded."""
    from fury import actor as fury_actor

    return fury_actor.surface(vertices.astype(np.float32), faces.astype(np.int32), colors=colors.astype(np.float32))


def _points(actor) -> np.ndarray:
    return actor.geometry.positions.data


def _normals(actor) -> np.ndarray | None:
    normals = getattr(actor.geometry, "normals", None)
    return None if normals is None else normals.data


def _announce(actor) -> None:
    actor.geometry.positions.update_full()
    if getattr(actor.geometry, "normals", None) is not None:
        actor.geometry.normals.update_full()


def build(scene) -> Drawing:
    """Actors for every binding of ``scene``, drawn at the poses pybullet holds now
    (:func:`conformance.backends.common.lay_out`), as FURY 2 actors, already on the GPU.

    A tiny first draw puts them there, as a window's first frame does: until then every buffer waits
    for a full upload, and any change made meanwhile would reach the GPU announced or not."""
    drawing = lay_out(scene, _fury_actor, _points, _normals, _announce, make_surface=_fury_surface)
    _first_draw(drawing)
    return drawing


def _first_draw(drawing: Drawing) -> None:
    stage = _stage(drawing)
    _draw(stage.scene.main_scene, stage.camera, _WARM_UP_SIZE, "none", canvas=_warm_up_canvas())


def flush(drawing: Drawing) -> None:
    """Hand the renderer every change announced since the last frame, as a live window does before it
    draws: announced ranges go to the GPU and stop being pending, so that a later change that is not
    announced shows as one (:func:`content_time` does not move) rather than riding on an upload that
    an earlier frame asked for. A buffer the sync replaced has nothing on the GPU yet: a tiny draw puts
    it there, as the window's next frame would."""
    from pygfx.renderers.wgpu.engine.update import update_resource

    replaced = False
    for actor in drawing.actors.values():
        for _, buffer in _buffers(actor):
            if buffer._wgpu_object is None:
                replaced = True
            else:
                update_resource(buffer)
    if replaced:
        _first_draw(drawing)


@contextlib.contextmanager
def perturbed(target, *, transform: np.ndarray | None = None, recolour=None) -> Iterator[None]:
    """Within the block, ``target`` is drawn moved by the world ``transform`` (4x4) or with its vertex
    colours mapped by ``recolour`` ((n, 3) floats in 0..1 to the same); restored on exit. For measuring
    what the image checks see (:mod:`conformance.rendering.measure_tolerances`), not for checks."""
    t, geometry = target, target.actor.geometry
    if recolour is not None:
        colours = geometry.colors.data
        saved = colours.copy()
        colours[t.start:t.stop, :3] = recolour(colours[t.start:t.stop, :3].astype(float))
        geometry.colors.update_full()
        try:
            yield
        finally:
            colours[:] = saved
            geometry.colors.update_full()
        return
    if not t.shared:
        before = np.array(t.actor.local.matrix)
        t.actor.local.matrix = transform @ before
        try:
            yield
        finally:
            t.actor.local.matrix = before
        return
    with moved_range(t, transform, _points(t.actor), _normals(t.actor), lambda: _announce(t.actor)):
        yield


def _matrix(actor) -> np.ndarray:
    """The actor's world matrix: its own transform (position, rotation, scale or a matrix set whole)
    composed with every parent's."""
    return np.asarray(actor.world.matrix, dtype=np.float64)


def world_vertices(actor) -> np.ndarray:
    """The actor's vertices as pygfx will draw them: ``geometry.positions`` through ``actor.world.matrix``."""
    return transformed(_points(actor), _matrix(actor))


def world_normals(actor) -> np.ndarray | None:
    """The actor's ``normals`` buffer as pygfx will light it (through the inverse transpose of the world
    matrix), unit length; None when it has none (flat shading derives normals from the faces)."""
    normals = _normals(actor)
    return None if normals is None else turned_normals(normals, _matrix(actor))


def impostor_radii(actor) -> np.ndarray | None:
    """For an actor that draws spheres with a shader (FURY 2's default ``actor.sphere``, ``impostor=True``:
    a billboard of six vertices at each sphere's centre), each vertex's sphere radius in world units; None
    for an actor whose triangles are what it draws."""
    if getattr(actor, "billboard_mode", None) != "impostor":
        return None
    radii = getattr(actor, "billboard_radii", None)
    if radii is None:
        sizes = np.asarray(getattr(actor, "billboard_sizes", np.zeros((0, 2))), dtype=np.float64)
        radii = sizes.max(axis=1) / 2 if sizes.size else np.zeros(0)
    radii = np.asarray(radii, dtype=np.float64).reshape(-1)
    count = len(_points(actor))
    if not len(radii) or count % len(radii):
        return None
    scale = np.linalg.norm(_matrix(actor)[:3, :3], axis=0).max()  # the shader scales the quad with the actor
    return np.repeat(radii, count // len(radii)) * scale


def _buffers(actor) -> list[tuple[str, object]]:
    geometry = actor.geometry
    return [(name, b) for name in ("positions", "normals") if (b := getattr(geometry, name, None)) is not None]


def hand_over(actor) -> None:
    """Take the actor's announced changes as a live window's next frame does, without drawing: pygfx's
    renderer asks each buffer for its pending ranges (``_gfx_get_chunk_descriptions``, which clears them)
    and uploads them. Until that happens a buffer stays "wholly pending" and further ``update_range``
    calls do not move its revision, so a change announced every frame would look unannounced. App mode
    calls this after every tick, where the app's own window does not draw.

    Returns, per buffer name, the ``(offset, size)`` item ranges taken: what the renderer would upload,
    whole chunks of them, so app mode keeps a copy of what the GPU holds (:mod:`conformance.apps.picture`).
    A buffer already on the GPU (the app, or a kit scene's runner, drew or flushed it) gets its ranges
    uploaded as :func:`flush` does, and None: the GPU itself holds what was announced."""
    from pygfx.renderers.wgpu.engine.update import update_resource

    taken = {}
    for name, buffer in _buffers(actor):
        if buffer._wgpu_object is not None:
            update_resource(buffer)
            taken[name] = None
        else:
            taken[name] = [tuple(d[:2]) for d in buffer._gfx_get_chunk_descriptions()]
    return taken


def content_time(actor) -> int:
    """The newest revision of the actor's position and normal buffers: pygfx bumps a buffer's revision
    on every ``update_range``/``update_full``/``update_indices``, and a new buffer has a new one."""
    return max(b._rev for _, b in _buffers(actor))


def content_state(actor) -> tuple[int, bytes, tuple[int, ...]]:
    """The revision (:func:`content_time`), a copy of the position and normal data and each buffer's
    own revision, to tell a change pygfx was told about from one it was not (pygfx uploads only
    announced ranges)."""
    buffers = _buffers(actor)
    return (max(b._rev for _, b in buffers), b"".join(bytes(memoryview(np.ascontiguousarray(b.data))) for _, b in buffers),
            tuple(b._rev for _, b in buffers))


def unannounced(actor, before: tuple[int, bytes], after: tuple[int, bytes]) -> str | None:
    """What of the actor's position and normal buffers changed from ``before`` to ``after``
    (:func:`content_state`) and will not reach the GPU, as "its normals changed at vertices 120–239,
    outside every range announced on them"; ``None`` when every change will. pygfx uploads only the
    chunks that ``update_range``/``update_indices`` marked (or the whole buffer after ``update_full`` or
    when new), so a changed vertex outside them, or a buffer changed while another was announced, stays
    old on screen. Read after the sync and before the changes are handed over (:func:`flush`, :func:`hand_over`)."""
    buffers = _buffers(actor)
    old, new = before[1], after[1]
    if len(old) != len(new):  # a buffer replaced by one of another size: new buffers are wholly pending
        stale = [name for name, b in buffers if b._chunks_dirt_flag != 2]
        return f"its {' and '.join(stale)} were replaced by buffers of another size, not announced whole" if stale else None
    offset = 0
    revisions = before[2] if len(before) > 2 else (None,) * len(buffers)
    for (name, buffer), revision in zip(buffers, revisions):
        size = np.asarray(buffer.data).nbytes
        was, now = old[offset:offset + size], new[offset:offset + size]
        offset += size
        if was == now or buffer._chunks_dirt_flag == 2:
            continue
        changed = np.flatnonzero((np.frombuffer(was, np.uint8) != np.frombuffer(now, np.uint8))
                                 .reshape(max(buffer.nitems, 1), -1).any(axis=1))
        if not buffer._chunks_dirt_flag and revision is not None and buffer._rev != revision:
            # Announced, and already taken by a draw since ``before`` (an app that draws inside its own
            # tick): the ranges are gone, so what was announced can no longer be told range by range.
            continue
        if not buffer._chunks_dirt_flag or not buffer.nitems:
            return f"its {name} changed at {_vertices(changed)}, with nothing announced on them"
        missed = changed[~buffer._chunk_mask[changed // buffer._chunk_size]]
        if missed.size:
            return f"its {name} changed at {_vertices(missed)}, outside every range announced on them"
    return None


def _vertices(items: np.ndarray) -> str:
    """``vertices 3–7`` or ``vertices 3–7 and 12–20 (9 of them)``: the runs of changed items, the first two."""
    runs = np.split(items, np.flatnonzero(np.diff(items) != 1) + 1)
    spans = [f"{r[0]}" if r.size == 1 else f"{r[0]}–{r[-1]}" for r in runs[:2]]
    more = f" and {len(runs) - 2} more runs" if len(runs) > 2 else ""
    return f"vertex {spans[0]}" if items.size == 1 else f"vertices {' and '.join(spans)}{more} ({items.size} of them)"


def mesh_signature(actor) -> tuple[int, str, str]:
    """Vertex count and digests of the faces and vertex colours: what a sync must leave alone."""
    geometry = actor.geometry
    cells = hashlib.sha1(np.ascontiguousarray(geometry.indices.data).tobytes()).hexdigest()
    colors = getattr(geometry, "colors", None)
    color_digest = hashlib.sha1(np.ascontiguousarray(colors.data).tobytes()).hexdigest() if colors is not None else ""
    return len(geometry.positions.data), cells, color_digest


# -- off-screen rendering -----------------------------------------------------------------------------

_canvas = None  # one off-screen canvas and renderer per process, made on first use
_renderer = None
_start_error = None  # the paragraph, once wgpu failed to start in this process
_warm_up = None  # a second, tiny one for the first draw of every drawing (resizing costs more than it)
_WARM_UP_SIZE = (8, 8)
_stages: "weakref.WeakKeyDictionary[Drawing, Any]" = weakref.WeakKeyDictionary()


def _warm_up_canvas():
    global _warm_up
    if _warm_up is None:
        import pygfx
        from rendercanvas.offscreen import RenderCanvas

        _canvas_and_renderer(_WARM_UP_SIZE)  # the main one first: it says what is wrong if wgpu cannot start
        canvas = RenderCanvas(size=_WARM_UP_SIZE, pixel_ratio=1)
        _warm_up = (canvas, pygfx.WgpuRenderer(canvas, pixel_ratio=1, ppaa="none"))
    return _warm_up


def _canvas_and_renderer(size: tuple[int, int]):
    global _canvas, _renderer, _start_error
    if _start_error is not None:  # asked once per process: wgpu takes a second or more to fail again
        raise BackendError(_start_error)
    if _canvas is None:
        os.environ.setdefault("XDG_RUNTIME_DIR", "/tmp")  # wgpu's Vulkan loader only warns without it
        cffi_types.install()
        import pygfx
        from rendercanvas.offscreen import RenderCanvas

        try:
            _canvas = RenderCanvas(size=tuple(size), pixel_ratio=1)
            _renderer = pygfx.WgpuRenderer(_canvas, pixel_ratio=1)
        except Exception as exc:  # wgpu raises its own types for a missing adapter or driver
            _canvas, _start_error = None, _cannot_start(exc)
            raise BackendError(_start_error) from exc
    if tuple(_canvas.get_logical_size()) != tuple(float(v) for v in size):
        _canvas.set_logical_size(*size)
    return _canvas, _renderer


def _cannot_start(exc: Exception) -> str:
    """One paragraph: wgpu's complaint on one line, the adapter and driver variables set, what to try."""
    chosen = set_among(WGPU_VARIABLES)
    unset = f"unset {' and '.join(chosen)} to let wgpu choose its own library, backend and adapter; otherwise, " if chosen else ""
    return (f"FURY 2 renders through wgpu, which could not start with {asked_for(WGPU_VARIABLES)} "
            f"({type(exc).__name__}: {' '.join(str(exc).split())}). To fix it, {unset}without a GPU wgpu needs "
            "Mesa's Vulkan driver: `apt-get install mesa-vulkan-drivers` (Debian/Ubuntu), or run "
            "`./kit setup --backend pygfx`, which installs it.")


class _Stage:
    """A drawing's FURY scene, kept while the drawing lives, the way an application keeps one scene:
    its camera, with FURY's headlight (a directional light riding on the camera, plus FURY's ambient
    light), and a second scene of flat-coloured twins of the actors for :func:`render_ids`."""

    def __init__(self, drawing: Drawing):
        import pygfx
        from fury import window

        self.scene = window.Scene(background=(1.0, 1.0, 1.0, 1.0))
        for actor in drawing.actors.values():
            self.scene.add(actor)
        self.camera = pygfx.PerspectiveCamera(50, 1)
        self.camera.add(pygfx.DirectionalLight())
        self.scene.add(self.camera)
        self.id_scene = None
        self.twins: list = []

    def ids(self, drawing: Drawing):
        """The ID scene: for each actor a mesh sharing its index and position buffers (so it draws what
        the GPU holds of the actor), unlit, coloured per vertex by target."""
        if self.id_scene is None:
            import pygfx

            self.id_scene = pygfx.Scene()
            self.id_scene.add(pygfx.Background.from_color((0.0, 0.0, 0.0, 1.0)))
            for actor, codes in id_codes(drawing, lambda a: len(a.geometry.positions.data)):
                geometry = pygfx.Geometry(indices=actor.geometry.indices, positions=actor.geometry.positions,
                                          colors=pygfx.Buffer(_linear(codes)))
                twin = pygfx.Mesh(geometry, pygfx.MeshBasicMaterial(color_mode="vertex", side=actor.material.side))
                self.id_scene.add(twin)
                self.twins.append((actor, twin))
        for actor, twin in self.twins:
            # Whatever the sync did since: a replaced buffer, a new transform, a hidden actor.
            for name in ("indices", "positions"):
                if getattr(twin.geometry, name) is not getattr(actor.geometry, name):
                    setattr(twin.geometry, name, getattr(actor.geometry, name))
            twin.local.matrix = actor.world.matrix
            twin.visible = _visible(actor)
            twin.material.side = actor.material.side
        return self.id_scene


def _linear(codes: np.ndarray) -> np.ndarray:
    """uint8 sRGB codes as the float32 linear colours that pygfx writes back as exactly those codes
    (it takes vertex colours as linear and encodes the picture as sRGB: 18 came out as 75)."""
    c = codes.astype(np.float64) / 255
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def _visible(actor) -> bool:
    while actor is not None:
        if not actor.visible:
            return False
        actor = actor.parent
    return True


def _stage(drawing: Drawing) -> _Stage:
    stage = _stages.get(drawing)
    if stage is None:
        stage = _stages[drawing] = _Stage(drawing)
    return stage


def _set_camera(camera, spec, size: tuple[int, int]) -> None:
    """Give the pygfx ``camera`` the scene camera ``spec`` exactly: its world matrix is the inverse of
    :func:`conformance.backends.projection.view_matrix`, and its frustum the vertical view angle
    ``spec.view_angle`` at aspect width/height. pygfx spreads ``fov`` over the mean of width and
    height (``height = 2·size/(1 + aspect)``), hence the conversion."""
    from conformance.backends import projection

    width, height = size
    aspect = width / height
    half = np.radians(spec.view_angle) / 2
    camera.fov = float(np.degrees(2 * np.arctan(np.tan(half) * (1 + aspect) / 2)))
    camera.aspect = aspect
    camera.depth_range = tuple(float(v) for v in spec.clipping_range)
    camera.local.matrix = np.linalg.inv(projection.view_matrix(spec))


def _draw(scene, camera, size: tuple[int, int], ppaa: str, canvas=None) -> np.ndarray:
    canvas, renderer = canvas or _canvas_and_renderer(size)
    if renderer.ppaa != ppaa:
        renderer.ppaa = ppaa
    canvas.request_draw(lambda: renderer.render(scene, camera))
    picture = np.asarray(canvas.draw())
    return np.ascontiguousarray(picture[..., :3])


def render(drawing: Drawing, camera, size: tuple[int, int], *, background=(1.0, 1.0, 1.0),
           multisamples: int = MULTISAMPLES) -> np.ndarray:
    """An off-screen picture of the drawing, ``(height, width, 3)`` uint8, top row first.

    The camera is applied whole (:func:`_set_camera`); the light is FURY's own (its ambient light and a
    directional light on the camera); ``multisamples`` 0 turns anti-aliasing off. The drawing keeps
    one scene from picture to picture, so that data changed without ``update_range``/``update_full``
    stays stale here as it does in a live window."""
    stage = _stage(drawing)
    colour = tuple(float(v) for v in background) + (1.0,)
    if tuple(stage.scene.background) != colour:
        stage.scene.background = colour  # FURY replaces its Background object: only when it changes
    _set_camera(stage.camera, camera, size)
    return _draw(stage.scene.main_scene, stage.camera, size, "default" if multisamples else "none")  # what FURY renders


def render_ids(drawing: Drawing, camera, size: tuple[int, int]) -> np.ndarray:
    """``(height, width)`` int32: the index into ``drawing.targets`` of the target seen at each pixel,
    -1 for the background; top row first, like :func:`render`.

    Each actor is drawn by a twin that shares its index and position buffers (what the GPU holds of
    them, announced or not), its world matrix, visibility and face culling, coloured flat per target
    range, unlit, without anti-aliasing, through the same camera code as :func:`render`. The actors
    themselves are not touched."""
    stage = _stage(drawing)
    scene = stage.ids(drawing)
    _set_camera(stage.camera, camera, size)
    return decode_ids(_draw(scene, stage.camera, size, "none"), len(drawing.targets))


def renderer_info() -> dict[str, str]:
    """What draws the pictures: the wgpu adapter (vendor, device, driver, backend) and the FURY,
    pygfx and wgpu versions (a golden made by another renderer is judged with looser tolerances)."""
    import importlib.metadata as md

    _, renderer = _canvas_and_renderer((64, 64))
    info = {"backend": NAME}
    for dist in ("fury", "pygfx", "wgpu"):
        info[dist] = md.version(dist)
    adapter = renderer.device.adapter.info
    for key in ("vendor", "device", "description", "adapter_type", "backend_type"):
        info[f"adapter_{key}"] = str(adapter.get(key, ""))
    return info
