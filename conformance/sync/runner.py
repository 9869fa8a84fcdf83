"""Run a scene with a sync implementation: build, set up the sync, and advance frame by frame.

The order of a frame is fixed: the events of that frame (teleports, joint resets, kicks; see
:mod:`conformance.bullet.events`), the scene's own actions, ``p.stepSimulation()``, then the sync under
test. Frame 0 is the sync called once right after set-up (after frame-0 events), before any step.
"""

from __future__ import annotations

import contextlib
from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping, Sequence

from conformance import backends
from conformance.bullet import truth
from conformance.backends.common import Drawing
from conformance.bullet.client import NOT_THE_DEFAULT_CLIENT, decoy_client
from conformance.errors import SyncRaised
from conformance.bullet.events import Event
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
    events: Sequence[Event] = ()

    def __post_init__(self):
        self._by_frame = defaultdict(list)
        for event in self.events:
            self._by_frame[event.frame].append(event)
        #: Each actor's vertex count, topology and colours as built, before any sync.
        self.built_mesh = {name: backends.mesh_signature(a) for name, a in self.drawing.actors.items()}
        #: (frame, actor name) of every sync that changed an actor's data without telling the renderer.
        self.unannounced: list[tuple[int, str, str]] = []  # (frame, actor, what was not announced)
        #: The actors whose vertex data (positions or normals) the sync changed or announced in some call, or its
        #: factory did (:func:`running` adds those): a soft body's actor missing here was never copied into
        #: (:mod:`conformance.judge.diagnosis` tells a sync that drew it as a rigid body from one that copied late).
        self.wrote: set[str] = set()
        self._after: dict[str, tuple[int, bytes]] = {}
        self._items = truth.items_of(self.drawing.targets)
        # pyBullet's readings of every target when the current frame began, before its events and step
        # (the previous step's), and just before each event so far: the earlier poses a diagnosis tries
        # (:mod:`conformance.judge.diagnosis`). Kept as the run goes, because replaying the physics to find
        # them cost a run per failure; kept as read, because most runs never need them as poses.
        self._previous: tuple | None = None
        self._before_events: list[tuple[Event, tuple]] = []

    @property
    def previous(self) -> tuple[Any, Any] | None:
        """pyBullet's link-frame poses of every target (positions, quaternions) at the previous step,
        when the current frame began (None at frame 0)."""
        return None if self._previous is None else truth.frames_of(self._previous)

    @property
    def previous_nodes(self) -> dict[int, Any] | None:
        """Each soft target's nodes (by target index, all of its body's) at the previous step (None at frame 0)."""
        return None if self._previous is None else truth.nodes_of(self._previous)

    @property
    def before_events(self) -> list[tuple[Event, tuple[Any, Any]]]:
        """(event, every target's link-frame poses just before it) for each event applied so far."""
        return [(event, truth.frames_of(states)) for event, states in self._before_events]

    def poses(self) -> tuple[Any, Any]:
        """pyBullet's link-frame poses of every target now: positions ``(n, 3)``, quaternions ``(n, 4)``."""
        return truth.link_frames(self.drawing.world.p, self._items)

    def apply_events(self, states: tuple | None = None) -> None:
        """Apply the events of the current frame, noting what pyBullet read just before them."""
        events = self._by_frame.get(self.frame, ())
        if events:
            before = truth.read_states(self.drawing.world.p, self._items) if states is None else states
            for event in events:
                self._before_events.append((event, before))
                event.apply(self.scene)

    def apply_event(self, event: Event) -> None:
        """Apply one event now (not scheduled: the sync-order machine's), noting what pyBullet read just before
        it, as scheduled events are: a drawing left at that pose is named (``before-event``)."""
        self._before_events.append((event, truth.read_states(self.drawing.world.p, self._items)))
        event.apply(self.scene)

    def step(self) -> None:
        """One frame of physics without syncing: events, actions, ``stepSimulation``."""
        self.frame += 1
        self._previous = truth.read_states(self.drawing.world.p, self._items)
        self.apply_events(self._previous)
        self.scene.advance(self.frame - 1)

    def sync(self) -> None:
        """Call the sync under test for the current frame, noting changes the renderer was not told
        about: a live renderer re-uploads geometry only when the data's modification time (VTK) or
        revision (pygfx) moves. Then hand the announced changes over, as a live window's next frame does."""
        actors = self.drawing.actors
        # What an actor held after the last sync is what it holds now unless its time moved since
        # (a render swaps colours, say), so each frame copies every actor's data once, not twice.
        before = {}
        for name, actor in actors.items():
            last = self._after.get(name)
            before[name] = last if last is not None and last[0] == backends.content_time(actor) else backends.content_state(actor)
        self.syncer(self.frame)
        self._after = {name: backends.content_state(a) for name, a in actors.items()}
        for name, after in self._after.items():
            if after[0] != before[name][0] or after[1] != before[name][1]:
                self.wrote.add(name)
            missed = backends.unannounced(actors[name], before[name], after) if after[1] != before[name][1] else None
            if missed:
                self.unannounced.append((self.frame, name, missed))
        backends.flush(self.drawing)

    def advance(self, frames: int = 1) -> None:
        """Step and sync ``frames`` times."""
        for _ in range(frames):
            self.step()
            self.sync()

    def frames(self, count: int) -> Iterator[int]:
        """Advance ``count`` frames, yielding the frame number after each (1-based)."""
        for _ in range(count):
            self.advance()
            yield self.frame


@contextlib.contextmanager
def running(scene: str, implementation: SyncImplementation, events: Sequence[Event] = (), **params: Any) -> Iterator[Run]:
    """Build ``scene`` with ``params``, draw it, start the sync, apply frame-0 events and sync frame 0;
    always disconnect. The scene is never on pyBullet's default client 0 (an empty decoy holds it,
    :func:`conformance.bullet.client.decoy_client`), so a sync that leaves out the scene's client fails here as
    in a user's program with more than one client, and its error says so."""
    client = -1
    with decoy_client():
        try:
            with build(scene, **params) as built:
                client = built.client
                drawing = backends.build(built)
                # A soft body's actor as built, to tell whether the sync's factory wrote into it (Run.wrote).
                soft = {id(t.actor) for t in drawing.targets if t.nodes is not None}
                built_soft = {name: backends.content_state(a) for name, a in drawing.actors.items() if id(a) in soft}
                syncer = implementation.start(drawing.world)
                run = Run(scene=built, drawing=drawing, syncer=syncer, params=dict(built.params), events=tuple(events))
                run.wrote.update(name for name, state in built_soft.items()
                                 if backends.content_state(drawing.actors[name])[:2] != state[:2])
                run.apply_events()
                run.sync()
                yield run
        except SyncRaised as err:
            # pybullet raises its own class, named ``error``, when a call names a body its client has not
            if client == 0 or ": error: " not in str(err):
                raise
            raise SyncRaised(f"{err} {NOT_THE_DEFAULT_CLIENT}") from err.__cause__
