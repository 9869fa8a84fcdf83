"""``kill-rate --wrong MODULE --right MODULE [--matrix OUT.md]``: how many deliberately wrong syncs the
checks reject; with ``--matrix``, every wrong sync through every check (survey runs) and the matrix of
which check kills which (:mod:`conformance.discrimination.kill_matrix`)."""

from __future__ import annotations

from conformance.commands.common import add_backend_run_arguments, emit, page_header, replace_block
from conformance.commands.verdicts import jobs
from conformance.validation import argparse_type, existing_file, file_to_write, module_name

NAME = "kill-rate"
HELP = "check every class of a module of wrong syncs and one of right syncs"
TAKES_PYTEST_ARGS = True


def add_arguments(parser) -> None:
    parser.add_argument("--wrong", required=True, action="append", type=argparse_type(module_name, "--wrong"),
                        help="module whose classes are wrong sync implementations (repeat for several)")
    parser.add_argument("--right", required=True, type=argparse_type(module_name, "--right"), help="module whose classes are right sync implementations")
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None, help="also write the markdown here")
    parser.add_argument("--matrix", type=argparse_type(file_to_write, "--matrix"), default=None, metavar="OUT.md",
                        help="run every wrong sync through every check (survey mode, slower) and write the kill matrix here")
    parser.add_argument("--jobs", type=jobs, default=None, help="pytest processes at a time (default 1)")
    add_backend_run_arguments(parser)
    parser.add_argument("--readme", type=argparse_type(existing_file, "--readme"), default=None, help="also put the table in this markdown file, between "
                        "'<!-- conformance:kill-rate -->' and '<!-- /conformance:kill-rate -->'")


def run(args, extra) -> int:
    from conformance import backends
    from conformance.discrimination import verdicts

    wrong = [spec for module in args.wrong for spec in verdicts.implementations(module)]
    right = verdicts.implementations(args.right)
    # A wrong implementation needs only its first failure, unless the matrix asks for every check's verdict;
    # a right one must pass everything.
    outcomes = verdicts.check_all(wrong, stop_at_first=not args.matrix, survey=bool(args.matrix), pytest_args=extra,
                                  jobs=args.jobs)
    accepted = verdicts.check_all(right, pytest_args=extra, jobs=args.jobs)
    summaries = {spec: verdicts.what_it_is(spec) for spec in wrong + right}
    text = verdicts.kill_rate_table(outcomes, accepted, summaries)
    emit(f"Checked on the {backends.describe()}.\n\n{text}", args.out, page_header(args))  # which FURY, in every copy
    if args.matrix:
        from conformance.discrimination import kill_matrix
        from conformance.files import write_atomically

        import shlex

        made_by = shlex.join(["python", "-m", "conformance", "kill-rate", *[part for module in args.wrong for part in ("--wrong", module)], "--right", args.right,
                              "--matrix", str(args.matrix), *[w for source in args.scenes for w in ("--scenes", source)], *(["--", *extra] if extra else [])])
        text_matrix = f"# Kill matrix, {backends.describe()}\n\nMade by `{made_by}`.\n\n{kill_matrix.markdown(outcomes)}\n"
        write_atomically(args.matrix, text_matrix.encode("utf-8"))
    if args.json:
        verdicts.save_run(args.json, outcomes + accepted, {spec: ("right" if spec in right else "wrong") for spec in right + wrong})
    if args.readme:
        if args.beside:
            runs = []
            for path in args.beside:
                label, kept, roles = verdicts.load_run(path)
                runs.append((label, [o for o in kept if roles.get(o.spec) == "wrong"], [o for o in kept if roles.get(o.spec) == "right"]))
            runs.append((verdicts.current_label(), outcomes, accepted))
            text = verdicts.kill_rate_beside(runs, summaries)
        replace_block(args.readme, "kill-rate", text)
    return 0 if all(o.failed for o in outcomes) and all(o.passed for o in accepted) else 1
