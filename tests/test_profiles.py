"""Hypothesis profiles: under ``default`` a failing property reports its first counter-example, unshrunk,
and says so and how to shrink it; under ``shrink`` (and ``ci``) the counter-example is shrunk fully."""

from __future__ import annotations

import re

import pytest

PROPERTY = """
from hypothesis import given, strategies as st
from conformance.profiles import check_settings

# Computed, never a literal: Hypothesis draws the integer literals of the source it imports (about 4 runs
# in 60 drew 1000 itself when this read `x < 1000`), and an unshrunk run would then report the limit.
LIMIT = int("7" * 3)

@check_settings(examples=200)
@given(st.integers(0, 10**9))
def test_small(x):
    assert x < LIMIT, f"x={x}"
"""


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
