"""The kit's own events on an app: teleports, kicks and joint resets between ticks.

An app's bodies move only as its story goes: a wall that tips about one axis never shows that Euler
angles applied in the wrong order turn a body about the wrong axes. Because the kit drives the app's
loop, it can do to the app what it does to its scenes (:mod:`conformance.bullet.events`): before the app's
callback of tick ``k``, turn a body to a hard orientation, kick it, or reset a joint, or teleport or kick a
soft body (every node at once), so that the app's sync has to draw poses its story never produces. Every
event is applied on every pyBullet client of the app that has bodies (an app may keep an empty client, or one per world). Events name bodies by position
in the list of a client's *dynamic* bodies (``which`` modulo its length; static bodies are left where the app put them,
so an app may draw them as part of the world) and joints by position in the list of movable joints,
and are drawn by Hypothesis (:func:`conformance.checks.strategies.app_events`), so a failure is reproducible from its JSON.

An event wrapped in :class:`AfterStep` is applied instead right after the first ``stepSimulation`` of its
tick, before the app's sync reads: a body teleported there is at rest when the sync runs
(``resetBasePositionAndOrientation`` leaves its velocity zero, pybullet-facts.md), which after a step
under gravity it never is. The scene checks sync right after their events, with no step between; this
is how an app's sync meets the same state.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

from conformance.bullet import events as scene_events
from conformance.apps.bodies import Frame

__all__ = ["AfterStep", "apply", "apply_after_step", "as_dict", "from_dicts"]


@dataclass(frozen=True)
class AfterStep:
    """``event``, applied right after the first step of its tick instead of before the tick."""

    event: object

    @property
    def frame(self) -> int:
        return self.event.frame


def _scene(client: int, frames: list[Frame], dynamic: bool):
    from conformance.bullet.client import BoundClient

    p = BoundClient(client)
    wanted = sorted({f.body for f in frames if f.client == client and f.link == -1 and f.node < 0 and (f.mass > 0 or not dynamic)})
    soft = sorted({f.body for f in frames if f.client == client and f.node >= 0})
    dt = p.getPhysicsEngineParameters()["fixedTimeStep"]
    return SimpleNamespace(p=p, bindings=[SimpleNamespace(body=b, soft=False) for b in wanted]
                           + [SimpleNamespace(body=b, soft=True) for b in soft], dt=dt)


def apply(events, tick: int, frames: list[Frame]) -> None:
    """Apply the events of ``tick`` on every client of ``frames`` (before the app's callback of that tick)."""
    due = [e for e in events if e.frame == tick and not isinstance(e, AfterStep)]
    for client in sorted({f.client for f in frames}):
        _apply(due, client, frames)


def apply_after_step(events, tick: int, client: int, frames: list[Frame]) -> None:
    """Apply the :class:`AfterStep` events of ``tick`` on ``client`` (after its first step of that tick)."""
    _apply([e.event for e in events if e.frame == tick and isinstance(e, AfterStep)], client, frames)


def _apply(due, client: int, frames: list[Frame]) -> None:
    if not due:
        return
    for event in due:
        scene = _scene(client, frames, dynamic=not isinstance(event, scene_events.JointReset))
        if scene.bindings:
            event.apply(scene)
            if not isinstance(event, (scene_events.Kick, scene_events.SoftKick)):
                _clear_of_static(scene.p, client, frames)


#: how deep in a static body a body may be left by the kit's teleport or joint reset (m)
DEPTH = 1e-3


def _clear_of_static(p, client: int, frames: list[Frame]) -> None:
    """Lift each dynamic body out of the static bodies the kit's own teleport or joint reset put it in, along
    the contact normal: a robot pushed into the ground plane has a part below it, which pyBullet's renderer
    hides behind the plane and an app that does not draw the plane shows, so the pictures disagree about a
    pose no story of the app's produces (measured: R2-D2 rejected by ``pictured`` in most draws of 20
    perturbed runs). The sync still meets the turned pose; it only lands on the ground, not in it."""
    statics = sorted({f.body for f in frames if f.client == client and f.link == -1 and f.node < 0 and f.mass == 0})
    movers = sorted({f.body for f in frames if f.client == client and f.link == -1 and f.node < 0 and f.mass > 0})
    for body in movers:
        for _ in range(4):
            deepest = min((c for s in statics for c in p.getClosestPoints(body, s, 0.0)), key=lambda c: c[8], default=None)
            if deepest is None or deepest[8] >= -DEPTH:
                break
            pos, orn = p.getBasePositionAndOrientation(body)
            p.resetBasePositionAndOrientation(body, [a - deepest[8] * n for a, n in zip(pos, deepest[7])], orn)


def as_dict(event) -> dict:
    import json

    if isinstance(event, AfterStep):
        return {**as_dict(event.event), "after_step": True}
    return json.loads(scene_events.dumps([event]))[0]


def from_dicts(items) -> list:
    import json

    items = [dict(item) for item in items]
    flags = [bool(item.pop("after_step", False)) for item in items]
    return [AfterStep(e) if after else e for e, after in zip(scene_events.loads(json.dumps(items)), flags)]
