"""Survey mode: a check that keeps going after its first failure and reports every kind of failure.

By default a check stops at its first failing frame (fast, and what ``-x`` runs want). In survey
mode (``--conformance-survey``, ini ``conformance_survey``; what ``python -m conformance verdicts``
uses) the kit's assertions *note* a failure instead of raising it, the check runs every frame it
would have run, and the check fails at the end with the first failure's message (exactly as default
mode would have printed it) and a line listing every kind that failed with its worst figure.

What is guaranteed:

* A :class:`Survey` keeps, per kind of failure (:data:`KINDS`), the worst figure seen: the value
  against its limit, their ratio (how many tolerances off), the frame, the target, how many
  failures of that kind were noted, and the one-line message of the worst one.
* "Worst" is the largest ratio; a NaN or missing ratio counts as infinitely bad, and among equally
  bad failures the first one noted is kept (so a count-like kind names its first frame).
* The plugin writes each check's kinds into its JSON record (:func:`kinds_of`), in survey mode and
  in default mode alike (a default-mode failure has the one kind of its first failure).

This module imports nothing heavy: the plugin calls it for every check of every test suite.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import pytest

__all__ = [
    "KINDS",
    "RAISED",
    "SURVEY",
    "Survey",
    "WORST",
    "WORST_NORMALS",
    "enabled",
    "figure",
    "figure_from_message",
    "format_figure",
    "kind_of_check",
    "kind_of_failure",
    "kinds_of",
    "settle",
    "times",
    "worse",
]

#: The worst vertex error a check measured (failing or not), for the verdict table's ✓ cells.
WORST = pytest.StashKey[dict]()
#: The worst vertex-normal angle a check saw, in its tolerance (:mod:`conformance.discrimination.tolerance_use`).
WORST_NORMALS = pytest.StashKey[dict]()
#: The survey of a check running in survey mode.
SURVEY = pytest.StashKey["Survey"]()

#: The kind and figure of the failure a :class:`~conformance.checks.pytest_helpers.Kit` raised last (default mode).
RAISED = pytest.StashKey[dict]()
#: Set on an item whose passing call report :func:`settle` turned into a failure.
_SETTLED = pytest.StashKey[str]()

#: Kinds of failure, in the order tables list them, with what each means.
KINDS: Mapping[str, str] = {
    "vertices": "a vertex drawn away from where pyBullet's pose puts it",
    "normals": "a stored vertex normal not turned with its body (lit wrongly)",
    "Modified": "vertex data changed without telling the renderer (FURY 0.12: Modified()/utils.update_actor; "
                "FURY 2: positions.update_range()/update_full()), so a live window keeps the old picture",
    "bounds": "a drawn box outside getAABB, or short of it",
    "mesh": "vertex count, cells or colours changed by the sync",
    "physics touched": "the sync changed pyBullet's state",
    "every frame = once": "syncing every frame and syncing once draw different vertices",
    "pass-through": "a filtered pair not drawn overlapping where physics has them pass through",
    "golden render": "the render differs from the golden snapshot",
    "silhouette": "a silhouette differs from pyBullet's own renderer's",
    "repeatable render": "the same drawing renders differently twice",
}

#: The kind of a check whose failures are all of one kind (the frame checks note theirs by kind).
_CHECK_KINDS = {
    "test_sync_does_not_touch_physics": "physics touched",
    "test_sync_keeps_the_mesh": "mesh",
    "test_syncing_every_frame_equals_syncing_once": "every frame = once",
    "test_drawn_bounds_agree_with_get_aabb": "bounds",
    "test_pass_through_is_drawn_overlapping": "pass-through",
    "test_golden_render": "golden render",
    "test_silhouettes_match_pybullet_at_golden_frames": "silhouette",
    "test_silhouettes_match_in_any_orientation": "silhouette",
    "test_same_scene_renders_identically": "repeatable render",
}

#: How the kit's messages name where: ``[scene(params), frame N`` or ``[scene, frame N``.
_WHERE = re.compile(r"\[[A-Za-z_][A-Za-z0-9_]*(?:\(.*?\))?, frame (\d+)")
#: The kit's own figures, as its messages print them: (kind, pattern of value and limit, unit, at least?).
_FIGURES = (
    ("vertices", re.compile(r"error (\S+) m > tolerance (\S+) m"), "m", False),
    ("normals", re.compile(r"normal is turned (\S+) rad .*? within (\S+) rad"), "rad", False),
    ("bounds", re.compile(r"sticks out of getAABB by (\S+) m along \w \(tolerance (\S+) m\)"), "m", False),
    ("bounds", re.compile(r"falls (\S+) m short of getAABB along \w \(margin (\S+) m\)"), "m", False),
    ("every frame = once", re.compile(r"drawn (\S+) m apart .*? within (\S+) m"), "m", False),
    ("silhouette", re.compile(r"\((\d+) pixels off beyond the edge, (\d+) allowed"), "pixels off", False),
    ("silhouette", re.compile(r"IoU with pyBullet's mask = ([^\s,]+), but should be at least ([^\s,]+)"), "IoU", True),
    ("golden render", re.compile(r"(?:differing|shaded)_fraction (\S+) > ([^\s;]+)"), "of the picture", False),
)
_FIGURE_KINDS = frozenset(name for name, *_ in _FIGURES)


def enabled(config) -> bool:
    """Whether survey mode is on: ``--conformance-survey``, else the ini ``conformance_survey``."""
    option = config.getoption("conformance_survey", default=None)
    if option is not None:
        return bool(option)
    try:
        return bool(config.getini("conformance_survey"))
    except ValueError:  # the plugin that declares it is not loaded
        return False


def kind_of_check(check: str) -> str | None:
    """The one kind every failure of ``check`` is, or None for the frame checks (several kinds)."""
    return _CHECK_KINDS.get(check)


def kind_of_failure(check: str, message: str) -> str:
    """The kind of a failure raised by ``check`` with ``message``: the check's one kind, else what the
    message shows (a vertex error, a turned normal, a change not announced), else the check's name."""
    kind = kind_of_check(check)
    if kind is not None:
        return kind
    for name, pattern, *_ in _FIGURES:
        if name in ("vertices", "normals") and pattern.search(message):
            return name
    return "Modified" if "without marking it modified" in message else check


def _ratio(value, limit, at_least: bool) -> float:
    """How many tolerances off: value/limit for an upper bound; for a lower bound (an IoU of at
    least ``limit``) the shortfall against the allowed one, (1 - value)/(1 - limit)."""
    if value is None or limit is None:
        return math.inf
    value, limit = float(value), float(limit)
    if at_least:
        value, limit = 1.0 - value, 1.0 - limit
    if limit == 0:
        return math.inf if value != 0 else 0.0
    return value / limit


def figure(*, value=None, limit=None, unit: str = "", frame: int | None = None, target: str | None = None,
           at_least: bool = False, message: str = "", failures: int = 1) -> dict[str, Any]:
    """One kind's figure as the JSON record stores it (plain numbers and strings)."""
    ratio = _ratio(value, limit, at_least)
    return {"value": None if value is None else float(value), "limit": None if limit is None else float(limit),
            "unit": unit, "ratio": ratio, "at_least": at_least, "frame": frame, "target": target,
            "failures": failures, "message": message.strip().splitlines()[0][:1000] if message.strip() else ""}


def _severity(fig: Mapping[str, Any]) -> float:
    ratio = fig.get("ratio")
    return math.inf if ratio is None or ratio != ratio else float(ratio)


def worse(new: Mapping[str, Any], old: Mapping[str, Any] | None) -> bool:
    """Whether ``new`` replaces ``old`` as a kind's worst figure (ties keep the old, earlier one)."""
    return old is None or _severity(new) > _severity(old)


def times(ratio: float) -> str:
    """A ratio to the tolerance in two significant digits, or as many more as keep it on its side of
    1 (1.0004 is "1.0004", never "1", which would read as within tolerance)."""
    for digits in (2, 3, 4, 6, 9):
        text = f"{ratio:.{digits}g}"
        if (float(text) > 1) == (ratio > 1):
            break
    return text


def format_figure(fig: Mapping[str, Any], *, frame: bool = True) -> str:
    """``2.54e-06 m (1.9×tol, frame 153)``; ``IoU 0.094 (45×tol, frame 131)``; ``from frame 3`` (a kind
    without a measure, e.g. Modified)."""
    parts = []
    value, unit = fig.get("value"), fig.get("unit") or ""
    if value is not None:
        number = f"{value:.3g}"
        parts.append(f"{unit} {number}" if unit == "IoU" else f"{number} {unit}".strip())
    inner = []
    ratio = fig.get("ratio")
    if fig.get("limit") is not None and ratio is not None and math.isfinite(ratio):
        inner.append(f"{times(ratio)}×tol")
    if frame and fig.get("frame") is not None:
        if value is None:  # a kind without a measure keeps its first failure: say since when
            return f"from frame {fig['frame']}"
        inner.append(f"frame {fig['frame']}")
    text = " ".join(parts)
    if inner:
        text = f"{text} ({', '.join(inner)})" if text else ", ".join(inner)
    return text


def figure_from_message(kind: str, message: str) -> dict[str, Any]:
    """A figure read back from a failure message in the kit's own formats: the frame from its
    ``[scene…, frame N`` context, and the worst value against its limit that the message prints for
    ``kind`` (for a kind without a format of its own, e.g. ``pass-through``, any figure printed)."""
    where = _WHERE.search(message)
    frame = int(where.group(1)) if where else None
    best = None
    for name, pattern, unit, at_least in _FIGURES:
        if name != kind and kind in _FIGURE_KINDS:
            continue
        for found in pattern.finditer(message):
            try:
                value, limit = float(found.group(1)), float(found.group(2))
            except ValueError:
                continue
            new = figure(value=value, limit=limit, unit=unit, at_least=at_least, frame=frame, message=message)
            if worse(new, best):
                best = new
        if best is not None and name == kind:  # a kind's first format that matched is its figure (one unit)
            break
    return best or figure(frame=frame, message=message)


@dataclass
class Survey:
    """Per kind, the worst failure noted, and the full message of the first failure noted."""

    kinds: dict[str, dict[str, Any]] = field(default_factory=dict)
    first: str | None = None
    first_kind: str | None = None

    def note(self, kind: str, message: str | Callable[[], str], *, first: str | Callable[[], str] | None = None,
             **numbers: Any) -> None:
        """Note a failure of ``kind``; ``numbers`` as :func:`figure` takes them. ``message`` says what
        the figure is about; ``first``, if given, is what default mode would have raised, kept if this is
        the first failure noted (default: ``message``). Either may be a callable, called only when
        needed (a survey of 10,000 failing frames builds a few messages, not 10,000)."""
        old = self.kinds.get(kind)
        count = 1 + (old["failures"] if old else 0)
        new = figure(**numbers, failures=count)
        text = None
        if worse(new, old):
            text = message() if callable(message) else message
            self.kinds[kind] = figure(**numbers, failures=count, message=text)
        else:
            old["failures"] = count
        if self.first is None:
            if first is None:
                first = message if text is None else text
            self.first = first() if callable(first) else first
            self.first_kind = kind

    def merge(self, other: "Survey") -> None:
        """Add what ``other`` noted (a check's findings made elsewhere, e.g. in a shared run), as if
        noted here after what this survey already holds."""
        for kind, fig in other.kinds.items():
            old = self.kinds.get(kind)
            if worse(fig, old):
                self.kinds[kind] = dict(fig, failures=fig["failures"] + (old["failures"] if old else 0))
            else:
                old["failures"] += fig["failures"]
        if self.first is None:
            self.first, self.first_kind = other.first, other.first_kind

    def summary(self) -> str:
        """One line: every kind that failed with its worst figure, worst first."""
        ranked = sorted(self.kinds.items(), key=lambda item: -_severity(item[1]))
        return "every kind that failed (survey of every frame): " + "; ".join(
            f"{kind} {format_figure(fig)}{' ' + repr(fig['target']) if fig.get('target') else ''}"
            f" [{fig['failures']} failure{'s' if fig['failures'] != 1 else ''}]" for kind, fig in ranked)

    def failure_text(self) -> str:
        """What the check fails with: the first failure's message, then :meth:`summary`."""
        return f"{self.first}\n{self.summary()}"


def settle(item, report) -> None:
    """Survey mode, after a check's call: a check that noted failures and raised none fails now,
    with :meth:`Survey.failure_text`; one that also raised keeps its own failure and gets the
    survey as a report section. Nothing changes for a check that noted nothing."""
    survey = item.stash.get(SURVEY, None)
    if report.when != "call" or survey is None or not survey.kinds or hasattr(report, "wasxfail"):
        return
    if report.passed:
        report.outcome = "failed"
        report.longrepr = survey.failure_text()
        item.stash[_SETTLED] = report.nodeid
    elif report.failed:
        report.sections.append(("conformance survey", survey.failure_text()))


def _image_figures(item, report) -> dict[str, dict[str, Any]]:
    """The worst failed image check of this check (golden render, silhouette), from the records the
    image checks keep in the results directory: their measured numbers, frame by frame."""
    try:
        from conformance.checks import image_options
        from conformance.reports import artefacts

        records = artefacts.read_records(image_options.from_config(item.config).results)
    except Exception:  # no results directory, or no image options in this session: nothing to add
        return {}
    found: dict[str, dict[str, Any]] = {}
    for record in records:
        if record.nodeid != report.nodeid or record.passed or record.kind not in ("golden", "silhouette"):
            continue
        if record.kind == "golden":
            keys = [k for k in record.limits if k in record.metrics]
            if not keys:
                continue
            key = max(keys, key=lambda k: _ratio(record.metrics[k], record.limits[k], False))
            unit = "FLIP mean" if key.endswith("flip_mean") else "of the picture"  # "sync: flip_mean" …
            new = figure(value=record.metrics[key], limit=record.limits[key], unit=unit, frame=record.frame,
                         message=record.message)
            kind = "golden render"
        else:
            target = re.search(r"silhouette of '([^']*)'", record.message)
            target = target.group(1) if target else None
            if "pixels_off" in record.metrics and "pixels_off" in record.limits:
                new = figure(value=record.metrics["pixels_off"], limit=record.limits["pixels_off"], unit="pixels off",
                             frame=record.frame, target=target, message=record.message)
            elif "iou" in record.metrics and "iou" in record.limits:  # a record of an earlier kit
                new = figure(value=record.metrics["iou"], limit=record.limits["iou"], unit="IoU", at_least=True,
                             frame=record.frame, target=target, message=record.message)
            else:
                continue
            kind = "silhouette"
        old = found.get(kind)
        new["failures"] = 1 + (old["failures"] if old else 0)
        if worse(new, old):
            found[kind] = new
        else:
            old["failures"] = new["failures"]
    return found


def kinds_of(item, report, message: str) -> dict[str, dict[str, Any]]:
    """The kinds of failure of one check's report, for its JSON record: what the survey noted,
    and, for a failure raised (default mode, or a check outside the survey), its kind (by check, or
    read from the message) with the figure its message or its image records give. ``{}`` when the
    report did not fail."""
    if not report.failed:
        return {}
    survey = item.stash.get(SURVEY, None)
    kinds = {kind: dict(fig) for kind, fig in (survey.kinds.items() if survey is not None else ())}
    settled = report.when == "call" and item.stash.get(_SETTLED, None) == report.nodeid
    raised = item.stash.get(RAISED, None) if report.when == "call" else None
    if not settled and raised is not None:  # the kit raised it, and said what kind it is
        for kind, fig in raised.items():
            if worse(fig, kinds.get(kind)):
                kinds[kind] = dict(fig)
    elif not settled:  # the check raised this failure itself
        kind = kind_of_failure(getattr(item, "originalname", item.name), message)
        images = _image_figures(item, report) if kind in ("golden render", "silhouette") else {}
        found = images.get(kind) or figure_from_message(kind, message.removeprefix("Failed: "))
        if worse(found, kinds.get(kind)):
            kinds[kind] = found
    return kinds
