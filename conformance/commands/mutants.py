"""``mutants [--target NAME…] [--sample] [--results FILE.json] [--out PAGE.md]``: mutants of the kit's own
right syncs, each judged by the kit, and the page with the score and every survivor's verdict
(:mod:`conformance.discrimination.mutants`)."""

from __future__ import annotations

import shlex
import sys
import time

from conformance.validation import argparse_type, file_to_write

NAME = "mutants"
HELP = "mutate the kit's own right syncs and check every mutant (mutation score, survivors and their verdicts)"
TAKES_PYTEST_ARGS = True


def add_arguments(parser) -> None:
    from conformance.discrimination import mutants

    parser.add_argument("--target", action="append", choices=mutants.target_names(), default=None,
                        help="what to mutate (repeatable; default all): frames (frames.py, both references share it), "
                        "reference (the backend's own reference.py), vectorised (tests/: right_syncs' einsum closure)")
    parser.add_argument("--sample", action="store_true", help="only the fixed fast sample that CI keeps at 100 %% "
                        "(conformance.discrimination.mutants.SAMPLE)")
    parser.add_argument("--results", type=argparse_type(file_to_write, "--results"), default=None, metavar="FILE.json",
                        help="keep every mutant's result here, and judge only the mutants it does not have yet "
                        "(a mutant's id changes with its code, so a changed file is judged anew)")
    parser.add_argument("--budget", type=float, default=None, metavar="MINUTES",
                        help="start no mutant after this long; the page then says how many were judged")
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None, help="write the page here")


def run(args, extra) -> int:
    from conformance import backends
    from conformance.discrimination import mutants
    from conformance.errors import ConformanceError
    from conformance.files import write_atomically

    names = args.target or mutants.target_names()
    targets = {name: mutants.TARGETS[name]() for name in names}
    found = {name: mutants.generate(target) for name, target in targets.items()}
    if args.sample:
        sample = mutants.SAMPLE.get(backends.NAME, ())
        found = {name: [m for m in ms if m.id in sample] for name, ms in found.items()}
        missing = set(sample) - {m.id for ms in found.values() for m in ms} if not args.target else set()
        if missing:
            raise ConformanceError(f"the fast sample names mutants that are no longer made: {', '.join(sorted(missing))} (the "
                                   "mutated code changed); pick others from the full run's page and update conformance.discrimination.mutants.SAMPLE")
    results = mutants.load_results(args.results) if args.results else {}
    meta = {"backend": backends.NAME, "fury": backends.fury_version()}
    started = time.monotonic()
    for name, target in targets.items():
        todo = [m for m in found[name] if m.id not in results]
        if not todo or (args.budget is not None and time.monotonic() - started > 60 * args.budget):
            continue
        control = mutants.judge(target, None, pytest_args=extra)
        print(f"{name}: the unmutated copy: {control.state} in {control.seconds:.0f} s", file=sys.stderr)
        if control.state != "survived":
            raise ConformanceError(f"the unmutated copy of {target.path} does not pass ({control.state}: {control.check} "
                                   f"[{control.scene}] {control.message}); no mutant can be judged against it")
        for k, mutant in enumerate(todo, 1):
            if args.budget is not None and time.monotonic() - started > 60 * args.budget:
                break
            # A mutant still running at 4 times the unmutated copy's time is stopped: timed out.
            result = mutants.judge(target, mutant, pytest_args=extra, timeout=max(120.0, 4 * control.seconds))
            results[mutant.id] = result
            print(f"{name} {k}/{len(todo)} {mutant.id} {mutant.function}:{mutant.line}: {result.state} in {result.seconds:.0f} s "
                  f"{result.check} [{result.scene}]", file=sys.stderr)
            if args.results:
                mutants.save_results(args.results, results, meta)
    made_by = shlex.join(["python", "-m", "conformance", "mutants", *[p for n in args.target or () for p in ("--target", n)],
                          *(["--sample"] if args.sample else []), *(["--results", str(args.results)] if args.results else []),
                          *(["--out", str(args.out)] if args.out else []), *(["--", *extra] if extra else [])])
    title = f"Mutants of the kit's right syncs, {backends.describe()}"
    text = mutants.markdown(found, results, mutants.read_verdicts(), title=title, made_by=made_by,
                            sample=mutants.SAMPLE.get(backends.NAME, ()))
    if args.out:
        write_atomically(args.out, text.encode("utf-8"))
    print(text)
    judged = [results[m.id] for ms in found.values() for m in ms if m.id in results]
    verdicts = mutants.read_verdicts()
    open_gaps = [r for r in judged if r.state == "survived" and not verdicts.get(r.id, "").startswith("equivalent")]
    return 1 if open_gaps else 0
