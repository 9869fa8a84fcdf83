"""The command line: ``python -m conformance`` (or ``fury-conformance``).

* ``run [--sync SPEC] [pytest args]``: the conformance checks, with a verdict per scene;
* ``scenes``: the reference scenes and their parameters;
* ``render SCENE [--step N] [--out PNG]``: a picture of a scene at a step, synced by a sync;
* ``check SCENE [--sync SPEC] [--frames N] [--params JSON] [--events JSON]``: replay one run frame
  by frame and print each frame's worst error (what a failing check's "reproduce:" line runs);
* ``verdicts SPEC…``: the checks against several syncs, as markdown verdict tables;
* ``kill-rate --wrong MODULE --right MODULE``: how many deliberately wrong syncs the checks reject;
* ``documented``: pybullet's behaviour measured against its documentation, as a markdown table;
* ``regen [SCENE…] [--missing | --failing]``: make golden snapshots anew and say what changed.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from conformance.errors import ConformanceError

__all__ = ["main"]


def _params(text: str | None) -> dict:
    if not text:
        return {}
    try:
        value = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConformanceError(f"--params={text!r} is not JSON ({exc.msg}); write e.g. --params '{{\"rows\": 3}}'") from None
    if not isinstance(value, dict):
        raise ConformanceError(f"--params={text!r} is a JSON {type(value).__name__}, but should be an object of scene parameters")
    return {k: tuple(v) if isinstance(v, list) else v for k, v in value.items()}


def _cmd_run(args, extra: list[str]) -> int:
    import subprocess

    # A pytest process of its own: in this one the kit is already imported, too late for pytest to
    # rewrite its asserts. The plug-in starts (and stops) a virtual display if it needs one.
    argv = [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-p", "no:cacheprovider", "--sync", args.sync, *extra]
    return subprocess.call(argv)


def _cmd_scenes(args, extra) -> int:
    from conformance import scenes

    for name, spec in scenes.SCENES.items():
        print(f"{name}  [{spec.origin}, {spec.steps} steps]  {spec.title}: {spec.description}")
        if args.verbose:
            for key, value in spec.defaults.items():
                print(f"    {key} = {value!r}")
    return 0


def _cmd_render(args, extra) -> int:
    from conformance import scenes
    from conformance.display import virtual_display

    names = scenes.names() if args.scene == ["all"] else args.scene
    if args.out and len(names) > 1:
        raise ConformanceError("--out names one file; with several scenes use --out-dir")
    with virtual_display():
        for name in names:
            _render_one(name, args)
    return 0


def _render_one(name: str, args) -> None:
    from conformance import backends, files, runner, scenes, sync

    spec = scenes.get(name)
    step = (spec.poster_step or spec.steps) if args.step is None else args.step
    out = Path(args.out or Path(args.out_dir) / f"{name}-step{step}.png")
    with runner.running(name, sync.load(args.sync), **_params(args.params)) as run:
        run.advance(step)
        size = tuple(args.size) if args.size else run.scene.image_size
        image = backends.render(run.drawing, run.scene.camera, size)
    files.write_atomically(out, files.encode_png(image))  # never a half-written picture under the final name
    print(f"wrote {out} ({size[0]}x{size[1]}, scene {name!r} at step {step}, sync {args.sync!r})")


def _cmd_check(args, extra) -> int:
    from conformance import compare, events, runner, scenes, sync

    spec = scenes.get(args.scene)
    frames = spec.steps if args.frames is None else args.frames
    implementation = sync.load(args.sync)
    first_failure = None
    with runner.running(args.scene, implementation, events=events.loads(args.events or "[]"), **_params(args.params)) as run:
        for frame in range(frames + 1):
            if frame:
                run.advance()
            results = compare.compare_vertices(run.drawing, frame)
            problems = [r.describe() for r in results if not r.ok]
            problems += [r.describe() for r in compare.compare_normals(run.drawing, frame) if not r.ok]
            problems += [f"actor {name!r} changed without Modified()" for f, name in run.unannounced if f == frame]
            worst = max(results, key=lambda r: (r.error != r.error, r.error / r.tolerance if r.tolerance else r.error))
            if problems or args.verbose:
                print(f"frame {frame}: {len(problems)} problems; worst vertex: {worst.describe()}")
                for line in problems[:5]:
                    print(f"    {line}")
            if problems and first_failure is None:
                first_failure = (frame, problems[0])
    if first_failure is None:
        print(f"PASS {args.scene} with sync {args.sync!r}: every target within tolerance for frames 0..{frames}")
        return 0
    print(f"FAIL {args.scene} with sync {args.sync!r}: first failure at frame {first_failure[0]}: {first_failure[1]}")
    return 1


def _cmd_verdicts(args, extra) -> int:
    from conformance import verdicts

    outcomes = verdicts.check_all(args.specs, pytest_args=extra, jobs=args.jobs)
    text = verdicts.verdict_tables(outcomes)
    _emit(text, args.out)
    if args.readme:
        _replace_block(args.readme, "verdicts", text.split("\n\n")[0])  # the scene table
    return 0


def _cmd_kill_rate(args, extra) -> int:
    from conformance import verdicts

    wrong, right = verdicts.implementations(args.wrong), verdicts.implementations(args.right)
    # A wrong implementation needs only its first failure; a right one must pass everything.
    outcomes = verdicts.check_all(wrong, stop_at_first=True, pytest_args=extra, jobs=args.jobs)
    accepted = verdicts.check_all(right, pytest_args=extra, jobs=args.jobs)
    summaries = {spec: verdicts.what_it_is(spec) for spec in wrong + right}
    text = verdicts.kill_rate_table(outcomes, accepted, summaries)
    _emit(text, args.out)
    if args.readme:
        _replace_block(args.readme, "kill-rate", text)
    return 0 if all(o.failed for o in outcomes) and all(o.passed for o in accepted) else 1


def _cmd_regen(args, extra) -> int:
    from conformance import scenes
    from conformance.display import virtual_display
    from conformance.rendering import golden, snapshots

    names = args.scene or scenes.names()
    for name in names:
        scenes.get(name)  # an unknown name fails before anything is rendered or written
    directory = Path(args.golden_dir) if args.golden_dir else golden.default_dir()
    mode = "missing" if args.missing else "failing" if args.failing else "all"
    counts = {"new": 0, "changed": 0, "unchanged": 0}
    with virtual_display():
        for name in names:
            for change in snapshots.regenerate(name, directory, mode=mode):
                counts[change.status] += 1
                print(change.describe())
    print(f"goldens in {directory}: {counts['new']} new, {counts['changed']} changed, {counts['unchanged']} unchanged"
          + ("" if mode == "all" else f" (only {mode} ones were made)"))
    return 0


def _cmd_documented(args, extra) -> int:
    from conformance import documented

    _emit(documented.table(), args.out)
    return 0


def _emit(text: str, out: str | None) -> None:
    print(text)
    if out:
        Path(out).write_text(text + "\n", encoding="utf-8")


def _replace_block(path: str, name: str, text: str) -> None:
    """Put ``text`` between the lines ``<!-- conformance:NAME -->`` and ``<!-- /conformance:NAME -->``
    of the markdown file ``path`` (written whole, atomically)."""
    start, end = f"<!-- conformance:{name} -->", f"<!-- /conformance:{name} -->"
    target = Path(path)
    try:
        old = target.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConformanceError(f"--readme {path!r}: cannot read it ({exc.strerror})") from None
    if old.count(start) != 1 or old.count(end) != 1 or old.index(start) > old.index(end):
        raise ConformanceError(f"--readme {path!r}: needs one line {start!r} followed by one line {end!r} "
                               "around the place the table goes")
    new = old[:old.index(start) + len(start)] + "\n" + text.strip() + "\n" + old[old.index(end):]
    tmp = target.with_name(target.name + ".tmp")
    tmp.write_text(new, encoding="utf-8")
    tmp.replace(target)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m conformance", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run the conformance checks (extra arguments go to pytest)")
    run.add_argument("--sync", default=None, help="sync implementation (short name or module:attribute)")

    listing = sub.add_parser("scenes", help="list the reference scenes")
    listing.add_argument("-v", "--verbose", action="store_true", help="also list parameters and defaults")

    render = sub.add_parser("render", help="render scenes at a step to PNGs")
    render.add_argument("scene", nargs="+", help="scene names, or 'all'")
    render.add_argument("--step", type=int, default=None, help="frames to run first (default: the scene's poster frame)")
    render.add_argument("--sync", default="reference")
    render.add_argument("--params", default=None, help="scene parameters as a JSON object")
    render.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), default=None)
    render.add_argument("--out", default=None, help="PNG path for one scene (default: OUT_DIR/SCENE-stepN.png)")
    render.add_argument("--out-dir", default=".", help="directory for the PNGs (default: the current directory)")

    check = sub.add_parser("check", help="replay a scene with a sync and print errors frame by frame")
    check.add_argument("scene")
    check.add_argument("--sync", default=None)
    check.add_argument("--frames", type=int, default=None)
    check.add_argument("--params", default=None, help="scene parameters as a JSON object")
    check.add_argument("--events", default=None, help="teleports, joint resets and kicks as JSON (from a failure)")
    check.add_argument("-v", "--verbose", action="store_true", help="print every frame, not only failing ones")
    verdict = sub.add_parser("verdicts", help="check several syncs and print markdown verdict tables "
                                                "(extra arguments go to pytest, e.g. --hypothesis-profile ci)")
    verdict.add_argument("specs", nargs="+", help="sync implementations (short names or module:attribute)")
    verdict.add_argument("--out", default=None, help="also write the markdown here")
    verdict.add_argument("--jobs", type=int, default=None, help="pytest processes at a time (default 1)")
    verdict.add_argument("--readme", default=None, help="also put the scene table in this markdown file, between "
                         "'<!-- conformance:verdicts -->' and '<!-- /conformance:verdicts -->'")

    kill = sub.add_parser("kill-rate", help="check every class of a module of wrong syncs and one of right syncs")
    kill.add_argument("--wrong", required=True, help="module whose classes are wrong sync implementations")
    kill.add_argument("--right", required=True, help="module whose classes are right sync implementations")
    kill.add_argument("--out", default=None, help="also write the markdown here")
    kill.add_argument("--jobs", type=int, default=None)
    kill.add_argument("--readme", default=None, help="also put the table in this markdown file, between "
                      "'<!-- conformance:kill-rate -->' and '<!-- /conformance:kill-rate -->'")

    regen = sub.add_parser("regen", help="make golden snapshots anew (reference sync), atomically; print what changed")
    regen.add_argument("scene", nargs="*", help="scene names (default: every scene)")
    which = regen.add_mutually_exclusive_group()
    which.add_argument("--missing", action="store_true", help="only goldens that are missing or unreadable")
    which.add_argument("--failing", action="store_true", help="only goldens that are missing, unreadable or fail "
                       "the render check with the reference sync")
    regen.add_argument("--golden-dir", default=None, help="directory of goldens (default: the kit's own)")

    doc = sub.add_parser("documented", help="measure pybullet against its documentation and print the table")
    doc.add_argument("--out", default=None, help="also write the markdown here")
    return parser


def main(argv: list[str] | None = None) -> int:
    from conformance.sync import resolve_spec

    args, extra = _parser().parse_known_args(argv)
    if extra and args.command not in ("run", "verdicts", "kill-rate"):
        _parser().error(f"unrecognized arguments: {' '.join(extra)}")
    if hasattr(args, "sync"):
        args.sync = resolve_spec(args.sync)
    handler = {"run": _cmd_run, "scenes": _cmd_scenes, "render": _cmd_render, "check": _cmd_check,
               "verdicts": _cmd_verdicts, "kill-rate": _cmd_kill_rate, "documented": _cmd_documented,
               "regen": _cmd_regen}[args.command]
    try:
        return handler(args, extra)
    except ConformanceError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
