"""The zoo's table: models x styles x FURYs, each program accepted, rejected or not judged (and why).

Rendered from the journal's outcomes (:class:`conformance.zoo.judging.Outcome`) and the survey
(:class:`conformance.zoo.models.Survey`) alone, so the table of one FURY's run and another's put beside it
(``zoo --beside``) is the same code.
"""

from __future__ import annotations

from collections import Counter

from conformance.apps.verdict import lead
from conformance.zoo.styles import STYLES, applicable

__all__ = ["markdown"]

FURY = {"vtk": "FURY 0.12", "pygfx": "FURY 2"}
MARK = {"accepted": "✓", "rejected": "✗", "error": "!"}


def markdown(outcomes, surveys: dict, *, made_by: str, backends=("vtk", "pygfx")) -> str:
    """The zoo's page: a summary per FURY, the table, every rejection with its first line, and the models not judged."""
    all_outcomes = list(outcomes)
    wrong = [o for o in outcomes if o.mistake]
    outcomes = [o for o in outcomes if not o.mistake]
    by_key = {(o.model, o.style, o.backend): o for o in outcomes}
    ran = [b for b in backends if any(o.backend == b for o in outcomes)]
    lines = ["# The zoo: every model pyBullet ships, drawn right, judged by app mode", "",
             "<!-- generated: do not edit; made by the commands below -->", "",
             "What app mode answers for right programs drawing the models of `pybullet_data` in the styles users write "
             "(docs/apps.md, \"The zoo\"). Made by:", "", "```sh", made_by, "```", "",
             "| FURY | right programs | accepted | rejected | could not judge | a right program's verdict (s): median, "
             "slowest | every program's verdict, added up |", "|---|---|---|---|---|---|---|"]
    for backend in ran:
        mine = [o for o in outcomes if o.backend == backend]
        count = Counter(o.outcome for o in mine)
        times = sorted(o.seconds for o in mine) or [0.0]
        every = sum(o.seconds for o in all_outcomes if o.backend == backend)
        slowest = max(mine, key=lambda o: o.seconds) if mine else None
        lines.append(f"| {FURY[backend]} | {len(mine)} | {count['accepted']} | {count['rejected']} | {count['error']} | "
                     f"{times[len(times) // 2]:.1f}, {times[-1]:.1f} ({slowest.model if slowest else ''} {slowest.style if slowest else ''}) | "
                     f"{every / 60:.0f} min |")
    styles = [s for s in STYLES.values() if any(o.style == s.name for o in outcomes)]
    lines += ["", f"Each cell: {', '.join(FURY[b] for b in ran)}; ✓ accepted, ✗ rejected, ! the kit could not judge it, "
              "· the style does not apply (why: below the table), blank: not run.", "",
              "| model | " + " | ".join(s.name for s in styles) + " |", "|---|" + "---|" * len(styles)]
    judged = sorted({o.model for o in outcomes})
    for model in judged:
        cells = []
        for style in styles:
            marks = []
            for backend in ran:
                outcome = by_key.get((model, style.name, backend))
                if outcome is not None:
                    marks.append(MARK[outcome.outcome])
                elif model in surveys and applicable(style, surveys[model], backend):
                    marks.append("·")
                else:
                    marks.append(" ")
            cells.append(" ".join(marks))
        lines.append(f"| `{model}` | " + " | ".join(cells) + " |")
    lines += ["", "Where a style does not apply: " + "; ".join(
        f"{s.name}: {_when(s.name)}" for s in styles) + "."]
    rejected = [o for o in outcomes if o.outcome != "accepted"]
    lines += ["", f"## Rejected or not judged ({len(rejected)})", ""]
    if not rejected:
        lines.append("None.")
    for o in sorted(rejected, key=lambda o: (o.model, o.style, o.backend)):
        diagnosis = f" (diagnosis: {', '.join(o.diagnoses)})" if o.diagnoses else ""
        lines.append(f"- `{o.model}` {o.style}, {FURY[o.backend]}: {o.outcome}: {o.first}{diagnosis}")
    if wrong:
        lines += ["", *_wrong_table(wrong, ran), "", *_named(wrong), "", *_cost(wrong, by_key, ran)]
    unusable = sorted((m, s.unusable) for m, s in surveys.items() if s.unusable)
    lines += ["", f"## Models not judged ({len(unusable)})", "",
              "A model that does not load, has nothing to draw or nothing that moves cannot tell a right drawing from a "
              "wrong one.", "", "| model | why |", "|---|---|"]
    lines += [f"| `{m}` | {why} |" for m, why in unusable]
    return "\n".join(lines)


#: a wrong program's outcome, as its cell shows it
WRONG_MARK = {"rejected": "✓", "missed": "✗", "limit": "≈", "no-difference": "∅", "error": "!"}


def _wrong_table(wrong, ran) -> list[str]:
    """The mistakes injected: a summary per FURY and mistake, the cells per model, every miss."""
    from conformance.zoo.mistakes import MISTAKES

    names = [m for m in MISTAKES if any(o.mistake == m for o in wrong)]
    lines = ["## Mistakes injected", "",
             "Each mistake of `conformance/zoo/mistakes.py` made in one style of each model (the style turning with "
             "the mistake and the model). ✓ rejected; ✗ accepted though its drawing differs from the right program's "
             "(a miss); ≈ a miss whose reason is measured and stated below (a limit of app mode); ∅ the mistake changes nothing this model shows (every vertex within 0.1 mm of the right "
             "program's, in its own run and in the perturbed opening: no inertial offset, no visual frame, a scale "
             "of 1…), not counted; ! the kit could not judge it.", "",
             "| FURY | mistake | programs | rejected | missed | limits | no difference | could not judge |",
             "|---|---|---|---|---|---|---|---|"]
    for backend in ran:
        for name in names:
            mine = [o for o in wrong if o.backend == backend and o.mistake == name]
            count = Counter(o.outcome for o in mine)
            lines.append(f"| {FURY[backend]} | {name} | {len(mine)} | {count['rejected']} | {count['missed']} | "
                         f"{count['limit']} | {count['no-difference']} | {count['error']} |")
    by_key = {(o.model, o.mistake, o.backend): o for o in wrong}
    lines += ["", f"Each cell: {', '.join(FURY[b] for b in ran)}; the style the mistake was made in follows the mark.", "",
              "| model | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    for model in sorted({o.model for o in wrong}):
        cells = []
        for name in names:
            found = [by_key.get((model, name, b)) for b in ran]
            style = next((o.style for o in found if o is not None), "")
            marks = " ".join(WRONG_MARK[o.outcome] if o is not None else " " for o in found)
            cells.append(f"{marks} {style}".strip())
        lines.append(f"| `{model}` | " + " | ".join(cells) + " |")
    missed = [o for o in wrong if o.outcome in ("missed", "limit", "error")]
    lines += ["", f"### Missed, limits, or not judged ({len(missed)})", ""]
    lines += [f"- `{o.model}` {o.style} with {o.mistake}, {FURY[o.backend]}: {o.outcome}"
              + (f", drawn up to {o.shown:.3g} m from the right program" if o.outcome == "missed" else f": {o.first}")
              for o in sorted(missed, key=lambda o: (o.model, o.mistake, o.backend))] or ["None."]
    return lines


def _named(wrong) -> list[str]:
    """Whether each rejected program's failure names its mistake (issue 48): the diagnosis the mistake should
    get (``Mistake.diagnosis``) first, later, none, or another first, both FURYs together."""
    from conformance.zoo.mistakes import MISTAKES

    lines = ["## Mistakes named", "",
             "Which mistake each rejected program's report leads with (its first line after the run's, the most "
             "explanatory of the diagnoses its checks named: `conformance.apps.verdict.LEAD_ORDER`), both FURYs "
             "together (each program's latest verdict): the mistake's own diagnosis first, later, none at all, or "
             "another first (named wrong).", "",
             "| mistake | its diagnosis | rejected | named first | named later | none | another first (which) |",
             "|---|---|---|---|---|---|---|"]
    totals = Counter()
    for name, mistake in MISTAKES.items():
        mine = [o for o in wrong if o.mistake == name and o.outcome == "rejected"]
        if not mine:
            continue
        count, others = Counter(), Counter()
        for o in mine:
            first = lead(o.diagnoses)
            names = mistake.diagnosis.split("|")  # "a|b": the drawing calls for one of the two
            cell = ("first" if first in names else "later" if set(names) & set(o.diagnoses)
                    else "none" if not first else "other")
            count[cell] += 1
            if cell == "other":
                others[first] += 1
        totals.update(count)
        which = ", ".join(f"{k} {v}" for k, v in others.most_common(3))
        lines.append(f"| {name} | `{(mistake.diagnosis or '-').replace('|', '` or `')}` | {len(mine)} | {count['first']} | {count['later']} | "
                     f"{count['none']} | {count['other']}{f' ({which})' if which else ''} |")
    judged = sum(totals.values()) or 1
    lines += ["", f"Named first: {totals['first']} of {sum(totals.values())} ({100 * totals['first'] / judged:.0f} %); "
                  f"named wrong (another first): {totals['other']}; none: {totals['none']}."]
    return lines


def _cost(wrong, right, ran) -> list[str]:
    """A rejected program's verdict against its right twin's (the same model in the same style), per FURY."""
    lines = ["## What a rejection costs", "",
             "Each rejected program's time to its verdict against its right twin's (the same model in the same style; "
             "each program's latest verdict). A rejection is meant to cost at most twice an acceptance.", "",
             "| FURY | rejected programs | time against the right twin's: median | slowest (the program) | more than twice |",
             "|---|---|---|---|---|"]
    for backend in ran:
        ratios = sorted(((o.seconds / twin.seconds, o) for o in wrong
                         if o.backend == backend and o.outcome == "rejected"
                         and (twin := right.get((o.model, o.style, backend))) is not None and twin.seconds > 0),
                        key=lambda pair: pair[0])
        if not ratios:
            continue
        top, slowest = ratios[-1]
        lines.append(f"| {FURY[backend]} | {len(ratios)} | {ratios[len(ratios) // 2][0]:.2f}× | {top:.2f}× "
                     f"(`{slowest.model}` {slowest.style} with {slowest.mistake}, {slowest.seconds:.0f} s) | "
                     f"{sum(r > 2 for r, _ in ratios)} |")
    return lines


def _when(style: str) -> str:
    return {"playback": "no revolute or prismatic joint", "fixed": "not a URDF with joints",
            "scaled": "MJCF (loadMJCF takes no globalScaling)", "merged": "not a URDF with fixed joints",
            "impostors": "no sphere visual shape, or FURY 0.12"}.get(style, "always applies")
