"""The confusion matrix of diagnoses: for every wrong program or sync whose mistake is known, the mistake the
kit's failure leads with against the one that was made (issue 48: a diagnosis is right or silent).

A *case* is one wrong thing the kit rejected, from one of four corpora: the wrong syncs of ``tests/`` (their
docstring's ``Diagnosis:`` line), the wrong example apps (their ``EXPECT:`` line), the soft-body wrong syncs,
and the mistakes injected into the model zoo (:data:`conformance.zoo.mistakes.MISTAKES`). Its *cell* is
``right`` (the expected name leads; for a mistake outside the catalogue, labelled ``-``: nothing is named),
``none`` (nothing named where a name was expected) or ``other:NAME`` (a name that is not the mistake made:
the user would fix what was not broken). A cell is worse than another in that order (:func:`worse`), which is
what the CI tests hold each case to against the committed record (``docs/confusion-BACKEND.json``).
"""

from __future__ import annotations

import json
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

from conformance.judge.ties import UNDECIDED  # names of two mistakes at once: none of the two, and neither wrong

__all__ = ["CORPORA", "UNDECIDED", "Case", "cell", "load", "markdown", "record", "save", "worse"]

#: The corpora, in the order the page shows them, and what each is.
CORPORA = {
    "syncs": "the wrong syncs of `tests/` (`wrong_syncs`, `order_syncs`, `soft_syncs`), each run as "
             "`pytest --sync … -x` runs it: the first failure a user reads",
    "apps": "the wrong example apps of `examples/BACKEND/wrong/`, each judged as `python -m conformance app` judges "
            "it: the line its report leads with",
    "zoo": "the mistakes injected into the model zoo (docs/zoo.md), each program's latest verdict in the zoo's "
           "journal: the line its report leads with",
}


@dataclass
class Case:
    """One rejected wrong thing: which, the mistake made (``expected``, "-" for one outside the catalogue) and
    the one the kit's failure leads with (``named``, "" for none)."""

    corpus: str
    item: str
    expected: str
    named: str
    where: str = ""                           # the check (and scene) that named it, or the first failure's
    also: list = field(default_factory=list)  # the other names the failure printed, in its order (not kept)

    @property
    def cell(self) -> str:
        return cell(self.expected, self.named)





def cell(expected: str, named: str) -> str:
    """``right``, ``none`` or ``other:NAME`` for a case that should name ``expected`` ("-": nothing) and names
    ``named`` ("" nothing)."""
    if named == (expected if expected != "-" else "") or (named and named in expected.split("|")):
        return "right"  # "a|b": the drawing calls for one of two names (a mesh scale the same on every axis or not)
    return "none" if not named or expected in UNDECIDED.get(named, ()) else f"other:{named}"


_ORDER = {"right": 0, "none": 1}


def worse(before: str, now: str) -> bool:
    """Whether cell ``now`` is worse than ``before``: right, then none, then a wrong name; one wrong name for
    another is worse too (what the user is sent to fix changed)."""
    rank_before, rank_now = _ORDER.get(before, 2), _ORDER.get(now, 2)
    return rank_now > rank_before or (rank_now == 2 and now != before)


def record(cases) -> dict:
    """The committed record of ``cases``: corpus → item → cell."""
    found = defaultdict(dict)
    for case in cases:
        found[case.corpus][case.item] = case.cell
    return {corpus: dict(sorted(items.items())) for corpus, items in sorted(found.items())}


def save(path, cases, meta: dict) -> None:
    """Write ``cases`` and ``meta`` (the FURY, the command) to ``path``, atomically: one line a case, ``[item,
    expected, named, where]`` under its corpus (the zoo's without ``where``: its page lists none), so that a
    change of one case is one line of a diff."""
    from conformance.files import write_atomically

    lines = ["{", f'"meta": {json.dumps(meta, sort_keys=True)},', '"cases": {']
    corpora = sorted({c.corpus for c in cases})
    for k, corpus in enumerate(corpora):
        rows = sorted([c.item, c.expected, c.named] + ([c.where] if corpus != "zoo" else [])
                      for c in cases if c.corpus == corpus)
        lines.append(f"{json.dumps(corpus)}: [")
        lines += [json.dumps(row) + ("," if i < len(rows) - 1 else "") for i, row in enumerate(rows)]
        lines.append("]" + ("," if k < len(corpora) - 1 else ""))
    lines += ["}", "}"]
    write_atomically(path, ("\n".join(lines) + "\n").encode("utf-8"))


def load(path) -> tuple[dict, list[Case]]:
    """``(meta, cases)`` of a file :func:`save` wrote; a file that is missing or not one says so in one paragraph."""
    from conformance.errors import ConformanceError

    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        cases = [Case(corpus, *row) for corpus, rows in data["cases"].items() for row in rows]
        return data["meta"], cases
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        raise ConformanceError(f"{path}: cannot read it as a confusion record ({type(exc).__name__}: {exc}); it is "
                               "written by `python -m conformance confusion --json PATH`, which makes it again") from None


def _percent(part: int, whole: int) -> str:
    return f"{100 * part / whole:.0f} %" if whole else "—"


def markdown(runs: list[tuple[str, list[Case]]]) -> str:
    """The page: a summary per corpus and FURY, then per corpus the matrix (rows: the mistake made; columns:
    named right, none, another), then every case named wrong. ``runs``: (FURY label, its cases)."""
    lines = ["| corpus | FURY | cases | named right | none | named wrong |", "|---|---|---|---|---|---|"]
    for corpus in CORPORA:
        for label, cases in runs:
            mine = [c for c in cases if c.corpus == corpus]
            if not mine:
                continue
            count = Counter(c.cell.partition(":")[0] for c in mine)
            lines.append(f"| {corpus} | {label} | {len(mine)} | {count['right']} ({_percent(count['right'], len(mine))}) "
                         f"| {count['none']} | {count['other']} |")
    for corpus, what in CORPORA.items():
        mine = [(label, c) for label, cases in runs for c in cases if c.corpus == corpus]
        if not mine:
            continue
        lines += ["", f"## {corpus.capitalize()}", "", f"Cases: {what}. Each cell counts both FURYs' cases.", "",
                  "| mistake made (its diagnosis) | cases | named right | none | named wrong (as) |", "|---|---|---|---|---|"]
        by_row = defaultdict(list)
        for label, case in mine:
            by_row[case.expected].append(case)
        for expected in sorted(by_row, key=lambda e: (e == "-", e)):
            rows = by_row[expected]
            count = Counter(c.cell.partition(":")[0] for c in rows)
            others = Counter(c.named for c in rows if c.cell.startswith("other"))
            which = ", ".join(f"`{k}` {v}" for k, v in others.most_common())
            shown = ("`-` (outside the catalogue: none may be named)" if expected == "-"
                     else "`" + expected.replace("|", "` or `") + "`")  # a | would split the table's cell
            lines.append(f"| {shown} | {len(rows)} | {count['right']} | {count['none']} | {count['other']}"
                         f"{f' ({which})' if which else ''} |")
        wrong = [(label, c) for label, c in mine if c.cell.startswith("other")]
        if wrong and corpus != "zoo":  # the zoo's are too many to list; docs/zoo.md has each program's command
            lines += ["", "Named wrong:", ""]
            lines += [f"- {label}: `{c.item}` ({c.expected}) named `{c.named}`" + (f" in {c.where}" if c.where else "")
                      for label, c in sorted(wrong, key=lambda lc: (lc[1].item, lc[0]))]
    return "\n".join(lines)
