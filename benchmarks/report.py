"""A bench run as markdown tables (what is printed and put in the README) and as JSON (every figure)."""

from __future__ import annotations

import dataclasses
import json

from . import app_mode, floor, machine, pictures, reads, suite, syncs
from .main import Results

__all__ = ["as_json", "markdown"]


def _ms(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    return f"{seconds * 1e3:.3g} ms" if seconds < 1 else f"{seconds:.3g} s"


def _ratio(value: float) -> str:
    return f"{value:.2f}×" if value < 10 else f"{value:.3g}×"


def _duration(seconds: float) -> str:
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes} min {rest} s" if minutes else f"{seconds:.1f} s"


def _sync_table(results: Results) -> list[str]:
    figures = results.syncs
    sizes = sorted({f.bodies for f in figures})
    lines = ["| drawing | per frame | " + " | ".join(f"{n:,} bodies" for n in sizes) + " | draws right |",
             "|---|---|" + "---|" * len(sizes) + "---|"]
    for style in syncs.STYLES:
        names = list(dict.fromkeys(f.name for f in figures if f.style == style))
        names = [syncs.FLOOR] + [n for n in names if n not in (syncs.FLOOR, syncs.STEP)] + [syncs.STEP]
        for name in names:
            row = {f.bodies: f for f in figures if f.style == style and f.name == name}
            if not row:
                continue
            if name == syncs.FLOOR:
                label, cells = "**floor**", [_ms(row[n].seconds) if n in row else "" for n in sizes]
            else:
                label, cells = f"`{name}`", [_ratio(row[n].ratio) if n in row else "" for n in sizes]
            judged = [f for f in row.values() if f.wrong is not None]
            right = "" if not judged else ("yes" if not any(f.wrong for f in judged) else "no: " + ", ".join(
                f"{f.wrong:,}/{f.bodies:,}" for f in judged if f.wrong))
            where = "whole actors" if style == "whole" else "one shared actor"
            lines.append(f"| {where} | {label} | " + " | ".join(cells) + f" | {right} |")
    return lines


def _verdict_table(results: Results) -> list[str]:
    lines = ["| target | measured | verdict |", "|---|---|---|"]
    for v in results.verdicts:
        note = f" ({v.note})" if v.note else ""
        lines.append(f"| {v.target} | {v.measured}{note} | {'**pass**' if v.passed else '**miss**'} |")
    return lines


def _reads_table(results: Results) -> list[str]:
    lines = ["| how | per pose | ratio | what it shows |", "|---|---|---|---|"]
    for f in results.reads:
        lines.append(f"| {f.name} | {f.seconds * 1e6:.3f} µs | {_ratio(f.ratio)} | {f.note} |")
    return lines


def _floor_paragraph(results: Results) -> list[str]:
    """Where the floor's time goes, with the numbers: pyBullet's read, not Python around it."""
    by = {f.name: f for f in results.reads}
    read, call = by.get(reads.FLOOR_READ), by.get("`isConnected(c)`, in a loop")
    fastest = min(results.reads[:3], key=lambda f: f.seconds, default=None)
    if read is None or call is None or fastest is None:
        return []
    return [f"The floor is pyBullet's read: {read.seconds * 1e6:.2f} µs a body, of which crossing from Python to "
            f"pyBullet is {call.seconds * 1e6:.2f} µs. pyBullet 3.2 has no call reading several bodies' poses "
            f"(`getLinkStates` reads the links of one body), so a sync reading every pose cannot go under it; the "
            f"fastest per-body read found is {fastest.name} ({_ratio(fastest.ratio)} the floor's)."]


def _pictures_table(results: Results) -> list[str]:
    scenes = list(dict.fromkeys(f.scene for f in results.pictures))
    sizes = {f.scene: f.size for f in results.pictures}
    lines = ["| per picture | " + " | ".join(f"`{s}` ({sizes[s][0]}×{sizes[s][1]})" for s in scenes) + " |",
             "|---|" + "---|" * len(scenes)]
    for name in dict.fromkeys(f.name for f in results.pictures):
        row = {f.scene: f for f in results.pictures if f.name == name}
        if name == pictures.FRAME:
            cells = [_ms(row[s].seconds) for s in scenes]
            name = f"**{name}**"
        else:
            cells = [_ratio(row[s].ratio) for s in scenes]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def _suite_table(results: Results) -> list[str]:
    lines = ["| run | wall time | ratio | exit | checks failed |", "|---|---|---|---|---|"]
    for f in results.suite:
        if f.name == suite.BASELINE:
            lines.append(f"| **{f.name}** | {_duration(f.seconds)} | 1.00× | | |")
        else:
            failed = f"{f.failed} of {f.failed + f.passed}" if f.failed is not None and f.passed is not None else ""
            lines.append(f"| {f.name} | {_duration(f.seconds)} | {_ratio(f.ratio)} | {f.returncode} | {failed} |")
    return lines


def _apps_table(results: Results) -> list[str]:
    lines = ["| app | ticks | the app's own tick | recording | judging | kit ÷ app | pictures, once a run |",
             "|---|---|---|---|---|---|---|"]
    for f in results.apps:
        lines.append(f"| {f.name} | {f.ticks} | {f.baseline * 1e3:.1f} ms | {f.record * 1e3:.1f} ms | "
                     f"{f.judge * 1e3:.1f} ms | {_ratio(f.ratio)} | {getattr(f, 'picture', 0.0) * 1e3:.0f} ms |")
    return lines


def markdown(results: Results) -> str:
    """The tables, each introduced by what its figures are ratios to."""
    o = results.options
    out = [f"Measured {results.started} on {machine.describe(results.machine, results.renderer)}. Every figure is a ratio to a "
           f"baseline measured in the same run and process, each the best of {o.repeats} rounds "
           "(`python -m conformance bench`, code in `benchmarks/`)."]
    if results.syncs:
        out += ["", f"**Sync cost per frame**, as a ratio to the floor (whose own time is given). The floor: {floor.DEFINITION} "
                "Bricks 1 m apart in zero gravity, drifting and spinning, never touching; every frame timed "
                "after an untimed `stepSimulation()`, itself timed for scale. *Draws right*: the kit's vertex check "
                "on the sync's drawing after the timed frames.", ""]
        out += _sync_table(results)
    if results.verdicts:
        out += ["", "**Targets** (pass or miss; never a failing test):", ""] + _verdict_table(results)
    if results.reads:
        out += ["", f"**Reading poses** from pyBullet, {o.reads_bodies:,} bodies (links: {reads.LINKS_PER_BODY} a body), "
                f"per pose, as a ratio to the floor's read, {reads.FLOOR_READ}:", ""] + _reads_table(results)
        out += [""] + _floor_paragraph(results)
    if results.pictures:
        out += ["", "**Pictures** at the scenes' own size (drawn by the GPU named above), as a ratio to "
                f"{pictures.FRAME.split(': ', 1)[0]} of the same scene ({pictures.FRAME.split(': ', 1)[1]}; its own time given):",
                ""] + _pictures_table(results)
    if results.apps:
        out += ["", f"**App mode** (`python -m conformance app`, {app_mode.TICKS} ticks, best of "
                f"{min(o.repeats, 3)} runs), per tick, as a ratio to the app's own tick in the same run (its callbacks: "
                "step, sync, render):", ""] + _apps_table(results)
    if results.verdict_costs:
        out += ["", f"**A failing robot's verdict** (`python -m conformance app`, best of {min(o.repeats, 2)}), as a ratio "
                "to the passing verdict of the same robot in the same run (target: at most 2):", "",
                "| failing app, against the passing one | failing | passing | ratio |", "|---|---|---|---|"]
        out += [f"| {f.name} | {f.seconds:.1f} s | {f.baseline:.1f} s | {_ratio(f.ratio)} |" for f in results.verdict_costs]
    if results.suite:
        out += ["", f"**Whole runs** (subprocesses, best of {o.suite_repeats}), as a ratio to {suite.BASELINE}:", ""]
        out += _suite_table(results)
    return "\n".join(out).replace("\n\n\n", "\n\n")


def as_json(results: Results) -> str:
    """Every figure, with seconds, ratios and what they are ratios to, and the options and machine."""
    options = {**dataclasses.asdict(results.options), "reads_bodies": results.options.reads_bodies}
    return json.dumps({
        "started": results.started,
        "machine": results.machine,
        "renderer": results.renderer,
        "options": options,
        "syncs": [f.as_dict() for f in results.syncs],
        "targets": [v.as_dict() for v in results.verdicts],
        "reads": [f.as_dict() for f in results.reads],
        "pictures": [f.as_dict() for f in results.pictures],
        "verdict_costs": [f.as_dict() for f in results.verdict_costs],
        "suite": [f.as_dict() for f in results.suite],
        "apps": [f.as_dict() for f in results.apps],
    }, indent=2)
