"""A run's summary in Markdown, for where reviewers look: a CI job's summary page, or a file kept beside the run.

Made from what the plugin already keeps (its per-check records, the per-scene verdicts it prints, and the
image-check records of the results directory), as :mod:`.report` makes its page from the same records.

What a summary holds, and in what order: the run's verdict and facts (sync, backend, shard, counts, pytest's
exit status); the per-scene verdicts, failed scenes first; the first failing check in the order the checks
reported, with its message, its diagnosis (the known mistake it is, when one is), its reproduce command, and
its pictures; then every failing check, one table row each (at most :data:`MAX_ROWS`), with its diagnosis.

Guarantees: text taken from a record is escaped (it can neither start Markdown markup nor HTML, nor break a
table row), code goes in fences longer than any backtick run it holds, and a file is written whole or not at
all (:func:`conformance.files.write_atomically`). A summary appended to a file keeps what the file held.
Pictures are linked relative to the summary's file; on a page whose links cannot reach files (GitHub's job
summary) their paths are shown instead, with a link to where the run's files are kept when one is given.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence
from urllib.parse import quote

from conformance.files import write_atomically
from conformance.rendering.records import ImageCheck

__all__ = ["MAX_ROWS", "Run", "append", "render", "write"]

#: At most this many failing checks in the table (GitHub keeps 1 MiB of a step's summary).
MAX_ROWS = 100
#: At most this many characters of a message or diagnosis in a table cell.
_CELL = 300

_MARKS = {"FAIL": "❌", "PASS": "✅", "INCOMPLETE": "⚠️", "NOT RUN": "⚠️", "SKIP": "➖", "LEFT OUT": "➖"}
_ORDER = ("FAIL", "INCOMPLETE", "NOT RUN", "SKIP", "PASS", "LEFT OUT")
#: The pictures of each kind of image check that show the failure, in the order they are linked.
_SHOWN_ROLES = {"vertices": ("outlined",), "golden": ("actual", "difference", "expected", "reference"),
                "silhouette": ("mask_difference", "fury_mask", "pybullet_mask"), "framing": ("actual",)}
#: pytest's exit statuses, as a summary says them.
_EXIT = {0: "all selected checks passed", 1: "some checks failed", 2: "interrupted", 3: "pytest's internal error",
         4: "usage error", 5: "no check ran, or none that runs the sync"}


@dataclass
class Run:
    """What a summary is made of.

    ``scenes``: (verdict, scene, detail) rows as the terminal prints them; ``records``: the plugin's records
    (``nodeid``, ``scene``, ``outcome``, ``message``, ``diagnosis``, ``reproduce``), in the order the checks
    reported; ``pictures``: the image-check records of the results directory (``results``), whose picture paths
    are relative to it; ``report``: the HTML report, when one was written; ``artifacts``: a URL where the run's
    files are kept (a CI run's page), or None; ``extra``: sentences said under the facts (why a green run is not
    a pass)."""

    sync: str
    backend: str
    exitstatus: int
    scenes: Sequence[tuple[str, str, str]] = ()
    records: Sequence[Mapping] = ()
    pictures: Sequence[ImageCheck] = ()
    results: Path | None = None
    report: Path | None = None
    shard: str | None = None
    artifacts: str | None = None
    extra: Sequence[str] = ()


# -- Markdown ------------------------------------------------------------------------------------------

_SPECIAL = re.compile(r"([\\`*_\[\]<>&~#!])")


def _text(value: object, limit: int | None = None) -> str:
    """``value`` as inline Markdown text on one line: markup characters escaped, cut to ``limit``."""
    text = " ".join(str(value).split())
    if limit is not None and len(text) > limit:
        text = text[:limit - 1] + "…"
    return _SPECIAL.sub(r"\\\1", text)


def _code(value: object) -> str:
    """``value`` as an inline code span on one line."""
    text = " ".join(str(value).split())
    ticks = "`" * (max((len(run) for run in re.findall(r"`+", text)), default=0) + 1)
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{ticks}{pad}{text}{pad}{ticks}"


def _fence(value: str, language: str = "text") -> str:
    """``value`` as a fenced code block (the fence longer than any backtick run inside)."""
    fence = "`" * max(3, max((len(run) for run in re.findall(r"`+", value)), default=0) + 1)
    return f"{fence}{language}\n{value.rstrip()}\n{fence}"


def _cell(markdown: str) -> str:
    """Inline Markdown made safe inside a table cell: a ``|`` would end the cell, even inside a code span."""
    return markdown.replace("|", "\\|")


# -- what is shown -------------------------------------------------------------------------------------

def _outcomes(records: Sequence[Mapping]) -> dict[str, str]:
    """Each check's outcome (a failure in any phase is its outcome), by node id, in the order of the records."""
    found: dict[str, str] = {}
    for record in records:
        nodeid, outcome = record.get("nodeid", ""), record.get("outcome", "")
        if nodeid not in found or outcome == "failed":
            found[nodeid] = outcome
    return found


def _failures(records: Sequence[Mapping]) -> list[Mapping]:
    """The first failing record of each failing check, in the order the checks reported."""
    seen, failing = set(), []
    for record in records:
        if record.get("outcome") == "failed" and record.get("nodeid") not in seen:
            seen.add(record.get("nodeid"))
            failing.append(record)
    return failing


def _message(record: Mapping) -> str:
    """A record's first line, without the ``Failed: `` that ``pytest.fail`` puts before a check's own words."""
    message = str(record.get("message") or "")
    return message[len("Failed: "):] if message.startswith("Failed: ") else message


def _verdict(run: Run) -> str:
    if any(r.get("outcome") == "failed" for r in run.records) or any(v == "FAIL" for v, _, _ in run.scenes):
        return "FAIL"
    if run.exitstatus == 0:
        return "PASS"
    return "NOT PASSED"


def _link(path: Path, links_from: Path | None, label: str) -> str:
    """A link to ``path`` relative to ``links_from`` (the summary's directory); its path as code when None."""
    if links_from is None:
        try:
            shown = path.resolve().relative_to(Path.cwd().resolve())
        except ValueError:
            shown = path
        return f"{_text(label)} {_code(shown.as_posix())}"
    relative = Path(os.path.relpath(path.resolve(), links_from.resolve())).as_posix()
    return f"[{_text(label)}]({quote(relative)})"


def _pictures_of(nodeid: str, run: Run) -> list[ImageCheck]:
    return [p for p in run.pictures if p.nodeid == nodeid and not p.passed and p.images]


def _picture_links(record: ImageCheck, run: Run, links_from: Path | None) -> str:
    roles = [r for r in _SHOWN_ROLES.get(record.kind, ()) if r in record.images] or list(record.images)
    links = " · ".join(_link(run.results / record.images[role], links_from, role) for role in roles)
    return f"{_text(record.kind)}, frame {int(record.frame)}: {links}"


def _first_failure(record: Mapping, run: Run, links_from: Path | None) -> list[str]:
    lines = [f"### First failure: {_code(record.get('nodeid', ''))}", "", _fence(_message(record) or "(no message)")]
    if record.get("diagnosis"):
        lines += ["", f"**Diagnosis:** {_text(record['diagnosis'])}"]
    if record.get("reproduce"):
        lines += ["", "**Reproduce:**", "", _fence(record["reproduce"], "sh")]
    pictures = _pictures_of(record.get("nodeid", ""), run) if run.results is not None else []
    if pictures:
        lines += ["", "**Pictures:**", ""]
        lines += [f"- {_picture_links(p, run, links_from)}" for p in pictures[:6]]
        if len(pictures) > 6:
            lines.append(f"- and {len(pictures) - 6} more in the report")
    return lines


def _failure_table(failing: Sequence[Mapping], run: Run, links_from: Path | None) -> list[str]:
    counted = f"All {len(failing)} failing checks" if len(failing) > 1 else "1 failing check"
    lines = [f"<details><summary>{counted}</summary>", "",
             "| check | scene | failure | diagnosis | pictures |", "|---|---|---|---|---|"]
    for record in failing[:MAX_ROWS]:
        pictures = _pictures_of(record.get("nodeid", ""), run) if run.results is not None else []
        shown = ""
        if pictures:
            first = pictures[0]
            role = next((r for r in _SHOWN_ROLES.get(first.kind, ()) if r in first.images), next(iter(first.images)))
            shown = (_link(run.results / first.images[role], links_from, role) if links_from is not None
                     else f"{len(pictures)} in the report")
        lines.append("| " + " | ".join(_cell(cell) for cell in (
            _code(record.get("nodeid", "")), _text(record.get("scene") or ""), _text(_message(record), _CELL),
            _text(record.get("diagnosis") or "", _CELL), shown)) + " |")
    if len(failing) > MAX_ROWS:
        lines.append(f"\n… and {len(failing) - MAX_ROWS} more: every failure is in the JUnit XML and the terminal log.")
    return lines + ["", "</details>"]


def render(run: Run, links_from: Path | None = None) -> str:
    """The summary of ``run`` as Markdown. ``links_from``: the directory of the file it will be written to,
    which picture links are made relative to; None where links cannot reach files (paths are shown)."""
    verdict = _verdict(run)
    outcomes = list(_outcomes(run.records).values())
    counts = ", ".join(f"{outcomes.count(k)} {k}" for k in ("failed", "passed", "skipped", "xfailed") if outcomes.count(k))
    facts = [f"sync {_code(run.sync)}", _text(run.backend)] + ([f"shard {_code(run.shard)}"] if run.shard else [])
    facts += [counts or "no check reported",
              f"pytest exit status {run.exitstatus}" + (f" ({_EXIT[run.exitstatus]})" if run.exitstatus in _EXIT else "")]
    lines = [f"## {_MARKS.get(verdict, '⚠️')} FURY–pyBullet conformance: {verdict}", "", " · ".join(facts)]
    lines += [f"\n{_text(line)}" for line in run.extra]
    if run.scenes:
        rows = sorted(run.scenes, key=lambda row: _ORDER.index(row[0]) if row[0] in _ORDER else 0)
        lines += ["", "| verdict | scene | checks |", "|---|---|---|"]
        lines += ["| " + " | ".join(_cell(c) for c in (f"{_MARKS.get(v, '')} {v}", _text(scene), _text(detail))) + " |"
                  for v, scene, detail in rows]
    failing = _failures(run.records)
    if failing:
        lines += [""] + _first_failure(failing[0], run, links_from)
        lines += [""] + _failure_table(failing, run, links_from)
    where = []
    if run.report is not None and run.report.is_file():
        where.append(_link(run.report, links_from, "the report, every check with pictures"))
    if run.artifacts:
        where.append(f"[the run's kept files (artifacts)]({run.artifacts})")
    if where:
        lines += ["", "Pictures: " + "; ".join(where) + "."]
    return "\n".join(lines) + "\n"


def write(run: Run, path: str | os.PathLike) -> Path:
    """Write the summary of ``run`` to ``path`` (replacing it), pictures linked relative to it."""
    path = Path(path)
    return write_atomically(path, render(run, path.absolute().parent).encode("utf-8"))


def append(run: Run, path: str | os.PathLike) -> Path:
    """Add the summary of ``run`` to the end of ``path`` (a CI page's summary file, which other steps and tools
    write to as well), pictures shown by their paths."""
    path = Path(path)
    try:
        before = path.read_bytes()
    except FileNotFoundError:
        before = b""
    if before and not before.endswith(b"\n\n"):
        before += b"\n" if before.endswith(b"\n") else b"\n\n"
    return write_atomically(path, before + render(run, None).encode("utf-8"))
