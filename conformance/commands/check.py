"""``check SCENE [--sync SPEC] [--frames N] [--params JSON] [--events JSON]``: replay one run frame by
frame and print each frame's worst error (what a failing check's "reproduce:" line runs).

Replacing ``check`` with ``render`` and adding ``--gif OUT.gif`` makes the same replay an animation
with the failing frames marked (the same frame check: :func:`conformance.rendering.animation.check_frame`)."""

from __future__ import annotations

from conformance import validation
from conformance.commands.common import add_tolerance_arguments, params, tolerance_of

NAME = "check"
HELP = "replay a scene with a sync and print errors frame by frame"


def add_arguments(parser) -> None:
    parser.add_argument("scene")
    # read in run(), not by the command line's common code: an empty value is refused with `error:`
    parser.add_argument("--sync", dest="sync_given", default=None, metavar="SPEC",
                        help="sync implementation (default: $CONFORMANCE_SYNC, else reference)")
    parser.add_argument("--frames", default=None, metavar="N", help="frames to replay after frame 0 "
                        "(default: the scene's step count)")
    parser.add_argument("--params", default=None, help="scene parameters as a JSON object")
    parser.add_argument("--events", default=None, help="teleports, joint resets and kicks as JSON (from a failure)")
    parser.add_argument("-v", "--verbose", action="store_true", help="print every frame, not only failing ones")
    add_tolerance_arguments(parser)


def run(args, extra) -> int:
    from conformance import scenes, sync
    from conformance.sync import runner
    from conformance.judge import diagnosis
    from conformance.bullet import events
    from conformance.rendering.animation import check_frame

    spec = scenes.get(args.scene)
    frames = spec.steps if args.frames is None else validation.whole_number("--frames", args.frames,
                                                                              high=validation.MAX_STEPS)
    scene_params = params(args.params)
    replayed = events.loads(args.events) if args.events is not None else []
    args.sync = validation.resolve_sync(args.sync_given)
    implementation = sync.load(args.sync)
    tolerance = tolerance_of(args)
    first_failure = None
    with runner.running(args.scene, implementation, events=replayed, **scene_params) as run:
        for frame in range(frames + 1):
            if frame:
                run.advance()
            check = check_frame(run, frame, tolerance)
            if check.problems or args.verbose:
                print(f"frame {frame}: {len(check.problems)} problems; worst vertex: {check.worst_vertex}")
                for line in check.problems[:5]:
                    print(f"    {line}")
            if check.problems and first_failure is None:
                first_failure = (frame, check.problems[0], diagnosis.diagnose_problems(run))
    if first_failure is None:
        print(f"PASS {args.scene} with sync {args.sync!r}: every target within tolerance for frames 0..{frames}")
        return 0
    print(f"FAIL {args.scene} with sync {args.sync!r}: first failure at frame {first_failure[0]}: {first_failure[1]}")
    if first_failure[2]:
        print(first_failure[2])
    return 1
