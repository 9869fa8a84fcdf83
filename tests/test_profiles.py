"""Hypothesis profiles: under ``default`` a failing property reports its first counter-example, unshrunk,
and says so and how to shrink it; under ``shrink`` (and ``ci``) the counter-example is shrunk fully."""

from __future__ import annotations

import re

import pytest

PROPERTY = """
from hypothesis import given, strategies as st
from conformance.profiles import check_settings

@check_settings(examples=200)
@given(st.integers(0, 10**9))
def test_small(x):
    assert x < 1000, f"x={x}"
"""


@pytest.mark.parametrize("profile, shrunk", [("default", False), ("shrink", True), ("ci", True)])
def test_a_counter_example_is_shrunk_only_where_the_profile_says(pytester, profile, shrunk):
    pytester.makepyfile(test_property=PROPERTY)
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--hypothesis-profile", profile)
    result.assert_outcomes(failed=1)
    out = result.stdout.str()
    # Shrunk means the smallest failing value, 1000 exactly; an unshrunk one is often the bound 10**9,
    # whose digits begin with "1000", so match the whole number.
    assert bool(re.search(r"x=1000\b", out)) == shrunk, out[-2000:]
    assert ("counter-example not shrunk" in out) == (not shrunk), out[-2000:]
    if not shrunk:
        assert "--hypothesis-profile shrink" in out
