"""``verdicts SPEC…``: the checks against several syncs, as markdown verdict tables.

The checks run in survey mode (``--conformance-survey``): each runs every frame and names every kind
of failure it finds with its worst figure, so a table cell is everything a sync gets wrong on a scene.
"""

from __future__ import annotations

from conformance.commands.common import add_backend_run_arguments, emit, page_header, replace_block
from conformance.validation import MAX_JOBS, argparse_type, existing_file, file_to_write, positive_int

NAME = "verdicts"
HELP = "check several syncs and print markdown verdict tables (extra arguments go to pytest, e.g. --hypothesis-profile ci)"
TAKES_PYTEST_ARGS = True

#: ``--jobs`` of this command and of ``kill-rate``: pytest processes at a time, at least 1.
jobs = argparse_type(positive_int, "--jobs", high=MAX_JOBS)


def add_arguments(parser) -> None:
    parser.add_argument("specs", nargs="+", help="sync implementations (short names or module:attribute)")
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None,
                        help="also write the markdown here")
    parser.add_argument("--jobs", type=jobs, default=None, help="pytest processes at a time (default 1)")
    add_backend_run_arguments(parser)
    parser.add_argument("--readme", type=argparse_type(existing_file, "--readme"), default=None, help="also put the scene table in this markdown file, between "
                        "'<!-- conformance:verdicts -->' and '<!-- /conformance:verdicts -->'")


def run(args, extra) -> int:
    from conformance import backends, sync
    from conformance.discrimination import verdicts

    for spec in args.specs:  # a spec that cannot load fails now, in one paragraph, not minutes later in a table
        sync.load(spec)
    outcomes = verdicts.check_all(args.specs, survey=True, pytest_args=extra, jobs=args.jobs)
    text = verdicts.verdict_tables(outcomes)
    emit(f"Checked on the {backends.describe()}.\n\n{text}", args.out, page_header(args))  # which FURY, in every copy
    if args.json:
        verdicts.save_run(args.json, outcomes)
    if args.readme:
        if args.beside:  # the scene table of every backend, this one last
            runs = [verdicts.load_run(path)[:2] for path in args.beside] + [(verdicts.current_label(), outcomes)]
            replace_block(args.readme, "verdicts", verdicts.verdicts_beside(runs))
        else:
            replace_block(args.readme, "verdicts", text.split("\n\n")[0])  # the scene table
    return 0
