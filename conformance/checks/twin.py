"""An unsynced twin of a run: the same scene built again and stepped alongside it, never synced.

pyBullet is deterministic: the same scene stepped the same way holds bit-identical state (measured: all 17
scenes, 30 frames, the reference sync's run against a twin stepped without it). So what the run holds after
each step must be what its twin holds; a difference is something a sync changed that
:meth:`scenes.base.Scene.physics_state` cannot read and that the step carried on: a soft body's node velocities
(``resetBaseVelocity`` sets every node's; pyBullet reports none), a force left pending
(``applyExternalForce`` acts at the next step), any state pyBullet keeps and does not report.
"""

from __future__ import annotations

import weakref

from conformance import scenes

__all__ = ["Twin", "of"]


class Twin:
    """``scene`` built again from its name and parameters, advanced frame by frame as the run is. ``usable``
    is False for a scene that two builds from the same parameters do not make alike (a user's scene drawing
    random numbers unseeded, which the determinism check names): its twin says nothing of the sync."""

    def __init__(self, scene):
        self.scene = scenes.build(scene.name, **scene.params)
        self.frame = 0
        with scenes.build(scene.name, **scene.params) as again:
            self.usable = again.physics_state() == self.scene.physics_state()

    def state(self, frame: int) -> bytes:
        """The twin's :meth:`~scenes.base.Scene.physics_state` after the step of ``frame`` (1-based)."""
        while self.frame < frame:
            self.scene.advance(self.frame)
            self.frame += 1
        return self.scene.physics_state()

    def close(self) -> None:
        self.scene.close()


_twins: "weakref.WeakKeyDictionary[object, Twin]" = weakref.WeakKeyDictionary()


def of(run) -> Twin:
    """The twin of ``run`` (a :class:`conformance.sync.runner.Run`), made on first use and closed with the run."""
    twin = _twins.get(run)
    if twin is None:
        twin = _twins[run] = Twin(run.scene)
        weakref.finalize(run, twin.close)
    return twin
