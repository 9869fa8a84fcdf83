"""Taking over FURY 0.12's window loop (VTK).

A FURY 0.12 app registers its per-frame function with ``ShowManager.add_timer_callback`` and hands control to
``showm.start()``, ``window.show`` or, when not interactive, ``window.record``. The kit leaves
``add_timer_callback``, ``render`` and ``exit`` as FURY wrote them (the window is off-screen, on the
kit's X display) and replaces only the calls that would wait for a person: ``start``, ``show`` and
``record`` drive the loop instead. One tick is one ``TimerEvent`` invoked on the interactor, which is
what VTK does when a timer fires: every ``TimerEvent`` observer runs once, with ``(iren, "TimerEvent")``.
The loop ends after the kit's tick count or when the app calls ``showm.exit()`` (VTK's ``GetDone()``).
"""

from __future__ import annotations

__all__ = ["install", "scene_actors"]

from conformance.apps.picture_vtk import SIZE

KIND = "FURY 0.12 ShowManager"


class _Source:
    """One ShowManager as a loop the kit drives."""

    def __init__(self, showm):
        self.showm = showm
        self.timers = 0  # add_timer_callback calls (VTK's interactor style observes TimerEvent itself)

    def ready(self) -> bool:
        return self.timers > 0 and getattr(self.showm, "iren", None) is not None

    def tick(self) -> None:
        self.showm.iren.InvokeEvent("TimerEvent")

    def done(self) -> bool:
        return bool(self.showm.iren.GetDone())

    def actors(self):
        return scene_actors(self.showm.scene)

    def describe(self) -> str:
        return "FURY 0.12 ShowManager: its add_timer_callback functions (every TimerEvent observer), once a tick"

    def ended(self) -> str:
        return "the app called showm.exit()"

    def camera(self):
        from conformance.apps import picture_vtk

        return picture_vtk.camera(self.showm)

    def faces(self, actors, camera, size, gpu):
        from conformance.apps import picture_vtk

        return picture_vtk.faces(self.showm, actors, camera, size, gpu)


def scene_actors(scene) -> list:
    """The scene's 3D actors that draw polygon data (2D text and UI actors are not bodies)."""
    found = []
    collection = scene.GetActors()
    collection.InitTraversal()
    for _ in range(collection.GetNumberOfItems()):
        actor = collection.GetNextActor()
        mapper = actor.GetMapper()
        data = mapper.GetInput() if mapper is not None else None
        if data is not None and hasattr(data, "GetPoints") and data.GetPoints() is not None and data.GetNumberOfPoints():
            found.append(actor)
    return found


def install(driver) -> None:
    """Patch FURY 0.12's window module so that the app's loop runs under ``driver``."""
    from fury import window

    original_init = window.ShowManager.__init__
    original_add = window.ShowManager.add_timer_callback

    def __init__(self, *args, **kwargs):
        original_init(self, *args, **kwargs)
        self._kit_app_size = tuple(self.size)  # the picture check draws at the app's aspect
        self.window.SetOffScreenRendering(1)  # drawn on the kit's display, never mapped
        self.window.SetSize(*SIZE)
        # No multisampling: the picture check draws faces in code colours in this window, which blending
        # would spoil; the recorded vertices do not depend on it.
        self.window.SetMultiSamples(0)
        self._kit_source = _Source(self)
        driver.offer(self._kit_source)

    def add_timer_callback(self, repeat, duration, timer_callback):
        self._kit_source.timers += 1

        def observed(obj, event):
            # VTK prints an exception raised in an observer and goes on; the kit notes it as a verdict too
            try:
                return timer_callback(obj, event)
            except Exception as exc:
                driver.raised(exc)
                raise
            except BaseException as fault:  # the kit's own (KitFault): VTK would swallow it like the app's
                driver.faulted(fault)
                raise

        return original_add(self, repeat, duration, observed)

    def start(self, *args, **kwargs):
        driver.reached("showm.start()")

    def show(*args, **kwargs):
        driver.reached("window.show()")

    def record(*args, **kwargs):
        driver.reached("window.record()")  # the app's picture file is not written

    window.ShowManager.__init__ = __init__
    window.ShowManager.add_timer_callback = add_timer_callback
    window.ShowManager.start = start
    window.show = show
    window.record = record

