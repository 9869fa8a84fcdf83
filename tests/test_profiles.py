"""Hypothesis profiles: under ``default`` a failing property reports its first counter-example, unshrunk,
and says so and how to shrink it; under ``shrink`` (and ``ci``) the counter-example is shrunk fully."""

from __future__ import annotations

import re

import pytest

PROPERTY = """
from hypothesis import given, strategies as st
from conformance.checks.profiles import check_settings

# Computed, never a literal: Hypothesis draws the integer literals of the source it imports (about 4 runs
# in 60 drew 1000 itself when this read `x < 1000`), and an unshrunk run would then report the limit.
LIMIT = int("7" * 3)

@check_settings(examples=200)
@given(st.integers(0, 10**9))
def test_small(x):
    assert x < LIMIT, f"x={x}"
"""


@pytest.mark.fury_free("its verdict cannot depend on the FURY: Hypothesis alone, in a pytester run")
@pytest.mark.parametrize("profile, shrunk", [("default", False), ("shrink", True), ("ci", True)])
def test_a_counter_example_is_shrunk_only_where_the_profile_says(pytester, profile, shrunk):
    pytester.makepyfile(test_property=PROPERTY)
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--hypothesis-profile", profile)
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    # Shrunk means the smallest failing value, 777 exactly; match the whole number, not a prefix.
    assert bool(re.search(r"x=777\b", out)) == shrunk, out[-2000:]
    assert ("counter-example not shrunk" in out) == (not shrunk), out[-2000:]
    if not shrunk:
        assert "--hypothesis-profile shrink" in out


def test_each_example_reports_how_close_it_came_to_failing(monkeypatch):
    """``Kit.aiming`` hands Hypothesis the worst vertex error of the example in tolerances: near zero
    for the reference, a real fraction for float32 increments; never from outside an example, never a NaN."""
    from hypothesis import given, settings, strategies as st

    from conformance import sync
    from conformance.checks import profiles
    from conformance.checks.pytest_helpers import VERTEX_TARGET, Kit
    from conformance.test_vertices import check_run
    from conformance.judge.tolerances import DEFAULT

    seen: list[tuple[float, str]] = []
    monkeypatch.setattr(profiles, "target", lambda value, label: seen.append((value, label)))
    profiles.aim(0.5, "outside")  # not in an example: nothing
    profiles.aim(float("nan"), "nan")

    def closest(spec: str) -> float:
        seen.clear()

        @settings(max_examples=1, database=None, deadline=None)
        @given(st.just(None))
        def example(_):
            check_run(Kit(sync.load(spec), DEFAULT), "chain", {}, 8)

        example()
        [(value, label)] = seen
        assert label == VERTEX_TARGET
        return value

    # FURY 2 stores every vertex in float32: the reference uses 1.5 % of the tolerance there (0 on FURY 0.12)
    assert closest("reference") < 0.03 < closest("wrong_syncs:Float32Incremental") < 1.0  # drifting, not yet failing
