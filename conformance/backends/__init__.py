"""Renderer backends: everything that knows how a FURY version builds, reads and renders actors.

The rest of the kit talks to a backend only through these functions:

* ``build(scene) -> Drawing``: actors for every binding, with each target's reference geometry;
* ``world_vertices(actor) -> (n, 3)``: what the renderer will draw, in world coordinates;
* ``world_normals(actor)``: the stored vertex normals as they will be lit, or None;
* ``mesh_signature(actor)``: vertex count, topology and colours, to check a sync keeps the mesh;
* ``content_state(actor)``: modification time and a copy of the data, to check changes are announced;
* ``content_time(actor)``: the modification time alone (cheap);
* ``render(drawing, camera, size, *, multisamples) -> (h, w, 3) uint8``: an off-screen picture;
* ``render_ids(drawing, camera, size) -> (h, w) int32``: each pixel's target index (-1 background),
  every target drawn flat in its own colour (the silhouette check against pyBullet's renderer);
* ``renderer_info() -> dict``: what draws the pictures (OpenGL vendor/renderer/version, VTK version);
* ``MULTISAMPLES``: the anti-aliasing every picture is made with unless asked otherwise.

FURY 0.12 (VTK) is the only backend today; FURY 2.x (pygfx) would be a sibling module.
"""

from __future__ import annotations

from .vtk import MULTISAMPLES, Drawing, build, content_state, content_time, mesh_signature, render, render_ids, renderer_info, world_normals, world_vertices

__all__ = ["MULTISAMPLES", "Drawing", "build", "content_state", "content_time", "mesh_signature", "render", "render_ids", "renderer_info", "world_normals", "world_vertices"]
