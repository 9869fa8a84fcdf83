"""Property-based runs of an app: the kit's events between ticks, drawn by Hypothesis.

The first run is always the same hard opening (:func:`opening`): four dynamic bodies turned in place
to hard orientations (a half turn about a skew axis, Euler gimbal lock, negative w), a joint reset,
a kick, and a soft body teleported, turned and kicked — so that even one perturbed run turns bodies. (Hypothesis's first derandomised draw is the
simplest one, no event at all.) The others are drawn by Hypothesis.

Each example is a whole run of the app in its own process (a few seconds), so the search is bounded:
``examples`` runs, no shrinking (a failing run is reported with its events as drawn, and its
reproduce line replays exactly that run). The draw is derandomised, so the same app meets the same
events on every machine and every run: the verdict is reproducible without a database.
"""

from __future__ import annotations

from hypothesis import HealthCheck, Phase, given, settings

from conformance.checks import strategies

__all__ = ["opening", "search"]


def opening() -> list:
    """The first perturbed run's events: every way of turning a body the kit has, early in the run,
    one body turned between the step and the sync of tick 4, so that the sync sees it at rest, and a soft
    body teleported, turned and kicked (no-ops in an app without one)."""
    from conformance.apps.perturb import AfterStep
    from conformance.bullet.events import JointReset, Kick, SoftKick, SoftTeleport, Teleport

    hard = strategies.HARD_ORIENTATIONS
    # a half turn about (1, 1, 1); then, written with negative w, pitch +90°, pitch near -90°, pitch -90°
    turns = (hard[8], hard[11], hard[17], hard[13])
    return ([Teleport(frame=1, which=i, offset=(0.0, 0.0, 0.0), orientation=q) for i, q in enumerate(turns)]
            + [JointReset(frame=2, which=0, value=1.0, orientation=hard[10]),
               Kick(frame=3, which=1, velocity=(1.0, -1.0, 2.0), offset=(0.0, 0.0, 0.0), spin=(5.0, -7.0, 3.0)),
               AfterStep(Teleport(frame=4, which=0, offset=(0.0, 0.0, 0.0), orientation=hard[13])),
               # a soft body lifted 0.1 m and turned a half turn about (1, 1, 1), then every node kicked
               SoftTeleport(frame=5, which=0, offset=(0.0, 0.0, 0.1), orientation=hard[8]),
               SoftKick(frame=7, which=0, velocity=(1.0, -1.0, 2.0))])


class _Found(Exception):
    def __init__(self, result):
        self.result = result


def search(script, *, examples: int, ticks: int | None = None, tick_function=None, timeout=None, tolerance=None,
           seed: int | None = None):
    """The first run of ``examples`` that fails any check, as an :class:`~conformance.apps.AppResult`, or None.
    With ``seed``, the runs after the opening are drawn at random from that seed (``app --seed``, and
    ``precision``, which measures false alarms over random draws); without, derandomized."""
    from conformance import apps
    from conformance.apps import perturb

    ticks = ticks or apps.PERTURBED_TICKS
    if examples <= 0:
        return None
    first = apps.check_app(script, ticks=ticks, events=[perturb.as_dict(e) for e in opening()],
                           tick_function=tick_function, tolerance=tolerance, timeout=timeout)
    if not first.passed or examples == 1:
        return None if first.passed else first

    @settings(max_examples=examples - 1, derandomize=seed is None, database=None, deadline=None, phases=[Phase.generate],
              suppress_health_check=list(HealthCheck))
    @given(events=strategies.app_events(ticks))
    def run(events):
        result = apps.check_app(script, ticks=ticks, events=[perturb.as_dict(e) for e in events],
                                tick_function=tick_function, tolerance=tolerance, timeout=timeout)
        if not result.passed:
            raise _Found(result)

    if seed is not None:
        from hypothesis import seed as seeded

        run = seeded(seed)(run)
    try:
        run()
    except _Found as found:
        return found.result
    return None
