"""How much of each tolerance right syncs use: the figure behind "nothing too loose" (issue 17).

A tolerance is there to let a right sync pass; one that a right sync never comes near lets wrong ones
pass too. From the runs of right syncs (:func:`conformance.discrimination.verdicts.check`), this collects, per
*allowance* (a vertex check's position tolerance, its normals' angle, each golden-picture metric of the
sync verdict and of the renderer verdict, the silhouettes' pixels off), the largest fraction of it that any right sync
used on any scene and frame, and where. An allowance whose worst use is under :data:`LOOSE` (a tenth)
is flagged *loose*, and :data:`REASONS` says, for each flagged one, why it stays or what it becomes.

Use is ``measured / limit`` for an upper bound, and ``(1 − measured) / (1 − limit)`` for a lower bound
on a score that is 1 when perfect (IoU): the share of the room below 1 that was used. Bounds of 0
(nothing allowed), bounds that are off (a fraction of the picture allowed up to all of it) and the
framing requirements (a body large enough on screen) are not tolerances and are left out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

__all__ = ["LOOSE", "REASONS", "Use", "markdown", "unexplained", "uses", "worst_uses"]

#: A tolerance whose worst right-sync use is under this fraction of it is flagged.
LOOSE = 0.1

#: Why each allowance found loose stays as it is (or what it should become), by :attr:`Use.allowance`.
REASONS: dict[str, str] = {
    "golden renderer: flip_mean (same-renderer)": (
        "keep: a backstop, never the deciding bound here: the same-renderer set's 2-level pixel bound fails "
        "first on every measured error and on any change of the whole picture by more than 2 levels; 0.03 is "
        "the other-renderer set's value, where ±1 noise alone reaches 0.019 (docs/image-tolerances.md)."),
    "golden sync: flip_mean (same-renderer)": (
        "keep: as for the renderer verdict; the sync verdict compares two renders on one renderer, where the "
        "pixel bound decides."),
    "golden renderer: differing_fraction (same-renderer)": (
        "keep: one bound for both FURYs, set on llvmpipe (FURY 0.12), where right syncs use 43-55 % of it; "
        "lavapipe (FURY 2) flips fewer edge pixels (at most 3 of the 40 allowed, measured), and the bound is "
        "placed by the errors too: the smallest measured error differs in 158 pixels, 4 times it "
        "(docs/image-tolerances.md)."),
    "golden sync: differing_fraction (same-renderer)": (
        "keep: as for the renderer verdict (the same bound, the same renders)."),
    "silhouette pixels_off": (
        "keep: the bound (the larger of 2 % of a body's pixels and 6 pixels) is set by the worst right-sync draws "
        "over the scenes' parameters, run lengths and turns, not by a tolerance-use run's few examples: a 72-pixel "
        "brick with 3 pixels off, a cylinder's rim (conformance/rendering/silhouettes.py; docs/precision.md)."),
    "silhouette iou": (
        "keep (records of an earlier kit): the silhouettes are now bounded by pixels off."),
    "normals angle": (
        "keep: the allowance (1e-4 rad) is set by what a wrong sync does, not by float32: a normal left "
        "as built is off by the body's turn, ≥ 1e-2 rad after one frame of any scene that turns; right "
        "syncs store normals in float32 (≈1e-7 rad)."),
}


@dataclass(frozen=True)
class Use:
    """One measured figure against its allowance: ``use`` is the fraction of the allowance used."""

    allowance: str
    use: float
    measured: float
    limit: float
    where: str


def _at_least(metric: str) -> bool:
    from conformance.reports.report import AT_LEAST_PREFIXES

    name = metric.split(": ")[-1]  # a golden's "sync: iou" is judged like "iou"
    return name.startswith(AT_LEAST_PREFIXES) or name.endswith("_iou")


def _use(metric: str, measured: float, limit: float, at_least: bool) -> float | None:
    """The fraction of the allowance used, or None where the bound allows nothing or everything (a
    fraction of the picture allowed up to 1: the bound is off in that tolerance set)."""
    if metric.endswith("_fraction") and limit >= 1.0 and not at_least:
        return None
    if at_least:
        room = 1.0 - limit
        return None if room <= 0 else (1.0 - measured) / room
    return None if limit <= 0 else measured / limit


def uses(sync: str, records: Iterable[dict], images: Iterable[dict]) -> list[Use]:
    """Every figure of one sync's run: its plugin records (``worst``, ``worst_normals``) and its image
    records (``metrics`` against ``limits``)."""
    found = []
    for record in records:
        for key, allowance, unit in (("worst", "vertex position", "m"), ("worst_normals", "normals angle", "rad")):
            worst = record.get(key)
            if worst and worst.get("tolerance"):
                where = f"{record['check']} [{record.get('scene')}] {worst.get('target')!r} frame {worst.get('frame')}, {sync}"
                found.append(Use(allowance, float(worst["error"]) / float(worst["tolerance"]), float(worst["error"]),
                                 float(worst["tolerance"]), where))
    for image in images:
        if image.get("kind") not in ("golden", "silhouette"):
            continue
        tolerance_set = image.get("details", {}).get("tolerance_set")
        for metric, limit in image.get("limits", {}).items():
            measured = image.get("metrics", {}).get(metric)
            if not isinstance(measured, (int, float)) or not isinstance(limit, (int, float)) or math.isnan(measured):
                continue
            use = _use(metric, float(measured), float(limit), _at_least(metric))
            if use is None:
                continue
            label = f"{image['kind']} {metric}" + (f" ({tolerance_set})" if tolerance_set and image["kind"] == "golden" else "")
            found.append(Use(label, use, float(measured), float(limit), f"{image['scene']} frame {image['frame']}, {sync}"))
    return found


def worst_uses(found: Iterable[Use]) -> dict[str, Use]:
    """The largest use of each allowance (a NaN counts as the largest), in order of allowance."""
    worst: dict[str, Use] = {}
    for use in found:
        kept = worst.get(use.allowance)
        if kept is None or not (kept.use >= use.use):
            worst[use.allowance] = use
    return dict(sorted(worst.items()))


def markdown(worst: dict[str, Use], reasons: dict[str, str] | None = None) -> str:
    """The table of allowances with their worst right-sync use; under it each loose one with its reason
    (or "no reason written yet", which :func:`unexplained` reports)."""
    reasons = REASONS if reasons is None else reasons
    rows = ["| allowance | worst use by a right sync | measured | allowance | where |", "|---|---|---|---|---|"]
    loose = []
    for name, use in worst.items():
        flag = " **loose**" if use.use < LOOSE else ""
        if flag:
            loose.append(name)
        rows.append(f"| {name} | {use.use:.1%}{flag} | {use.measured:.3g} | {use.limit:.3g} | {use.where} |")
    text = "\n".join(rows)
    if loose:
        text += f"\n\nLoose (worst use under {LOOSE:.0%} of the allowance):\n\n" + "\n".join(
            f"- **{name}**: {reasons.get(name, 'no reason written yet')}" for name in loose)
    return text


def unexplained(worst: dict[str, Use], reasons: dict[str, str] | None = None) -> list[str]:
    """The loose allowances with no reason in ``reasons`` (:data:`REASONS`)."""
    reasons = REASONS if reasons is None else reasons
    return [name for name, use in worst.items() if use.use < LOOSE and name not in reasons]
