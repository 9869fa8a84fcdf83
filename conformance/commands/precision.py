"""``precision [SPEC…] [--right MODULE] [--apps GLOB…] --seeds N``: how often the kit rejects right syncs
and right apps over random draws, with each check's worst use of its allowances
(:mod:`conformance.discrimination.precision`). Exits 1 on any false alarm."""

from __future__ import annotations

from conformance.commands.common import emit
from conformance.commands.verdicts import jobs
from conformance.validation import argparse_type, file_to_write, module_name, positive_int, whole_number

NAME = "precision"
HELP = "run right syncs and right apps over many random draws and report every false alarm"
TAKES_PYTEST_ARGS = False


def add_arguments(parser) -> None:
    parser.add_argument("specs", nargs="*", help="right sync implementations (default: reference, unless only --apps)")
    parser.add_argument("--right", action="append", default=[], type=argparse_type(module_name, "--right"),
                        help="also every implementation of this module of right syncs (repeatable)")
    parser.add_argument("--apps", action="append", default=[], metavar="GLOB",
                        help="right apps to run, their own run and --app-runs perturbed runs from each seed (repeatable)")
    parser.add_argument("--seeds", type=argparse_type(positive_int, "--seeds", high=1_000_000), default=10,
                        help="processes per sync (seeds first-seed, first-seed+1, …; default 10)")
    parser.add_argument("--right-seeds", type=argparse_type(positive_int, "--right-seeds", high=1_000_000), default=None,
                        metavar="M", help="processes per sync of the --right modules (default: --seeds): the named syncs "
                        "get the most draws")
    parser.add_argument("--app-seeds", type=argparse_type(positive_int, "--app-seeds", high=1_000_000), default=None,
                        metavar="M", help="seeds per app (default: --seeds)")
    parser.add_argument("--first-seed", type=argparse_type(whole_number, "--first-seed"), default=1, metavar="S")
    parser.add_argument("--factor", type=argparse_type(positive_int, "--factor", high=100_000), default=10,
                        help="default-profile runs of each check one process stands for (its examples are this "
                        "multiple of the default's; default 10)")
    parser.add_argument("--checks", default="", metavar="EXPR",
                        help="only the drawing checks pytest's -k EXPR picks: to give the checks that draw their own "
                        "scene (the physics laws) many more runs at a small cost, e.g. --checks 'not test_vertices_match "
                        "and not test_syncing_every and not test_builds_across and not test_sync_order'")
    parser.add_argument("--app-runs", type=argparse_type(whole_number, "--app-runs", high=1000), default=3, metavar="K",
                        help="perturbed runs of each app per seed (default 3)")
    parser.add_argument("--jobs", type=jobs, default=None, help="processes at a time (default 1)")
    parser.add_argument("--timeout", type=argparse_type(positive_int, "--timeout"), default=3600, metavar="S",
                        help="seconds one process may take before it is stopped (default 3600)")
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None, help="also write the markdown here")
    parser.add_argument("--journal", type=argparse_type(file_to_write, "--journal"), default=None, metavar="FILE.jsonl",
                        help="keep every draw here as it finishes, and make again only the draws it does not hold: "
                        "a long run stopped goes on where it was")


def run(args, extra) -> int:
    import glob
    import shlex
    import sys

    from conformance import backends, sync
    from conformance.discrimination import precision, verdicts

    named = list(args.specs) or ([] if args.apps or args.right else ["reference"])
    others = [spec for module in args.right for spec in verdicts.implementations(module) if spec not in named]
    specs = named + others
    for spec in specs:  # a spec that cannot load fails now, in one paragraph
        sync.load(spec)
    paths = sorted({path for pattern in args.apps for path in glob.glob(pattern)})
    missing = [pattern for pattern in args.apps if not glob.glob(pattern)]
    if missing:
        print(f"error: --apps {', '.join(map(repr, missing))} matched no file", file=sys.stderr)
        return 2
    def seeds(count):
        return list(range(args.first_seed, args.first_seed + (count or args.seeds)))

    journal = precision.Journal(args.journal) if args.journal else None
    common = {"jobs": args.jobs, "timeout": args.timeout, "journal": journal}
    # The few draws first, the named syncs' many last: a long run stopped part-way has some of everything,
    # and with --journal a second run with fewer --seeds tabulates what the first made.
    app_runs = precision.app_draws(paths, seeds(args.app_seeds), runs=args.app_runs, **common) if paths else []
    drawn = {"factor": args.factor, "select": args.checks}
    syncs = precision.sync_draws(others, seeds(args.right_seeds), **drawn, **common)
    syncs = precision.sync_draws(named, seeds(args.seeds), **drawn, **common) + syncs
    made_by = shlex.join(["python", "-m", "conformance", "precision", *args.specs,
                          *[part for module in args.right for part in ("--right", module)],
                          *[part for pattern in args.apps for part in ("--apps", pattern)],
                          *[w for source in args.scenes for w in ("--scenes", source)],
                          "--seeds", str(args.seeds), *(["--right-seeds", str(args.right_seeds)] if args.right_seeds else []),
                          *(["--app-seeds", str(args.app_seeds)] if args.app_seeds else []),
                          "--first-seed", str(args.first_seed), "--factor", str(args.factor),
                          *(["--checks", args.checks] if args.checks else []),
                          *(["--app-runs", str(args.app_runs)] if paths else [])])
    emit(precision.markdown(syncs, app_runs, made_by=made_by, backend=backends.describe()), args.out)
    alarms = any(d.false_alarms or d.broken for d in syncs) or any(d.failed or d.error for d in app_runs)
    return 1 if alarms else 0
