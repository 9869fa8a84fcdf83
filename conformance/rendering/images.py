"""Image comparison (no pytest here, so the command line can reuse it)."""

from __future__ import annotations

import numpy as np

__all__ = ["assert_identical", "difference"]


def difference(a: np.ndarray, b: np.ndarray) -> tuple[int, int]:
    """Number of differing pixels and the largest channel difference."""
    if a.shape != b.shape:
        raise ValueError(f"image shapes differ: {a.shape} vs {b.shape}")
    delta = np.abs(a.astype(np.int16) - b.astype(np.int16))
    return int(np.count_nonzero(delta.max(axis=-1))), int(delta.max(initial=0))


def assert_identical(a: np.ndarray, b: np.ndarray, *, what: str) -> None:
    __tracebackhide__ = True
    if a.shape != b.shape:
        raise AssertionError(f"{what}: sizes differ, {a.shape[1]}x{a.shape[0]} vs {b.shape[1]}x{b.shape[0]}")
    pixels, worst = difference(a, b)
    if pixels:
        raise AssertionError(f"{what}: {pixels} of {a.shape[0] * a.shape[1]} pixels differ (largest channel difference {worst})")
