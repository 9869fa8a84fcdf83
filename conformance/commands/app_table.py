"""``app-table PATH… [--out FILE]``: run example apps that state what the kit must answer about them
(an ``EXPECT:`` line in their docstring) and write the table of what it answered, like the kill rate."""

from __future__ import annotations

from pathlib import Path

from conformance import validation
from conformance.commands.common import emit, page_header
from conformance.errors import ConformanceError
from conformance.validation import argparse_type, file_to_write

NAME = "app-table"
HELP = "run example apps (EXPECT: lines) through app mode and write the table of verdicts"


def add_arguments(parser) -> None:
    parser.add_argument("paths", nargs="+", metavar="PATH", help="example apps, or directories of them (searched "
                        "recursively for *.py)")
    parser.add_argument("--ticks", default=None, metavar="N", help="ticks of each app's own run (default 120)")
    parser.add_argument("--perturbed", default="3", metavar="K", help="perturbed runs of an app whose own run passes "
                        "(default 3)")
    parser.add_argument("--timeout", default="300", metavar="S", help="seconds one run of an app may take")
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None,
                        help="also write the markdown here (docs/app-examples-BACKEND.md)")


def example_paths(paths) -> list[Path]:
    from conformance.apps.mapping import SUFFIX  # an app's mapping beside it is not an app

    found = []
    for given in paths:
        path = Path(given)
        if path.is_dir():
            found += sorted(p for p in path.rglob("*.py") if not p.name.startswith("_") and not p.name.endswith(SUFFIX))
        elif path.is_file():
            found.append(path)
        else:
            raise ConformanceError(f"app-table: {given!r} is neither an app's .py file nor a directory of them")
    if not found:
        raise ConformanceError(f"app-table: no .py files in {', '.join(map(repr, map(str, paths)))}")
    return found


def run(args, extra) -> int:
    from conformance import backends
    from conformance.apps import examples

    ticks = None if args.ticks is None else validation.whole_number("--ticks", args.ticks, low=1,
                                                                    high=validation.MAX_STEPS)
    runs = validation.whole_number("--perturbed", args.perturbed, low=0, high=1000)
    timeout = validation.finite_non_negative("--timeout", args.timeout)
    paths = example_paths(args.paths)
    for path in paths:  # every EXPECT line read before the first (slow) run
        examples.expectation(path)
    outcomes = []
    for path in paths:
        outcome = examples.judge_example(path, ticks=ticks, perturbed=runs, timeout=timeout)
        print(f"{'ok  ' if outcome.agrees else 'DIFF'} {path}: expected {outcome.expected}, got {outcome.verdict()} "
              f"({outcome.seconds:.0f} s)", flush=True)
        outcomes.append(outcome)
    emit("\n" + examples.table(outcomes, backends.describe()), args.out, page_header(args))
    return 0 if all(o.agrees for o in outcomes) else 1
