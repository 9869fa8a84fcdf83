"""What a failing check's ``<failure message="…">`` says in pytest's JUnit XML (``--junitxml``): its first line,
then its diagnosis.

CI services show a JUnit failure by that attribute (GitLab's test report, the annotations of GitHub's JUnit
reporters) and fold the element's text, the whole failure, away. pytest takes the attribute from the report's
crash line (``longrepr.reprcrash.message``: a check's whole failure message), and recent pytest (9.2 here) keeps
of it only the whole lines that fit in :data:`BUDGET` characters. A vertex check's first line (the error, then the scene
with its parameters) is often 400 long, so the ``diagnosis:`` line under it, the known mistake the drawing is,
was dropped there.

:func:`lead_with_the_diagnosis` guarantees that the lines pytest keeps hold the diagnosis of a failure that has
one: when they would not, the crash line becomes the first line (cut in its middle, where the scene's
parameters are, to leave room), the diagnosis, the ``reproduce:`` line when it fits too, then the other lines.
The failure's text, in the terminal and in the XML element, is left as it was; so is a failure without a
diagnosis, or whose diagnosis is kept already.
"""

from __future__ import annotations

__all__ = ["BUDGET", "lead_with_the_diagnosis"]

#: The characters of whole lines pytest's junitxml keeps in a message attribute (``MESSAGE_ATTR_BUDGET``).
BUDGET = 500
#: At most this much of the budget goes to the diagnosis, so the first line keeps the rest.
_DIAGNOSIS_SHARE = 300


def _kept(lines: list[str]) -> list[str]:
    """The lines pytest keeps of a message attribute: whole lines while they fit in :data:`BUDGET`."""
    kept, size = [], 0
    for line in lines:
        if kept and size + len(line) + 1 > BUDGET:
            break
        kept.append(line)
        size += len(line) + 1
    return kept


def _first(lines, prefix: str) -> str | None:
    return next((line.strip() for line in lines if line.strip().startswith(prefix)), None)


def _cut_middle(line: str, width: int) -> str:
    """``line`` in at most ``width`` characters: its head and its tail (the frame and sync), "…" between."""
    if len(line) <= width:
        return line
    tail = width // 3
    return line[:width - tail - 1] + "…" + line[len(line) - tail:]


def lead_with_the_diagnosis(report) -> None:
    """Make the lines of ``report``'s crash line that pytest keeps for the XML hold its diagnosis (see the module)."""
    crash = getattr(report.longrepr, "reprcrash", None) if report.failed else None
    if crash is None or not crash.message:
        return
    lines = crash.message.splitlines()
    diagnosis = _first(lines, "diagnosis: ") or _first(str(report.longrepr).splitlines(), "diagnosis: ")
    if diagnosis is None or diagnosis in (line.strip() for line in _kept(lines)):
        return
    if len(diagnosis) > _DIAGNOSIS_SHARE:
        diagnosis = diagnosis[:_DIAGNOSIS_SHARE - 1] + "…"
    head = [_cut_middle(lines[0], BUDGET - len(diagnosis) - 2), diagnosis]
    reproduce = _first(lines, "reproduce: ")
    if reproduce is not None and len(_kept(head + [reproduce])) == 3:
        head.append(reproduce)
    moved = {line.strip() for line in head[1:]}
    crash.message = "\n".join(head + [line for line in lines[1:] if line.strip() not in moved])
