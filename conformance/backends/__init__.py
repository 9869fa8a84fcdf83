"""Renderer backends: everything that knows how a FURY version builds, reads and renders actors.

The backend in force follows the installed FURY: 0.12 is :mod:`~conformance.backends.vtk`, 2.x is
:mod:`~conformance.backends.pygfx` (the two are the same package, ``fury``, so one environment holds
one of them). The rest of the kit talks to a backend only through these names:

* ``NAME``: ``"vtk"`` or ``"pygfx"``, named in the pytest header and every report; it picks the goldens;
* ``build(scene) -> Drawing``: actors for every binding, with each target's reference geometry;
* ``world_vertices(actor) -> (n, 3)``: what the renderer will draw, in world coordinates;
* ``world_normals(actor)``: the stored vertex normals as they will be lit, or None;
* ``impostor_radii(actor)``: each vertex's sphere radius for an actor a shader draws as spheres, or None;
* ``mesh_signature(actor)``: vertex count, topology and colours, to check a sync keeps the mesh;
* ``hand_over(actor)``: take its announced changes as a window's next frame would (app mode, after every tick);
* ``content_state(actor)``: a change counter and a copy of the data, to check changes are announced
  (VTK's ``Modified()``, pygfx's ``update_range``/``update_full``);
* ``content_time(actor)``: the change counter alone (cheap);
* ``flush(drawing)``: hand announced changes to the renderer, as a live window does between frames;
* ``render(drawing, camera, size, *, multisamples) -> (h, w, 3) uint8``: an off-screen picture;
* ``render_ids(drawing, camera, size) -> (h, w) int32``: each pixel's target index (-1 background),
  every target drawn flat in its own colour (the silhouette check against pyBullet's renderer);
* ``perturbed(target, *, transform=, recolour=)``: a context moving or recolouring one target, to
  measure what the image checks see (not used by checks);
* ``renderer_info() -> dict``: what draws the pictures (backend, versions, GPU adapter);
* ``ANNOUNCE``: what tells the renderer that vertex data changed, for failure messages;
* ``LIGHTING``: how every picture is lit, in words, for the golden manifests;
* ``MULTISAMPLES``: the anti-aliasing every picture is made with unless asked otherwise.

Beside the two backends live what every picture needs whatever draws it: ``projection`` (the camera as
matrices), ``display`` (the virtual X display VTK needs, started once and never leaked) and
``renderer_start`` (whether VTK's OpenGL driver can start, asked of a child process first).
"""

from __future__ import annotations

import functools
import importlib
import importlib.metadata

from conformance.errors import BackendError

__all__ = ["ANNOUNCE", "LIGHTING", "MULTISAMPLES", "NAME", "NAMES", "Drawing", "build", "content_state", "content_time", "describe", "flush", "fury_version", "hand_over", "impostor_radii", "mesh_signature", "perturbed",
           "render", "render_ids", "renderer_info", "renderer_label", "unannounced", "world_normals", "world_vertices"]

#: Backend names and the FURY each one is: the ``./kit --backend`` values and ``golden/<name>/``.
NAMES = {"vtk": "FURY 0.12 (VTK)", "pygfx": "FURY 2 (pygfx/wgpu)"}


@functools.lru_cache(maxsize=None)
def fury_version() -> str:
    """The installed FURY's version, read from its metadata without importing it."""
    try:
        return importlib.metadata.version("fury")
    except importlib.metadata.PackageNotFoundError:
        raise BackendError(
            "FURY is not installed, so there is nothing to check the sync against. Install the kit with "
            "the FURY it checks: `pip install 'fury-pybullet-conformance[fury012]'` for FURY 0.12 (VTK), or "
            "`[fury2]` for FURY 2 (pygfx); or run `./kit run --backend vtk|pygfx`, which sets up either.") from None


def _backend_name() -> str:
    version = fury_version()
    major = version.split(".")[0]
    if major == "0":
        return "vtk"
    if major == "2":
        return "pygfx"
    raise BackendError(f"FURY {version} is installed, but the kit has backends for FURY 0.12 (VTK) and FURY 2.x "
                       f"(pygfx) only. Install one of them: `pip install 'fury-pybullet-conformance[fury2]'`.")


def describe() -> str:
    """The backend in force and what it is made of, e.g. ``backend pygfx (FURY 2.0.0: pygfx 0.17.0, wgpu 0.32.0)``,
    for the pytest header and every report (read from package metadata: nothing is imported)."""
    name = _backend_name()
    parts = ("vtk",) if name == "vtk" else ("pygfx", "wgpu")
    libraries = []
    for dist in parts:
        try:
            libraries.append(f"{dist} {importlib.metadata.version(dist)}")
        except importlib.metadata.PackageNotFoundError:
            libraries.append(f"{dist} missing")
    return f"backend {name} (FURY {fury_version()}: {', '.join(libraries)})"


def renderer_label(info: dict) -> str:
    """One line naming the GPU of a :func:`renderer_info` dict, whichever backend made it."""
    if "gl_renderer" in info:
        return " / ".join(info.get(k, "?") for k in ("gl_vendor", "gl_renderer", "gl_version"))
    return " / ".join(info.get(k, "?") for k in ("adapter_device", "adapter_description", "adapter_backend_type"))


_module = None


def _backend():
    global _module
    if _module is None:
        _module = importlib.import_module(f"conformance.backends.{_backend_name()}")
    return _module


def __getattr__(name: str):
    # Resolved on first use, so that loading the pytest plugin (and `--help`) never imports a renderer.
    if name == "NAME":
        return _backend_name()
    if name in __all__:
        return getattr(_backend(), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
