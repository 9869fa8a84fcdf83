"""The FURY 0.12 / VTK 9.3 backend: build actors, read back what VTK draws, render off-screen.

This is the only module that touches VTK objects on the kit's side (sync implementations under
test, being FURY code, touch them too).
"""

from __future__ import annotations

import contextlib
import hashlib
import weakref
from typing import Any, Iterator

import numpy as np
from vtkmodules.util import numpy_support

from conformance.backends.common import Drawing, decode_ids, id_codes, lay_out, moved_range, transformed, turned_normals
from conformance.backends.display import close_x_connection, ensure_display, on_stop, x_connection
from conformance.errors import DisplayUnavailable, SceneError
from conformance.backends.renderer_start import check_gl

__all__ = ["ANNOUNCE", "LIGHTING", "MULTISAMPLES", "NAME", "Drawing", "build", "content_state", "content_time", "flush", "hand_over", "mesh_signature", "perturbed", "render", "render_ids", "renderer_info", "world_normals", "world_vertices"]


def _fury_actor(kind: str, centers: np.ndarray, colors: np.ndarray, sizes: np.ndarray):
    """One FURY 0.12 actor drawing one shape per row of ``sizes`` at the origin in its canonical direction."""
    from fury import actor as fury_actor

    n = len(centers)
    if kind == "box":
        # FURY's unit box spans ±0.5 and keeps its axes for direction +x.
        return fury_actor.box(centers=centers, directions=np.tile([1.0, 0, 0], (n, 1)), scales=2 * sizes, colors=colors)
    if kind == "sphere":
        return fury_actor.sphere(centers=centers, colors=colors, radii=sizes[:, 0])
    # FURY scales its unit-height cylinder primitive *uniformly* by `heights`, so the drawn radius
    # is radius × height: pass radius / height to draw the collision cylinder's own radius.
    ratios = sizes[:, 0] / sizes[:, 1]
    if not np.allclose(ratios, ratios[0], rtol=0, atol=1e-12):
        raise SceneError("cylinders that share one FURY actor must have the same radius/height ratio")
    return fury_actor.cylinder(centers=centers, directions=np.tile([0, 0, 1.0], (n, 1)), colors=colors,
                               radius=float(ratios[0]), heights=sizes[:, 1], capped=True, resolution=16)


def _fury_surface(vertices: np.ndarray, faces: np.ndarray, colors: np.ndarray):
    """A FURY 0.12 surface through ``vertices`` (a soft body's nodes), its triangles ``faces``."""
    from fury import actor as fury_actor

    return fury_actor.surface(vertices, faces=faces, colors=colors)


#: Per actor, the Python wrappers of what the checks walk to every frame (mapper, polydata, points, point data,
#: normals, matrix), kept alive and never read: VTK makes a new wrapper for a C++ object that no Python
#: reference holds, 2 µs a call, and the walk from an actor to its points cost a brick wall's frame 0.6 ms
#: (measured: ``world_vertices`` 19.6 µs an actor, 10.5 µs with the wrappers held). The walk is still made
#: every time, so an actor whose arrays a sync swapped is read as it is now.
_WRAPPERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _input(actor):
    """The actor's mapper input (its polydata), the wrappers on the way to its arrays kept alive."""
    mapper = actor.GetMapper()
    data = mapper.GetInput()
    points = data.GetPoints()
    kept = _WRAPPERS.get(actor)
    if kept is None or kept[1] is not data or kept[2] is not points:
        point_data = data.GetPointData()
        _WRAPPERS[actor] = (mapper, data, points, points.GetData() if points is not None else None, point_data,
                            point_data.GetNormals(), actor.GetMatrix())
    return data


def _points(actor) -> np.ndarray:
    """The actor's vertex array as a writable numpy view (VTK arrays export the buffer protocol,
    ten times cheaper than ``numpy_support.vtk_to_numpy``, which matters once per actor per frame)."""
    return np.asarray(_input(actor).GetPoints().GetData())


def _normals(actor) -> np.ndarray | None:
    """The actor's stored vertex normals as a writable numpy view, or None."""
    normals = _input(actor).GetPointData().GetNormals()
    return None if normals is None else np.asarray(normals)


def _announce(actor) -> None:
    data = actor.GetMapper().GetInput()
    data.GetPoints().Modified()
    if data.GetPointData().GetNormals() is not None:
        data.GetPointData().GetNormals().Modified()
    data.Modified()


def build(scene) -> Drawing:
    """Actors for every binding of ``scene``, drawn at the poses pybullet holds now
    (:func:`conformance.backends.common.lay_out`), as FURY 0.12 actors."""
    return lay_out(scene, _fury_actor, _points, _normals, _announce, make_surface=_fury_surface)


def flush(drawing: Drawing) -> None:
    """Nothing to hand over between frames: VTK compares modification times when it draws."""


@contextlib.contextmanager
def perturbed(target, *, transform: np.ndarray | None = None, recolour=None) -> Iterator[None]:
    """Within the block, ``target`` is drawn moved by the world ``transform`` (4x4) or with its vertex
    colours mapped by ``recolour`` ((n, 3) floats in 0..1 to the same); restored on exit. For measuring
    what the image checks see (:mod:`conformance.rendering.measure_tolerances`), not for checks."""
    from vtkmodules.vtkCommonMath import vtkMatrix4x4

    t = target
    data = t.actor.GetMapper().GetInput()
    if recolour is not None:
        # FURY's spheres colour by the "colors" point array (their active scalars are something
        # else); boxes and cylinders have it as the active scalars.
        scalars = data.GetPointData().GetArray("colors") or data.GetPointData().GetScalars()
        colours = numpy_support.vtk_to_numpy(scalars)
        saved = colours.copy()
        shifted = recolour(colours[t.start:t.stop, :3].astype(float) / 255)
        colours[t.start:t.stop, :3] = np.round(shifted * 255).astype(colours.dtype)
        scalars.Modified()
        data.Modified()
        try:
            yield
        finally:
            colours[:] = saved
            scalars.Modified()
            data.Modified()
        return
    if not t.shared:
        before = t.actor.GetUserMatrix()
        user = np.eye(4) if before is None else np.array([[before.GetElement(r, c) for c in range(4)] for r in range(4)])
        matrix = vtkMatrix4x4()
        matrix.DeepCopy((transform @ user).ravel().tolist())  # the world transform after the user matrix
        t.actor.SetUserMatrix(matrix)
        try:
            yield
        finally:
            t.actor.SetUserMatrix(before)
        return
    with moved_range(t, transform, _points(t.actor), _normals(t.actor), lambda: _announce(t.actor)):
        yield


def world_vertices(actor) -> np.ndarray:
    """The actor's vertices as VTK will draw them: polydata points through ``actor.GetMatrix()``,
    which composes position, orientation, origin, scale, user matrix and user transform."""
    return transformed(_points(actor), _matrix(actor))


def _matrix(actor) -> np.ndarray:
    """The actor's full 4x4 matrix (position, orientation, origin, scale, user matrix and transform)."""
    elements = [0.0] * 16
    matrix = actor.GetMatrix()
    matrix.DeepCopy(elements, matrix)  # the static overload: fill `elements` from `matrix`
    return np.array(elements).reshape(4, 4)


def world_normals(actor) -> np.ndarray | None:
    """The actor's stored vertex normals as VTK will light them (through the inverse transpose of
    the actor's matrix), unit length; None when the actor stores none."""
    normals = _normals(actor)
    if normals is None:
        return None
    return turned_normals(normals, _matrix(actor))


def impostor_radii(actor) -> None:
    """FURY 0.12's actors draw their triangles: no impostor spheres (see the pygfx backend)."""
    return None


def content_time(actor) -> int:
    """The modification time of the actor's data alone (the first half of :func:`content_state`)."""
    return _input(actor).GetMTime()


def hand_over(actor) -> None:
    """Nothing to take: VTK's modification times only grow, so every announcement shows (see pygfx's);
    and VTK uploads the whole geometry whenever its time moved, so there is no GPU copy to keep (None)."""
    return None


def content_state(actor) -> tuple[int, bytes]:
    """The modification time VTK's mapper compares to decide whether to re-upload the geometry, and
    a copy of the point and normal data, to tell a change VTK was told about from one it was not.
    (A copy, not a digest: copying and comparing a few kilobytes is cheaper than hashing them.)"""
    data = _input(actor)
    points = data.GetPoints().GetData()
    normals = data.GetPointData().GetNormals()
    content = bytes(memoryview(points)) if normals is None else bytes(memoryview(points)) + bytes(memoryview(normals))
    return data.GetMTime(), content


def unannounced(actor, before: tuple[int, bytes], after: tuple[int, bytes]) -> str | None:
    """What changed from ``before`` to ``after`` (:func:`content_state`) without reaching the GPU, or
    ``None``: VTK's mapper re-uploads all of the geometry (points and normals) when the data's
    modification time moved, whichever array's ``Modified()`` moved it, so a change is unannounced only
    when nothing moved it."""
    if after[0] > before[0]:
        return None
    points = actor.GetMapper().GetInput().GetPoints().GetData()
    size = points.GetNumberOfTuples() * points.GetNumberOfComponents() * points.GetDataTypeSize()
    which = [name for name, (a, b) in (("points", (before[1][:size], after[1][:size])),
                                      ("normals", (before[1][size:], after[1][size:]))) if a != b]
    return f"its {' and '.join(which)} changed, and no Modified() followed"


def mesh_signature(actor) -> tuple[int, str, str]:
    """Vertex count and digests of the cells and vertex colours: what a sync must leave alone."""
    data = actor.GetMapper().GetInput()
    cells = hashlib.sha1()
    for getter in (data.GetPolys, data.GetStrips, data.GetLines, data.GetVerts):
        array = getter().GetData() if getter() is not None else None
        if array is not None:
            cells.update(numpy_support.vtk_to_numpy(array).tobytes())
    colors = data.GetPointData().GetScalars()
    color_digest = hashlib.sha1(numpy_support.vtk_to_numpy(colors).tobytes()).hexdigest() if colors is not None else ""
    return data.GetNumberOfPoints(), cells.hexdigest(), color_digest


NAME = "vtk"

#: What tells the renderer that vertex data changed, as failure messages name it.
ANNOUNCE = "Modified()/utils.update_actor"

#: How every picture is lit, as the golden manifests say.
LIGHTING = "VTK's default headlight (follows the camera)"

#: Anti-aliasing samples of every picture unless a caller asks otherwise.
MULTISAMPLES = 8

_stages: "weakref.WeakKeyDictionary[Drawing, Any]" = weakref.WeakKeyDictionary()  # see _stage
_window = None  # one off-screen render window per process, created on first use
_connection = None  # the X connection it renders through (VTK does not close one it did not open)


def _render_window():
    """The process's off-screen render window, made once and reused for every picture. VTK 9.3 calls
    ``abort()`` when its own ``XOpenDisplay`` fails, so the window is handed a connection that
    :func:`conformance.backends.display.x_connection` opened with retries; and when it cannot make an OpenGL
    context, so a child process tries first (:func:`conformance.backends.renderer_start.check_gl`), and a
    driver that cannot start is a :class:`~conformance.errors.DisplayUnavailable`, not an abort."""
    global _window, _connection
    if _window is None:
        from fury import window

        connection = x_connection()
        try:
            check_gl()
        except DisplayUnavailable:
            close_x_connection(connection)
            raise
        _connection = connection
        _window = window.RenderWindow()
        _window.SetDisplayId(f"_{_connection:016x}_p_void")  # VTK's spelling of a void* argument
        _window.SetOffScreenRendering(1)
        _window.SetMultiSamples(MULTISAMPLES)
        on_stop(_release_window)
    return _window


def _release_window() -> None:
    global _window, _connection
    if _window is not None:
        for stage in list(_stages.values()):
            if _window.HasRenderer(stage):
                _window.RemoveRenderer(stage)
        _stages.clear()
        _window.Finalize()
        _window = None
    if _connection is not None:
        close_x_connection(_connection)
        _connection = None


def _stage(drawing: Drawing):
    """The drawing's own FURY scene, made on its first picture and kept in the process's render
    window while the drawing lives, the way an application keeps one scene in its window.

    Keeping it is what makes a picture show what a live window shows: VTK releases an actor's
    uploaded geometry when the actor leaves a renderer, so a fresh scene per picture would upload
    the vertex array anew every time, and a sync that changed vertices without ``Modified()`` would
    look right here while a live window goes on drawing the old ones."""
    stage = _stages.get(drawing)
    if stage is None:
        from fury import window

        stage = window.Scene()
        for actor in drawing.actors.values():
            stage.add(actor)
        _stages[drawing] = stage
        weakref.finalize(drawing, _drop_stage, stage)
    return stage


def _drop_stage(stage) -> None:
    if _window is not None and _window.HasRenderer(stage):
        _window.RemoveRenderer(stage)
    stage.clear()


def render(drawing: Drawing, camera, size: tuple[int, int], *, background=(1.0, 1.0, 1.0),
           multisamples: int = MULTISAMPLES) -> np.ndarray:
    """An off-screen picture of the drawing, ``(height, width, 3)`` uint8, top row first.

    The camera is applied whole (position, focal point, view up, vertical view angle and the clipping
    range, which is set after FURY's ``set_camera`` resets it to the scene's bounds). The light is
    VTK's default headlight, which follows the camera; ``multisamples`` is the anti-aliasing. The
    drawing keeps one scene in the render window from picture to picture (:func:`_stage`).
    """
    ensure_display()
    from fury import window

    stage = _stage(drawing)
    stage.background(background)
    _set_camera(stage, camera)
    render_window = _render_window()
    render_window.SetMultiSamples(multisamples)
    if not render_window.HasRenderer(stage):
        render_window.AddRenderer(stage)
    renderers = render_window.GetRenderers()
    renderers.InitTraversal()
    for _ in range(renderers.GetNumberOfItems()):
        other = renderers.GetNextItem()
        other.SetDraw(other is stage)  # other drawings' scenes stay, undrawn
    render_window.SetSize(*size)
    render_window.Render()
    return window.snapshot(stage, size=tuple(size), render_window=render_window)


def _set_camera(stage, camera) -> None:
    """Apply ``camera`` whole to ``stage``: the one camera code path of :func:`render` and
    :func:`render_ids`. The clipping range is set after FURY's ``set_camera``, which resets it to the
    scene's bounds; the view angle is vertical (VTK's default)."""
    stage.set_camera(position=camera.position, focal_point=camera.focal_point, view_up=camera.view_up)
    vtk_camera = stage.GetActiveCamera()
    vtk_camera.SetViewAngle(camera.view_angle)
    vtk_camera.SetClippingRange(*camera.clipping_range)


def renderer_info() -> dict[str, str]:
    """What draws the pictures: the OpenGL vendor, renderer and version strings as VTK reports them,
    and the VTK version (a golden made by another renderer is judged with looser tolerances)."""
    from vtkmodules.vtkCommonCore import vtkVersion

    ensure_display()
    window = _render_window()
    if "OpenGL renderer string" not in window.ReportCapabilities():
        window.Render()  # the context, and so the strings, exist only once something was drawn
    info = {"backend": "vtk", "vtk": vtkVersion.GetVTKVersion()}
    for line in window.ReportCapabilities().splitlines():
        key, _, value = line.partition(":")
        for name in ("vendor", "renderer", "version"):
            if key.strip() == f"OpenGL {name} string":
                info[f"gl_{name}"] = value.strip()
    return info


# -- the flat ID render (the silhouette check) ------------------------------------------------------

def render_ids(drawing: Drawing, camera, size: tuple[int, int]) -> np.ndarray:
    """``(height, width)`` int32: the index into ``drawing.targets`` of the target seen at each pixel,
    -1 for the background; top row first, like :func:`render`.

    Each target is drawn in its own flat colour (point scalars; targets sharing an actor get their own
    vertex range ``start:stop`` coloured), unlit (lighting off, ambient 1, diffuse 0, specular 0,
    opacity 1), without anti-aliasing, through :func:`render` itself, so the camera is applied by the
    same code. Only the colour is replaced: vertices, user matrix, position, orientation, scale,
    visibility and everything else a sync left on an actor is drawn as it is. Afterwards each actor
    has its own property object, mapper colour settings and colour bytes back, byte for byte.

    Writing the colours and writing them back bumps the modification time of the point data, so VTK
    re-uploads each actor's geometry for this picture and for the next one: a sync that changed vertices
    without ``Modified()`` would be drawn right here and in any picture after it. That is acceptable
    because the golden check renders first in each frame and catches such a sync; the vertex checks'
    ``content_state`` compares times around the sync call only, which this does not straddle.
    """
    from vtkmodules.vtkRenderingCore import vtkProperty

    restore = []
    render_window = _render_window()
    multisamples = render_window.GetMultiSamples()
    try:
        for actor, codes in id_codes(drawing, lambda a: a.GetMapper().GetInput().GetNumberOfPoints()):
            mapper, data = actor.GetMapper(), actor.GetMapper().GetInput()
            scalars = data.GetPointData().GetScalars()
            saved = (actor, actor.GetProperty(), mapper.GetScalarVisibility(), mapper.GetColorMode(),
                     mapper.GetScalarMode(), scalars)
            if scalars is not None and scalars.GetDataTypeAsString() == "unsigned char" \
                    and scalars.GetNumberOfComponents() in (3, 4):
                # Written in place, so the array object, its name and its place in the point data stay.
                view = numpy_support.vtk_to_numpy(scalars).reshape(len(codes), -1)
                restore.append(saved + (view.copy(),))
                view[:, :3] = codes
                if view.shape[1] == 4:
                    view[:, 3] = 255
                scalars.Modified()
            else:
                restore.append(saved + (None,))
                data.GetPointData().SetScalars(numpy_support.numpy_to_vtk(codes, deep=True))
            flat = vtkProperty()
            flat.DeepCopy(actor.GetProperty())  # culling, representation, … as the actor has them
            flat.LightingOff()
            flat.SetAmbient(1.0)
            flat.SetDiffuse(0.0)
            flat.SetSpecular(0.0)
            flat.SetOpacity(1.0)
            actor.SetProperty(flat)
            mapper.ScalarVisibilityOn()
            mapper.SetColorModeToDirectScalars()
            mapper.SetScalarModeToUsePointData()
        picture = render(drawing, camera, size, background=(0.0, 0.0, 0.0), multisamples=0)
    finally:
        render_window.SetMultiSamples(multisamples)
        for actor, prop, visibility, color_mode, scalar_mode, scalars, bytes_ in reversed(restore):
            mapper, data = actor.GetMapper(), actor.GetMapper().GetInput()
            if bytes_ is not None:
                numpy_support.vtk_to_numpy(scalars).reshape(len(bytes_), -1)[:] = bytes_
                scalars.Modified()
            else:
                data.GetPointData().SetScalars(scalars)
            actor.SetProperty(prop)
            mapper.SetScalarVisibility(visibility)
            mapper.SetColorMode(color_mode)
            mapper.SetScalarMode(scalar_mode)
    return decode_ids(picture, len(drawing.targets))
