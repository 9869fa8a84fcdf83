"""Golden snapshots of the reference scenes: making them, and the two verdicts on each.

* :func:`make` runs a scene with the reference sync and renders it at its golden frames
  (``SceneSpec.frames_with_goldens()``: the first, the middle of the action, the last), capturing the
  physics state of each frame for the manifest;
* :func:`check_render` (the *render* verdicts) restores a golden's stored physics state in a run of
  the sync under test, syncs and renders (:func:`draw`), then judges the picture twice
  (:mod:`conformance.rendering.reftest`): against a live reference render of the same state (the
  *sync* verdict) and the live reference against the golden (the *renderer* verdict), whatever
  pyBullet does on this machine. Frames are checked in order in one run, so what a sync leaves
  behind from one frame (geometry it changed without telling VTK, a pose it draws a frame late)
  shows in the next;
* :func:`check_physics` (the *physics* verdict) compares a live run's state at each golden frame
  with the stored one: a difference there is pyBullet or the platform, not rendering;
* :func:`regenerate` writes goldens anew (atomically, unchanged bytes untouched) and says what
  changed and by how much; a golden whose picture is the same and whose state differs only by float
  noise (:data:`conformance.bullet.state.NOISE_SHARE` of the physics tolerance) is kept as it is, so another CPU regenerates no noise.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.metadata
import inspect
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from conformance import backends, files
from conformance.bullet import state
from conformance.errors import GoldenError, GoldenFramesBadly
from conformance.rendering import framing
from conformance.rendering import golden as storage
from conformance.rendering.records import ImageCheck

__all__ = ["Change", "check_physics", "check_render", "draw", "make", "only_float_noise", "regenerate"]

#: The sync whose drawing the goldens show.
GOLDEN_SYNC = "reference"


def manifest(run, frame: int, captured: dict[str, Any], renderer: dict[str, str]) -> dict[str, Any]:
    scene = run.scene
    return {
        "format": storage.FORMAT,
        "scene": scene.name,
        "params": dict(scene.params),
        "frame": frame,
        "camera": scene.camera.as_dict(),
        "size": list(scene.image_size),
        "background": [1.0, 1.0, 1.0],
        "lighting": backends.LIGHTING,
        "multisamples": backends.MULTISAMPLES,
        "sync": GOLDEN_SYNC,
        "renderer": renderer,
        "versions": storage.library_versions(),
        "state": captured,
    }


def make(scene_name: str) -> list[tuple[int, np.ndarray, dict[str, Any]]]:
    """Run ``scene_name`` (default parameters) with the reference sync; at each golden frame, the
    picture and its manifest."""
    from conformance import scenes, sync
    from conformance.sync import runner

    wanted = sorted(set(scenes.get(scene_name).frames_with_goldens()))
    renderer = backends.renderer_info()
    made, framed = [], []
    with runner.running(scene_name, sync.load(GOLDEN_SYNC)) as run:
        for frame in wanted:
            run.advance(frame - run.frame)
            framed.append(framing.of_scene(run.drawing, run.scene.camera, run.scene.image_size, scene=scene_name, frame=frame))
            image = backends.render(run.drawing, run.scene.camera, run.scene.image_size)
            made.append((frame, image, manifest(run, frame, state.capture(run.scene), renderer)))
    badly = [record for record in framed if not record.passed]
    if badly:  # refused before anything is written: the next run's framing check would fail on them
        raise GoldenFramesBadly(
            f"scene {scene_name!r}: no golden made, the camera frames it badly: {badly[0].message}"
            + (f" (and at {len(badly) - 1} more golden frame(s))" if len(badly) > 1 else "")
            + ". A body cut off or a few pixels across passes any picture check whatever the sync does to it. "
            "Move the scene's camera (its SceneSpec's Camera: position, focal point, view angle, clipping range) "
            "until every body is inside the picture, and regenerate.")
    return made


def load(directory: Path | str, scene, frame: int, params=None) -> storage.Golden:
    """The golden of a built scene at ``frame``, validated against its parameters (or ``params``: a
    golden variant's are the default scene's), camera and size."""
    return storage.read(directory, scene.name, frame, params=dict(scene.params if params is None else params),
                        camera=scene.camera.as_dict(), size=tuple(scene.image_size))


def draw(run, golden: storage.Golden) -> np.ndarray:
    """The sync under test's render of a golden frame: the golden's stored physics state restored in
    ``run``, the sync called once, the picture taken. Call it frame after frame in one run, so that
    what a sync leaves behind from one frame shows in the next."""
    frame = golden.manifest["frame"]
    state.restore(run.scene, golden.state)
    run.frame = frame
    run.sync()
    return backends.render(run.drawing, run.scene.camera, run.scene.image_size)


def check_render(run, golden: storage.Golden, *, sync: str, here: dict[str, str], override: str | None = None,
                 reference: np.ndarray | None = None) -> tuple[ImageCheck, dict[str, np.ndarray]]:
    """Both picture verdicts on one golden frame (:func:`conformance.rendering.reftest.judge`): the sync's
    render against the live reference, and the live reference against the golden; and the pictures for
    the report. ``reference``: the live reference if already drawn (else drawn now, in a second scene)."""
    from conformance.rendering import reftest

    actual = draw(run, golden)
    if reference is None:
        reference = reftest.references(run.scene.name, {golden.manifest["frame"]: golden},
                                       run.scene.params)[golden.manifest["frame"]]
    return reftest.judge(golden, actual, reference, here=here, override=override, sync=sync)


@dataclass(frozen=True)
class PhysicsVerdict:
    frame: int
    difference: state.PhysicsDifference
    chaotic: bool  # the frame is past the scene's chaotic step: another platform may differ here

    def as_dict(self) -> dict[str, Any]:
        return {"frame": self.frame, "chaotic": self.chaotic, **self.difference.as_dict()}


def check_physics(scene_name: str, goldens: dict[int, storage.Golden]) -> list[PhysicsVerdict]:
    """The physics verdict: the live run's state at each golden frame against the stored one. Needs
    no sync and no renderer: a sync does not touch physics (``test_sync_does_not_touch_physics``), so
    the goldens' states, captured in a run with the reference sync, are the bare scene's."""
    from conformance import scenes

    spec = scenes.get(scene_name)
    live = live_states(scene_name, tuple(sorted(goldens)))
    return [PhysicsVerdict(frame, state.compare(live[frame], goldens[frame].state),
                           spec.chaotic_after is not None and frame > spec.chaotic_after)
            for frame in sorted(goldens)]


@functools.lru_cache(maxsize=None)
def live_states(scene_name: str, frames: tuple[int, ...]) -> dict[int, dict[str, Any]]:
    """The bare scene's physics state (default parameters) at ``frames``, stepped once per process:
    both golden verdicts of every sync run need it, and a scene steps the same way every time
    (``test_is_deterministic_in_process``). With :data:`SHARED_STATES` naming a directory, once for
    all the processes that share it (:func:`_shared_file`)."""
    from conformance import scenes

    shared = _shared_file(scene_name, frames)
    if shared is not None:
        try:
            return {int(frame): s for frame, s in json.loads(shared.read_bytes())["states"].items()}
        except (OSError, ValueError, KeyError, TypeError, AttributeError):  # none yet, or not whole: step it
            pass
    states = {}
    with scenes.build(scene_name) as scene:
        done = 0
        for frame in frames:
            for step in range(done, frame):
                scene.advance(step)
            done = frame
            states[frame] = state.capture(scene)
    if shared is not None:
        try:
            files.write_atomically(shared, json.dumps({"scene": scene_name, "states": states}).encode("utf-8"))
        except OSError:  # not shared, then: this process has the states all the same
            pass
    return states


#: The environment variable naming a directory where the processes of one session share :func:`live_states`
#: (the kit's own test session sets it for its sync runs: each right sync's run stepped the three wall
#: scenes, 3.1 s of CPU, to replay the same physics; ``tests/background.py``).
SHARED_STATES = "CONFORMANCE_SHARED_STATES"


def _shared_file(scene_name: str, frames: tuple[int, ...]) -> Path | None:
    """Where the states of ``scene_name`` at ``frames`` are shared, named by everything they follow from:
    the scene (its module's source, parameters, gravity), the code that steps and captures a scene, and
    pyBullet's version; None unless :data:`SHARED_STATES` is set. Floats go through JSON exactly (repr)."""
    from conformance import scenes
    from conformance.scenes import base

    directory = os.environ.get(SHARED_STATES)
    if not directory:
        return None
    spec = scenes.get(scene_name)
    digest = hashlib.sha256(json.dumps([scene_name, list(frames), repr(sorted(spec.defaults.items())), list(spec.gravity),
                                        importlib.metadata.version("pybullet")]).encode("utf-8"))
    for source in (inspect.getsourcefile(spec.populate), base.__file__, state.__file__):
        if source is None:  # a scene whose code has no file: nothing to name it by, so not shared
            return None
        digest.update(Path(source).read_bytes())
    return Path(directory) / f"{scene_name}-{digest.hexdigest()[:24]}.json"


@dataclass(frozen=True)
class Change:
    """What regenerating one golden did."""

    scene: str
    frame: int
    status: str  # "new", "changed" (both written), "unchanged", "kept" (float noise only: not written)
    pixels: int = 0  # differing pixels against the old golden
    largest: int = 0  # largest channel difference
    physics: str = ""  # the physics difference against the old manifest, if it had one
    state: str = ""  # the largest float difference of the states: the noise kept, or one beyond the bound
    replaced: str = ""  # why the old golden could not be read as this scene's (another camera, a damaged file)

    def describe(self) -> str:
        where = f"{self.scene} frame {self.frame}"
        if self.status == "new":
            return f"{where}: new"
        if self.status == "unchanged":
            return f"{where}: unchanged (byte-identical)"
        if self.status == "kept":
            return f"{where}: kept, not rewritten: same pixels, and the state differs only by float noise ({self.state})"
        if self.pixels < 0:
            picture = "the old picture could not be decoded, so nothing was compared"
        elif self.pixels:
            picture = f"{self.pixels} pixels differ (largest channel difference {self.largest})"
        else:
            picture = "pixels identical"
        return (f"{where}: changed: {picture}" + (f"; physics: {self.physics}" if self.physics else "")
                + (f"; state beyond float noise: {self.state}" if self.state else "")
                + (f"; the old golden did not fit the scene: {self.replaced}" if self.replaced else ""))


def only_float_noise(old: storage.Golden, image: np.ndarray, made: dict[str, Any]) -> state.FloatNoise | None:
    """The state's float noise when it is all that tells a fresh golden from ``old``: the same pixels,
    every other manifest entry equal, and no float of the state farther than the bound; else None
    (then the golden is written as usual). A state equal to the last bit is no noise: nothing to keep."""
    fresh = storage.jsonable(made)
    if (old.image.shape != image.shape or not np.array_equal(old.image, image)
            or {k: v for k, v in fresh.items() if k != "state"} != {k: v for k, v in old.manifest.items() if k != "state"}):
        return None
    noise = state.float_noise(fresh["state"], old.state)
    if noise is None or not noise.is_noise or storage.encode_manifest(fresh) == storage.encode_manifest(old.manifest):
        return None
    return noise


def regenerate(scene_name: str, directory: Path | str, *, mode: str = "all", tolerance_override: str | None = None) -> list[Change]:
    """Make a scene's goldens anew and write those that ``mode`` selects: ``all``, ``missing``
    (missing or unreadable), or ``failing`` (missing, unreadable, or failing the renderer verdict
    with the reference sync). A selected golden that differs only by float noise
    (:func:`only_float_noise`) is kept: neither file is touched."""
    from conformance import scenes
    from conformance.rendering import images

    if mode not in ("all", "missing", "failing"):
        raise ValueError(f"mode={mode!r}, but should be 'all', 'missing' or 'failing'")
    changes = []
    here = backends.renderer_info()
    spec = scenes.get(scene_name)
    for frame, image, made in make(scene_name):
        replaced = ""
        try:
            old = storage.read(directory, scene_name, frame, params=dict(spec.defaults),
                               camera=spec.camera.as_dict(), size=tuple(spec.image_size))
        except GoldenError as exc:
            old = None  # missing or unreadable: every mode makes it anew
            replaced = getattr(exc, "problem", "")
            before = storage.picture_of(directory, scene_name, frame)
        if old is not None and mode == "missing":
            continue
        if old is not None and mode == "failing":
            from conformance.rendering import compare, reftest

            # The fresh picture is a live reference: failing is the renderer verdict failing.
            if compare.compare_images(old.image, image, reftest.renderer_tolerance(old, image, here, tolerance_override)[0]).passed:
                continue
        noise = only_float_noise(old, image, made) if old is not None else None
        if noise is not None:  # writing it would commit another CPU's last bits, and nothing else
            changes.append(Change(scene_name, frame, "kept", state=noise.describe()))
            continue
        png, _ = storage.paths(directory, scene_name, frame)
        existed = png.exists()
        if not storage.write(directory, scene_name, frame, image, made):
            changes.append(Change(scene_name, frame, "unchanged"))
            continue
        if old is None:
            if not existed:
                changes.append(Change(scene_name, frame, "new"))
                continue
            # A golden made for another camera or size is replaced: say how many of its pixels changed,
            # never "identical" for a picture that was not compared (a camera moved: 73,625 differed).
            if before is None:
                pixels, largest = -1, 0
            elif before.shape == image.shape:
                pixels, largest = images.difference(before, image)
            else:
                pixels, largest = image.shape[0] * image.shape[1], 255
            changes.append(Change(scene_name, frame, "changed", pixels, largest, replaced=replaced))
            continue
        pixels, largest = images.difference(old.image, image) if old.image.shape == image.shape else (image.size // 3, 255)
        physics = state.compare(made["state"], old.state)
        noise = state.float_noise(storage.jsonable(made["state"]), old.state)
        changes.append(Change(scene_name, frame, "changed", pixels, largest,
                              "" if physics.position == 0 and physics.angle == 0 else physics.describe(),
                              noise.describe() if noise is not None and not noise.is_noise else ""))
    return changes
