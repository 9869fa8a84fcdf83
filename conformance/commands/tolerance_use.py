"""``tolerance-use [SPEC…] [--right MODULE] [--out FILE]``: how much of each tolerance right syncs use,
and which tolerances are loose (:mod:`conformance.discrimination.tolerance_use`)."""

from __future__ import annotations

from conformance.commands.common import emit
from conformance.commands.verdicts import jobs
from conformance.validation import argparse_type, file_to_write, module_name

NAME = "tolerance-use"
HELP = "run right syncs and show how much of each tolerance they use; flag the loose ones"
TAKES_PYTEST_ARGS = True


def add_arguments(parser) -> None:
    parser.add_argument("specs", nargs="*", help="right sync implementations (default: reference)")
    parser.add_argument("--right", action="append", default=[], type=argparse_type(module_name, "--right"),
                        help="also every implementation of this module of right syncs (repeatable)")
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None, help="also write the markdown here")
    parser.add_argument("--jobs", type=jobs, default=None, help="pytest processes at a time (default 1)")


def run(args, extra) -> int:
    import shlex

    from conformance import backends, sync
    from conformance.discrimination import tolerance_use, verdicts

    specs = list(args.specs) + [spec for module in args.right for spec in verdicts.implementations(module)]
    specs = specs or ["reference"]
    for spec in specs:  # a spec that cannot load fails now, in one paragraph
        sync.load(spec)
    outcomes = verdicts.check_all(specs, pytest_args=extra, jobs=args.jobs)
    from conformance.sync import printed

    sources = [w for source in args.scenes for w in ("--scenes", source)]
    failed = [o.spec for o in outcomes if not o.passed]
    if failed:
        # A figure from a failing sync says nothing about what a right one needs.
        print(f"error: {', '.join(failed)} failed the checks, so it is not a right sync and its figures are not "
              f"counted; run `{shlex.join([printed.python(), '-m', 'conformance', 'verdicts', *failed, *sources, *(['--', *extra] if extra else [])])}` "
              "to see why.")
        return 1
    worst = tolerance_use.worst_uses(u for o in outcomes for u in tolerance_use.uses(o.spec, o.records, o.images))
    made_by = shlex.join(["python", "-m", "conformance", "tolerance-use", *args.specs,
                          *[part for module in args.right for part in ("--right", module)], *sources,
                          *(["--", *extra] if extra else [])])
    emit(f"### Tolerance use, {backends.describe()}\n\nMade by `{made_by}` ({len(specs)} right syncs, "
         f"Hypothesis profile {verdicts.PROFILE} unless given).\n\n{tolerance_use.markdown(worst)}", args.out)
    missing = tolerance_use.unexplained(worst)
    if missing:
        print(f"note: {', '.join(missing)} used under {tolerance_use.LOOSE:.0%} of the allowance and no reason is "
              "written for keeping it (conformance/discrimination/tolerance_use.py, REASONS): tighten it or say why it stays.")
    return 0
