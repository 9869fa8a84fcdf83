"""Where pyBullet says a body is, drawn over the sync's picture: the outline of pyBullet's own silhouette.

On a failing frame the kit's pictures (``render --gif``, and the report's card of a failing vertex
check) show the sync's drawing with the edge of each failing target as pyBullet's tiny renderer sees
it from the same camera (:func:`conformance.rendering.silhouettes.pybullet_mask`, the same mask the
silhouette check compares against), in :data:`OUTLINE_COLOUR`. A body drawn in the right place sits
inside its outline; one drawn a step late, at its centre of mass or turned the wrong way sits beside
or across it, so the gap shows without reading numbers.

Guarantees: the outline is only pixels of the failing targets' regions that touch another region (a
4-neighbour outside the target), widened by :data:`WIDTH` - 1 pixels inwards, so it never covers
anything outside where pyBullet draws the target; the picture is otherwise unchanged.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
from scipy import ndimage

from conformance.rendering.silhouettes import pybullet_mask

__all__ = ["OUTLINE_COLOUR", "WIDTH", "draw", "edges", "expected_outline", "outlined"]

#: Magenta: no scene colour, kept exactly by a GIF's palette, and distinct from the failure border's red.
OUTLINE_COLOUR = (255, 0, 255)
#: Pixels of outline, counted inwards from a region's edge.
WIDTH = 2


def edges(ids: np.ndarray, which: Iterable[int], width: int = WIDTH) -> np.ndarray:
    """``(height, width)`` bool: the pixels of the regions of ``ids`` labelled one of ``which`` that lie
    within ``width`` pixels (4-connected steps) of another label."""
    out = np.zeros(ids.shape, dtype=bool)
    for i in set(which):
        region = ids == i
        if region.any():
            # Padding with "outside" makes a region cut by the picture's border outlined there too.
            inner = ndimage.binary_erosion(np.pad(region, 1), iterations=width)[1:-1, 1:-1]
            out |= region & ~inner
    return out


def expected_outline(run, names: Iterable[str], size: tuple[int, int] | None = None) -> np.ndarray:
    """The outline (:func:`edges`) of the targets ``names`` of ``run`` (a :class:`conformance.sync.runner.Run`)
    where pyBullet has them now, seen from the scene's camera at ``size`` (default: the scene's)."""
    scene = run.scene
    size = tuple(size) if size else tuple(scene.image_size)
    ids = pybullet_mask(scene, scene.bindings, scene.camera, size)
    wanted = set(names)
    return edges(ids, [i for i, b in enumerate(scene.bindings) if b.name in wanted])


def draw(picture: np.ndarray, outline: np.ndarray, colour=OUTLINE_COLOUR) -> np.ndarray:
    """A copy of ``picture`` (H, W, 3 uint8) with the pixels of ``outline`` in ``colour``."""
    if picture.shape[:2] != outline.shape:
        raise ValueError(f"outline of shape {outline.shape}, but should be the picture's {picture.shape[:2]}")
    drawn = np.array(picture, dtype=np.uint8, copy=True)
    drawn[outline] = colour
    return drawn


def outlined(run, names: Iterable[str], size: tuple[int, int] | None = None) -> np.ndarray:
    """The sync's drawing of ``run`` now, rendered from the scene's camera at ``size``, with the expected
    outline of the targets ``names`` over it. Needs a display (:func:`conformance.backends.display.ensure_display`)."""
    from conformance import backends

    size = tuple(size) if size else tuple(run.scene.image_size)
    return draw(backends.render(run.drawing, run.scene.camera, size), expected_outline(run, names, size))
