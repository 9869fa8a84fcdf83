"""FURY–pyBullet conformance kit: does FURY draw what pyBullet simulates?

Run ``pytest --pyargs conformance --sync module:attr`` (or ``pytest conformance/`` in a checkout).
"""

from __future__ import annotations

from conformance.errors import ConformanceError
from conformance.world import Target, World

__version__ = "0.1.0"
__all__ = ["ConformanceError", "Target", "World", "__version__"]
