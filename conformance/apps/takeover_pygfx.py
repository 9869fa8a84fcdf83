"""Taking over FURY 2's window loop (pygfx/wgpu).

FURY 2.0 offers one way to run code every frame: ``ShowManager.register_callback(func, time, repeat,
name, *args)``, which schedules ``func(*args)`` on the canvas's event loop every ``time`` seconds until
``cancel_callback(name)``; ``showm.start()`` runs that loop, and ``window.show``/``window.snapshot`` are
the one-call ways to put a scene on screen or in a file. (Its ``add_animation`` plays keyframe
animations, which pyBullet does not drive, and a canvas ``request_draw`` function is FURY's own draw.)

The kit makes every ShowManager off-screen (``window_type="offscreen"``: no window, no display), keeps
``register_callback``'s bookkeeping (``showm._callbacks``) without scheduling anything, and replaces
the calls that would wait: ``start``, ``show`` and ``snapshot`` drive the loop instead. One tick calls
every registered repeating callback once, in the order they were registered, and each one-shot
callback at the first tick. The loop ends after the kit's tick count, when the app has cancelled every
callback, or when it calls ``showm.close()``.
"""

from __future__ import annotations

import inspect

__all__ = ["install", "scene_actors"]


class _Source:
    def __init__(self, showm):
        self.showm = showm
        self.once: list = []
        self.closed = False

    def ready(self) -> bool:
        return bool(getattr(self.showm, "_callbacks", None)) or bool(self.once)

    def tick(self) -> None:
        once, self.once = self.once, []
        for func, args in once:
            func(*args)
        for func, _time, _repeat, args in list(self.showm._callbacks.values()):
            func(*args)

    def done(self) -> bool:
        return self.closed or not (self.showm._callbacks or self.once)

    def actors(self):
        return scene_actors(self.showm.scene)

    def describe(self) -> str:
        return "FURY 2 ShowManager: its register_callback functions, once a tick"

    def ended(self) -> str:
        return "the app called showm.close()" if self.closed else "the app cancelled its callbacks"

    def camera(self):
        from conformance.apps import picture_pygfx

        return picture_pygfx.camera(self.showm)

    def faces(self, actors, camera, size, gpu):
        from conformance.apps import picture_pygfx

        return picture_pygfx.faces(self.showm, actors, camera, size, gpu)


def scene_actors(scene) -> list:
    """Every mesh under the scene (its main scene for a FURY 2 ``Scene``), in scene-graph order."""
    import pygfx

    root = getattr(scene, "main_scene", scene)
    found = []
    root.traverse(lambda obj: found.append(obj) if isinstance(obj, pygfx.Mesh) and obj.geometry is not None
                  and getattr(obj.geometry, "positions", None) is not None else None)
    return found


def install(driver) -> None:
    """Patch FURY 2's window module so that the app's loop runs under ``driver``."""
    from fury import window

    from conformance.backends import cffi_types

    cffi_types.install()  # the app's pictures parse wgpu's types as the kit's do (a second of CPU a run)

    original_init = window.ShowManager.__init__
    original_close = window.ShowManager.close
    signature = inspect.signature(original_init)
    default_size = tuple(signature.parameters["size"].default) if "size" in signature.parameters else (800, 800)

    def __init__(self, *args, **kwargs):
        kwargs["window_type"] = "offscreen"
        original_init(self, *args, **kwargs)
        try:  # the picture check draws at the app's aspect
            self._kit_app_size = tuple(signature.bind(self, *args, **kwargs).arguments.get("size", default_size))
        except TypeError:
            self._kit_app_size = default_size
        self._kit_source = _Source(self)
        driver.offer(self._kit_source)

    def register_callback(self, func, time, repeat, name, *args):
        if repeat:
            if name not in self._callbacks:  # FURY 2 refuses a second callback of one name too
                self._callbacks[name] = (func, time, repeat, args)
        else:
            self._kit_source.once.append((func, args))

    def close(self):
        self._kit_source.closed = True
        if driver.finished:
            original_close(self)

    def start(self, *args, **kwargs):
        driver.reached("showm.start()")

    def show(*args, **kwargs):
        driver.reached("window.show()")

    def snapshot(*args, **kwargs):
        driver.reached("window.snapshot()")  # the app's picture file is not written

    window.ShowManager.__init__ = __init__
    window.ShowManager.register_callback = register_callback
    window.ShowManager.close = close
    window.ShowManager.start = start
    window.show = show
    window.snapshot = snapshot
