"""``compare SPEC SPEC [SCENE…]``: two sync implementations side by side on the same scenes, where their
drawings differ, and which one pyBullet agrees with.

Both run each scene (default: every scene) with the same parameters in lockstep, frames 0 to the
scene's step count (or ``--frames N``); per scene a plain table lists every target drawn more than a
tolerance apart by the two, or judged differently: the largest distance between the two drawings of
a vertex and its frame, and each one's worst error against the kit's truth in tolerances. Below the
table, a paragraph for each sync that raised (which, scene, frame), wrote NaN, changed vertex data
without ``Modified()``, or changed pyBullet's state. ``--image [FRAME]`` also renders both at FRAME
(default: the last frame; frame 0 is rendered first, as a live window would) and compares the pictures.

A side agrees with pyBullet on a scene when every vertex it drew was within tolerance at every frame,
it announced every change to VTK, left pyBullet's state alone and did not raise. Exit status: 0 when
both agree on every scene, 1 when either does not (the summary says which, where and how badly), 2 on
bad input (an unknown scene, a spec that does not load, a bad option), before anything runs.
"""

from __future__ import annotations

import json

from conformance import validation
from conformance.commands.common import params as parse_params
from conformance.errors import InvalidArgument

NAME = "compare"
HELP = "two sync implementations side by side on the same scenes, and which one pyBullet agrees with"

#: How many targets a scene's table lists before it says how many more there are.
MAX_ROWS = 15


def add_arguments(parser) -> None:
    parser.add_argument("specs", nargs=2, metavar="SPEC", help="the two sync implementations, A and B "
                        "(short names or module:attribute)")
    parser.add_argument("scene", nargs="*", help="scenes to compare them on (default: every scene)")
    parser.add_argument("--frames", default=None, metavar="N",
                        help="frames to run after frame 0 (default: each scene's own step count)")
    parser.add_argument("--params", default=None, help="scene parameters as a JSON object (with one scene only)")
    parser.add_argument("--image", nargs="?", const="last", default=None, metavar="FRAME",
                        help="also render both at FRAME (default: the last frame) and compare the pictures")


# ---- the arguments (rules in conformance.validation); each refusal is one paragraph ------

def frames_option(text: str | None) -> int | None:
    """``--frames``: None (each scene's own count) or a whole number ≥ 0 (0: frame 0 only)."""
    return None if text is None else validation.whole_number("--frames", text, high=validation.MAX_STEPS)


def image_option(text: str | None) -> int | str | None:
    """``--image [FRAME]``: None (no pictures), ``"last"``, or a whole number ≥ 0."""
    if text is None or text == "last":
        return text
    from conformance import scenes

    if text in scenes.names():  # the one mistake argparse makes likely: a scene taken for --image's FRAME
        raise validation.BadArgument(f"--image={text!r} (str), but should be a frame number, 0 or more; {text!r} is a "
                                     "scene: name the scenes before --image, or give it a frame")
    return validation.whole_number("--image", text, high=validation.MAX_STEPS)


def scene_names(names: list[str]) -> list[str]:
    """The scenes asked for, each once, in order (default: every registered scene); an unknown name
    is an error that lists the scenes there are."""
    from conformance import scenes

    known = scenes.names()
    unknown = [n for n in names if n not in known]
    if unknown:
        raise InvalidArgument(f"scene {unknown[0]!r} is not a scene; the scenes are: {', '.join(known)} "
                               "(python -m conformance scenes -v describes them)")
    return list(dict.fromkeys(names)) or known


def scene_params(scene: str, params: dict) -> None:
    """``--params`` names only parameters ``scene`` has (their values are the scene's to check)."""
    from conformance import scenes

    known = scenes.get(scene).defaults
    unknown = [k for k in params if k not in known]
    if unknown:
        raise InvalidArgument(f"--params names {unknown[0]!r}, but scene {scene!r} has no such parameter; its "
                               f"parameters are {', '.join(known)}")


def image_frame_for(image: int | str | None, frames: int, scene: str) -> int | None:
    """The frame to compare pictures at on ``scene``, which runs frames 0..``frames``."""
    if image is None or image == "last":
        return None if image is None else frames
    if image > frames:
        raise InvalidArgument(f"--image={image}, but scene {scene!r} runs frames 0..{frames} only; "
                               f"ask for a frame within them, or run more with --frames {image}")
    return image


# ---- the command -----------------------------------------------------------------------------------------

def run(args, extra) -> int:
    import contextlib

    from conformance import scenes, sync
    from conformance.discrimination import side_by_side
    from conformance.progress import progress

    frames = frames_option(args.frames)
    image = image_option(args.image)
    names = scene_names(args.scene)
    if args.params and len(names) != 1:
        raise InvalidArgument(f"--params applies to one scene, but {len(names)} are selected; name the scene "
                               "the parameters are for, e.g. compare A B mixed_shapes --params '{\"grouping\": \"by_kind\"}'")
    params = parse_params(args.params)
    if params:
        scene_params(names[0], params)
    plan = []
    for name in names:
        count = scenes.get(name).steps if frames is None else frames
        plan.append((name, count, image_frame_for(image, count, name)))
    a, b = (sync.load(spec) for spec in args.specs)  # a spec that does not load: one paragraph, exit 2
    if a.target == b.target:
        print(f"note: A and B are the same implementation ({a.target}); their drawings can differ only if it "
              "is not deterministic.\n")
    display = contextlib.nullcontext()
    if image is not None:
        from conformance.backends.display import virtual_display

        display = virtual_display()
    results = []
    with display:
        for name, count, image_frame in progress(plan, what="scenes compared"):
            result = side_by_side.compare_scene(name, a, b, frames=count, params=params, image_frame=image_frame)
            print(scene_report(result))
            print()
            results.append(result)
    print(summary(results))
    return 0 if passed(results) else 1


# ---- the report ------------------------------------------------------------------------------------------

def _table(rows: list[list[str]]) -> list[str]:
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    return ["  " + "  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows]


def _who(verdict: str) -> str:
    return {"both": "both", "A agrees": "A", "B agrees": "B", "neither": "neither"}[verdict]


def scene_report(result) -> str:
    """A scene's comparison as plain text: a heading with the verdict, the table of targets that
    differ (largest gap first; whose vertices pyBullet agrees with), and a paragraph for a sync that
    raised, NaN written, changes not announced to VTK, or pyBullet's state changed."""
    a_spec, b_spec = result.specs
    params = json.dumps(dict(result.params), sort_keys=True, default=list)
    frames = f"frames 0..{result.frames}" if result.frames else "frame 0"
    lines = [f"{result.scene}, {frames}: A = {a_spec!r}, B = {b_spec!r}", f"  params {params}",
             f"  pyBullet agrees with: {_who(result.verdict)}"]
    rows = result.differing
    if result.targets and not rows:
        widest = max(result.targets, key=lambda t: t.gap)
        lines.append(f"  every target drawn alike, within a tolerance of each other at every frame (largest distance "
                     f"{widest.describe_gap()}, {widest.target!r}); A's worst error {result.worst('A').describe()}, "
                     f"B's {result.worst('B').describe()}")
    elif rows:
        table = [["target", "largest A–B distance", "A's worst error", "B's worst error", "vertices agree"]]
        table += [[t.target, t.describe_gap(), t.a.describe(), t.b.describe(), _who(t.verdict)] for t in rows[:MAX_ROWS]]
        lines += _table(table)
        if len(rows) > MAX_ROWS:
            lines.append(f"  … and {len(rows) - MAX_ROWS} more targets that differ")
        alike = len(result.targets) - len(rows)
        if alike:
            lines.append(f"  ({alike} other target{'s' if alike != 1 else ''} drawn alike and within tolerance)")
    for side, spec in zip(("A", "B"), result.specs):
        bad = [t for t in result.targets if not (t.a if side == "A" else t.b).finite]
        if bad:
            first = min(bad, key=lambda t: (t.a if side == "A" else t.b).frame)
            judgement = first.a if side == "A" else first.b
            lines.append(f"  {side} ({spec!r}) wrote non-finite coordinates (NaN or inf) into the vertices of "
                         f"{len(bad)} target{'s' if len(bad) != 1 else ''}, first {first.target!r} at frame "
                         f"{judgement.frame}: {judgement.result.describe()}")
    for side, spec in zip(("A", "B"), result.specs):
        if side in result.touched_physics:
            lines.append(f"  {side} ({spec!r}) changed pyBullet's state in its sync call at frame "
                         f"{result.touched_physics[side]}, but a sync should only read it; from then on each side is "
                         "judged against its own run's physics")
        unannounced = result.unannounced.get(side) or []
        if unannounced:
            from conformance import backends

            frame, actor, missed = unannounced[0]
            lines.append(f"  {side} ({spec!r}) changed vertex data without {backends.ANNOUNCE} in "
                         f"{len(unannounced)} sync call{'s' if len(unannounced) != 1 else ''} (first: actor {actor!r} at "
                         f"frame {frame}: {missed}): a live window keeps drawing the old vertices")
    if result.physics_diverged is not None and not result.touched_physics:
        lines.append(f"  the two runs' pyBullet poses differ from frame {result.physics_diverged} on, though neither "
                     "sync call changed the state: each side is judged against its own run")
    if result.image is not None:
        check = result.image
        same = check.metrics.get("largest_difference", 1.0) == 0
        lines.append(f"  pictures at frame {result.image_frame}: " + (
            "identical" if same else f"{'alike within' if check.passed else 'differ beyond'} the same-renderer "
            f"tolerance: {check.message}"))
    if result.error:
        lines.append(f"  {result.error}")
    return "\n".join(lines)


def passed(results) -> bool:
    """Both sides agree with pyBullet on every scene."""
    return all(r.verdict == "both" for r in results)


def summary(results) -> str:
    """The overall verdict: both agree everywhere, or which side does not agree, on which scenes, how badly."""
    from conformance.checks import survey

    if not results:
        return "nothing compared"
    if passed(results):
        return f"both agree with pyBullet on every scene compared ({len(results)})."
    lines = []
    for side, spec in zip(("A", "B"), results[0].specs):
        where = []
        for r in results:
            if r.raised == side:
                where.append(f"{r.scene} (raised at frame {r.raised_frame})")
            elif not r.draws_right(side):
                target = r.worst_target(side)
                judgement = target.a if side == "A" else target.b
                figure = "non-finite" if not judgement.finite else f"{survey.times(judgement.ratio)}×tol"
                where.append(f"{r.scene} ({figure}, {target.target!r}, frame {judgement.frame})")
            elif side in r.touched_physics:
                where.append(f"{r.scene} (changed pyBullet's state at frame {r.touched_physics[side]})")
            elif r.unannounced.get(side):
                where.append(f"{r.scene} (vertex data changed unannounced from frame {r.unannounced[side][0][0]})")
        if where:
            lines.append(f"{side} ({spec!r}) does not agree with pyBullet on {len(where)} of {len(results)} scenes: "
                         + ", ".join(where) + ".")
        else:
            lines.append(f"{side} ({spec!r}) agrees with pyBullet on every scene compared.")
    return "\n".join(lines)
