"""Hypothesis settings for the conformance checks.

Four profiles: Hypothesis' ``default`` (fast: each check runs the few examples it asks for, randomly
drawn, and reports the first counter-example it finds without shrinking it, so that a wrong sync's
full verdict takes about as long as a right one's: shrinking a scene run by scene run took minutes);
``shrink`` (``--hypothesis-profile shrink``: the default's examples, and every counter-example shrunk
as far as Hypothesis goes), ``ci`` (derandomized, so every CI run tries the same examples, four times
as many, shrunk) and ``triage`` (derandomized, the default's examples, not shrunk: for telling right
from wrong quickly, as the ``verdicts`` and ``kill-rate`` commands do). With any other profile the
checks take its ``max_examples`` and phases. Every failure carries the kit's own ``reproduce:`` line,
shrunk or not. Physics steps take milliseconds, so deadlines are off and the "too slow" health check is
suppressed.
"""

from __future__ import annotations

import math

from hypothesis import HealthCheck, Phase, settings, target
from hypothesis.control import currently_in_test_context

__all__ = ["CI_FACTOR", "DRAW_FACTOR", "STATEFUL_STEPS", "aim", "app_examples", "check_settings", "describe", "shrinks", "stateful_steps"]

CI_FACTOR = 4
_SLOW_OK = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much]

# No profile runs Hypothesis' targeted phase: the checks report how close each example came to failing
# (:func:`aim`), but climbing on it found float32 drift later, not sooner, at the kit's budgets (measured:
# docs/discrimination.md, "Search, not luck"), and on a wrong sync it runs past max_examples.
_SHRINK = (Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink)
_NO_SHRINK = (Phase.explicit, Phase.reuse, Phase.generate)
settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True,
                          suppress_health_check=_SLOW_OK, phases=_SHRINK)
settings.register_profile("triage", derandomize=True, deadline=None, print_blob=True,
                          suppress_health_check=_SLOW_OK, phases=_NO_SHRINK)
settings.register_profile("shrink", deadline=None, print_blob=True, suppress_health_check=_SLOW_OK, phases=_SHRINK)
# Random draws in bulk, for measuring false alarms (``python -m conformance precision``): no example
# database (a draw replayed from an earlier run is not a new draw), nothing shrunk, and
# :data:`PRECISION_FACTOR` times the default's examples in one process (set by $CONFORMANCE_DRAW_FACTOR).
settings.register_profile("precision", derandomize=False, deadline=None, print_blob=True, suppress_health_check=_SLOW_OK,
                          database=None, phases=(Phase.explicit, Phase.generate))

#: Examples per profile, as a multiple of what a check asks for under ``default``.
_FACTORS = {"default": 1, "shrink": 1, "ci": CI_FACTOR, "triage": 1, "precision": 1}
#: Profiles whose counter-examples are reported as found.
_UNSHRUNK = {"default", "triage", "precision"}
#: The environment variable that sets the ``precision`` profile's multiple of the default's examples.
DRAW_FACTOR = "CONFORMANCE_DRAW_FACTOR"


def _factor(profile: str) -> int:
    if profile == "precision":
        import os

        from conformance import validation

        return validation.whole_number(DRAW_FACTOR, os.environ.get(DRAW_FACTOR, "1"), low=1, high=100_000)
    return _FACTORS[profile]


def _profile() -> str:
    return settings.get_current_profile_name()


def check_settings(examples: int) -> settings:
    """Settings for a check that wants ``examples`` examples under the fast default profile."""
    profile = _profile()
    if profile in _FACTORS:
        count = examples * _factor(profile)
    else:
        count = settings.default.max_examples
    if profile in _UNSHRUNK:
        return settings(max_examples=count, deadline=None, suppress_health_check=_SLOW_OK, print_blob=True,
                        phases=_NO_SHRINK)
    return settings(max_examples=count, deadline=None, suppress_health_check=_SLOW_OK, print_blob=True)


def shrinks() -> bool:
    """Whether the checks shrink a counter-example under the current profile."""
    profile = _profile()
    return profile not in _UNSHRUNK and Phase.shrink in settings.default.phases


#: Perturbed runs of an app per profile: each is a whole run of the app in its own process (seconds), so
#: not a multiple of the scene checks' examples.
_APP_EXAMPLES = {"default": 2, "ci": 3, "triage": 2, "precision": 2}


def app_examples() -> int:
    """How many perturbed runs ``test_app_perturbed`` makes of each app under the current profile."""
    profile = _profile()
    if profile in _APP_EXAMPLES:
        return _APP_EXAMPLES[profile] * (_factor(profile) if profile == "precision" else 1)
    return settings.default.max_examples


#: Calls per program of the sync-order state machine (conformance/test_sync_order.py) under the kit's
#: profiles: a few syncs after each kind of change. Its programs scale with the profile like every
#: check's examples; this bounds each one (docs/numbers.md, "Sync order": 4-7 % of a ci run).
STATEFUL_STEPS = 30


def stateful_steps() -> int:
    """``stateful_step_count`` of the sync-order state machine: :data:`STATEFUL_STEPS` under the kit's
    profiles, the profile's own under any other."""
    return STATEFUL_STEPS if _profile() in _FACTORS else settings.default.stateful_step_count


def describe() -> str:
    profile = _profile()
    how = {"default": "fast, random examples, counter-examples not shrunk",
           "shrink": "random examples, counter-examples shrunk",
           "ci": f"derandomized, x{CI_FACTOR} examples",
           "triage": "derandomized, counter-examples not shrunk",
           "precision": f"random, no example database, x{_factor('precision')} examples, not shrunk"}.get(profile, "user profile")
    return f"hypothesis profile {profile!r} ({how})"


def aim(observation: float, label: str) -> None:
    """Tell Hypothesis how close this example came to failing (``observation``: the worst error as a
    fraction of its tolerance; 1 fails) with ``hypothesis.target``: ``--hypothesis-show-statistics``
    then prints each check's highest figure (how much of its tolerance a right sync uses), and a
    profile with ``Phase.target`` climbs towards the worst case (docs/discrimination.md, "Search, not
    luck", for why the kit's own profiles do not). Outside an example (a fixed run), or for a value
    that is not finite (the check fails on it anyway), it does nothing."""
    if currently_in_test_context() and math.isfinite(observation):
        target(float(observation), label=label)
