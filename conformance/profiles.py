"""Hypothesis settings for the conformance checks.

Two profiles: Hypothesis' ``default`` (fast: each check runs the few examples it asks for, randomly
drawn) and ``ci`` (``--hypothesis-profile ci``: derandomized, so every CI run tries the same
examples, and four times as many). With any other profile the checks take its ``max_examples``.
Physics steps take milliseconds, so deadlines are off and the "too slow" health check is suppressed.
"""

from __future__ import annotations

from hypothesis import HealthCheck, settings

__all__ = ["CI_FACTOR", "check_settings", "describe"]

CI_FACTOR = 4
_SLOW_OK = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much]

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True,
                          suppress_health_check=_SLOW_OK)


def _profile() -> str:
    return settings.get_current_profile_name()


def check_settings(examples: int) -> settings:
    """Settings for a check that wants ``examples`` examples under the fast default profile."""
    profile = _profile()
    if profile == "default":
        count = examples
    elif profile == "ci":
        count = examples * CI_FACTOR
    else:
        count = settings.default.max_examples
    return settings(max_examples=count, deadline=None, suppress_health_check=_SLOW_OK, print_blob=True)


def describe() -> str:
    profile = _profile()
    how = {"default": "fast, random examples", "ci": f"derandomized, x{CI_FACTOR} examples"}.get(profile, "user profile")
    return f"hypothesis profile {profile!r} ({how})"
