"""The result record of one image check: what was compared, the numbers, the verdict, the pictures.

Comparisons return these; the pytest plugin turns them into pass/fail, :mod:`.artefacts` writes their
pictures, :mod:`.report` renders a page from a list of them (as JSON, so records made by several
pytest-xdist workers can be gathered from disk).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

__all__ = ["GOLDEN_VERDICTS", "ImageCheck"]

#: The name under which test_golden_render puts each frame's sync and renderer verdicts on its report
#: (``user_properties``), for the plugin's JSON (:mod:`.reftest`).
GOLDEN_VERDICTS = "conformance_golden_verdicts"
#: The kinds of image check.
KINDS = ("crashed", "vertices", "golden", "silhouette", "framing")


@dataclass
class ImageCheck:
    """One image check.

    ``kind``: ``golden`` (a render against a committed golden), ``silhouette`` (FURY's silhouette of
    each target against pyBullet's own renderer), ``framing`` (every body on screen and large enough),
    ``vertices`` (a vertex check's failing frame, pictured with pyBullet's outline: :mod:`.misplaced`),
    ``crashed`` (a check whose process the sync crashed: the paragraph and the native stack, no picture).
    ``metrics`` are the measured numbers and ``limits`` the bounds they were held to, by the same keys
    where a key has a bound (e.g. ``differing_fraction`` ≤ ``limits["differing_fraction"]``; for a
    silhouette, ``iou`` of the worst target ≥ ``limits["iou"]``). ``images`` maps a role (``expected``,
    ``actual``, ``difference``, ``pybullet_mask``, ``fury_mask``, ``mask_difference``) to a path
    relative to the results directory; empty until :mod:`.artefacts` writes them. ``details`` holds
    kind-specific data (per-target IoU, the physics verdict of a golden, the tolerance set's name).
    """

    kind: str
    scene: str
    frame: int
    passed: bool
    message: str = ""
    sync: str = ""
    params: dict[str, Any] = field(default_factory=dict)
    metrics: dict[str, float] = field(default_factory=dict)
    limits: dict[str, float] = field(default_factory=dict)
    images: dict[str, str] = field(default_factory=dict)
    details: dict[str, Any] = field(default_factory=dict)
    reproduce: str = ""
    nodeid: str = ""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind={self.kind!r}, but should be one of {KINDS}")

    def to_json(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> "ImageCheck":
        names = {f.name for f in dataclasses.fields(cls)}
        return cls(**{k: v for k, v in data.items() if k in names})
