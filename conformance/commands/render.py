"""``render SCENE… [--step N] [--out PNG | --out-dir DIR]``: a picture of a scene at a step, synced by a
sync; ``render SCENE --gif OUT.gif [--frames A:B:S]``: an animation of it, failing frames marked.

Every argument is checked (:mod:`conformance.validation`) before the display starts or anything is
written. The animation takes ``--sync``, ``--params`` and ``--events`` as ``check`` does, and its
``--frames N`` means frames 0 to N as in ``check``, so a failure's "reproduce:" line becomes an
animation by replacing ``check`` with ``render`` and adding ``--gif OUT.gif``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from conformance import validation
from conformance.commands.common import add_tolerance_arguments, params, tolerance_of
from conformance.errors import BadArgument

NAME = "render"
HELP = "render scenes at a step to PNGs, or a scene's frames to an animated GIF with failing frames marked"

#: Failing frames described one per line; the summary line lists every failing frame's number.
MAX_LISTED = 10
#: Pictures in an animation made without --frames: every k-th frame, so that at most this many.
DEFAULT_ANIMATION_FRAMES = 120


def add_arguments(parser) -> None:
    # Numbers are taken as text and checked by conformance.validation: one message shape for every refusal.
    parser.add_argument("scene", nargs="+", help="scene names, or 'all'")
    parser.add_argument("--step", default=None, metavar="N",
                        help="frames to run first (default: the scene's poster frame)")
    parser.add_argument("--sync", dest="sync_given", default=None, metavar="SPEC",
                        help="sync implementation (default: $CONFORMANCE_SYNC, else reference)")
    parser.add_argument("--params", default=None, help="scene parameters as a JSON object")
    parser.add_argument("--events", default=None, help="teleports, joint resets and kicks as JSON (from a failure)")
    add_tolerance_arguments(parser)
    parser.add_argument("--size", nargs=2, metavar=("W", "H"), default=None, help="picture size in pixels")
    parser.add_argument("--out", default=None, help="PNG path for one scene (default: OUT_DIR/SCENE-stepN.png)")
    parser.add_argument("--out-dir", default=None, help="directory for the PNGs (default: the current directory)")
    parser.add_argument("--gif", default=None, metavar="OUT",
                        help="write an animation of one scene instead: OUT.gif (or OUT.mp4 with imageio-ffmpeg)")
    parser.add_argument("--frames", default=None, metavar="A:B:S",
                        help=f"with --gif: frames A to B every S ('N' is 0:N, as in check; default: every frame, "
                        f"thinned to at most {DEFAULT_ANIMATION_FRAMES} pictures)")


@dataclass
class _Request:
    """The command's arguments, every one checked."""

    names: list[str]
    specs: dict[str, Any]
    sync: str = ""
    implementation: Any = None
    size: tuple[int, int] | None = None
    params: dict = field(default_factory=dict)
    events: list = field(default_factory=list)
    tolerance: Any = None
    step: int | None = None
    out: Path | None = None
    out_dir: Path | None = None
    gif: Path | None = None
    frames: range | None = None


def run(args, extra) -> int:
    request = _validated(args)
    from conformance.backends.display import virtual_display

    with virtual_display():
        if request.gif is not None:
            return _animate(request)
        for name in request.names:
            _render_one(name, request)
    return 0


def _validated(args) -> _Request:
    """Every argument checked, before the display starts or anything is written."""
    from conformance import scenes, sync
    from conformance.rendering import animation
    from conformance.bullet import events

    names = scenes.names() if args.scene == ["all"] else args.scene
    request = _Request(names=names, specs={name: scenes.get(name) for name in names})  # unknown names refused here
    if args.size is not None:
        request.size = validation.image_size("--size", args.size)
    request.params = params(args.params)
    request.events = events.loads(args.events) if args.events is not None else []
    request.tolerance = tolerance_of(args)
    if args.gif is not None:
        why = "--gif writes one animation; choose its frames with --frames A:B:S"
        for flag, value in (("--step", args.step), ("--out", args.out), ("--out-dir", args.out_dir)):
            validation.absent(flag, value, "left out with --gif", why)
        if len(names) != 1:
            raise BadArgument(f"scene={' '.join(args.scene)!r} (str), but should be one scene name with --gif: "
                              "an animation shows one scene.")
        request.gif = validation.animation_path("--gif", args.gif)
        spec = request.specs[names[0]]
        if args.frames is None:
            stride = max(1, -(-(spec.steps + 1) // DEFAULT_ANIMATION_FRAMES))
            request.frames = range(0, spec.steps + 1, stride)
        else:
            request.frames = validation.frame_range("--frames", args.frames)
        validation.animation_pixels("--frames", args.frames, request.frames, request.size or tuple(spec.image_size))
        animation.check_writer(request.gif)
    else:
        validation.absent("--frames", args.frames, "given only with --gif OUT.gif",
                          "a picture shows one step (--step N), an animation shows frames")
        if args.step is not None:
            request.step = validation.whole_number("--step", args.step, high=validation.MAX_STEPS)
        if args.out is not None:
            if len(names) > 1:
                raise BadArgument(f"--out={args.out!r} (str), but should be left out with {len(names)} scenes: it "
                                  "names one file; with several scenes use --out-dir.")
            validation.absent("--out-dir", args.out_dir, "left out with --out", "--out names the file itself")
            request.out = validation.file_to_write("--out", args.out, suffixes=(".png",))
        else:
            request.out_dir = validation.directory_to_write("--out-dir", args.out_dir if args.out_dir is not None else ".")
    # `--sync` is read here, not by the command line's common code, so that an empty one (or an empty
    # $CONFORMANCE_SYNC) is refused with the one-line `error:` rather than a traceback.
    request.sync = validation.resolve_sync(args.sync_given)
    request.implementation = sync.load(request.sync)  # a spec that does not load is refused here too
    return request


def _render_one(name: str, request: _Request) -> None:
    from conformance import backends, files
    from conformance.sync import runner

    spec = request.specs[name]
    step = request.step if request.step is not None else (spec.poster_step or spec.steps)
    out = request.out or request.out_dir / f"{name}-step{step}.png"
    with runner.running(name, request.implementation, events=request.events, **request.params) as run:
        run.advance(step)
        size = request.size or tuple(run.scene.image_size)
        image = backends.render(run.drawing, run.scene.camera, size)
    files.write_atomically(out, files.encode_png(image))  # never a half-written picture under the final name
    print(f"wrote {out} ({size[0]}x{size[1]}, scene {name!r} at step {step}, sync {request.sync!r})")


def _animate(request: _Request) -> int:
    """Exit status 0 when every pictured frame passes the check, 1 when any fails (as ``check``)."""
    from conformance.rendering import animation

    name, frames = request.names[0], request.frames
    made = animation.record(name, request.implementation, frames, request.gif, size=request.size,
                            events=request.events, params=request.params, tolerance=request.tolerance)
    for check in made.failing[:MAX_LISTED]:
        print(f"frame {check.frame}: {len(check.problems)} problems; worst: {check.worst_problem}")
    if len(made.failing) > MAX_LISTED:
        print(f"… and {len(made.failing) - MAX_LISTED} more failing frames (`check` lists every one)")
    span = f"frames {frames.start}..{frames[-1]}" + (f" every {frames.step}" if frames.step > 1 else "")
    print(f"wrote {made.path} ({len(frames)} pictures, {span}, {made.size[0]}x{made.size[1]}, scene {name!r}, "
          f"sync {request.sync!r})")
    if made.failing:
        failing = ", ".join(str(c.frame) for c in made.failing)
        print(f"FAIL {name} with sync {request.sync!r}: {len(made.failing)} of {len(frames)} pictured frames "
              f"fail (marked with a red border): {failing}")
        return 1
    print(f"PASS {name} with sync {request.sync!r}: every pictured frame within tolerance")
    return 0
