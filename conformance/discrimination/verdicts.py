"""Run the conformance checks against several sync implementations and tabulate the verdicts.

Each implementation is checked in its own pytest process (``-m sync``: the checks that run a sync)
that writes a JSON report (``--conformance-report``) and keeps its pictures in a results directory of
its own; this module reads the reports and renders markdown: a scene × implementation table, a
property × implementation table, and why each implementation failed. It also computes the kill rate
of a set of deliberately wrong implementations. No pytest run here: the plugin writes the records,
this module only reads them (:mod:`conformance.checks.survey` is where both agree on kinds and figures).

``verdicts`` runs in survey mode (``--conformance-survey``): every check runs every frame and its
record names every *kind* of failure it found (vertices, normals, Modified, bounds, …) with the
worst figure of each, so a cell says everything an implementation gets wrong on a scene, not only
what failed first. ``kill-rate`` needs only a first failure and stops there (``-x``, default mode).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field

from conformance.checks import survey
from conformance.progress import progress

__all__ = ["Outcome", "check", "check_all", "command", "current_label", "implementations", "kill_rate_beside", "kill_rate_table", "load_run",
           "record_kinds", "save_run", "verdicts_beside", "verdict_tables", "what_it_is"]


@dataclass
class Outcome:
    """One implementation's run: pytest's exit status and the plugin's records."""

    spec: str
    exitstatus: int
    records: list[dict] = field(default_factory=list)
    stderr: str = ""
    #: The run's image-check records (:class:`conformance.rendering.records.ImageCheck`, as dicts).
    images: list[dict] = field(default_factory=list)

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.records if r["outcome"] == "failed"]

    @property
    def passed(self) -> bool:
        return self.exitstatus == 0


#: The Hypothesis profile of these runs unless the caller names one: derandomized, so a table can be
#: regenerated, and unshrunk, so a wrong implementation is rejected at its first counter-example.
PROFILE = "triage"


def implementations(module_name: str) -> list[str]:
    """``module:name`` specs of the sync implementations a module offers: its ``__all__``, else every
    public class or function defined in it."""
    import importlib
    import inspect

    module = importlib.import_module(module_name)
    names = getattr(module, "__all__", None) or [
        name for name, obj in vars(module).items()
        if (inspect.isclass(obj) or inspect.isfunction(obj)) and obj.__module__ == module_name and not name.startswith("_")]
    return [f"{module_name}:{name}" for name in names]


def what_it_is(spec: str) -> str:
    """One line on what an implementation is: the first clause of its docstring, without the
    ``Wrong: ``/``Right: `` label that the kit's own examples start with."""
    import inspect
    import re

    from conformance.sync import load

    doc = inspect.getdoc(load(spec).factory) or ""
    text = re.sub(r"^(Wrong|Right): ", "", " ".join(doc.split("\n\n")[0].split()))
    # the first ": " or ". " outside parentheses ("static (mass 0: the ground…)" is one clause)
    end = next((m for m in re.finditer(r"(?<!i\.e)(: |\. )", text)
                if text[:m.start()].count("(") <= text[:m.start()].count(")")), None)
    return (text[:end.start()] if end else text).replace("|", "/")


def command(spec: str, *, stop_at_first: bool = False, survey: bool = False, pytest_args=(), report: str | None = None,
            results: str | None = None) -> list[str]:
    """The pytest command line that checks ``spec`` (what a user would type, with ``python -m``):
    ``stop_at_first`` adds ``-x``; ``survey`` adds ``--conformance-survey``; ``results`` is where the
    image checks keep their pictures (ignored when ``pytest_args`` name a results directory)."""
    pytest_args = list(pytest_args)
    profile = [] if any(a.startswith("--hypothesis-profile") for a in pytest_args) else ["--hypothesis-profile", PROFILE]
    own_results = results and not any(a.startswith("--conformance-results") for a in pytest_args)
    return [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-m", "sync", "-q", "-p", "no:cacheprovider",
            "--sync", spec, *profile, *(["--conformance-report", report] if report else []),
            *(["--conformance-results", results] if own_results else []),
            *(["--conformance-survey"] if survey else []), *(["-x"] if stop_at_first else []), *pytest_args]


def check(spec: str, *, stop_at_first: bool = False, survey: bool = False, pytest_args=(), env=None,
          timeout: float | None = None, fork: bool = True) -> Outcome:
    """Run the sync checks on ``spec`` in a pytest process of its own and read its report. The run's
    pictures go to a temporary directory of its own, so runs side by side never share one. A run still
    going after ``timeout`` seconds is stopped: no records, and its stderr says so. The process is forked
    from the app server (:mod:`conformance.discrimination.forked`) unless ``fork`` is false or there is none."""
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.json")
        argv = command(spec, stop_at_first=stop_at_first, survey=survey, pytest_args=list(pytest_args), report=report,
                       results=os.path.join(tmp, "results"))
        from conformance.backends.display import child_environment, dies_with_this_process
        from conformance.discrimination import forked

        try:
            proc = forked.run(argv[3:], env=child_environment(env), timeout=timeout) if fork else None
            if proc is None:
                proc = subprocess.run(argv, capture_output=True, text=True, env=child_environment(env), timeout=timeout,
                                      preexec_fn=dies_with_this_process(waited_for=True))  # none outlives a killed command
        except subprocess.TimeoutExpired:
            return Outcome(spec, -9, [], f"the run did not complete within {timeout:g} s and was stopped")
        if not os.path.exists(report):
            return Outcome(spec, proc.returncode, [], (proc.stderr or proc.stdout)[-1500:])
        with open(report, encoding="utf-8") as fh:
            data = json.load(fh)
        import dataclasses

        from conformance.reports.artefacts import read_records

        images = [dataclasses.asdict(r) for r in read_records(os.path.join(tmp, "results"))]
        return Outcome(spec, proc.returncode, data["records"], proc.stderr[-1500:], images)


def check_all(specs: list[str], *, stop_at_first: bool = False, survey: bool = False, pytest_args: list[str] = (),
              jobs: int | None = None, env=None) -> list[Outcome]:
    """Run the sync checks for every spec, ``jobs`` processes at a time (default 1: the runs are
    CPU-bound, so more processes than cores only slow each other); ``env`` is their environment.
    Outcomes come back in the order of ``specs``; a bar on a terminal counts the finished ones."""
    with ThreadPoolExecutor(max_workers=jobs or 1) as pool:
        futures = [pool.submit(check, s, stop_at_first=stop_at_first, survey=survey, pytest_args=pytest_args, env=env)
                   for s in specs]
        for _ in progress(as_completed(futures), total=len(futures), what="implementations checked"):
            pass
        return [f.result() for f in futures]


def record_kinds(record: dict) -> dict[str, dict]:
    """The kinds of failure of one record, each with its worst figure: as the plugin wrote them, or,
    for a record without them (an older report), the one kind its first failure shows."""
    if record.get("outcome") != "failed":
        return {}
    if record.get("kinds"):
        return record["kinds"]
    message = record.get("message", "")
    kind = survey.kind_of_failure(record["check"], message)
    return {kind: survey.figure_from_message(kind, message)}


def _merge_kinds(records: list[dict]) -> dict[str, tuple[dict, dict]]:
    """kind -> (its worst figure over ``records``, the record it came from), in the order of :data:`survey.KINDS`."""
    worst: dict[str, tuple[dict, dict]] = {}
    for r in records:
        for kind, fig in record_kinds(r).items():
            if survey.worse(fig, worst.get(kind, (None,))[0]):
                worst[kind] = (fig, r)
    order = list(survey.KINDS)
    return dict(sorted(worst.items(), key=lambda item: order.index(item[0]) if item[0] in order else len(order)))


def _cell(records: list[dict]) -> str:
    if not records:
        return "–"
    failed = [r for r in records if r["outcome"] == "failed"]
    if failed:
        kinds = _merge_kinds(failed)
        found = "<br>".join(f"{kind} {survey.format_figure(fig)}".strip() for kind, (fig, _) in kinds.items())
        return f"✗ {len(failed)}/{len(records)}" + (f": {found}" if found else "")
    worst = [r["worst"] for r in records if r.get("worst")]
    ratio = max((w["ratio"] for w in worst), default=None)
    error = max((w["error"] for w in worst), default=None)
    measured = f" {error:.1e} m ({ratio:.2g}×tol)" if ratio is not None else ""
    return f"✓{measured}"


def _why(outcome: Outcome) -> list[str]:
    """One line per kind of failure: its worst figure, where, and the message that showed it."""
    lines = []
    for kind, (fig, record) in _merge_kinds(outcome.failed).items():
        having = [r for r in outcome.failed if kind in record_kinds(r)]
        scenes = sorted({str(r["scene"]) for r in having if r["scene"]}, key=_scene_order)
        where = f" on {record['scene']}" if record["scene"] else ""
        target = f", {fig['target']!r}" if fig.get("target") else ""
        spread = (f"; in {len(having)} check{'s' if len(having) != 1 else ''}"
                  + (f" on {len(scenes)} scene{'s' if len(scenes) != 1 else ''} ({', '.join(scenes)})" if scenes else ""))
        message = fig.get("message") or record.get("message", "")
        worst = "worst " if fig.get("value") is not None else ""  # a kind without a measure: its first failure
        lines.append(f"- `{outcome.spec}` · **{kind}**: {worst}{survey.format_figure(fig)}{where}{target}, "
                     f"`{record['check']}`{spread}: {message[:300]}")
    return lines


def verdict_tables(outcomes: list[Outcome]) -> str:
    """Markdown: scenes × implementations, properties × implementations, and why each failure failed.

    A passing cell gives the worst vertex error measured (and its ratio to the tolerance); a failing
    one gives failing/total checks and every kind of failure with its worst figure (value, ratio to
    the tolerance, frame). "Why" has one line per implementation and kind: the worst figure, where,
    how widespread, and the message of the failure that showed it."""
    specs = [o.spec for o in outcomes]
    scenes = sorted({r["scene"] for o in outcomes for r in o.records if r["scene"]}, key=_scene_order)
    checks = sorted({r["check"] for o in outcomes for r in o.records})
    lines = ["| scene | " + " | ".join(f"`{s}`" for s in specs) + " |", "|---|" + "---|" * len(specs)]
    for scene in scenes:
        row = [_cell([r for r in o.records if r["scene"] == scene]) for o in outcomes]
        lines.append(f"| {scene} | " + " | ".join(row) + " |")
    lines += ["", "| property (check) | " + " | ".join(f"`{s}`" for s in specs) + " |", "|---|" + "---|" * len(specs)]
    for check in checks:
        row = [_cell([r for r in o.records if r["check"] == check]) for o in outcomes]
        lines.append(f"| `{check}` | " + " | ".join(row) + " |")
    lines += ["", "Why (every kind of failure of each implementation: its worst figure, where, and the failure that "
              "showed it):", ""]
    for o in outcomes:
        if o.passed:
            continue
        if not o.records:
            lines.append(f"- `{o.spec}`: the run did not complete: {o.stderr.strip().splitlines()[-1] if o.stderr.strip() else o.exitstatus}")
            continue
        lines += _why(o)
    return "\n".join(lines)


def kill_rate_table(wrong: list[Outcome], right: list[Outcome], summaries: dict[str, str] | None = None) -> str:
    """Markdown: each wrong implementation killed or not (by which check), each right one passing or
    not; ``summaries`` (spec -> one line) says what each implementation is."""
    summaries = summaries or {}
    killed = [o for o in wrong if o.failed]
    lines = [f"Kill rate: {len(killed)}/{len(wrong)} wrong implementations rejected; "
             f"{sum(o.passed for o in right)}/{len(right)} right implementations accepted.", "",
             "| implementation | what it is | verdict | first failing check |", "|---|---|---|---|"]
    for o in wrong:
        first = o.failed[0] if o.failed else None
        verdict = "killed" if first else ("ERROR" if o.exitstatus not in (0, 1) else "survived")
        lines.append(f"| `{o.spec}` | {summaries.get(o.spec, 'wrong')} | {verdict} | "
                     f"{first['check'] + ' [' + str(first['scene']) + ']' if first else ''} |")
    for o in right:
        first = o.failed[0] if o.failed else None
        lines.append(f"| `{o.spec}` | {summaries.get(o.spec, 'right')} | {'passed' if o.passed else 'REJECTED'} | "
                     f"{first['check'] + ' [' + str(first['scene']) + ']' if first else ''} |")
    return "\n".join(lines)


# -- one backend's run kept, and two backends side by side -------------------------------------------

def save_run(path: str, outcomes: list[Outcome], roles: dict[str, str] | None = None) -> None:
    """Keep a run's outcomes as JSON, with the backend that made them, to be put beside another
    backend's (:func:`verdicts_beside`, :func:`kill_rate_beside`): the backends are two environments,
    so one process never has both."""
    from conformance import backends
    from conformance.files import write_atomically

    payload = {"backend": backends.NAME, "fury": backends.fury_version(), "roles": roles or {},
               "outcomes": [{"spec": o.spec, "exitstatus": o.exitstatus, "records": o.records, "stderr": o.stderr[-2000:]}
                            for o in outcomes]}
    write_atomically(path, json.dumps(payload, indent=1, default=float).encode("utf-8"))


def load_run(path: str) -> tuple[str, list[Outcome], dict[str, str]]:
    """``(label, outcomes, roles)`` of a run kept by :func:`save_run` (roles: spec -> "wrong"/"right" for
    a kill-rate run); the label names its FURY."""
    from conformance.errors import ConformanceError

    try:
        payload = json.loads(open(path, encoding="utf-8").read())
        outcomes = [Outcome(o["spec"], int(o["exitstatus"]), o["records"], o.get("stderr", "")) for o in payload["outcomes"]]
        return f"FURY {payload['fury']} ({payload['backend']})", outcomes, payload.get("roles", {})
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ConformanceError(f"--beside {path}: not a run kept by --json ({type(exc).__name__}: {exc}); make it with "
                               "the same command and --json in the other backend's environment") from None


def current_label() -> str:
    from conformance import backends

    return f"FURY {backends.fury_version()} ({backends.NAME})"


def verdicts_beside(runs: list[tuple[str, list[Outcome]]]) -> str:
    """Markdown: scenes × implementations, each cell the verdict on every backend, labelled."""
    specs = list(dict.fromkeys(o.spec for _, outcomes in runs for o in outcomes))
    scenes = sorted({r["scene"] for _, outcomes in runs for o in outcomes for r in o.records if r["scene"]}, key=_scene_order)
    lines = ["| scene | " + " | ".join(f"`{s}`" for s in specs) + " |", "|---|" + "---|" * len(specs)]
    for scene in scenes:
        row = []
        for spec in specs:
            cells = []
            for label, outcomes in runs:
                records = [r for o in outcomes if o.spec == spec for r in o.records if r["scene"] == scene]
                cells.append(f"**{label.split(' (')[0]}**: {_cell(records)}")
            row.append("<br>".join(cells))
        lines.append(f"| {scene} | " + " | ".join(row) + " |")
    return "\n".join(lines)


def kill_rate_beside(runs: list[tuple[str, list[Outcome], list[Outcome]]], summaries: dict[str, str]) -> str:
    """Markdown: the kill rate of every backend, then each implementation's verdict on each, side by side."""
    head = [f"{label}: {sum(bool(o.failed) for o in wrong)}/{len(wrong)} wrong implementations rejected, "
            f"{sum(o.passed for o in right)}/{len(right)} right ones accepted." for label, wrong, right in runs]
    labels = [label.split(" (")[0] for label, _, _ in runs]
    lines = ["Kill rate: " + " ".join(head), "",
             "| implementation | what it is | " + " | ".join(labels) + " |", "|---|---|" + "---|" * len(runs)]
    specs = list(dict.fromkeys(o.spec for _, wrong, right in runs for o in wrong + right))
    for spec in specs:
        cells = []
        for _, wrong, right in runs:
            mine = [o for o in wrong if o.spec == spec]
            theirs = [o for o in right if o.spec == spec]
            if mine:
                first = mine[0].failed[0] if mine[0].failed else None
                verdict = "killed" if first else ("ERROR" if mine[0].exitstatus not in (0, 1) else "**survived**")
            elif theirs:
                first = theirs[0].failed[0] if theirs[0].failed else None
                verdict = "passed" if theirs[0].passed else "**REJECTED**"
            else:
                cells.append("–")
                continue
            cells.append(verdict + (f": {first['check']} [{first['scene']}]" if first else ""))
        lines.append(f"| `{spec}` | {summaries.get(spec, '')} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _scene_order(name: str) -> int:
    from conformance import scenes

    names = scenes.names()
    return names.index(name) if name in names else len(names)
