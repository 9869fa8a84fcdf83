"""A render against its golden, within a tolerance set (no pytest here: the command line reuses it).

Three numbers decide (all measured by ``python -m conformance.rendering.measure_tolerances``, the
table is in ``docs/image-tolerances.md``):

* ``differing_fraction``: the fraction of pixels whose largest channel difference exceeds
  ``pixel_threshold`` *and* that lie in a ``block`` x ``block`` square of such pixels (a binary
  opening). Anti-aliasing differences (another GPU, another multisampling pattern) are one pixel
  wide along edges; a body drawn elsewhere or in another colour differs in a filled area. With
  ``block=2`` multisampling off vs 8x leaves at most 52 such pixels on all 14 scenes (the brick
  wall's hundreds of edges included) where a bare count leaves up to 4,041.
* ``largest_difference``: the largest channel difference (reported; not bounded).
* ``flip_mean``: NVIDIA's FLIP (``flip-evaluator``), mean over the picture, bounded to catch a
  diffuse change no pixel of which passes the threshold (lighting, gamma, colour management).

Why FLIP, not scikit-image's SSIM (measured on 14 scenes x 3 frames, 450x384): SSIM is blind to a
recolour (a 60° hue shift of one body leaves no SSIM-map pixel below 0.8 in ``tumbling``), FLIP
sees every recolour (≥ 311 pixels above 0.2); neither separates the errors from multisampling off
as a global mean (1-SSIM up to 0.020 and FLIP up to 0.012 for MSAA off, vs down to 0.00004 and
0.00008 for a turned body), so the bound is a guard, the count decides. FLIP costs ~85 ms per
comparison against SSIM's ~17 ms, but installs 1.3 MB with no dependencies, where scikit-image
brings 56 MB (networkx, imageio, tifffile).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Mapping

import numpy as np
from scipy import ndimage

from conformance.errors import ImageSizeMismatch, InvalidArgument
from conformance.rendering.records import ImageCheck

__all__ = [
    "OTHER_RENDERER",
    "SAME_RENDERER",
    "TOLERANCES",
    "ImageTolerance",
    "compare_images",
    "difference_image",
    "tolerance",
]


@dataclass(frozen=True)
class ImageTolerance:
    """A named tolerance set. ``pixel_threshold``: a channel difference (0..255) above which a pixel
    differs; ``block``: a differing pixel counts only inside a ``block`` x ``block`` square of
    differing pixels (1: every one counts); ``max_differing_fraction``: the most of the picture that
    may differ; ``max_flip_mean``: the largest mean FLIP error."""

    name: str
    pixel_threshold: int
    block: int
    max_differing_fraction: float
    max_flip_mean: float
    #: Shading: a pixel differs in shade when a channel differs by more than ``shade_threshold`` inside
    #: a 3x3 square of such pixels; at most ``max_shaded_fraction`` of the picture may. A body turned
    #: across the view (towards or away from the headlight) changes the shade of whole faces by a few
    #: levels while its outline moves by less than anti-aliasing does.
    shade_threshold: int = 4
    max_shaded_fraction: float = 1.0

    def __post_init__(self):
        checks = {
            "pixel_threshold": (int, lambda v: 0 <= v <= 255, "an integer from 0 to 255"),
            "block": (int, lambda v: 1 <= v <= 8, "an integer from 1 to 8"),
            "max_differing_fraction": ((int, float), lambda v: 0 <= v <= 1, "a number from 0 to 1"),
            "max_flip_mean": ((int, float), lambda v: 0 <= v <= 1, "a number from 0 to 1"),
            "shade_threshold": (int, lambda v: 0 <= v <= 255, "an integer from 0 to 255"),
            "max_shaded_fraction": ((int, float), lambda v: 0 <= v <= 1, "a number from 0 to 1"),
        }
        for field_name, (kind, ok, wanted) in checks.items():
            value = getattr(self, field_name)
            if isinstance(value, bool) or not isinstance(value, kind) or not ok(value):
                raise InvalidArgument(f"ImageTolerance {field_name}={value!r} ({type(value).__name__}), "
                                      f"but should be {wanted}")

    def override(self, **values: str | float | int) -> "ImageTolerance":
        """A copy with fields replaced; strings (from a command line or ini file) are parsed first.
        Unknown names and unparsable or out-of-range values raise :class:`InvalidArgument` naming
        the argument, its value and its type."""
        names = [f.name for f in dataclasses.fields(self) if f.name != "name"]
        parsed = {}
        for key, value in values.items():
            if key not in names:
                raise InvalidArgument(f"{key}={value!r} ({type(value).__name__}) is not an image tolerance; "
                                      f"the tolerances are {', '.join(names)}")
            if isinstance(value, str):
                try:
                    value = int(value) if key in ("pixel_threshold", "block", "shade_threshold") else float(value)
                except ValueError:
                    raise InvalidArgument(f"{key}={value!r} (str), but should be a number") from None
            parsed[key] = value
        return dataclasses.replace(self, **parsed)


#: The golden was rendered by this machine's renderer: Mesa llvmpipe renders bit-identically from one
#: process to the next (measured: 0 differing pixels over 42 goldens). A right sync whose vertices
#: differ from the reference's only by float rounding (well within the vertex tolerance) still flips
#: a few edge pixels: up to 22 by more than 2 levels (``right_syncs:vectorised_vertex_sync``,
#: ``mixed_shapes`` frame 360), so up to 40 pixels (2.3e-4) may differ; every error differs in ≥ 158.
SAME_RENDERER = ImageTolerance("same-renderer", pixel_threshold=2, block=1, max_differing_fraction=2.3e-4,
                               max_flip_mean=0.03)
#: The golden came from another GPU or driver: anti-aliasing and rounding differ. Passes multisampling
#: off vs 8x (≤ 52 differing pixels in 2x2 blocks, 3.0e-4) and ±1 noise (none); fails one body moved
#: 2 px (≥ 68 pixels, 3.9e-4) or recoloured (≥ 250). See docs/image-tolerances.md for the margins.
#: Shading: multisampling off vs 8x leaves at most 39 pixels differing by more than 4 levels in 3x3
#: squares; a 3° turn of a box across the view leaves at least 64 (docs/image-tolerances.md).
OTHER_RENDERER = ImageTolerance("other-renderer", pixel_threshold=32, block=2, max_differing_fraction=3.5e-4,
                                max_flip_mean=0.03, shade_threshold=4, max_shaded_fraction=2.9e-4)
TOLERANCES: Mapping[str, ImageTolerance] = {t.name: t for t in (SAME_RENDERER, OTHER_RENDERER)}


def tolerance(name: str, **overrides: str | float | int) -> ImageTolerance:
    """The tolerance set called ``name`` (``same-renderer``, ``other-renderer``) with ``overrides``."""
    if name not in TOLERANCES:
        raise InvalidArgument(f"tolerance={name!r} ({type(name).__name__}), but should be one of: {', '.join(TOLERANCES)}")
    return TOLERANCES[name].override(**overrides)


def _checked(expected: np.ndarray, actual: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    expected, actual = np.asarray(expected), np.asarray(actual)
    for role, image in (("expected", expected), ("actual", actual)):
        if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
            raise InvalidArgument(f"{role} is {image.dtype} {image.shape}, but should be RGB uint8 (height, width, 3)")
    if expected.shape != actual.shape:
        raise ImageSizeMismatch(f"the render is {actual.shape[1]}x{actual.shape[0]} but the golden is "
                                f"{expected.shape[1]}x{expected.shape[0]}: re-record the golden at the scene's image size")
    return expected, actual


def _differing(expected: np.ndarray, actual: np.ndarray, threshold: int, block: int) -> np.ndarray:
    delta = np.abs(expected.astype(np.int16) - actual.astype(np.int16)).max(axis=-1)
    mask = delta > threshold
    if block > 1:
        # Keep only pixels inside a block x block square of differing pixels: removes the one-pixel
        # wide anti-aliasing seams along edges, keeps filled areas.
        mask = ndimage.binary_opening(mask, structure=np.ones((block, block), bool))
    return mask


#: How far, in pixels, FLIP's error reaches from a pixel that differs: at flip-evaluator's default 67 pixels
#: per degree a one-pixel change gives errors up to 10 pixels away and none farther (tests/test_image_compare.py
#: measures it); 12 leaves room.
FLIP_REACH = 12


def flip_mean(expected: np.ndarray, actual: np.ndarray) -> float:
    """Mean FLIP error (0 = identical, 1 = opposite) of two sRGB uint8 pictures, over the whole picture.

    FLIP's error at a pixel depends on the pixels within :data:`FLIP_REACH` of it alone, so it is 0 wherever
    nothing within reach differs: each connected region of pixels within reach of a difference is evaluated
    in a crop of its own, grown by the reach so that each of its pixels sees its whole neighbourhood, and
    their errors summed. The same mean as one evaluation of the whole picture (to 5e-6 relative, float32
    sums), at less than half its cost on FURY 2's golden comparisons, where a few hundred pixels differ."""
    import flip_evaluator

    changed = np.any(expected != actual, axis=-1)
    if not changed.any():
        return 0.0
    height, width = changed.shape
    near = ndimage.binary_dilation(changed, np.ones((2 * FLIP_REACH + 1,) * 2, dtype=bool))
    regions, _ = ndimage.label(near)
    total = 0.0
    for k, (rows, columns) in enumerate(ndimage.find_objects(regions), start=1):
        top, left = max(rows.start - FLIP_REACH, 0), max(columns.start - FLIP_REACH, 0)
        bottom, right = min(rows.stop + FLIP_REACH, height), min(columns.stop + FLIP_REACH, width)
        crop = (slice(top, bottom), slice(left, right))
        errors, _, _ = flip_evaluator.evaluate(expected[crop].astype(np.float32) / 255,
                                               actual[crop].astype(np.float32) / 255, "LDR", applyMagma=False)
        errors = np.asarray(errors).reshape(bottom - top, right - left)
        total += float(errors[regions[crop] == k].sum(dtype=np.float64))
    return total / (height * width)


def compare_images(expected: np.ndarray, actual: np.ndarray, tolerance: ImageTolerance, *,
                   scene: str = "", frame: int = 0) -> ImageCheck:
    """``actual`` against ``expected`` (RGB uint8, same size) within ``tolerance``: an
    :class:`ImageCheck` of kind ``golden`` that passed iff ``differing_fraction`` ≤
    ``max_differing_fraction`` and ``flip_mean`` ≤ ``max_flip_mean``. Raises
    :class:`ImageSizeMismatch` when the sizes differ (a different question than a different picture)."""
    expected, actual = _checked(expected, actual)
    mask = _differing(expected, actual, tolerance.pixel_threshold, tolerance.block)
    largest = int(np.abs(expected.astype(np.int16) - actual.astype(np.int16)).max(initial=0))
    shaded = _differing(expected, actual, tolerance.shade_threshold, 3)
    metrics = {
        "differing_fraction": float(mask.mean()),
        "shaded_fraction": float(shaded.mean()),
        "differing_pixels": float(mask.sum()),
        "largest_difference": float(largest),
        "flip_mean": flip_mean(expected, actual) if largest else 0.0,
    }
    limits = {"differing_fraction": tolerance.max_differing_fraction, "flip_mean": tolerance.max_flip_mean,
              "shaded_fraction": tolerance.max_shaded_fraction}
    failed = [key for key, limit in limits.items() if metrics[key] > limit]
    message = "; ".join(f"{key} {metrics[key]:.3g} > {limits[key]:.3g}" for key in failed) or "within tolerance"
    return ImageCheck(kind="golden", scene=scene, frame=frame, passed=not failed,
                      message=f"{tolerance.name}: {message} ({int(metrics['differing_pixels'])} pixels differ by "
                              f"more than {tolerance.pixel_threshold} in {tolerance.block}x{tolerance.block} blocks)",
                      metrics=metrics, limits=limits,
                      details={"tolerance": dataclasses.asdict(tolerance)})


def difference_image(expected: np.ndarray, actual: np.ndarray) -> np.ndarray:
    """A picture of where two renders differ: the golden greyed and faded, every differing pixel
    over it from pink (1 level) to saturated red/magenta (≥ 64 levels). RGB uint8, same size."""
    expected, actual = _checked(expected, actual)
    grey = expected.astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32)
    out = np.repeat((155 + 0.35 * grey)[..., None], 3, axis=-1)
    delta = np.abs(expected.astype(np.int16) - actual.astype(np.int16)).max(axis=-1)
    strength = np.clip(delta / 64.0, 0.25, 1.0)[delta > 0][:, None]
    magenta = np.array([255.0, 0.0, 160.0], np.float32)
    out[delta > 0] = (1 - strength) * out[delta > 0] + strength * magenta
    return np.round(out).astype(np.uint8)
