"""FURY 0.12's side of an app's picture: its own scene, in its own window, each face in a code colour.

The app's ShowManager window draws the picture (the kit made it off-screen and without multisampling,
:mod:`conformance.apps.takeover_vtk`), so what the app's renderer does with its actors is what the
picture shows: an actor's visibility, every matrix and transform VTK composes, its culling. For that
one render the kit swaps, and then puts back byte for byte, what would blend the codes: each judged
actor gets cell scalars coding its faces, a flat unlit property of opacity 1 (a copy of its own, so
culling and representation stay) and no texture; the scene's other props (2D text, UI) are hidden and
the background is black. An actor's own opacity and vertex alpha are read, not drawn: faces fainter
than :data:`conformance.apps.picture.FAINT` are flagged. New cell scalars do not make VTK upload the
points again (measured: ``wrong/brick_wall_single_no_update_actor.py``, whose points change without
``Modified()``, is drawn here with its bricks where they were built, as its window draws them), so the
picture shows what the app's window holds; the ``announced`` check names that mistake.
"""

from __future__ import annotations

import numpy as np

from conformance.apps import picture

__all__ = ["SIZE", "camera", "faces"]

#: The size of the app's window under the kit (off-screen): the checks read vertices, not pixels, and
#: the app's own size (900×768, say) made its renders most of an app's run on the CPU. A picture is
#: taken at its own size and the window put back to this one.
SIZE = (64, 64)

_ARRAY = "conformance-face-codes"


def camera(showm):
    """``(Camera, app window size, "")``, or ``(None, None, why)`` for a camera the kit cannot reproduce."""
    cam = showm.scene.GetActiveCamera()
    size = tuple(getattr(showm, "_kit_app_size", None) or showm.size)
    if cam.GetParallelProjection():
        return None, None, "the app's camera is a parallel projection; pyBullet's picture is drawn in perspective"
    aspect = size[0] / size[1]
    angle = (picture.view_angle(horizontal=cam.GetViewAngle(), aspect=aspect) if cam.GetUseHorizontalViewAngle()
             else cam.GetViewAngle())
    return picture.Camera(tuple(cam.GetPosition()), tuple(cam.GetFocalPoint()), tuple(cam.GetViewUp()), angle), size, ""


def _corners(data) -> np.ndarray:
    """The first :data:`~conformance.apps.picture.CORNERS` points of every cell (a cell with fewer repeats
    its last), in VTK's cell order (verts, lines, polys, strips): what cell scalars are indexed by."""
    from vtkmodules.util import numpy_support

    corners = []
    for cells in (data.GetVerts(), data.GetLines(), data.GetPolys(), data.GetStrips()):
        if cells is None or not cells.GetNumberOfCells():
            continue
        offsets = numpy_support.vtk_to_numpy(cells.GetOffsetsArray())
        connectivity = numpy_support.vtk_to_numpy(cells.GetConnectivityArray())
        starts, sizes = offsets[:-1], np.diff(offsets)
        corners.append(np.stack([connectivity[starts + np.minimum(j, sizes - 1)] for j in range(picture.CORNERS)], axis=1))
    return np.concatenate(corners).astype(np.int64) if corners else np.zeros((0, picture.CORNERS), np.int64)


def _alpha(actor) -> np.ndarray:
    """Each vertex's opacity as VTK blends it: the property's times the vertex colour's alpha, where
    the mapper colours by four-component unsigned-char point scalars."""
    from vtkmodules.util import numpy_support

    mapper, data = actor.GetMapper(), actor.GetMapper().GetInput()
    alpha = np.full(data.GetNumberOfPoints(), actor.GetProperty().GetOpacity())
    scalars = data.GetPointData().GetScalars()
    if (mapper.GetScalarVisibility() and scalars is not None and scalars.GetNumberOfComponents() == 4
            and scalars.GetDataTypeAsString() == "unsigned char" and mapper.GetScalarMode() in (0, 1)):
        alpha = alpha * numpy_support.vtk_to_numpy(scalars)[:, 3] / 255.0
    return alpha


def faces(showm, actors, cam, size, gpu=None) -> dict:
    """Render the app's ``actors`` in its own window from ``cam`` at ``size``; see :func:`picture.take`."""
    from vtkmodules.util import numpy_support
    from vtkmodules.vtkRenderingCore import vtkProperty, vtkWindowToImageFilter

    scene, window = showm.scene, showm.window
    datas = [a.GetMapper().GetInput() for a in actors]
    counts = [d.GetNumberOfPoints() for d in datas]
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(int)
    corners = [_corners(d) for d in datas]
    colours, owners = picture.face_codes(corners, list(offsets[:-1]))
    faint = np.concatenate([_alpha(a) < picture.FAINT for a in actors]) if actors else np.zeros(0, bool)
    hidden = [not a.GetVisibility() for a in actors]
    undo = []
    try:
        judged = {id(a) for a in actors}
        props = scene.GetViewProps()
        props.InitTraversal()
        for _ in range(props.GetNumberOfItems()):
            prop = props.GetNextProp()
            if id(prop) not in judged and prop.GetVisibility():  # 2D text, UI: not bodies, and not flat
                prop.SetVisibility(0)
                undo.append(lambda prop=prop: prop.SetVisibility(1))
        start = 0
        for actor, data, face_corners in zip(actors, datas, corners):
            mapper = actor.GetMapper()
            cells = data.GetCellData()
            active = cells.GetScalars()
            codes = numpy_support.numpy_to_vtk(colours[start:start + len(face_corners)], deep=True)
            codes.SetName(_ARRAY)
            start += len(face_corners)
            cells.SetScalars(codes)
            flat = vtkProperty()
            flat.DeepCopy(actor.GetProperty())
            flat.LightingOff()
            flat.SetAmbient(1.0)
            flat.SetDiffuse(0.0)
            flat.SetSpecular(0.0)
            flat.SetOpacity(1.0)
            saved = (actor.GetProperty(), actor.GetTexture(), mapper.GetScalarVisibility(), mapper.GetColorMode(),
                     mapper.GetScalarMode())
            actor.SetProperty(flat)
            actor.SetTexture(None)
            mapper.ScalarVisibilityOn()
            mapper.SetColorModeToDirectScalars()
            mapper.SetScalarModeToUseCellData()

            def put_back(actor=actor, mapper=mapper, cells=cells, active=active, saved=saved):
                prop, texture, visibility, colour_mode, scalar_mode = saved
                cells.RemoveArray(_ARRAY)
                if active is not None:
                    cells.SetScalars(active)
                actor.SetProperty(prop)
                actor.SetTexture(texture)
                mapper.SetScalarVisibility(visibility)
                mapper.SetColorMode(colour_mode)
                mapper.SetScalarMode(scalar_mode)

            undo.append(put_back)
        vtk_camera = scene.GetActiveCamera()
        state = (vtk_camera.GetPosition(), vtk_camera.GetFocalPoint(), vtk_camera.GetViewUp(), vtk_camera.GetViewAngle(),
                 vtk_camera.GetClippingRange(), vtk_camera.GetUseHorizontalViewAngle(), scene.GetBackground(),
                 scene.GetGradientBackground())
        vtk_camera.SetPosition(*cam.position)
        vtk_camera.SetFocalPoint(*cam.focal_point)
        vtk_camera.SetViewUp(*cam.view_up)
        vtk_camera.SetUseHorizontalViewAngle(0)
        vtk_camera.SetViewAngle(cam.view_angle)
        vtk_camera.SetClippingRange(*cam.clipping_range)
        scene.SetBackground(0.0, 0.0, 0.0)
        scene.GradientBackgroundOff()

        def camera_back():
            position, focal, up, angle, clipping, horizontal, background, gradient = state
            vtk_camera.SetPosition(*position)
            vtk_camera.SetFocalPoint(*focal)
            vtk_camera.SetViewUp(*up)
            vtk_camera.SetViewAngle(angle)
            vtk_camera.SetUseHorizontalViewAngle(horizontal)
            vtk_camera.SetClippingRange(*clipping)
            scene.SetBackground(*background)
            scene.SetGradientBackground(gradient)
            window.SetSize(*SIZE)

        undo.append(camera_back)
        window.SetSize(*size)
        window.Render()
        grab = vtkWindowToImageFilter()
        grab.SetInput(window)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.ShouldRerenderOff()
        grab.Update()
        image = grab.GetOutput()
        width, height, _ = image.GetDimensions()
        pixels = numpy_support.vtk_to_numpy(image.GetPointData().GetScalars()).reshape(height, width, 3)[::-1]
    finally:
        for step in reversed(undo):
            step()
    notes = []
    if (width, height) != tuple(size):
        notes.append(f"the app's window drew {width}x{height} pixels where {size[0]}x{size[1]} were asked")
    return {"faces": picture.decode(np.ascontiguousarray(pixels), len(owners)), "corners": owners, "faint": faint,
            "stale": np.zeros(int(offsets[-1]), bool), "hidden": hidden, "notes": notes}
