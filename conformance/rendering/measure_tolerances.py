"""Measure the golden-image metrics on every reference scene: the numbers behind the tolerance sets.

``python -m conformance.rendering.measure_tolerances [--scenes a,b] [--out docs/image-tolerances.md]``
renders each scene (reference sync) at its golden frames, then, against that render, measures

* benign changes, which the ``other-renderer`` set must pass: a re-render in another process
  (``rerender``), ±1 random intensity noise (``noise``), multisampling off instead of 8x (``msaa_off``);
* real errors, which both sets must fail: one body moved 2 px across the view (``moved``), turned 3°
  about the camera's right axis through its centre (``turned``; boxes only), its vertex colours' hue shifted 60°
  (``recoloured``);

and writes a markdown table of each metric's min/max per scene and change. The perturbation helpers
(:func:`pick_target`, :func:`perturbed`) are reused by the kit's tests, so both judge the same changes.
"""

from __future__ import annotations

import argparse
import colorsys
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["BENIGN", "ERRORS", "IN_PLANE", "perturbed", "pick_target", "render_frames", "with_noise"]

#: The changes that must pass the other-renderer set, and those that must fail both sets.
BENIGN = ("rerender", "noise", "msaa_off")
ERRORS = ("moved", "turned", "recoloured")
#: A turn in the picture plane (boxes only): not in :data:`ERRORS`, since the other-renderer set cannot
#: promise to catch it; the live reference's same-renderer verdict does (:mod:`.measure_reftest`).
IN_PLANE = "turned_in_plane"

MOVE_PIXELS = 2.0
TURN_DEGREES = 3.0
HUE_SHIFT = 60.0 / 360.0
#: Smallest on-screen box (px²) of a body worth perturbing: 16x16 px for a move or a recolour; for
#: a turn 40x40 px, since 3° moves the outline of a body 40 px across by only about 1 px.
MIN_AREA = 16 * 16
MIN_AREA_TURNED = 40 * 40


def _basis(camera):
    """Camera forward, right and up unit vectors (world)."""
    position = np.asarray(camera.position, float)
    forward = np.asarray(camera.focal_point, float) - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(camera.view_up, float))
    right /= np.linalg.norm(right)
    return position, forward, right, np.cross(right, forward)


def _screen_box(vertices, camera, size) -> tuple[float, float, float, float, float]:
    """Projected (x0, y0, x1, y1) in pixels of world ``vertices`` and the nearest depth (m)."""
    position, forward, right, up = _basis(camera)
    rel = vertices - position
    depth = rel @ forward
    scale = size[1] / (2 * math.tan(math.radians(camera.view_angle) / 2))
    d = np.maximum(depth, 1e-6)
    x = size[0] / 2 + scale * (rel @ right) / d
    y = size[1] / 2 - scale * (rel @ up) / d
    return float(x.min()), float(y.min()), float(x.max()), float(y.max()), float(depth.min())


def pick_target(run, size, *, turning: bool = False) -> int:
    """Index of the body to perturb: of the six largest on screen (bounding box wholly in view,
    between :data:`MIN_AREA` — :data:`MIN_AREA_TURNED` and no spheres when ``turning`` — and a quarter
    of the picture, so not a ground plate), the one with most pixels visible (bodies hide each
    other: a brick behind the wall is no test). Renders once per candidate."""
    from conformance import backends

    camera = run.scene.camera
    candidates = []
    for i, t in enumerate(run.drawing.targets):
        # A sphere or cylinder turned about its own axis looks the same: turn boxes only.
        if turning and run.scene.bindings[i].shape.kind != "box":
            continue
        vertices = backends.world_vertices(t.actor)[t.start:t.stop]
        x0, y0, x1, y1, near = _screen_box(vertices, camera, size)
        area = (x1 - x0) * (y1 - y0)
        inside = x0 >= 0 and y0 >= 0 and x1 <= size[0] and y1 <= size[1] and near > 0
        if inside and (MIN_AREA_TURNED if turning else MIN_AREA) <= area <= size[0] * size[1] / 4:
            candidates.append((-area, i))
    if not candidates:
        raise LookupError(f"scene {run.scene.name!r}: no body of reasonable on-screen size to perturb")
    base = backends.render(run.drawing, camera, size)
    visible = []
    for _, i in sorted(candidates)[:6]:
        with perturbed(run, i, "recoloured"):
            shown = backends.render(run.drawing, camera, size)
        visible.append((int(np.count_nonzero((shown != base).any(axis=-1))), i))
    pixels, best = max(visible)
    if pixels < (MIN_AREA_TURNED if turning else MIN_AREA) / 2:
        raise LookupError(f"scene {run.scene.name!r}: no body of reasonable size is visible enough to perturb")
    return best


def _rotation(axis, degrees: float) -> np.ndarray:
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    a = math.radians(degrees)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(a) * k + (1 - math.cos(a)) * k @ k


def _world_transform(run, i: int, kind: str) -> np.ndarray:
    """The 4x4 world transform that moves (2 px across the view), turns (3° about the camera's right
    axis, through the body's centre) or turns in the picture plane (``turned_in_plane``: 3° about the
    line of sight through the body's centre) target ``i``."""
    from conformance import backends

    t = run.drawing.targets[i]
    centre = backends.world_vertices(t.actor)[t.start:t.stop].mean(axis=0)
    camera = run.scene.camera
    position, forward, right, _ = _basis(camera)
    transform = np.eye(4)
    if kind == "moved":
        depth = float((centre - position) @ forward)
        pixel = 2 * depth * math.tan(math.radians(camera.view_angle) / 2) / run.scene.image_size[1]
        transform[:3, 3] = right * MOVE_PIXELS * pixel
    elif kind == IN_PLANE:
        # The outline turns, no face turns towards or away from the headlight: only a tolerance that
        # needs no anti-aliasing slack (one renderer against itself) can promise to see it.
        rotation = _rotation(centre - position, TURN_DEGREES)
        transform[:3, :3] = rotation
        transform[:3, 3] = centre - rotation @ centre
    else:
        # About the camera's right axis: the body tilts towards or away from the headlight, as a
        # wrong orientation usually does. (A turn in the picture plane moves a 40-100 px outline by
        # 1-3 px and changes no shade: the size of anti-aliasing differences between renderers, so
        # only the same-renderer set can promise to catch it.)
        rotation = _rotation(right, TURN_DEGREES)
        transform[:3, :3] = rotation
        transform[:3, 3] = centre - rotation @ centre
    return transform


def _shift_hue(rgb: np.ndarray) -> np.ndarray:
    """Colours (n, 3) in 0..1 with their hue turned by :data:`HUE_SHIFT`."""
    shifted = []
    for r, g, b in rgb:
        h, s, v = colorsys.rgb_to_hsv(r, g, b)
        # A grey has no hue to shift: give it some saturation so the change is a colour change.
        shifted.append(colorsys.hsv_to_rgb((h + HUE_SHIFT) % 1.0, max(s, 0.4), max(v, 0.3)))
    return np.array(shifted)


def perturbed(run, i: int, kind: str):
    """A context within which target ``i`` of ``run`` is ``moved``, ``turned`` or ``recoloured``
    (see the module docstring); everything is restored on exit (the backend's ``perturbed``)."""
    from conformance import backends

    target = run.drawing.targets[i]
    if kind == "recoloured":
        return backends.perturbed(target, recolour=_shift_hue)
    if kind not in ("moved", "turned", IN_PLANE):
        raise ValueError(f"kind={kind!r}, but should be one of {(*ERRORS, IN_PLANE)}")
    return backends.perturbed(target, transform=_world_transform(run, i, kind))


def with_noise(image: np.ndarray, seed: int = 0) -> np.ndarray:
    """``image`` with independent uniform -1/0/+1 added to every channel (clipped to 0..255)."""
    noise = np.random.default_rng(seed).integers(-1, 2, size=image.shape)
    return np.clip(image.astype(np.int16) + noise, 0, 255).astype(np.uint8)


def render_frames(scene: str, *, variants: bool = True) -> dict[tuple[int, str], np.ndarray]:
    """Renders of ``scene`` at its golden frames: ``(frame, "base")`` and, with ``variants``,
    ``(frame, change)`` for ``msaa_off`` and each of :data:`ERRORS` (``turned`` skipped where every
    body is a sphere: a turned tessellated sphere is a different question)."""
    from conformance import backends, scenes, sync
    from conformance.sync.runner import running

    spec = scenes.get(scene)
    images = {}
    with running(scene, sync.load("reference")) as run:
        for frame in spec.frames_with_goldens():
            run.advance(frame - run.frame)
            camera, size = run.scene.camera, run.scene.image_size
            images[frame, "base"] = backends.render(run.drawing, camera, size)
            if not variants:
                continue
            images[frame, "msaa_off"] = backends.render(run.drawing, camera, size, multisamples=0)
            for kind in ERRORS:
                try:
                    i = pick_target(run, size, turning=kind == "turned")
                except LookupError:
                    continue
                with perturbed(run, i, kind):
                    images[frame, kind] = backends.render(run.drawing, camera, size)
    return images


def _table(scene_names, rerender_of) -> str:
    from conformance.rendering.compare import OTHER_RENDERER, SAME_RENDERER, _differing, compare_images, flip_mean

    header = ("| scene | change | same-renderer: pixels > 2 | other-renderer: pixels > 32 in 2x2 blocks "
              "| other-renderer: pixels > 4 in 3x3 blocks (shade) | raw pixels > 32 | FLIP mean |\n"
              "|---|---|---|---|---|---|---|\n")
    lines, overall, verdicts = [], {}, {}
    for scene in scene_names:
        images = render_frames(scene)
        stats: dict[str, list[tuple[float, ...]]] = {}
        for (frame, kind), image in sorted(images.items()):
            if kind != "base":
                continue
            variants = {k: v for (f, k), v in images.items() if f == frame and k != "base"}
            variants["rerender"] = rerender_of[scene, frame]
            variants["noise"] = with_noise(image, seed=frame)
            for change, other in variants.items():
                verdicts.setdefault(change, []).append(
                    (compare_images(image, other, SAME_RENDERER).passed, compare_images(image, other, OTHER_RENDERER).passed))
                row = (_differing(image, other, SAME_RENDERER.pixel_threshold, SAME_RENDERER.block).sum(),
                       _differing(image, other, OTHER_RENDERER.pixel_threshold, OTHER_RENDERER.block).sum(),
                       _differing(image, other, OTHER_RENDERER.shade_threshold, 3).sum(),
                       _differing(image, other, OTHER_RENDERER.pixel_threshold, 1).sum(),
                       flip_mean(image, other))
                stats.setdefault(change, []).append(row)
                overall.setdefault(change, []).append(row)
        for change in BENIGN + ERRORS:
            if change not in stats:
                lines.append(f"| {scene} | {change} | n/a | n/a | n/a | n/a | n/a |")
                continue
            cols = np.array(stats[change], dtype=float)
            cells = [f"{cols[:, c].min():.0f}–{cols[:, c].max():.0f}" for c in range(4)]
            cells.append(f"{cols[:, 4].min():.5f}–{cols[:, 4].max():.5f}")
            lines.append(f"| {scene} | {change} | " + " | ".join(cells) + " |")
        print(f"measured {scene}", file=sys.stderr, flush=True)
    summary = ["| change | same-renderer: pixels > 2 | other-renderer: pixels > 32 in 2x2 blocks "
               "| other-renderer: pixels > 4 in 3x3 blocks (shade) | raw pixels > 32 | FLIP mean |",
               "|---|---|---|---|---|---|"]
    for change in BENIGN + ERRORS:
        cols = np.array(overall[change], dtype=float)
        cells = [f"{cols[:, c].min():.0f}–{cols[:, c].max():.0f}" for c in range(4)]
        cells.append(f"{cols[:, 4].min():.5f}–{cols[:, 4].max():.5f}")
        summary.append(f"| {change} | " + " | ".join(cells) + " |")
    passed = ["", "Verdicts of `compare_images` on every case above (passed / cases):", "",
              "| change | same-renderer | other-renderer |", "|---|---|---|"]
    for change in BENIGN + ERRORS:
        cases = verdicts.get(change, [])
        passed.append(f"| {change} | {sum(s for s, _ in cases)} / {len(cases)} | {sum(o for _, o in cases)} / {len(cases)} |")
    return "\n".join(summary + passed) + "\n\nPer scene (min–max over the golden frames):\n\n" + header + "\n".join(lines) + "\n"


def _timing() -> float:
    """Median milliseconds of one :func:`compare_images` at 450x384 with both metrics computed."""
    from conformance.rendering.compare import OTHER_RENDERER, compare_images

    rng = np.random.default_rng(0)
    a = rng.integers(0, 256, (384, 450, 3), dtype=np.uint8)
    b = with_noise(a)
    times = []
    for _ in range(7):
        start = time.perf_counter()
        compare_images(a, b, OTHER_RENDERER)
        times.append(time.perf_counter() - start)
    return 1000 * float(np.median(times))


def _header(out: str) -> str:
    """The page's opening (``--out``): that it is generated, by what, and what its rows are."""
    command = f"python -m conformance.rendering.measure_tolerances --out {out}"
    return (f"# Golden-image tolerances: the measurements\n\n<!-- generated by `{command}`; do not edit -->\n\n"
            f"Made by `{command}` (Mesa llvmpipe under Xvfb, 450x384, the reference sync, every scene at its golden "
            "frames). Read it to see how far each image-tolerance set ([pictures.md](pictures.md#image-tolerances)) "
            "is from the changes it must pass and the errors it must fail. Against each render: benign changes, "
            "which `other-renderer` must pass: `rerender` (another process), `noise` (±1 a channel), `msaa_off` "
            "(multisampling off); errors, which both sets must fail: `moved` (one body 2 px across the view), "
            "`turned` (one box 3° about the camera's right axis), `recoloured` (its hue +60°), each on the largest "
            "body on screen with most visible pixels (`n/a`: none in that scene).\n\n")


def main(argv=None) -> int:
    from conformance import scenes
    from conformance.backends.display import virtual_display

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default=",".join(scenes.names()))
    parser.add_argument("--out", default="")
    parser.add_argument("--render-base", default="", help=argparse.SUPPRESS)  # the re-render process
    args = parser.parse_args(argv)
    chosen = [s for s in args.scenes.split(",") if s]
    with virtual_display():
        if args.render_base:
            np.savez(args.render_base, **{f"{scene}|{frame}": image for scene in chosen
                                          for (frame, _), image in render_frames(scene, variants=False).items()})
            return 0
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "rerender.npz"
            # Another process: the same renderer, nothing shared with this one's VTK state.
            subprocess.run([sys.executable, "-m", "conformance.rendering.measure_tolerances", "--scenes", ",".join(chosen), "--render-base", str(path)],
                           check=True)
            with np.load(path) as stored:
                rerender_of = {(k.split("|")[0], int(k.split("|")[1])): stored[k] for k in stored.files}
        table = _table(chosen, rerender_of)
    text = table + f"\nOne `compare_images` at 450x384: {_timing():.0f} ms (median of 7).\n"
    if args.out:
        from conformance.files import write_atomically

        write_atomically(Path(args.out), (_header(args.out) + text).encode("utf-8"))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
