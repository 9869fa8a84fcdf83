"""``bench``: what syncing, stepping, rendering and checking cost, each a ratio to a baseline measured in the same run.

Prints markdown tables: sync cost per frame against the floor at several sizes, for whole actors and
one shared actor, with the team's targets judged pass or miss (never a failing test); ways of reading
poses from pyBullet; the cost of a picture and of the image checks; with ``--suite``, whole runs of
the checks (minutes). ``--json PATH`` writes every figure, ``--readme PATH`` puts the tables between
``<!-- conformance:bench -->`` and ``<!-- /conformance:bench -->``. Nothing is written unless asked.

The benchmarks live in the checkout's top-level ``benchmarks/`` directory, not in the installed
package: this command runs from a checkout (``./kit bench``).
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

from conformance.errors import ConformanceError
from conformance.validation import argparse_type, existing_file, file_to_write, positive_int, resolve_sync

NAME = "bench"
HELP = "measure sync, render and check costs against the floor (markdown; --json, --readme; --suite for whole runs)"

#: The checkout's root, where ``benchmarks/`` lives next to ``conformance/``.
CHECKOUT = Path(__file__).resolve().parents[2]


def benchmarks():
    """The ``benchmarks`` package of this checkout (put on ``sys.path`` if it is not importable yet)."""
    if not (CHECKOUT / "benchmarks" / "__init__.py").is_file():
        raise ConformanceError(f"bench needs the kit's checkout: no benchmarks/ next to {CHECKOUT / 'conformance'} "
                               "(an installed wheel does not carry them); run it from a clone, e.g. ./kit bench")
    if str(CHECKOUT) not in sys.path:
        sys.path.insert(0, str(CHECKOUT))
    return importlib.import_module("benchmarks")


def add_arguments(parser) -> None:
    parser.add_argument("--sizes", type=argparse_type(positive_int, "--sizes", high=1_000_000), nargs="+", default=[100, 1_000, 10_000], metavar="N",
                        help="body counts of the sync figures (default: 100 1000 10000); targets are judged at every "
                             "size but the smallest, the guide comparison at the second, linearity on the last two")
    parser.add_argument("--repeats", type=argparse_type(positive_int, "--repeats", high=10_000), default=15,
                        help="rounds per figure; each figure is the best round (default 15)")
    parser.add_argument("--sync", dest="sync_given", default=None,
                        help="the sync implementation the targets judge (short name or module:attribute; default reference)")
    parser.add_argument("--only", nargs="+", choices=["syncs", "reads", "pictures", "apps"], default=None,
                        help="measure only these parts (default: syncs, reads and pictures; apps: app mode's cost "
                             "per tick against the app's own)")
    parser.add_argument("--suite", nargs="?", const="all", choices=["all", "checks"], default=False,
                        help="also time whole runs as subprocesses: pytest conformance, serial and with -n 2, serial "
                             "against a wrong sync, and ./kit test (half an hour); --suite checks: all but ./kit test")
    parser.add_argument("--suite-repeats", type=argparse_type(positive_int, "--suite-repeats", high=100), default=1, help="runs of each whole run; the best counts (default 1)")
    parser.add_argument("--json", type=argparse_type(file_to_write, "--json", suffixes=(".json",)), default=None, metavar="PATH", help="also write every figure as JSON here")
    parser.add_argument("--readme", type=argparse_type(existing_file, "--readme"), default=None, metavar="PATH", help="also put the tables in this markdown file, "
                        "between '<!-- conformance:bench -->' and '<!-- /conformance:bench -->'")


def run(args, extra) -> int:
    from conformance.commands.common import replace_block
    from conformance.backends.display import virtual_display
    from conformance.files import write_atomically

    benchmarks()
    from benchmarks import main, report

    try:
        options = main.Options(sizes=tuple(args.sizes), repeats=args.repeats, subject=resolve_sync(args.sync_given),
                               parts=tuple(args.only or main.DEFAULT_PARTS), suite=args.suite, suite_repeats=args.suite_repeats)
    except ValueError as exc:
        raise ConformanceError(str(exc)) from None
    if args.readme:
        _check_readme(args.readme)  # before minutes of measuring, not after
    if "pictures" in options.parts:
        with virtual_display():
            results = main.run(options)
    else:
        results = main.run(options)
    text = report.markdown(results)
    print(text)
    if args.json:
        write_atomically(Path(args.json), (report.as_json(results) + "\n").encode("utf-8"))
    if args.readme:
        replace_block(args.readme, _block(), text)
    return 0


def _block() -> str:
    """The README block of the backend in force: FURY 0.12's is ``bench``, FURY 2's ``bench-pygfx``."""
    from conformance import backends

    return "bench" if backends.NAME == "vtk" else f"bench-{backends.NAME}"


def _check_readme(path: str) -> None:
    start, end = f"<!-- conformance:{_block()} -->", f"<!-- /conformance:{_block()} -->"
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise ConformanceError(f"--readme {path!r}: cannot read it ({exc.strerror})") from None
    if text.count(start) != 1 or text.count(end) != 1 or text.index(start) > text.index(end):
        raise ConformanceError(f"--readme {path!r}: needs one line {start!r} followed by one line {end!r} "
                               "around the place the table goes")
