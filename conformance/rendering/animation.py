"""Watch a scene move as a sync draws it: an animated GIF (or MP4) of chosen frames, failing ones marked.

:func:`check_frame` is the frame check of ``python -m conformance check`` (every target's worst
vertex and normal against pyBullet, and changes the sync made without telling the renderer), so a frame
marked here is a frame ``check`` reports. :func:`record` runs a scene, checks and renders each
chosen frame, and writes the animation; what is guaranteed:

* one picture per chosen frame, all of one size, in frame order; the physics runs every step in
  between (only the pictures are skipped);
* a failing frame has a red border (:data:`BORDER_RED`, :func:`border_width` pixels wide) and the
  caption "frame N: <its worst problem>" on red; a passing frame has no red border, only a small
  "frame N" caption;
* on a frame where targets are drawn out of tolerance, each such target's outline where pyBullet has
  it (:mod:`conformance.rendering.outline`, magenta) is drawn over the sync's picture;
* the file is written whole or not at all (:func:`conformance.files.write_atomically`); an MP4
  needs ``imageio-ffmpeg``, and without it :func:`check_writer` refuses before anything runs.
"""

from __future__ import annotations

import importlib.util
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np

from conformance.errors import ConformanceError

__all__ = [
    "BORDER_RED",
    "FRAME_SECONDS",
    "Animation",
    "FrameCheck",
    "border_width",
    "check_frame",
    "check_writer",
    "encode",
    "mark",
    "record",
]

#: The border of a failing frame: pure red, which a GIF's palette keeps and no scene colour is.
BORDER_RED = (255, 0, 0)
#: How long each picture shows: 25 pictures a second, whatever the stride between frames.
FRAME_SECONDS = 0.04


@dataclass(frozen=True)
class FrameCheck:
    """One frame's check: every failing target (as ``check`` prints them) and the worst of them."""

    frame: int
    problems: tuple[str, ...]
    worst_vertex: str  # the worst vertex of any target, failing or not (what `check -v` prints)
    worst_problem: str | None  # the failing target furthest out of tolerance; None when the frame passes
    misplaced: tuple[str, ...] = ()  # targets whose vertices are out of tolerance: their outline is drawn

    @property
    def ok(self) -> bool:
        return not self.problems


def _ratio(error: float, tolerance: float) -> float:
    """How far out of tolerance, for ranking problems; NaN (a non-finite drawing) ranks first."""
    if error != error:
        return math.inf
    return error / tolerance if tolerance else (math.inf if error else 0.0)


def check_frame(run, frame: int, tolerance=None) -> FrameCheck:
    """Check ``run`` (a :class:`conformance.sync.runner.Run`) as it stands at ``frame`` (to ``tolerance``, by
    default the kit's)."""
    from conformance.judge import compare

    tolerance = tolerance or compare.DEFAULT
    frames = compare.link_poses(run.drawing)
    vertices = compare.compare_vertices(run.drawing, frame, tolerance, frames=frames)
    normals = compare.compare_normals(run.drawing, frame, tolerance, frames=frames)
    ranked = [(_ratio(r.error, r.tolerance), r.describe()) for r in vertices if not r.ok]
    ranked += [(_ratio(r.angle, r.tolerance), r.describe()) for r in normals if not r.ok]
    unannounced = [f"actor {name!r}: {missed}" for f, name, missed in run.unannounced if f == frame]
    problems = tuple([text for _, text in ranked] + unannounced)
    worst = max(vertices, key=lambda r: _ratio(r.error, r.tolerance)).describe() if vertices else "no targets"
    worst_problem = max(ranked, key=lambda item: item[0])[1] if ranked else (unannounced[0] if unannounced else None)
    return FrameCheck(frame=frame, problems=problems, worst_vertex=worst, worst_problem=worst_problem,
                      misplaced=tuple(r.target for r in vertices if not r.ok))


# -- marking pictures --------------------------------------------------------------------------------

def border_width(size: tuple[int, int]) -> int:
    """Pixels of red around a failing frame of ``size`` (width, height): visible, never the whole picture."""
    return max(1, min(max(3, min(size) // 40), min(size) // 4))


def _font(height: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=max(9, height))
    except (TypeError, OSError):  # a Pillow without FreeType: its fixed bitmap font
        return ImageFont.load_default()


def _wrap(draw, text: str, font, width: int, max_lines: int) -> list[str]:
    """``text`` broken into lines no wider than ``width`` pixels, at most ``max_lines`` (the last cut with …)."""
    lines, line = [], ""
    for word in text.split():
        candidate = f"{line} {word}".strip()
        if draw.textlength(candidate, font=font) <= width or not line:
            line = candidate
        else:
            lines.append(line)
            line = word
    lines.append(line)
    if len(lines) > max_lines:
        lines = lines[:max_lines]
        lines[-1] += " …"
    for i, text_line in enumerate(lines):  # a single word longer than the width: cut it
        while draw.textlength(text_line, font=font) > width and len(text_line) > 2:
            text_line = text_line[:-2] + "…"
        lines[i] = text_line
    return lines


def mark(picture: np.ndarray, check: FrameCheck) -> np.ndarray:
    """``picture`` (H, W, 3 uint8) with ``check``'s caption, and a red border if the frame fails."""
    from PIL import Image, ImageDraw

    height, width = picture.shape[:2]
    image = Image.fromarray(np.ascontiguousarray(picture, dtype=np.uint8))
    draw = ImageDraw.Draw(image)
    inset = border_width((width, height)) if not check.ok else 0
    font = _font(max(9, min(16, height // 24)))
    line_height = int(font.getbbox("Ag")[3]) + 2 if hasattr(font, "getbbox") else 12
    pad = 3
    if check.ok:
        lines = [f"frame {check.frame}"]
        text_colour, box_colour = (40, 40, 40), (235, 235, 235)
    else:
        lines = _wrap(draw, f"frame {check.frame}: {check.worst_problem}", font, width - 2 * inset - 2 * pad,
                      max_lines=max(1, min(4, (height // 3) // line_height)))
        text_colour, box_colour = (255, 255, 255), (200, 0, 0)
    box_width = min(width - 2 * inset, int(max(draw.textlength(line, font=font) for line in lines)) + 2 * pad)
    box_height = min(height - 2 * inset, len(lines) * line_height + 2 * pad)
    draw.rectangle([inset, inset, inset + box_width - 1, inset + box_height - 1], fill=box_colour)
    for i, line in enumerate(lines):
        draw.text((inset + pad, inset + pad + i * line_height), line, fill=text_colour, font=font)
    if check.misplaced:  # say what the outline is, in its colour, bottom left
        from conformance.rendering.outline import OUTLINE_COLOUR

        legend = "outline: where pyBullet has it"
        legend_width = min(width - 2 * inset, int(draw.textlength(legend, font=font)) + 2 * pad)
        top = height - inset - line_height - 2 * pad
        draw.rectangle([inset, top, inset + legend_width - 1, height - inset - 1], fill=(255, 255, 255))
        draw.text((inset + pad, top + pad), legend, fill=OUTLINE_COLOUR, font=font)
    marked = np.asarray(image).copy()
    if not check.ok:
        marked[:inset, :] = BORDER_RED
        marked[-inset:, :] = BORDER_RED
        marked[:, :inset] = BORDER_RED
        marked[:, -inset:] = BORDER_RED
    return marked


# -- writing -------------------------------------------------------------------------------------------

def _format(path: Path) -> str:
    return path.suffix.lower().lstrip(".")


def check_writer(path: Path) -> None:
    """Refuse, before anything runs, an animation this environment cannot write."""
    if _format(path) not in ("gif", "mp4"):
        raise ConformanceError(f"--gif={str(path)!r}: the kit writes .gif or .mp4 animations")
    if _format(path) == "mp4" and importlib.util.find_spec("imageio_ffmpeg") is None:
        raise ConformanceError(
            f"--gif={str(path)!r}: writing an MP4 needs the package imageio-ffmpeg, which is not installed; "
            "`pip install imageio-ffmpeg`, or give a path ending in .gif"
        )


def encode(pictures: Sequence[np.ndarray], path: Path) -> bytes:
    """The bytes of an animation of ``pictures`` in the format ``path``'s suffix names, looping, one
    picture every :data:`FRAME_SECONDS`."""
    import imageio.v3 as iio

    check_writer(path)
    stack = np.stack([np.ascontiguousarray(p, dtype=np.uint8) for p in pictures])
    if _format(path) == "gif":
        return iio.imwrite("<bytes>", stack, extension=".gif", plugin="pillow",
                           duration=int(FRAME_SECONDS * 1000), loop=0)
    # ffmpeg writes to a file it names; a private one, read back, keeps the final write atomic.
    with tempfile.TemporaryDirectory() as scratch:
        temporary = os.path.join(scratch, "animation.mp4")
        iio.imwrite(temporary, stack, extension=".mp4", plugin="FFMPEG", fps=round(1 / FRAME_SECONDS),
                    macro_block_size=1)
        with open(temporary, "rb") as fh:
            return fh.read()


@dataclass
class Animation:
    """What :func:`record` made: where, of which frames, at which size, and each frame's check."""

    path: Path
    size: tuple[int, int]
    checks: list[FrameCheck] = field(default_factory=list)

    @property
    def failing(self) -> list[FrameCheck]:
        return [c for c in self.checks if not c.ok]


def record(scene: str, implementation, frames: range, out: Path, *, size: tuple[int, int] | None = None,
           events: Iterable[Any] = (), params: dict | None = None, show_progress: bool = True,
           tolerance=None) -> Animation:
    """Run ``scene`` with ``implementation`` (a loaded sync), check and render each frame of ``frames``,
    and write the animation to ``out``. Needs a display (:func:`conformance.backends.display.ensure_display`)."""
    from conformance import backends, files
    from conformance.sync import runner
    from conformance.progress import progress
    from conformance.rendering import outline

    check_writer(out)
    pictures = []
    with runner.running(scene, implementation, events=tuple(events), **(params or {})) as run:
        size = tuple(size) if size else tuple(run.scene.image_size)
        animation = Animation(path=out, size=size)
        chosen = progress(frames, total=len(frames), what=f"{scene} → {out.name}") if show_progress else frames
        for frame in chosen:
            run.advance(frame - run.frame)
            check = check_frame(run, frame, tolerance)
            animation.checks.append(check)
            picture = backends.render(run.drawing, run.scene.camera, size)
            if check.misplaced:
                picture = outline.draw(picture, outline.expected_outline(run, check.misplaced, size))
            pictures.append(mark(picture, check))
    files.write_atomically(out, encode(pictures, out))
    return animation
