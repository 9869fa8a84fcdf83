"""Each target's FURY silhouette against pyBullet's own renderer: the render check that needs no golden.

pyBullet draws its bodies itself: ``getCameraImage(width, height, viewMatrix, projectionMatrix,
renderer=ER_TINY_RENDERER, flags=ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX)`` (pyBullet Quickstart
Guide, "getCameraImage") returns a segmentation mask whose value at a pixel is
``objectUniqueId + ((linkIndex + 1) << 24)`` of the body seen there, -1 for none. The camera is the
scene's own, as 16-float column-major matrices from :mod:`.projection` (the Quickstart's
``computeViewMatrix`` and ``computeProjectionMatrixFOV`` give the same numbers, to float32).
FURY's side is :func:`conformance.backends.render_ids`: every target flat in its own colour.

Measured facts this relies on (pybullet 3.2.7, DIRECT mode; proved in ``tests/test_silhouettes.py``):

* the tiny renderer draws bodies created with collision shapes only (no visual shape): boxes,
  spheres and cylinders are all drawn, from the collision shape;
* row 0 of the mask is the top of the picture, as in VTK's (flipped) snapshot;
* the tiny renderer samples pixel corners, not centres: its picture is offset by half a pixel (+0.5 px
  right, -0.5 px up, measured on every box of ``mixed_shapes``); :data:`HALF_PIXEL` shifts its
  projection by half a pixel to undo that, after which a single box agrees pixel for pixel.

Thresholds, measured with the reference sync (IoU with a 1 px edge slack; pixels where the masks
show two different targets in contact left out, :func:`touching_pairs`): at every scene's golden
frames, boxes 0.994 (wrecking_ball, a brick partly hidden by the ball), 1.000 elsewhere; spheres
0.998 (wrecking_ball), 0.999 (pendulum), 1.000 elsewhere (pyBullet's coarser sphere is within 1 px of
FURY's); cylinders 0.976 (chain: 1 m discs seen as slivers of rim, 16-gon against pyBullet's
tessellation), 0.982 (wrecking_ball links). Over 5,000 random draws of the orientation property, which
also turns the ground: boxes 0.987, spheres 0.990, cylinders 0.722 (a cylinder cut by the turned
ground, where the tiny renderer's depth test draws the cut differently). Before pixels of bodies in
contact were left out, 1 draw in 300 failed a right sync (that cylinder: 13 FURY pixels against 68).
Hence ``MIN_IOU``: 0.98 for boxes and spheres, 0.7 for cylinders (weak: a cylinder is judged
coarsely). Those draws were the orientation property's, at the scenes' default parameters; over the
scenes' own parameter space two more things a right sync does not control showed (issue 28): a small
body has a few pixels off at a corner or a seam, more than 2 % of it (a 72-pixel brick, 3 pixels:
:data:`LEAST_OFF`), and a sphere large on screen is drawn by pyBullet as a coarse hull up to 7.5 % of
its radius inside FURY's finer one (free_fall's 1 m sphere, 5 px: :data:`ROUNDING`). Measured: a box moved by 2 px gives 0.969 (fails); a 3° turn of a 55 px box is NOT caught
with the 1 px slack (plain IoU 0.96-0.97, slack IoU 1.0); a 10 % wrong view angle or a 3 cm shifted
focal point fails.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import pybullet
from scipy import ndimage

from conformance import figures

from conformance.backends import projection
from conformance.rendering.records import ImageCheck

__all__ = ["LEAST_OFF", "MIN_IOU", "MIN_PIXELS", "ROUNDING", "SLACK", "TOUCHING", "compare_silhouettes", "mask_images",
           "projected_discs", "projected_radii", "pybullet_draws_it", "pybullet_mask", "rounded_slacks", "roundings", "silhouette_check", "silhouette_record", "thresholds",
           "touching_pairs"]

#: A target is judged only where it covers at least this many pixels in either mask: below that its
#: IoU is dominated by which edge pixels each rasteriser keeps.
MIN_PIXELS = 50

#: The worst IoU (with :data:`SLACK`) a target may have, by shape kind. See the module docstring.
MIN_IOU = {"box": 0.98, "sphere": 0.98, "cylinder": 0.7, "surface": 0.98}
#: Bodies closer than this (m) are in contact for :func:`touching_pairs`.
TOUCHING = 0.01

HALF_PIXEL = True

#: Pixels a silhouette's edge may be off before a mismatch counts (see :func:`compare_silhouettes`).
SLACK = 1

#: Pixels off (beyond the edge slack) that any target may have, however small: what rasterising a corner
#: seen edge-on or a seam between two bodies flips. Measured with the reference sync over 4,200 random
#: draws of every scene's parameters and run length (FURY 0.12): at most 2 on a box or sphere under 300
#: pixels; 3 on a 72-pixel brick of a random wall (the wrecking ball, ``--hypothesis-seed=5``: 0.959
#: against 0.98, a right sync rejected). Twice that: a box moved by 2 px is off by a pixel along two of
#: its sides, 14 pixels for the smallest judged box (50 pixels).
LEAST_OFF = 6

#: How far inside a sphere's true outline each renderer's tessellated outline may fall, as a fraction of
#: its radius on screen, (FURY's, pyBullet's). pyBullet's tiny renderer draws a sphere as a coarse hull:
#: up to 0.0748 of the radius inside, measured over 200 orientations of a 160-px sphere
#: (tests/test_silhouettes.py); FURY's spheres are 16 x 16 UV spheres, whose hull lies at most 0.024 of
#: the radius inside (1 - cos 12.6°, the half diagonal of an equatorial face; measured on the kit's mesh
#: in tests/test_silhouettes.py). Without it a right sync failed every random draw that made a sphere
#: large on screen: free_fall's sphere at 31,000 pixels, IoU 0.962, pyBullet's outline 5 px inside FURY's.
ROUNDING = {"sphere": (0.03, 0.08), "cylinder": (0.02, 0.03)}
#: A cylinder's rim likewise: pyBullet's lies up to 2.8 % of the radius inside the true circle (measured over
#: 30 turns about its axis, a 160-px rim seen end-on), FURY's 16-sided one 1.9 % (1 - cos 11.25°). Without
#: it a right app failed a perturbed run: FURY 0.12's chain example with its discs kicked into a stack, a
#: disc seen edge-on 45 pixels off where 34 were allowed, all of them on its outline.


def pybullet_draws_it(scene, frame: int) -> bool:
    """Whether pyBullet's tiny renderer shows ``scene`` as it is at ``frame``: not before the first step of a
    scene with a soft body, which it draws from a visual mesh that ``stepSimulation`` updates (before the
    first step, the file's mesh unscaled: soft_ball's ball 157,990 pixels at frame 0, 10,366 after one step)."""
    return frame > 0 or not any(b.soft for b in scene.bindings)


def pybullet_mask(scene, bindings: Sequence, camera, size, *, depth: bool = False):
    """``(height, width)`` int32: the index into ``bindings`` of the (body, link) pyBullet's tiny
    renderer sees at each pixel, -1 for the background or a body no binding names; top row first. With
    ``depth``, also the renderer's depth buffer (``(height, width)``, 1 where nothing is drawn), to put
    the pictures of several clients together."""
    width, height = size
    view = projection.view_matrix(camera).T.ravel().tolist()
    matrix = projection.projection_matrix(camera, size)
    if HALF_PIXEL:
        matrix[0, 2] += 1.0 / width
        matrix[1, 2] += 1.0 / height
    proj = matrix.T.ravel().tolist()
    image = scene.p.getCameraImage(width, height, viewMatrix=view, projectionMatrix=proj,
                                   renderer=pybullet.ER_TINY_RENDERER,
                                   flags=pybullet.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX)
    seg = np.asarray(image[4], dtype=np.int64).reshape(height, width)
    out = np.full(seg.shape, -1, dtype=np.int32)
    for i, b in enumerate(bindings):
        out[seg == b.body + ((b.link + 1) << 24)] = i
    if depth:
        return out, np.asarray(image[3], dtype=np.float64).reshape(height, width)
    return out


def _far_mismatch(a: np.ndarray, b: np.ndarray, slack_a: int, slack_b: int | None = None) -> int:
    """Pixels in exactly one of masks ``a`` and ``b`` that are far from the other mask: those only in
    ``a`` more than ``slack_a`` pixels (chessboard distance) from ``b``, those only in ``b`` more than
    ``slack_b`` (default ``slack_a``) from ``a``: what a different tessellation or rasterisation of the
    same edge cannot explain."""
    slack_b = slack_a if slack_b is None else slack_b
    return int(np.count_nonzero(a & ~_near(b, slack_a)) + np.count_nonzero(b & ~_near(a, slack_b)))


def _within(candidates: np.ndarray, other: np.ndarray, slack: int) -> np.ndarray:
    """The ``candidates`` pixels that lie within ``slack`` pixels (chessboard) of ``other``: the same as
    ``candidates & _near(other, slack)``, computed on the candidates' box alone (a brick wall's hundreds of
    touching pairs each have a few candidates, and a whole-picture dilation per pair made its picture check
    slow)."""
    found = np.zeros(candidates.shape, dtype=bool)
    rows, cols = np.nonzero(candidates)
    if not len(rows):
        return found
    grow = max(slack, 0)
    box = (slice(max(rows.min() - grow, 0), rows.max() + grow + 1), slice(max(cols.min() - grow, 0), cols.max() + grow + 1))
    found[box] = candidates[box] & _near(other[box], slack)
    return found


def _near(mask: np.ndarray, slack: int) -> np.ndarray:
    """``mask`` grown by ``slack`` pixels (chessboard distance)."""
    if slack <= 0:
        return mask
    return ndimage.binary_dilation(mask, np.ones((2 * slack + 1, 2 * slack + 1), dtype=bool))


def _in_disc(disc, shape, slack: int) -> np.ndarray:
    """The pixels (``shape`` = rows, columns) whose centres lie within a disc (column, row, radius in
    pixels) grown by ``slack``; none for no disc."""
    if disc is None:
        return np.zeros(shape, dtype=bool)
    column, row, radius = disc
    rows, columns = np.ogrid[:shape[0], :shape[1]]
    return (columns + 0.5 - column) ** 2 + (rows + 0.5 - row) ** 2 <= (radius + slack) ** 2


def rounded_slacks(pixels: int, rounding: tuple[float, float] | None, slack: int = SLACK,
                   radius: float | None = None) -> tuple[int, int]:
    """``(fury_only, pybullet_only)``: how many pixels from the other mask a pixel only in FURY's, only in
    pyBullet's, mask of a target may lie and be put down to the edge, for a target covering ``pixels``
    pixels. For a sphere (``rounding`` = the two renderers' :data:`ROUNDING`) each renderer's outline may
    lie inside the true one by its tessellation's depth, a fraction of its ``radius`` on screen (in
    pixels; by default that of a disc of ``pixels`` pixels, too small for a sphere partly hidden): pixels
    only FURY draws are explained up to pyBullet's depth, pixels only pyBullet draws up to FURY's."""
    if rounding is None:
        return slack, slack
    radius = max(math.sqrt(pixels / math.pi), radius or 0.0)
    fury, bullet = rounding
    return slack + math.ceil(bullet * radius), slack + math.ceil(fury * radius)


def touching_pairs(scene, bindings: Sequence, ids_fury: np.ndarray, ids_pybullet: np.ndarray,
                   distance: float = TOUCHING) -> set[tuple[int, int]]:
    """The pairs of targets (indices into ``bindings``) that the two masks show at the same pixel and
    that are in contact: pyBullet's closest points between them within ``distance`` (negative when
    they interpenetrate). Only such pairs can be drawn in either order by two honest renderers."""
    contested = (ids_fury >= 0) & (ids_pybullet >= 0) & (ids_fury != ids_pybullet)
    pairs = {tuple(sorted(pair)) for pair in np.unique(np.stack([ids_fury[contested], ids_pybullet[contested]], 1), axis=0).tolist()}
    touching = set()
    for i, j in pairs:
        a, b = bindings[i], bindings[j]
        if scene.p.getClosestPoints(a.body, b.body, distance, linkIndexA=a.link, linkIndexB=b.link):
            touching.add((i, j))
    return touching


def compare_silhouettes(ids_fury: np.ndarray, ids_pybullet: np.ndarray, *, min_pixels: int = MIN_PIXELS,
                        min_iou=0.95, slack: int = SLACK, names: Sequence[str] = (), scene: str = "",
                        frame: int = 0, touching: set[tuple[int, int]] | None = None,
                        rounding: Sequence[tuple[float, float] | None] | None = None,
                        discs: Sequence[tuple[float, float, float] | None] | None = None,
                        radii: Sequence[float | None] | None = None, least_off: int = LEAST_OFF) -> ImageCheck:
    """Per target, how well FURY's silhouette and pyBullet's agree, for every target covering at least
    ``min_pixels`` pixels in either mask; passes when each such target's IoU is at least its ``min_iou``
    (one number for every target, or a sequence indexed by target, e.g. :func:`thresholds`), or when it
    has no more than ``least_off`` pixels off (:data:`LEAST_OFF`: what rasterising a corner or a seam
    flips, which on a small body is more than its share of the IoU).

    Pixels where the two masks show two different targets of a ``touching`` pair (:func:`touching_pairs`)
    are left out (which of two bodies in contact is in front is the renderers' business, where each
    body is the sync's). The IoU is taken with an edge slack: a pixel in one mask only counts against the target if it is
    more than ``slack`` pixels from the other mask, so ``iou = 1 - off / union`` (``slack=0``: the plain
    intersection over union, also reported per target as ``plain_iou``). A target with a ``rounding``
    (:func:`roundings`: a sphere) has the slack of :func:`rounded_slacks` instead, and so do the pixels
    where its outline meets another target. ``discs`` are where the spheres are on screen, as physics
    has them (:func:`projected_discs`: column, row and radius in pixels): a pixel FURY draws of a sphere
    inside its disc (grown by the slack) is the sphere's, however little of pyBullet's coarser sphere
    shows near it (a sphere hidden but for a rim past another body's edge). ``radii`` are the other
    rounded targets' radii on screen (a cylinder's rim: :func:`projected_radii`), which scale their slack
    as a disc's radius does a sphere's. ``names`` name the targets."""
    if ids_fury.shape != ids_pybullet.shape:
        raise ValueError(f"mask shapes differ: {ids_fury.shape} vs {ids_pybullet.shape}")
    count = int(max(ids_fury.max(initial=-1), ids_pybullet.max(initial=-1), len(names) - 1)) + 1
    rounding = list(rounding) if rounding is not None else []
    rounding += [None] * (count - len(rounding))
    discs = list(discs) if discs is not None else []
    discs += [None] * (count - len(discs))
    given = list(radii) if radii is not None else []
    given += [None] * (count - len(given))
    radii = [d[2] if d is not None else r for d, r in zip(discs, given)]
    # Where two bodies touch or interpenetrate, which one is in front depends on each renderer's
    # tessellation and depth test (measured: a cylinder cut by a turned ground, 13 FURY pixels against
    # 68 pyBullet pixels, 1 draw in 300 of the orientation property, with the reference sync). Pixels
    # where the masks show two such bodies are left out of both targets' comparison; between bodies
    # apart, a different one in front is a body drawn in the wrong place, and counts.
    pair_ids = np.minimum(ids_fury, ids_pybullet).astype(np.int64) * (1 << 20) + np.maximum(ids_fury, ids_pybullet)
    allowed = np.array([i * (1 << 20) + j for i, j in (touching or ())], dtype=np.int64)
    differ = (ids_fury >= 0) & (ids_pybullet >= 0) & (ids_fury != ids_pybullet)
    contested = differ & np.isin(pair_ids, allowed)
    fury = np.bincount(ids_fury.ravel() + 1, minlength=count + 1)[1:]
    bullet = np.bincount(ids_pybullet.ravel() + 1, minlength=count + 1)[1:]
    # A sphere in front of another body: where its two outlines differ (each renderer's tessellation), one
    # picture shows the body behind and the other the sphere; those pixels are the sphere's edge, not the
    # other body's, and are left out of both as far as the sphere's own slack reaches.
    if differ.any():
        for k in set(np.unique(np.concatenate([ids_fury[differ], ids_pybullet[differ]])).tolist()):
            if rounding[k] is None:
                continue
            fury_only, bullet_only = rounded_slacks(int(max(fury[k], bullet[k])), rounding[k], slack, radii[k])
            mine_f, mine_b = differ & (ids_fury == k), differ & (ids_pybullet == k)
            contested |= (_within(mine_f, ids_pybullet == k, fury_only) | (mine_f & _in_disc(discs[k], ids_fury.shape, slack))
                          | _within(mine_b, ids_fury == k, bullet_only))
    # Two bodies in contact share an outline where they meet and overlap: where one renderer draws the
    # pair's edge with one body and the other with the other (interpenetrating discs of a chain, drawn in
    # either order), a pixel of one body over background lies within the edge slack of its partner in the
    # other picture. Measured: FURY 0.12's chain example kicked into a stack, a disc's rim 1-2 px below its
    # partner's, 18 pixels off on a 91-pixel disc.
    over_background = set(np.unique(ids_pybullet[(ids_pybullet >= 0) & (ids_fury < 0)]).tolist()) | set(
        np.unique(ids_fury[(ids_fury >= 0) & (ids_pybullet < 0)]).tolist())
    for i, j in touching or ():
        for k, partner in ((i, j), (j, i)):
            if k not in over_background:
                continue
            fury_only, bullet_only = rounded_slacks(int(max(fury[partner], bullet[partner])), rounding[partner], slack,
                                                    radii[partner])
            contested |= _within((ids_pybullet == k) & (ids_fury < 0), ids_fury == partner, bullet_only)
            contested |= _within((ids_fury == k) & (ids_pybullet < 0), ids_pybullet == partner, fury_only)
    fury_ids = np.where(contested, -1, ids_fury)
    bullet_ids = np.where(contested, -1, ids_pybullet)
    fury = np.bincount(fury_ids.ravel() + 1, minlength=count + 1)[1:]
    bullet = np.bincount(bullet_ids.ravel() + 1, minlength=count + 1)[1:]
    both = np.bincount(fury_ids[fury_ids == bullet_ids].ravel() + 1, minlength=count + 1)[1:]
    limits = [float(min_iou)] * count if np.ndim(min_iou) == 0 else [float(x) for x in min_iou]
    targets = []
    for i in np.flatnonzero(np.maximum(fury, bullet) >= min_pixels):
        a, b = fury_ids == i, bullet_ids == i
        fury_only, bullet_only = rounded_slacks(int(max(fury[i], bullet[i])), rounding[i], slack, radii[i])
        grow = max(fury_only, bullet_only)
        rows, cols = np.nonzero(a | b)  # work on the target's box, grown by the slack, not the whole picture
        box = (slice(max(rows.min() - grow, 0), rows.max() + grow + 1),
               slice(max(cols.min() - grow, 0), cols.max() + grow + 1))
        union = int(fury[i] + bullet[i] - both[i])
        if discs[i] is None:
            off = _far_mismatch(a[box], b[box], fury_only, bullet_only)
        else:  # FURY's pixels inside the sphere's disc are right wherever pyBullet's coarse sphere shows
            inside = _in_disc(discs[i], ids_fury.shape, slack)[box]
            off = int(np.count_nonzero(a[box] & ~_near(b[box], fury_only) & ~inside)
                      + np.count_nonzero(b[box] & ~_near(a[box], bullet_only)))
        targets.append({"target": names[i] if i < len(names) else f"#{i}", "index": int(i),
                        "iou": 1.0 - off / union, "plain_iou": float(both[i] / union), "off": off,
                        "allowed_off": max(least_off, int((1.0 - limits[i]) * union)),
                        "slack": [fury_only, bullet_only],
                        "fury_pixels": int(fury[i]), "pybullet_pixels": int(bullet[i]), "min_iou": limits[i]})
    for t in targets:
        t["passed"] = t["iou"] >= t["min_iou"] or t["off"] <= least_off
    # The worst target is the one furthest over its allowance of pixels off.
    worst = max(targets, key=lambda t: t["off"] / max(t["allowed_off"], 1), default=None)
    where = f"[{scene}, frame {frame}]"
    details = {"targets": targets, "min_pixels": min_pixels, "slack": slack, "least_off": least_off}
    if worst is None:
        return ImageCheck(kind="silhouette", scene=scene, frame=frame, passed=True, details=details,
                          message=f"no target covers {min_pixels} pixels in either mask {where}")
    figures.note("silhouette pixels off", worst["off"], max(worst["allowed_off"], 1), where=f"{worst['target']!r} {where}")
    passed = all(t["passed"] for t in targets)
    min_iou = worst["min_iou"]
    edge = (f"edge slack {slack} px" if worst["slack"] == [slack, slack] else
            f"edge slack {worst['slack'][0]} px for FURY's pixels, {worst['slack'][1]} px for pyBullet's (a sphere's tessellation)")
    message = (f"silhouette of {worst['target']!r}: IoU with pyBullet's mask = {worst['iou']:.3f}"
               f"{', but should be at least' if not passed else ' (at least'} {min_iou:.3f}{'' if not passed else ')'}"
               f" ({worst['off']} pixels off beyond the edge, {worst['allowed_off']} allowed; {worst['fury_pixels']} FURY "
               f"pixels, {worst['pybullet_pixels']} pyBullet pixels, plain IoU {worst['plain_iou']:.3f}, {edge}) {where}")
    failing = [t["target"] for t in targets if not t["passed"]]
    if len(failing) > 1:
        message += f"; {len(failing)} targets below it: {', '.join(failing[:10])}"
    # The bound is on pixels off; the IoU is told beside it (a small body passes below its IoU with a
    # corner's few pixels off).
    return ImageCheck(kind="silhouette", scene=scene, frame=frame, passed=passed, message=message,
                      metrics={"pixels_off": worst["off"], "iou": worst["iou"]},
                      limits={"pixels_off": worst["allowed_off"]}, details=details)


def thresholds(bindings: Sequence) -> list[float]:
    """Each binding's ``min_iou``, by the kind of its shape (:data:`MIN_IOU`)."""
    return [MIN_IOU[b.shape.kind] for b in bindings]


def projected_discs(scene, bindings: Sequence, camera, size) -> list[tuple[float, float, float] | None]:
    """Where each sphere binding is on screen now, as physics has it: ``(column, row, radius)`` in pixels
    (its centre projected, its radius at its depth); None for other shapes and a sphere behind the camera."""
    from conformance.bullet import poses, truth

    spheres = [i for i, b in enumerate(bindings) if b.shape.kind == "sphere"]
    found: list[tuple[float, float, float] | None] = [None] * len(bindings)
    if not spheres:
        return found
    positions, orientations = truth.link_frames(scene.p, [(bindings[i].body, bindings[i].link) for i in spheres])
    centres = np.array([poses.apply(pos, orn, [bindings[i].shape.position])[0]
                        for i, pos, orn in zip(spheres, positions, orientations)])
    pixels, depth = projection.project(camera, size, centres)
    per_metre = size[1] / 2 / math.tan(math.radians(camera.view_angle) / 2)
    for i, (column, row), d in zip(spheres, pixels, depth):
        if d > 0:
            found[i] = (float(column), float(row), float(bindings[i].shape.size[0] * per_metre / d))
    return found


def projected_radii(scene, bindings: Sequence, camera, size) -> list[float | None]:
    """Each cylinder binding's radius on screen in pixels at its centre's depth (what scales its rim's
    slack, :data:`ROUNDING`); None for other shapes (a sphere's is in :func:`projected_discs`)."""
    from conformance.bullet import poses, truth

    cylinders = [i for i, b in enumerate(bindings) if b.shape.kind == "cylinder"]
    found: list[float | None] = [None] * len(bindings)
    if not cylinders:
        return found
    positions, orientations = truth.link_frames(scene.p, [(bindings[i].body, bindings[i].link) for i in cylinders])
    centres = np.array([poses.apply(pos, orn, [bindings[i].shape.position])[0]
                        for i, pos, orn in zip(cylinders, positions, orientations)])
    _, depth = projection.project(camera, size, centres)
    per_metre = size[1] / 2 / math.tan(math.radians(camera.view_angle) / 2)
    for i, d in zip(cylinders, depth):
        if d > 0:
            found[i] = float(bindings[i].shape.size[0] * per_metre / d)
    return found


def roundings(bindings: Sequence) -> list[tuple[float, float] | None]:
    """Each binding's :data:`ROUNDING` (None for a shape both renderers draw exactly)."""
    return [ROUNDING.get(b.shape.kind) for b in bindings]


def _palette(count: int) -> np.ndarray:
    """A fixed colour per target index (black last, for -1): the same target, the same colour, in every picture."""
    rng = np.random.default_rng(12345)
    colors = rng.integers(60, 256, size=(count + 1, 3)).astype(np.uint8)
    colors[-1] = 0
    return colors


def mask_images(ids_fury: np.ndarray, ids_pybullet: np.ndarray) -> dict[str, np.ndarray]:
    """RGB uint8 pictures for a failure report: ``fury_mask`` and ``pybullet_mask`` (each target in its
    own colour, the same in both; background black) and ``mask_difference`` (white where both agree on
    a target, red where only FURY draws a target there, blue where only pyBullet does, yellow where
    both draw different targets)."""
    count = int(max(ids_fury.max(initial=-1), ids_pybullet.max(initial=-1))) + 1
    palette = _palette(count)
    difference = np.zeros(ids_fury.shape + (3,), dtype=np.uint8)
    same = (ids_fury == ids_pybullet) & (ids_fury >= 0)
    difference[same] = (255, 255, 255)
    difference[(ids_fury >= 0) & (ids_pybullet < 0)] = (255, 0, 0)
    difference[(ids_fury < 0) & (ids_pybullet >= 0)] = (0, 0, 255)
    difference[(ids_fury >= 0) & (ids_pybullet >= 0) & ~same] = (255, 255, 0)
    return {"fury_mask": palette[ids_fury], "pybullet_mask": palette[ids_pybullet], "mask_difference": difference}


def silhouette_check(run, sync: str, pictures=None, nodeid: str = "", check: str = "test_silhouettes_match_in_any_orientation",
                     tolerance=None):
    """FURY's ID render against pyBullet's mask for the run's current frame, as an ImageCheck (kept,
    with its masks when it failed, in the results directory when ``pictures`` is given); its reproduce
    line runs ``check`` (a whole pytest id, or a check's name) again."""
    from conformance import backends

    scene = run.scene
    ids_fury = backends.render_ids(run.drawing, scene.camera, scene.image_size)
    ids_bullet = pybullet_mask(scene, scene.bindings, scene.camera, scene.image_size)
    record = silhouette_record(run, sync, ids_fury, ids_bullet, check, tolerance)
    record.nodeid = nodeid
    if pictures is not None:
        pictures.keep(record, mask_images(ids_fury, ids_bullet))
    return record


def silhouette_record(run, sync: str, ids_fury, ids_bullet, check: str, tolerance=None):
    scene = run.scene
    record = compare_silhouettes(
        ids_fury, ids_bullet, min_iou=thresholds(scene.bindings), rounding=roundings(scene.bindings),
        discs=projected_discs(scene, scene.bindings, scene.camera, scene.image_size),
        radii=projected_radii(scene, scene.bindings, scene.camera, scene.image_size),
        names=[t.name for t in run.drawing.targets], scene=scene.name, frame=run.frame,
        touching=touching_pairs(scene, scene.bindings, ids_fury, ids_bullet))
    from conformance.sync.printed import reproduce_command, rerun_check
    from conformance.rendering.golden import jsonable

    record.sync = sync
    record.params = jsonable(dict(run.params))
    # The check itself reruns it (`check` compares vertices, not silhouettes); the frame-by-frame replay
    # of the same run shows whether its vertices are wrong too.
    record.reproduce = rerun_check(check, scene.name, sync, tolerance)
    record.details["replay"] = reproduce_command(scene.name, sync, run.frame, run.params, run.events, tolerance)
    return record
