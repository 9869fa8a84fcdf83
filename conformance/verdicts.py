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

__all__ = ["Outcome", "check_all", "kill_rate_table", "verdict_tables"]


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


def _run_one(spec: str, stop_at_first: bool, pytest_args: list[str]) -> Outcome:
    with tempfile.TemporaryDirectory() as tmp:
        report = os.path.join(tmp, "report.json")
        argv = [sys.executable, "-m", "pytest", "--pyargs", "conformance", "-m", "sync", "-q", "-p", "no:cacheprovider",
                "--sync", spec, "--conformance-report", report, *(["-x"] if stop_at_first else []), *pytest_args]
        proc = subprocess.run(argv, capture_output=True, text=True)
        if not os.path.exists(report):
            return Outcome(spec, proc.returncode, [], (proc.stderr or proc.stdout)[-1500:])
        with open(report, encoding="utf-8") as fh:
            data = json.load(fh)
        return Outcome(spec, proc.returncode, data["records"], proc.stderr[-1500:])


def check_all(specs: list[str], *, stop_at_first: bool = False, pytest_args: list[str] = (), jobs: int | None = None) -> list[Outcome]:
    """Run the sync checks for every spec, ``jobs`` processes at a time (default 1: VTK 9.3 aborts a
    process that fails to get a GLX context, which llvmpipe does now and then when several
    processes start rendering at once on a loaded machine)."""
    with ThreadPoolExecutor(max_workers=jobs or 1) as pool:
        return list(pool.map(lambda s: _run_one(s, stop_at_first, list(pytest_args)), specs))


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


def kill_rate_table(wrong: list[Outcome], right: list[Outcome]) -> str:
    """Markdown: each wrong implementation killed or not (by which check), each right one passing or not."""
    killed = [o for o in wrong if o.failed]
    lines = [f"Kill rate: {len(killed)}/{len(wrong)} wrong implementations rejected; "
             f"{sum(o.passed for o in right)}/{len(right)} right implementations accepted.", "",
             "| implementation | expected | verdict | first failing check |", "|---|---|---|---|"]
    for o in wrong:
        first = o.failed[0] if o.failed else None
        verdict = "killed" if first else ("ERROR" if o.exitstatus not in (0, 1) else "survived")
        lines.append(f"| `{o.spec}` | wrong | {verdict} | {first['check'] + ' [' + str(first['scene']) + ']' if first else ''} |")
    for o in right:
        first = o.failed[0] if o.failed else None
        lines.append(f"| `{o.spec}` | right | {'passed' if o.passed else 'REJECTED'} | "
                     f"{first['check'] + ' [' + str(first['scene']) + ']' if first else ''} |")
    return "\n".join(lines)


def _scene_order(name: str) -> int:
    from conformance import scenes

    names = scenes.names()
    return names.index(name) if name in names else len(names)
