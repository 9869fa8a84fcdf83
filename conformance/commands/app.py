"""``app PATH.py [PATH.py …] [--ticks N] [--perturbed K] [--seed S] [--events JSON] [--tick NAME] [--notes N|all]``: check your own
program, unmodified: the kit runs it headless, drives its own per-frame callback, and judges what its
actors draw against every body pyBullet simulates (no mapping needed; see conformance.apps). Exit status 0
every app passed, 1 some app failed, 3 the kit itself failed on some app (its traceback is printed; the app
is not judged)."""

from __future__ import annotations

import json

from conformance import validation

NAME = "app"
HELP = "check an application as it is: its own script, actors and loop"


def add_arguments(parser) -> None:
    parser.add_argument("paths", nargs="+", metavar="PATH.py", help="the app's script(s)")
    parser.add_argument("--ticks", default=None, metavar="N", help="ticks of the app's own run (default 120; the app "
                        "may end sooner with showm.exit())")
    parser.add_argument("--perturbed", default="3", metavar="K", help="runs with the kit's teleports, kicks and joint "
                        "resets drawn by Hypothesis between ticks (default 3; 0 for none)")
    parser.add_argument("--seed", default=None, metavar="S", help="draw the perturbed runs at random from this seed "
                        "(default: derandomized, the same runs every time)")
    parser.add_argument("--events", default=None, help="one run with these events (JSON, from a failure's reproduce line)")
    parser.add_argument("--tick", default=None, metavar="NAME", help="a module-level function of the app to call once "
                        "a tick, for an app whose loop is its own")
    parser.add_argument("--timeout", default="300", metavar="S", help="seconds one run of the app may take (default 300)")
    parser.add_argument("--notes", default=str(NOTES), metavar="N|all", help=f"notes printed under each check "
                        f"(default {NOTES}; 'all' for every one)")
    parser.add_argument("--results", default=None, metavar="DIR", help="where a failing picture check writes its "
                        "pictures and their records (default: the scene checks' results directory, conformance-results)")


#: Notes printed under each check.
NOTES = 3


def _print_result(result, label: str, results=None, notes: int | None = NOTES) -> None:
    r = result.recording
    steps = sorted(set(int(s) for s in r.steps[1:])) or [0]
    print(f"{label}: {r.ticks} ticks ({'/'.join(map(str, steps))} step(s) per tick); {r.ended}")
    from conformance.apps.verdict import lead_line

    if lead_line(result.verdicts):  # the first line read names the mistake, whichever check found it
        print(f"  {lead_line(result.verdicts)}")
    for check, verdict in result.verdicts.items():
        figure = f"  worst {verdict.worst:.3g} of its allowance" if verdict.worst is not None and verdict.passed else ""
        print(f"  {'PASS' if verdict.passed else 'FAIL'} {check}{figure}")
        for line in verdict.lines[:12]:
            print(f"      {line}")
        if len(verdict.lines) > 12:
            print(f"      … {len(verdict.lines) - 12} more lines")
        # What the check could not decide, or left out, is part of its verdict (a pass that judged nothing says so).
        unique = list(dict.fromkeys(verdict.notes))
        for note in unique[:notes]:
            print(f"      note: {note}")
        if notes is not None and len(unique) > notes:
            print(f"      … {len(unique) - notes} more notes (--notes all shows them)")
        if check == "pictured" and results is not None and not verdict.passed:  # nothing written for a pass
            from conformance.apps import pictured

            written = pictured.keep(verdict, results, result.reproduce())
            if written:
                print(f"      pictures (under {results}): {', '.join(written[:3])}"
                      + (f" and {len(written) - 3} more" if len(written) > 3 else ""))
    if not result.passed:
        print(f"  reproduce: {result.reproduce()}")


def run(args, extra) -> int:
    from conformance import apps, backends
    from conformance.apps import perturbed

    ticks = apps.DEFAULT_TICKS if args.ticks is None else validation.whole_number("--ticks", args.ticks, low=1,
                                                                                  high=validation.MAX_STEPS)
    runs = validation.whole_number("--perturbed", args.perturbed, low=0, high=1000)
    timeout = validation.finite_non_negative("--timeout", args.timeout)
    seed = None if args.seed is None else validation.whole_number("--seed", args.seed)
    notes = None if str(args.notes).strip() == "all" else validation.whole_number("--notes", args.notes)
    events = None
    if args.events is not None:
        from conformance.apps import perturb

        events = [perturb.as_dict(e) for e in perturb.from_dicts(json.loads(args.events) if args.events.strip() else [])]
    from pathlib import Path

    results = Path(args.results or validation.DEFAULT_RESULTS)
    failed = kit_failed = 0
    for path in args.paths:
        print(f"app {path} ({backends.describe()})")
        try:
            result = apps.check_app(path, ticks=ticks, events=events or (), tick_function=args.tick, timeout=timeout)
        except apps.AppFailed as err:
            print(f"  FAIL runs\n      {err}")
            failed += 1
            continue
        except apps.KitFailed as err:
            print(f"  ERROR kit\n      {err}")
            print(f"verdict: NONE {path} (the kit failed, not the app)")
            kit_failed += 1
            continue
        print(f"  loop: {result.recording.loop}")
        _print_result(result, "own run" if not events else "run with the given events", results, notes)
        ok = result.passed
        if ok and events is None and runs:
            try:
                found = perturbed.search(path, examples=runs, tick_function=args.tick, timeout=timeout, seed=seed)
            except apps.KitFailed as err:
                print(f"  ERROR kit (a perturbed run)\n      {err}")
                print(f"verdict: NONE {path} (the kit failed, not the app)")
                kit_failed += 1
                continue
            if found is None:
                drawn = "" if seed is None else f", drawn from seed {seed}"
                print(f"  PASS perturbed: {runs} runs of {apps.PERTURBED_TICKS} ticks with the kit's teleports, kicks and joint resets{drawn}")
            else:
                ok = False
                _print_result(found, f"perturbed run (events {json.dumps(found.events)}; not shrunk)", results, notes)
        failed += not ok
        print(f"verdict: {'PASS' if ok else 'FAIL'} {path}")
    return 3 if kit_failed else 1 if failed else 0
