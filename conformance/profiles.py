"""Hypothesis settings for the conformance checks.

Three profiles: Hypothesis' ``default`` (fast: each check runs the few examples it asks for, randomly
drawn), ``ci`` (``--hypothesis-profile ci``: derandomized, so every CI run tries the same
examples, and four times as many) and ``triage`` (derandomized, the default's examples, and a
counter-example is reported as found, not shrunk: for telling right from wrong quickly, as the
``verdicts`` and ``kill-rate`` commands do). With any other profile the checks take its ``max_examples``.
Physics steps take milliseconds, so deadlines are off and the "too slow" health check is suppressed.
"""

from __future__ import annotations

from hypothesis import HealthCheck, Phase, settings

__all__ = ["CI_FACTOR", "app_examples", "check_settings", "describe"]

CI_FACTOR = 4
_SLOW_OK = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much]

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True,
                          suppress_health_check=_SLOW_OK)
settings.register_profile("triage", derandomize=True, deadline=None, print_blob=True,
                          suppress_health_check=_SLOW_OK,
                          phases=[Phase.explicit, Phase.reuse, Phase.generate])

#: Examples per profile, as a multiple of what a check asks for under ``default``.
_FACTORS = {"default": 1, "ci": CI_FACTOR, "triage": 1}


def _profile() -> str:
    return settings.get_current_profile_name()


def check_settings(examples: int) -> settings:
    """Settings for a check that wants ``examples`` examples under the fast default profile."""
    profile = _profile()
    if profile in _FACTORS:
        count = examples * _FACTORS[profile]
    else:
        count = settings.default.max_examples
    return settings(max_examples=count, deadline=None, suppress_health_check=_SLOW_OK, print_blob=True)


#: Perturbed runs of an app per profile: each is a whole run of the app in its own process (seconds), so
#: not a multiple of the scene checks' examples.
_APP_EXAMPLES = {"default": 2, "ci": 3, "triage": 2}


def app_examples() -> int:
    """How many perturbed runs ``test_app_perturbed`` makes of each app under the current profile."""
    return _APP_EXAMPLES.get(_profile(), settings.default.max_examples)


def describe() -> str:
    profile = _profile()
    how = {"default": "fast, random examples", "ci": f"derandomized, x{CI_FACTOR} examples",
           "triage": "derandomized, counter-examples not shrunk"}.get(profile, "user profile")
    return f"hypothesis profile {profile!r} ({how})"
