"""The command line: ``python -m conformance`` (or ``fury-conformance``).

Each command lives in its own module of :mod:`conformance.commands`:

* ``run [--sync SPEC] [pytest args]``: the conformance checks, with a verdict per scene;
* ``scenes``: the reference scenes and their parameters;
* ``render SCENE [--step N] [--out PNG]``: a picture of a scene at a step, synced by a sync;
  ``render SCENE --gif OUT.gif [--frames A:B:S]``: an animation, failing frames marked;
* ``check SCENE [--sync SPEC] [--frames N] [--params JSON] [--events JSON]``: replay one run frame
  by frame and print each frame's worst error (what a failing check's "reproduce:" line runs);
* ``compare SPEC SPEC [SCENE…]``: two syncs side by side, and which one pyBullet agrees with;
* ``verdicts SPEC…``: the checks against several syncs, as markdown verdict tables;
* ``kill-rate --wrong MODULE --right MODULE``: how many deliberately wrong syncs the checks reject;
* ``regen [SCENE…] [--missing | --failing]``: make golden snapshots anew and say what changed;
* ``bench``: sync, render and check costs as ratios to the floor measured in the same run;
* ``documented``: pybullet's behaviour measured against its documentation, as a markdown table.

Every command takes ``--scenes SOURCE`` (repeatable): a file or module of your own scenes, seen by the
command and by every process it starts (:mod:`conformance.sync.own_scenes`).
"""

from __future__ import annotations

import argparse
import importlib
import sys

from conformance.sync import own_scenes
from conformance.commands import MODULES
from conformance.errors import ConformanceError

__all__ = ["main"]


def _commands() -> dict:
    modules = [importlib.import_module(f"conformance.commands.{name}") for name in MODULES]
    return {module.NAME: module for module in modules}


def _parser(commands: dict) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m conformance", description=__doc__.splitlines()[0])
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--scenes", action="append", default=[], metavar="SOURCE",
                        help="a .py file or module of your own scenes (SceneSpec objects); repeatable. "
                        "Also $CONFORMANCE_SCENES and the conformance.scenes entry points")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, module in commands.items():
        module.add_arguments(sub.add_parser(name, help=module.HELP, parents=[common],
                                            description=module.__doc__.split("\n\n")[0]))
    return parser


def main(argv: list[str] | None = None) -> int:
    commands = _commands()
    parser = _parser(commands)
    args, extra = parser.parse_known_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)  # as given: the command line a written page names
    if "--" in extra:  # `kill-rate … -- -k chain`: what follows is pytest's, and "--" itself would end pytest's options
        extra.remove("--")
    command = commands[args.command]
    if extra and not getattr(command, "TAKES_PYTEST_ARGS", False):
        parser.error(f"unrecognized arguments: {' '.join(extra)}")
    try:
        own_scenes.load_all(args.scenes)
        own_scenes.export(args.scenes)  # the processes this command starts see the same scenes
        return command.run(args, extra)
    except ConformanceError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
