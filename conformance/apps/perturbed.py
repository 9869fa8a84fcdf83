"""Property-based runs of an app: the kit's events between ticks, drawn by Hypothesis.

Each example is a whole run of the app in its own process (a few seconds), so the search is bounded:
``examples`` runs, no shrinking (a failing run is reported with its events as drawn, and its
reproduce line replays exactly that run). The draw is derandomised, so the same app meets the same
events on every machine and every run: the verdict is reproducible without a database.
"""

from __future__ import annotations

from hypothesis import HealthCheck, Phase, given, settings

from conformance import strategies

__all__ = ["search"]


class _Found(Exception):
    def __init__(self, result):
        self.result = result


def search(script, *, examples: int, ticks: int | None = None, tick_function=None, timeout=None, tolerance=None):
    """The first run of ``examples`` that fails any check, as an :class:`~conformance.apps.AppResult`, or None."""
    from conformance import apps
    from conformance.apps import perturb

    ticks = ticks or apps.PERTURBED_TICKS

    @settings(max_examples=examples, derandomize=True, database=None, deadline=None, phases=[Phase.generate],
              suppress_health_check=list(HealthCheck))
    @given(events=strategies.app_events(ticks))
    def run(events):
        result = apps.check_app(script, ticks=ticks, events=[perturb.as_dict(e) for e in events],
                                tick_function=tick_function, tolerance=tolerance, timeout=timeout)
        if not result.passed:
            raise _Found(result)

    try:
        run()
    except _Found as found:
        return found.result
    return None
