"""Run a scene with a sync implementation: build, set up the sync, and advance frame by frame.

The order of a frame is fixed: the scene's actions for that step, ``p.stepSimulation()``, then the
sync under test. Frame 0 is the sync called once right after set-up, before any step.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping

from conformance import backends
from conformance.backends import Drawing
from conformance.scenes import Scene, build
from conformance.sync import Syncer, SyncImplementation

__all__ = ["Run", "running"]


@dataclass(eq=False)
class Run:
    scene: Scene
    drawing: Drawing
    syncer: Syncer
    frame: int = 0
    params: Mapping[str, Any] = field(default_factory=dict)

    def advance(self, frames: int = 1) -> None:
        """Step and sync ``frames`` times."""
        for _ in range(frames):
            self.scene.advance(self.frame)
            self.frame += 1
            self.syncer(self.frame)

    def frames(self, count: int) -> Iterator[int]:
        """Advance ``count`` frames, yielding the frame number after each (1-based)."""
        for _ in range(count):
            self.advance()
            yield self.frame


@contextlib.contextmanager
def running(scene: str, implementation: SyncImplementation, **params: Any) -> Iterator[Run]:
    """Build ``scene`` with ``params``, draw it, start the sync and sync frame 0; always disconnect."""
    with build(scene, **params) as built:
        drawing = backends.build(built)
        syncer = implementation.start(drawing.world)
        syncer(0)
        yield Run(scene=built, drawing=drawing, syncer=syncer, params=dict(built.params))
