"""Run the conformance checks against several sync implementations and tabulate the verdicts.

Each implementation is checked in its own pytest process (``-m sync``: the checks that run a sync)
that writes a JSON report (``--conformance-report``); this module reads the reports and renders
markdown: a scene × implementation table with the worst error measured, a property × implementation
table, and the first failure of each failing check, which says why. It also computes the kill rate
of a set of deliberately wrong implementations. No pytest import here: the plugin writes the
records, this module only reads them.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

__all__ = ["Outcome", "check", "check_all", "command", "implementations", "kill_rate_table", "verdict_tables", "what_it_is"]


@dataclass
class Outcome:
    """One implementation's run: pytest's exit status and the plugin's records."""

    spec: str
    exitstatus: int
    records: list[dict] = field(default_factory=list)
    stderr: str = ""

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
    end = re.search(r"(?<!i\.e)(: |\. )", text)
    return (text[:end.start()] if end else text).replace("|", "/")


def command(spec: str, *, stop_at_first: bool = False, pytest_args=(), report: str | None = None) -> list[str]:
    """The pytest command line that checks ``spec`` (what a user would type, with ``python -m``)."""
    profile = [] if any(a.startswith("--hypothesis-profile") for a in pytest_args) else ["--hypothesis-profile", PROFILE]
    return [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-m", "sync", "-q", "-p", "no:cacheprovider",
            "--sync", spec, *profile, *(["--conformance-report", report] if report else []),
            *(["-x"] if stop_at_first else []), *pytest_args]


def check(spec: str, *, stop_at_first: bool = False, pytest_args=(), env=None) -> Outcome:
    """Run the sync checks on ``spec`` in a pytest process of its own and read its report."""
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.json")
        argv = command(spec, stop_at_first=stop_at_first, pytest_args=list(pytest_args), report=report)
        proc = subprocess.run(argv, capture_output=True, text=True, env=env)
        if not os.path.exists(report):
            return Outcome(spec, proc.returncode, [], (proc.stderr or proc.stdout)[-1500:])
        with open(report, encoding="utf-8") as fh:
            data = json.load(fh)
        return Outcome(spec, proc.returncode, data["records"], proc.stderr[-1500:])


def check_all(specs: list[str], *, stop_at_first: bool = False, pytest_args: list[str] = (), jobs: int | None = None,
              env=None) -> list[Outcome]:
    """Run the sync checks for every spec, ``jobs`` processes at a time (default 1: the runs are
    CPU-bound, so more processes than cores only slow each other); ``env`` is their environment."""
    with ThreadPoolExecutor(max_workers=jobs or 1) as pool:
        return list(pool.map(lambda s: check(s, stop_at_first=stop_at_first, pytest_args=pytest_args, env=env), specs))


def _cell(records: list[dict]) -> str:
    if not records:
        return "–"
    failed = [r for r in records if r["outcome"] == "failed"]
    worst = [r["worst"] for r in records if r.get("worst")]
    ratio = max((w["ratio"] for w in worst), default=None)
    error = max((w["error"] for w in worst), default=None)
    measured = f" {error:.1e} m ({ratio:.2g}×tol)" if ratio is not None else ""
    if failed:
        return f"✗ {len(failed)}/{len(records)}{measured}"
    return f"✓{measured}"


def verdict_tables(outcomes: list[Outcome]) -> str:
    """Markdown: scenes × implementations, properties × implementations, and why each failure failed."""
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
    lines += ["", "Why (the first failure of each failing check):", ""]
    for o in outcomes:
        if o.passed:
            continue
        if not o.records:
            lines.append(f"- `{o.spec}`: the run did not complete: {o.stderr.strip().splitlines()[-1] if o.stderr.strip() else o.exitstatus}")
            continue
        seen = set()
        for r in o.failed:
            if r["check"] in seen:
                continue
            seen.add(r["check"])
            lines.append(f"- `{o.spec}` · `{r['check']}` [{r['scene']}]: {r['message'][:300]}")
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


def _scene_order(name: str) -> int:
    from conformance import scenes

    names = scenes.names()
    return names.index(name) if name in names else len(names)
