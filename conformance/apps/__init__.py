"""App mode: checking a user's own program, unmodified, instead of a sync ported to the kit's protocol.

The kit runs the app's script in a process of its own (:mod:`~conformance.apps.launch`,
:mod:`~conformance.apps.child`), takes over FURY's window loop there (:mod:`~conformance.apps.driver`,
:mod:`~conformance.apps.takeover_vtk`, :mod:`~conformance.apps.takeover_pygfx`), drives the app's own
per-frame callback tick by tick and records every actor's drawn vertices and every pyBullet frame
(:mod:`~conformance.apps.recording`). The judgement needs no mapping from the user: each drawn vertex
must be rigidly held by one link frame or the world (:mod:`~conformance.apps.attachment`), sit on its
body's collision shape where it draws it (:mod:`~conformance.apps.placement`), and every moving body
must be drawn (:mod:`~conformance.apps.judge`). The kit's own events between ticks
(:mod:`~conformance.apps.perturb`) make it property-based.
"""

from __future__ import annotations

import json
import shlex
from dataclasses import dataclass, field

from conformance.apps.judge import CHECKS, judge
from conformance.apps.launch import AppFailed, KitFailed, record
from conformance.apps.recording import Recording
from conformance.apps.verdict import DIAGNOSES, Verdict

__all__ = ["CHECKS", "DIAGNOSES", "AppFailed", "AppResult", "KitFailed", "Recording", "Verdict", "check_app", "judge", "record",
           "reproduce_command"]

#: ticks of an app's own run, unless told otherwise
DEFAULT_TICKS = 120
#: ticks of each perturbed run (the kit's events fall in ticks 1..PERTURBED_TICKS-1)
PERTURBED_TICKS = 30


@dataclass
class AppResult:
    """One run of an app and its verdicts."""

    script: str
    ticks: int
    events: list
    recording: Recording
    verdicts: dict = field(default_factory=dict)
    tick_function: str | None = None

    @property
    def passed(self) -> bool:
        return all(v.passed for v in self.verdicts.values())

    def reproduce(self) -> str:
        return reproduce_command(self.script, self.ticks, self.events, self.tick_function)


def reproduce_command(script: str, ticks: int, events=(), tick_function: str | None = None) -> str:
    """The command that runs this run of the app again, with the --tick it was given (without it, an
    app whose loop is its own cannot be run)."""
    from conformance.sync import printed

    command = f"{shlex.quote(printed.python())} -m conformance app {shlex.quote(str(script))} --ticks {ticks}"
    if tick_function:
        command += f" --tick {shlex.quote(tick_function)}"
    if events:
        command += f" --events {shlex.quote(json.dumps(list(events), separators=(',', ':')))}"
    return command


def check_app(script, *, ticks: int = DEFAULT_TICKS, events=(), tick_function=None, tolerance=None,
              timeout: float | None = None) -> AppResult:
    """Run the app ``script`` under the kit and judge it (:func:`judge`); a failure whose run cannot tell a
    late sync from one before the app's own moves gets a second, short run that can
    (:mod:`~conformance.apps.told_apart`)."""
    from conformance.apps import launch
    from conformance.judge.tolerances import DEFAULT

    kwargs = {} if timeout is None else {"timeout": timeout}
    recording = launch.record(script, ticks=ticks, events=events, tick_function=tick_function, **kwargs)
    result = AppResult(str(script), ticks, list(events), recording, judge(recording, tolerance=tolerance or DEFAULT),
                       tick_function)
    if not result.passed:
        from conformance.apps import told_apart

        told_apart.settle(result, reproduce=reproduce_command, timeout=timeout)
    return result
