"""The kill matrix: every wrong sync against every check, from survey runs (issue: discrimination
measured like mutation testing).

The kill-rate table says whether a wrong sync is rejected and by which check first. The matrix says,
for every check, whether it rejects each wrong sync on its own, so that two things show: a check that
kills no mistake on its own (it is kept for a reason the docs give, or it is strengthened), and a
mistake that only one check kills (a single point of failure: weaken that check and the mistake
passes). A cell is one of Stryker's mutant states, as they apply to a check: killed, survived,
crashed (the process died in the sync: :mod:`conformance.session.isolation`), timed out (a sync call over its
limit: :mod:`conformance.sync.time_limit`), or not run (no record of the check: deselected).
"""

from __future__ import annotations

from typing import Sequence

__all__ = ["CELLS", "REASONS", "cell", "markdown", "matrix", "single_points", "useless_checks", "why_idle"]

#: The cell states and the mark each has in the table.
CELLS = {"killed": "✕", "survived": "·", "crashed": "C", "timed out": "T", "not run": " "}


#: Why a check that kills no wrong sync exists anyway, by the module that holds it or by its name.
REASONS = {
    "test_filters.py": "judges pyBullet's collision filters as the guide documents them (issue: collision filters "
                       "behave as documented); no sync runs in it",
    "test_forces.py": "judges pyBullet's external forces as the guide and the Quickstart document them; no sync runs in it",
    "test_materials.py": "judges pyBullet's integrator, damping, restitution and friction as documented; no sync runs in it",
    "test_builds_with_defaults": "judges the reference scene itself (it builds and draws something); no sync runs in it",
    "test_builds_across_parameters": "judges the reference scene itself across its parameters; no sync runs in it",
    "test_is_deterministic_in_process": "judges the scene (stepping is repeatable), which the golden verdicts rest on",
    "test_is_deterministic_across_processes": "judges the scene (stepping is repeatable across processes)",
    "test_disconnects_its_client": "judges the scene object (every client disconnected)",
    "test_draws_its_collision_geometry": "judges the kit's own actors (built from the collision shapes)",
    "test_golden_physics": "judges pyBullet and the platform against the goldens' stored state, never the sync",
    "test_no_stale_goldens": "judges the golden directories, never the sync",
    "test_scene_camera_frames_every_body": "judges the scene's camera (each golden shows its scene)",
    "test_same_scene_renders_identically": "judges the renderer's determinism, which the same-renderer tolerance rests on",
}


def why_idle(check: str, nodeid: str = "") -> str:
    """Why ``check`` (held in the module of ``nodeid``) may kill no wrong sync, or "" when nothing excuses it."""
    module = nodeid.split("::", 1)[0].rsplit("/", 1)[-1]
    return REASONS.get(check) or REASONS.get(module, "")


def cell(records: Sequence[dict]) -> str:
    """The state of one wrong sync against one check, from that check's records (one per scene)."""
    if not records:
        return "not run"
    failed = [r for r in records if r.get("outcome") == "failed"]
    if not failed:
        return "survived"
    if any("crashed" in (r.get("kinds") or {}) for r in failed):
        return "crashed"
    if all("did not return within" in r.get("message", "") for r in failed):
        return "timed out"
    return "killed"


def matrix(outcomes) -> tuple[list[str], dict[str, dict[str, str]]]:
    """``(checks, cells)``: the checks in the order first seen, and ``cells[spec][check]``."""
    checks: list[str] = []
    cells: dict[str, dict[str, str]] = {}
    for outcome in outcomes:
        by_check: dict[str, list[dict]] = {}
        for record in outcome.records:
            by_check.setdefault(record["check"], []).append(record)
            if record["check"] not in checks:
                checks.append(record["check"])
        cells[outcome.spec] = {check: cell(by_check.get(check, ())) for check in checks}
    for row in cells.values():
        for check in checks:
            row.setdefault(check, "not run")
    return checks, cells


def useless_checks(checks, cells) -> list[str]:
    """Checks that kill no wrong sync (a crash or a time-out is the isolation's verdict, not the check's)."""
    return [c for c in checks if not any(row[c] == "killed" for row in cells.values())]


def single_points(checks, cells) -> dict[str, str]:
    """Wrong syncs killed by exactly one check, and that check."""
    found = {}
    for spec, row in cells.items():
        killers = [c for c in checks if row[c] == "killed"]
        if len(killers) == 1:
            found[spec] = killers[0]
    return found


def markdown(outcomes) -> str:
    """The matrix as markdown, then the checks that kill nothing on their own (each with why it exists
    anyway, :func:`why_idle`) and the mistakes only one check kills."""
    checks, cells = matrix(outcomes)
    nodeids = {r["check"]: r.get("nodeid", "") for o in outcomes for r in o.records}
    short = {c: c.removeprefix("test_") for c in checks}
    lines = ["Cells: " + ", ".join(f"`{mark}` {state}" for state, mark in CELLS.items() if mark.strip())
             + "; blank: not run. Columns, in order: " + ", ".join(f"{i + 1} `{short[c]}`" for i, c in enumerate(checks)) + ".",
             "", "| wrong sync | " + " | ".join(str(i + 1) for i in range(len(checks))) + " | killed by |",
             "|---|" + "---|" * len(checks) + "---|"]
    for spec, row in cells.items():
        killers = sum(row[c] == "killed" for c in checks)
        lines.append(f"| `{spec}` | " + " | ".join(CELLS[row[c]] for c in checks) + f" | {killers} |")
    lines += ["", "**Checks that kill no wrong sync on their own**:", ""]
    idle = useless_checks(checks, cells)
    lines += [f"- `{c}`: {why_idle(c, nodeids.get(c, '')) or '**no reason written: strengthen it or say why it stays**'}"
              for c in idle] or ["- none"]
    lines += ["", "**Mistakes only one check kills** (single points of failure):", ""]
    single = single_points(checks, cells)
    lines += [f"- `{spec}`: only `{check}`" for spec, check in single.items()] or ["- none"]
    return "\n".join(lines)
