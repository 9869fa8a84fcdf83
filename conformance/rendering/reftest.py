"""A golden's two picture verdicts: what the sync did, and what the renderer did.

A golden is a picture made once, on one machine. Judging a sync's render against it alone mixes two
questions and answers the first loosely wherever the renderer differs: against llvmpipe's goldens a
right sync on softpipe needs the ``other-renderer`` set, and that set lets a body moved 2 px pass on
2 of 19 frames. So, as web-platform-tests' reftests do, each golden frame is judged twice:

* the **sync verdict**: the sync's render against a *live reference*: the same restored physics state
  drawn by the kit's own ``reference`` sync, now, in this process, on this renderer. Both pictures
  come from one renderer, so the tight ``same-renderer`` set applies on any machine (a re-render is
  0 pixels apart on llvmpipe, softpipe, zink and lavapipe: docs/pictures.md). It guarantees: the sync
  draws this state as the reference sync does, to within 40 pixels;
* the **renderer verdict**: the live reference against the stored golden. It guarantees: the
  rendering stack (FURY, VTK or pygfx, the driver) draws the reference as it did when the golden was
  made, within the set the pictures call for (:func:`renderer_tolerance`).

The check fails if either fails, and says which. Nothing here imports pytest: the command line and
the measurements reuse it. Comparisons return :class:`~conformance.rendering.records.ImageCheck`
records; :mod:`.report` and the plugin render them.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from typing import Any, Mapping

import numpy as np

from conformance.rendering import compare
from conformance.rendering import golden as storage
from conformance.rendering.records import GOLDEN_VERDICTS, ImageCheck

__all__ = ["GOLDEN_VERDICTS", "Verdict", "judge", "references", "renderer_tolerance"]

#: The sync that draws the live reference, as it drew the goldens.
REFERENCE_SYNC = "reference"

# (scene, params, camera, size, frame, state digest) -> picture. Per process: the renderer is the
# process's, and a scene's golden frames are drawn once however many checks judge them.
_CACHE: dict[tuple, np.ndarray] = {}


def _key(scene_name: str, golden: storage.Golden, variant: Mapping[str, Any]) -> tuple:
    m = golden.manifest
    state = hashlib.sha256(json.dumps(m["state"], sort_keys=True).encode("utf-8")).hexdigest()
    return (scene_name, json.dumps(m["params"], sort_keys=True), json.dumps(dict(variant), sort_keys=True),
            json.dumps(m["camera"], sort_keys=True), tuple(m["size"]), m["frame"], state)


def references(scene_name: str, goldens: Mapping[int, storage.Golden], variant: Mapping[str, Any] | None = None
               ) -> dict[int, np.ndarray]:
    """The live reference of each golden: its stored state restored in a fresh build of the scene (with
    a golden variant's parameters: its shared actors) and drawn by the ``reference`` sync on this
    process's renderer. Cached per process by the state, so two goldens holding the same state (a copy
    made elsewhere) share one render."""
    from conformance import backends, scenes, sync
    from conformance.sync import runner
    from conformance.bullet import state

    defaults = scenes.get(scene_name).defaults  # a parameter at its default is no variant: one cache entry
    variant = {k: v for k, v in (variant or {}).items() if k not in defaults or defaults[k] != v}
    wanted = {frame: _key(scene_name, g, variant) for frame, g in goldens.items()}
    missing = sorted(frame for frame, key in wanted.items() if key not in _CACHE)
    if missing:
        with runner.running(scene_name, sync.load(REFERENCE_SYNC), **variant) as run:
            for frame in missing:
                state.restore(run.scene, goldens[frame].state)
                run.frame = frame
                run.sync()
                _CACHE[wanted[frame]] = backends.render(run.drawing, run.scene.camera, run.scene.image_size)
    return {frame: _CACHE[key] for frame, key in wanted.items()}


def renderer_tolerance(golden: storage.Golden, reference: np.ndarray, here: Mapping[str, str],
                       override: str | None = None) -> tuple[compare.ImageTolerance, str]:
    """The set the renderer verdict holds the live reference to, and why.

    ``override`` when given. Else ``same-renderer`` when the golden's manifest names this renderer (a
    changed rendering stack under the same name must show), or when the pictures themselves agree
    within it although the names differ (zink draws llvmpipe's goldens to 0 pixels: the name
    misleads, the pictures do not). Else ``other-renderer``: anti-aliasing and rounding differ."""
    if override:
        return compare.tolerance(override), f"{override}, as asked"
    if storage.same_renderer(golden.renderer, here):
        return compare.SAME_RENDERER, "the golden's manifest names this renderer"
    tight = compare.SAME_RENDERER
    # The pixel count first: where it already exceeds the tight set, FLIP (~0.1 s) need not be computed.
    within = (compare._differing(golden.image, reference, tight.pixel_threshold, tight.block).mean()
              <= tight.max_differing_fraction)
    if within and compare.compare_images(golden.image, reference, tight).passed:
        return compare.SAME_RENDERER, ("the golden's manifest names another renderer, but the live reference "
                                       "equals the golden within the same-renderer set")
    return compare.OTHER_RENDERER, "the golden's manifest names another renderer, and the pictures differ"


@dataclasses.dataclass(frozen=True)
class Verdict:
    """One of a golden's two picture verdicts: who is judged, against what, within which set."""

    name: str  # "sync" or "renderer"
    check: ImageCheck  # compare_images' record: numbers, limits, pass/fail
    why: str  # why this tolerance set

    @property
    def passed(self) -> bool:
        return self.check.passed

    def sentence(self, size: tuple[int, int]) -> str:
        """``sync verdict FAIL: …`` with the pixels that differ against the pixels allowed."""
        tol = self.check.details["tolerance"]
        allowed = int(tol["max_differing_fraction"] * size[0] * size[1])
        pixels = int(self.check.metrics["differing_pixels"])
        what = ("the sync's render vs the live reference (the reference sync drawing the same restored state "
                "on this renderer)" if self.name == "sync" else "the live reference vs the stored golden")
        return (f"{self.name} verdict {'pass' if self.passed else 'FAIL'}: {what}: {pixels} px differ, "
                f"{allowed} allowed ({self.check.message}; set {tol['name']}: {self.why})")

    def as_dict(self) -> dict[str, Any]:
        return {"passed": self.passed, "tolerance_set": self.check.details["tolerance"]["name"], "why": self.why,
                "message": self.check.message, "metrics": dict(self.check.metrics), "limits": dict(self.check.limits)}


def judge(golden: storage.Golden, actual: np.ndarray, reference: np.ndarray, *, here: Mapping[str, str],
          override: str | None = None, sync: str = "") -> tuple[ImageCheck, dict[str, np.ndarray]]:
    """Both verdicts on one golden frame as one ``golden`` record (passed iff both passed; each verdict
    in ``details["verdicts"]``, its numbers in ``metrics`` and ``limits`` prefixed ``sync: `` and
    ``renderer: ``), and the pictures a report shows: the golden, the live reference, the sync's
    render, and the difference of each failed verdict."""
    m = golden.manifest
    scene, frame = m["scene"], m["frame"]
    # The sync is judged on this renderer, against this renderer: same-renderer unless a looser set is asked for.
    sync_set = compare.tolerance(override) if override else compare.SAME_RENDERER
    sync_why = f"{override}, as asked" if override else "both pictures come from this renderer"
    renderer_set, renderer_why = renderer_tolerance(golden, reference, here, override)
    verdicts = (Verdict("sync", compare.compare_images(reference, actual, sync_set), sync_why),
                Verdict("renderer", compare.compare_images(golden.image, reference, renderer_set), renderer_why))
    size = tuple(m["size"])
    metrics = {f"{v.name}: {k}": value for v in verdicts for k, value in v.check.metrics.items()}
    limits = {f"{v.name}: {k}": value for v in verdicts for k, value in v.check.limits.items()}
    record = ImageCheck(kind="golden", scene=scene, frame=frame, passed=all(v.passed for v in verdicts),
                        message="\n".join(v.sentence(size) for v in verdicts), sync=sync,
                        params=storage.jsonable(m["params"]), metrics=metrics, limits=limits,
                        details={"tolerance_set": verdicts[1].check.details["tolerance"]["name"],
                                 "verdicts": {v.name: v.as_dict() for v in verdicts},
                                 "golden": str(golden.png), "golden_renderer": golden.renderer})
    pictures = {"expected": golden.image, "reference": reference, "actual": actual}
    if not verdicts[0].passed:
        pictures["difference"] = compare.difference_image(reference, actual)
    if not verdicts[1].passed:
        pictures["reference_difference"] = compare.difference_image(golden.image, reference)
    return record, pictures


def bodies_where_pixels_differ(scene_name: str, golden: storage.Golden, variant: Mapping[str, Any] | None,
                               reference: np.ndarray, actual: np.ndarray, *, most: int = 5) -> str:
    """Who a failed sync verdict is about: each pixel where the sync's picture differs from the live
    reference's, named by the body pyBullet's pose puts there (the reference's drawing of the golden's
    state, rendered with one id per target). A body drawn where it is not, or not redrawn, shows as its
    name; pixels where pyBullet puts no body are something drawn where nothing is. One more scene built
    and one id picture: made only for a failure."""
    from conformance import backends, scenes, sync
    from conformance.sync import runner
    from conformance.bullet import state

    defaults = scenes.get(scene_name).defaults
    variant = {k: v for k, v in (variant or {}).items() if k not in defaults or defaults[k] != v}
    with runner.running(scene_name, sync.load(REFERENCE_SYNC), **variant) as run:
        state.restore(run.scene, golden.state)
        run.frame = golden.manifest["frame"]
        run.sync()
        ids = backends.render_ids(run.drawing, run.scene.camera, run.scene.image_size)
        names = [t.name for t in run.drawing.targets]
    differ = np.abs(reference.astype(np.int16) - actual.astype(np.int16)).max(axis=-1) > compare.SAME_RENDERER.pixel_threshold
    counts = np.bincount(ids[differ] + 1, minlength=len(names) + 1)
    named = sorted(((int(n), names[i]) for i, n in enumerate(counts[1:]) if n), reverse=True)
    parts = [f"{name!r} ({n} px)" for n, name in named[:most]]
    if len(named) > most:
        parts.append(f"{len(named) - most} more bodies ({sum(n for n, _ in named[most:])} px)")
    if counts[0]:
        parts.append(f"no body ({int(counts[0])} px: drawn where pyBullet has nothing)")
    return "where the pixels differ, pyBullet's poses put " + (", ".join(parts) if parts else "nothing")
