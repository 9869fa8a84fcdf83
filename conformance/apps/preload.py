"""What the server of the app processes imports once (:func:`conformance.apps.launch.record`): FURY, its
renderer and the kit's side of the app's process, so that each app process, forked from it, starts with
them imported. Importing them was most of a short app run: 0.7 s of CPU with FURY 0.12, 1.1 s with FURY 2,
against 0.1 s for the fork (measured with ``examples/*/chain.py``, 30 ticks).

Nothing is drawn, connected or started here: a fork shares only what was imported.
"""

from __future__ import annotations

__all__: list[str] = []


def _import() -> None:
    import fury.actor  # noqa: F401  (what the apps draw with)
    import fury.utils  # noqa: F401
    import fury.window  # noqa: F401

    import conformance.apps.child  # noqa: F401
    from conformance import backends

    if backends.NAME == "vtk":
        import conformance.apps.takeover_vtk  # noqa: F401
    else:
        import conformance.apps.takeover_pygfx  # noqa: F401


try:
    _import()
except Exception:  # noqa: BLE001  the app's process imports them again itself, and says what failed
    pass
