"""Apps that say what the kit must answer about them, and the table of what it answered.

An example app ends its module docstring with what it is and what the kit must say::

    MISTAKE: draws each ball with its quaternion read as (w, x, y, z)   (wrong apps only)
    EXPECT: fail attached wxyz        (or: EXPECT: pass; a diagnosis of "-" means none may be printed)

:func:`judge_example` runs the app as ``app`` does (its own run, then the perturbed runs when the own
run passes) and records what failed and which diagnoses were printed; :func:`table` is the markdown
that ``app-table`` writes into ``docs/``, like the kill rate's. The expectation is the app author's, so
an example whose verdict differs is reported as a disagreement of the kit with a reviewed answer.
"""

from __future__ import annotations

import ast
from dataclasses import asdict, dataclass, field
from pathlib import Path

from conformance.errors import ConformanceError
from conformance.apps.judge import CHECKS

__all__ = ["Expectation", "Outcome", "expectation", "judge_example", "table"]

_CHECKS = (*CHECKS, "perturbed")


@dataclass(frozen=True)
class Expectation:
    """``passes``, or the check that must fail and the diagnosis it must print (None: any, "-": none)."""

    passes: bool
    check: str | None = None
    diagnosis: str | None = None
    mistake: str = ""

    def __str__(self) -> str:
        return "pass" if self.passes else f"fail {self.check} {self.diagnosis or ''}".strip()


def expectation(path) -> Expectation:
    """The ``EXPECT:``/``MISTAKE:`` lines of the app at ``path``, validated."""
    from conformance.apps.verdict import DIAGNOSES

    path = Path(path)
    try:
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"), str(path))) or ""
    except (OSError, SyntaxError, ValueError) as exc:
        raise ConformanceError(f"{path}: cannot read its module docstring ({exc}); an example app states what the "
                               "kit must answer in it, e.g. a last line 'EXPECT: pass'") from None
    fields = {}
    for line in doc.splitlines():
        key, _, value = line.strip().partition(":")
        if key in ("EXPECT", "MISTAKE") and value.strip():
            fields[key] = value.strip()
    words = fields.get("EXPECT", "").split()
    if words == ["pass"]:
        return Expectation(True, mistake=fields.get("MISTAKE", ""))
    if len(words) in (2, 3) and words[0] == "fail" and words[1] in _CHECKS:
        diagnosis = words[2] if len(words) == 3 else None
        if diagnosis not in (None, "-") and diagnosis not in DIAGNOSES:
            raise ConformanceError(f"{path}: EXPECT names the diagnosis {diagnosis!r}, but should name one of "
                                   f"{', '.join(DIAGNOSES)} or '-' (no diagnosis)")
        return Expectation(False, words[1], diagnosis, fields.get("MISTAKE", ""))
    raise ConformanceError(f"{path}: its docstring's EXPECT line is {fields.get('EXPECT')!r}, but should be 'pass' or "
                           f"'fail CHECK [DIAGNOSIS|-]' with CHECK one of {', '.join(_CHECKS)}")


@dataclass
class Outcome:
    """What the kit said about one example app, beside what it should have said."""

    app: str
    expected: str
    mistake: str
    passed: bool
    failed: dict = field(default_factory=dict)      # check → diagnoses it printed
    error: str = ""                                 # the paragraph of an app the kit could not run
    agrees: bool = False
    seconds: float = 0.0

    def verdict(self) -> str:
        if self.passed:
            return "pass"
        return "fail " + ", ".join(f"{check}" + (f" ({', '.join(d)})" if d else "") for check, d in self.failed.items())

    as_dict = asdict


def _agrees(expected: Expectation, passed: bool, failed: dict) -> bool:
    if expected.passes or passed:
        return expected.passes and passed
    if expected.check not in failed:
        return False
    printed = [d for diagnoses in failed.values() for d in diagnoses]
    if expected.diagnosis == "-":
        return not printed
    return expected.diagnosis is None or expected.diagnosis in failed[expected.check]


def judge_example(path, *, ticks: int | None = None, perturbed: int = 3, timeout: float | None = None) -> Outcome:
    """Run the example app at ``path`` as ``python -m conformance app`` does and compare with its EXPECT line."""
    import time

    from conformance import apps
    from conformance.apps import perturbed as perturbed_runs

    expected = expectation(path)
    start = time.perf_counter()
    failed, error = {}, ""
    try:
        result = apps.check_app(path, ticks=ticks or apps.DEFAULT_TICKS, timeout=timeout)
        failed = {c: list(dict.fromkeys(v.diagnoses)) for c, v in result.verdicts.items() if not v.passed}
        if not failed and perturbed:
            found = perturbed_runs.search(path, examples=perturbed, timeout=timeout)
            if found is not None:
                failed = {"perturbed": list(dict.fromkeys(d for v in found.verdicts.values() if not v.passed
                                                          for d in v.diagnoses))}
    except apps.AppFailed as exc:
        failed, error = {"runs": []}, str(exc)
    passed = not failed
    return Outcome(str(path), str(expected), expected.mistake, passed, failed, error,
                   _agrees(expected, passed, failed), round(time.perf_counter() - start, 1))


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def table(outcomes, label: str) -> str:
    """The markdown of ``app-table``: a summary line, then one row per app."""
    right = [o for o in outcomes if o.expected == "pass"]
    wrong = [o for o in outcomes if o.expected != "pass"]
    lines = [f"Checked on the {label}: {sum(o.agrees for o in right)}/{len(right)} right apps accepted, "
             f"{sum(o.agrees for o in wrong)}/{len(wrong)} wrong apps rejected by the expected check with the "
             "expected diagnosis.", "",
             "| app | mistake | expected | the kit's verdict | agrees | s |", "|---|---|---|---|---|---|"]
    for o in sorted(outcomes, key=lambda o: (o.expected != "pass", o.app)):
        lines.append(f"| `{_cell(o.app)}` | {_cell(o.mistake) or '—'} | {_cell(o.expected)} | {_cell(o.verdict())} | "
                     f"{'yes' if o.agrees else '**no**'} | {o.seconds:.0f} |")
    return "\n".join(lines)
