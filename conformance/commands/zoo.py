"""``zoo [--models GLOB…] [--styles S,…] [--sample K] [--jobs N] [--out FILE] [--beside DIR] [pytest args]``: every
model pyBullet ships, made into right programs in the styles users write, each judged by app mode on this
FURY (:mod:`conformance.zoo`). Writes the programs, the survey and a journal of verdicts under
``--results`` (default ``conformance-results/zoo/BACKEND``), and the table. Exit status 0 every program
accepted, 1 some rejected or not judged. Arguments it does not know go to pytest (``--shard K/N``, ``-x``)."""

from __future__ import annotations

import fnmatch
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from conformance.commands.common import emit
from conformance.validation import argparse_type, file_to_write, positive_int, whole_number

NAME = "zoo"
HELP = "make right programs of every pybullet_data model in every style and judge each with app mode"
TAKES_PYTEST_ARGS = True


def add_arguments(parser) -> None:
    parser.add_argument("--models", action="append", default=[], metavar="GLOB",
                        help="only the models whose path in pybullet_data matches (repeatable; e.g. 'mjcf/*')")
    parser.add_argument("--styles", default="", metavar="S,…", help="only these styles (default: every one)")
    parser.add_argument("--random", type=argparse_type(whole_number, "--random", high=1000), default=20, metavar="N",
                        help="how many of random_urdfs/ to take (default 20)")
    parser.add_argument("--mistakes", default="none", metavar="all|none|M,…",
                        help="also inject these mistakes (conformance.zoo.mistakes) into the right programs, each into "
                        "one style a model: every wrong program must be rejected (default none)")
    parser.add_argument("--sample", type=argparse_type(positive_int, "--sample"), default=None, metavar="K",
                        help="judge K right programs (and K wrong ones) drawn at random from the plan (seeded by "
                        "--seed, else the commit)")
    parser.add_argument("--sample-wrong", type=argparse_type(positive_int, "--sample-wrong"), default=None, metavar="K",
                        help="judge K of the wrong programs only, drawn at random (every right program is judged)")
    parser.add_argument("--seed", type=argparse_type(whole_number, "--seed"), default=None, metavar="S")
    parser.add_argument("--ticks", type=argparse_type(positive_int, "--ticks", high=10_000), default=None, metavar="N",
                        help="ticks of each program's own run (default 40)")
    parser.add_argument("--perturbed", type=argparse_type(whole_number, "--perturbed", high=100), default=1, metavar="K",
                        help="perturbed runs of a program whose own run passes (default 1: the opening)")
    parser.add_argument("--jobs", type=argparse_type(positive_int, "--jobs", high=256), default=1, metavar="N",
                        help="pytest-xdist processes (default 1)")
    parser.add_argument("--again", action="store_true", help="judge again what the journal already holds")
    parser.add_argument("--results", default=None, metavar="DIR", help="where the programs, survey and journal go "
                        "(default conformance-results/zoo/BACKEND)")
    parser.add_argument("--beside", action="append", default=[], metavar="DIR",
                        help="another FURY's --results directory: its verdicts go in the table beside this one's")
    parser.add_argument("--out", type=argparse_type(file_to_write, "--out"), default=None,
                        help="also write the table here (docs/zoo.md)")


def plan(models, surveys: dict, styles, backend: str) -> list[tuple[str, str]]:
    """The ``(model, style)`` pairs to judge: every style that applies to every usable model."""
    from conformance.zoo.styles import applicable

    return [(m.path, s.name) for m in models for s in styles if not applicable(s, surveys[m.path], backend)]


def wrong_plan(pairs, mistakes) -> list[tuple[str, str, str]]:
    """The ``(model, style, mistake)`` triples to judge: each mistake in one of the model's styles it applies to,
    the style turning with the mistake and the model (every style meets every mistake somewhere in the zoo)."""
    import zlib

    from conformance.zoo.styles import STYLES

    by_model: dict[str, list[str]] = {}
    for model, style in pairs:
        by_model.setdefault(model, []).append(style)
    found = []
    for model, styles in by_model.items():
        for k, mistake in enumerate(mistakes):
            fits = [s for s in styles if mistake.applies(STYLES[s])]
            if fits:
                found.append((model, fits[(k + zlib.crc32(model.encode())) % len(fits)], mistake.name))
    return found


def run(args, extra) -> int:
    import random

    from conformance import backends
    from conformance.discrimination import precision
    from conformance.errors import ConformanceError
    from conformance.zoo import judging, models, table
    from conformance.zoo.mistakes import MISTAKES
    from conformance.zoo.styles import STYLES

    backend = backends.NAME
    names = [s.strip() for s in args.styles.split(",") if s.strip()] or list(STYLES)
    unknown = [s for s in names if s not in STYLES]
    if unknown:
        raise ConformanceError(f"--styles: {unknown[0]!r} is no style; the styles are {', '.join(STYLES)}")
    styles = [STYLES[s] for s in names]
    chosen = {"none": [], "all": list(MISTAKES)}.get(args.mistakes.strip(),
                                                     [m.strip() for m in args.mistakes.split(",") if m.strip()])
    unknown = [m for m in chosen if m not in MISTAKES]
    if unknown:
        raise ConformanceError(f"--mistakes: {unknown[0]!r} is no mistake; the mistakes are {', '.join(MISTAKES)}")
    results = Path(args.results or Path("conformance-results") / "zoo" / backend)
    population = [m for m in models.population(args.random)
                  if not args.models or any(fnmatch.fnmatch(m.path, g) for g in args.models)]
    if not population:
        raise ConformanceError(f"--models {' '.join(args.models)}: no model of pybullet_data matches")
    seed, source = (args.seed, "--seed") if args.seed is not None else precision.draw_seed()
    if args.sample is not None:  # the models first: surveying all of them would cost more than judging a sample
        population = sorted(random.Random(seed).sample(population, min(3 * args.sample, len(population))),
                            key=lambda m: m.path)
    start = time.perf_counter()
    print(f"zoo: surveying {len(population)} models ({backends.describe()})", file=sys.stderr)
    surveys = models.survey(population)
    # Merged into what earlier sittings surveyed: a sitting on a few models must not forget the others.
    _write_json(results / "survey.json", {**_surveyed(results), **{k: v.as_dict() for k, v in surveys.items()}})
    pairs = plan(population, surveys, styles, backend)
    wrong = wrong_plan(pairs, [MISTAKES[m] for m in chosen])
    if args.sample is not None:
        pairs = sorted(random.Random(seed).sample(pairs, min(args.sample, len(pairs))))
        wrong = sorted(random.Random(seed + 1).sample(wrong, min(args.sample, len(wrong))))
        print(f"zoo: {len(pairs) + len(wrong)} programs drawn from the plan with seed {seed} ({source}); --seed {seed} "
              "draws them again", file=sys.stderr)
    if args.sample_wrong is not None and args.sample is None:
        wrong = sorted(random.Random(seed + 1).sample(wrong, min(args.sample_wrong, len(wrong))))
        print(f"zoo: {len(wrong)} wrong programs drawn with seed {seed} ({source})", file=sys.stderr)
    journal_dir = results / "journal"
    done = {(o.model, o.style, o.mistake) for o in judging.load_journal(sorted(journal_dir.glob("*.jsonl")))
            if o.backend == backend}
    todo = pairs if args.again else [pair for pair in pairs if (*pair, "") not in done]
    todo_wrong = wrong if args.again else [triple for triple in wrong if tuple(triple) not in done]
    status = 0
    if todo or todo_wrong:
        plan_path = results / "plan.json"
        _write_json(plan_path, {"backend": backend, "pairs": todo, "wrong": todo_wrong,
                                "programs": str((results / "programs").resolve()),
                                "journal": str((journal_dir / "zoo").resolve()), "ticks": args.ticks or judging.TICKS,
                                "perturbed": args.perturbed})
        command = [sys.executable, "-m", "pytest", str(Path(__file__).resolve().parent.parent / "zoo" / "zoo_checks.py"),
                   "-p", "no:cacheprovider", "-q", "--no-header", "-rN", *(["-n", str(args.jobs)] if args.jobs > 1 else []),
                   *extra]
        already = len(pairs) + len(wrong) - len(todo) - len(todo_wrong)
        print(f"zoo: judging {len(todo)} right and {len(todo_wrong)} wrong programs ({already} already in the journal): "
              f"{' '.join(command)}", file=sys.stderr)
        env = dict(os.environ, CONFORMANCE_ZOO_PLAN=str(plan_path.resolve()))
        status = subprocess.run(command, env=env, cwd=results, check=False).returncode
    elapsed = time.perf_counter() - start
    wanted = {(*pair, "") for pair in pairs} | set(map(tuple, wrong))
    outcomes = [o for o in judging.load_journal(sorted(journal_dir.glob("*.jsonl")))
                if o.backend == backend and (o.model, o.style, o.mistake) in wanted]
    made_by = " ".join(["python", "-m", "conformance", "zoo", *sys.argv[2:]]) if sys.argv[1:2] == ["zoo"] else "python -m conformance zoo"
    made_by += f"   # in {backend}'s environment ({backends.describe()})"
    # Every sitting that judged programs into this journal, in order: the table was made by all of them.
    sittings = _sittings(results)
    if todo or todo_wrong:
        sittings.append({"command": made_by, "seconds": round(elapsed), "programs": len(todo) + len(todo_wrong)})
        _write_json(results / "run.json", {"backend": backend, "sittings": sittings})
    beside_outcomes, beside_surveys, beside_sittings = _beside(args.beside)
    commands = [_told(s) for s in beside_sittings + sittings]
    page = table.markdown(outcomes + beside_outcomes, {**beside_surveys, **surveys},
                          made_by="\n".join(commands) or made_by)
    emit(page, args.out)
    bad = [o for o in outcomes if o.outcome in (("missed", "error") if o.mistake else ("rejected", "error"))]
    if status not in (0, 1, 5) or len(outcomes) < len(wanted):
        print(f"zoo: pytest ended with status {status} and {len(wanted) - len(outcomes)} programs without a verdict",
              file=sys.stderr)
        return 2
    return 1 if bad else 0


def _beside(directories):
    from conformance.zoo import judging
    from conformance.zoo.models import Survey

    outcomes, surveys, runs = [], {}, []
    for directory in directories:
        directory = Path(directory)
        outcomes += judging.load_journal(sorted((directory / "journal").glob("*.jsonl")))
        survey = directory / "survey.json"
        if survey.exists():
            surveys.update({k: Survey(**v) for k, v in json.loads(survey.read_text(encoding="utf-8")).items()})
        runs += _sittings(directory)
    return outcomes, surveys, runs


def _surveyed(directory: Path) -> dict:
    """What a results directory's ``survey.json`` holds, model by model (empty when there is none)."""
    try:
        return dict(json.loads((Path(directory) / "survey.json").read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError):
        return {}


def _told(sitting: dict) -> str:
    """A sitting's command, with how many programs it judged and in how long where the record says."""
    told = [f"{sitting['programs']} programs" if "programs" in sitting else "",
            f"{sitting['seconds'] / 60:.0f} min" if "seconds" in sitting else ""]
    return sitting["command"] + ("; " + ", ".join(t for t in told if t) if any(told) else "")


def _sittings(directory: Path) -> list[dict]:
    """The sittings a results directory's ``run.json`` lists (each a command, its seconds and programs)."""
    path = Path(directory) / "run.json"
    try:
        return list(json.loads(path.read_text(encoding="utf-8")).get("sittings", []))
    except (OSError, ValueError, AttributeError):
        return []


def _write_json(path: Path, value) -> None:
    from conformance.files import write_atomically

    write_atomically(path, json.dumps(value, indent=1, sort_keys=True).encode("utf-8"))
