"""``assert_*`` helpers of the physics checks, with readable messages.

Messages follow the kit's style (array-api-tests): ``Δv=(…), but should be (…) [free_fall(mass=2.0, …),
step 1; applyExternalForce(…)]``: the quantity, its value, the value the document implies, and
where: the scene with its parameters, the step, and the calls that set the premise.
"""

from __future__ import annotations

import math

from typing import Any, Mapping

import numpy as np
import pytest

from conformance import figures
from conformance.bullet.collisions import Outcome

__all__ = [
    "assert_close",
    "assert_collision",
    "assert_drawn_overlapping",
    "assert_in_band",
    "assert_interpenetrating",
    "assert_vector_close",
    "context",
]


def context(scene: str, params: Mapping[str, Any], *details: str) -> str:
    """``[scene(k=v, …), detail; detail]``."""
    inner = ", ".join(f"{k}={_short(v)}" for k, v in params.items())
    return f"[{scene}({inner})" + (", " + "; ".join(details) if details else "") + "]"


def _short(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, tuple):
        return "(" + ", ".join(_short(v) for v in value) + ")"
    return repr(value)


def _vec(v) -> str:
    return "(" + ", ".join(f"{c:.9g}" for c in np.asarray(v, dtype=np.float64).ravel()) + ")"


def assert_vector_close(name: str, *, actual, expected, where: str, rtol: float, atol: float, law: str = "") -> None:
    """|actual − expected| ≤ atol + rtol·|expected| (Euclidean norms)."""
    __tracebackhide__ = True
    actual, expected = np.asarray(actual, dtype=np.float64), np.asarray(expected, dtype=np.float64)
    error = float(np.linalg.norm(actual - expected))
    bound = atol + rtol * float(np.linalg.norm(expected))
    figures.note(name, error, bound, where=where)
    if not error <= bound:  # NaN fails
        should = f"{law} = {_vec(expected)}" if law else _vec(expected)
        pytest.fail(f"{name}={_vec(actual)}, but should be {should} (error {error:.3g} > {bound:.3g}) {where}",
                    pytrace=False)


def assert_close(name: str, *, actual: float, expected: float, where: str, rtol: float, atol: float = 0.0,
                 law: str = "") -> None:
    """|actual − expected| ≤ atol + rtol·|expected|."""
    __tracebackhide__ = True
    error = abs(actual - expected)
    bound = atol + rtol * abs(expected)
    figures.note(name, error, bound, where=where)
    if not error <= bound:
        should = f"{law} = {expected:.9g}" if law else f"{expected:.9g}"
        pytest.fail(f"{name}={actual:.9g}, but should be {should} (error {error:.3g} > {bound:.3g}) {where}",
                    pytrace=False)


def assert_in_band(name: str, *, actual: float, low: float, high: float, where: str, law: str = "",
                   exact: float | None = None) -> None:
    """low ≤ actual ≤ high. ``exact``: the law's own value inside the band (the rest is a measured
    allowance), from which the figure is measured; without it, the band's middle."""
    __tracebackhide__ = True
    # The use of a band is how far from the law's value (else its middle) towards the edge on that side:
    # 1 on the edge. From the middle, a ball that does not bounce at all (apex/drop 0, the law's value
    # and the band's low edge) used 100 % of [0, 1e-3].
    centre = (low + high) / 2 if exact is None else exact
    edge = high if actual >= centre else low
    figures.note(name, abs(actual - centre), abs(edge - centre) or math.ulp(1.0), where=where)
    if not (low <= actual <= high):
        pytest.fail(f"{name}={actual:.6g}, but should be in [{low:.6g}, {high:.6g}]"
                    + (f" ({law})" if law else "") + f" {where}", pytrace=False)


def assert_collision(*, actual: Outcome, expected: bool, where: str) -> None:
    """The pair collided (contact points reported, order kept) or passed through (no contact
    points, order swapped, free flight exact), as ``expected``."""
    __tracebackhide__ = True
    if expected and not actual.collided:
        pytest.fail(f"outcome: {actual.describe()}, but should collide (contact points reported, "
                    f"a stays before b) {where}", pytrace=False)
    if not expected and not actual.passed_through:
        pytest.fail(f"outcome: {actual.describe()}, but should pass through (no contact points, a ends past b, "
                    f"free flight kept) {where}", pytrace=False)


def assert_drawn_overlapping(*, inside: Mapping[str, bool], distance: float, where: str, explained: str = "") -> None:
    """Each body's drawn centre lies inside the other's drawn shape. ``explained``: the ``diagnosis: …`` line of
    the frame's vertices, when a known mistake draws them where they are (printed under the failure)."""
    __tracebackhide__ = True
    missing = [name for name, ok in inside.items() if not ok]
    if missing:
        pytest.fail(f"drawn centre of {', '.join(missing)} outside the other body's drawn shape (drawn centres "
                    f"{distance:.4g} m apart), but physics has the pair interpenetrating, so they should be drawn "
                    f"overlapping {where}" + (f"\n{explained}" if explained else ""), pytrace=False)


def assert_interpenetrating(*, contacts: tuple[int, ...], distance: float, depth: float, where: str) -> None:
    """Physics has the pair passing through: no contact points so far, centres closer than the sum
    of the bodies' inner radii."""
    __tracebackhide__ = True
    if contacts:
        pytest.fail(f"contact points after frames {', '.join(map(str, contacts[:4]))}, but should be none: the "
                    f"pair is filtered and physics should let it pass through {where}", pytrace=False)
    if not distance < depth:
        pytest.fail(f"centre distance={distance:.6g} m, but should be below {depth:.6g} m (the sum of the inner "
                    f"radii): physics does not have the pair interpenetrating {where}", pytrace=False)
