"""The app's process: ``python -m conformance.apps.child SCRIPT --out REC.npz [--ticks N] [--events JSON] [--tick NAME]``.

Runs the app's script unmodified as ``__main__`` (with ``sys.argv = [SCRIPT]`` and its directory first on
``sys.path``, as ``python SCRIPT`` would), with the kit's patches (:mod:`conformance.apps.driver`) in
place, and writes what it recorded to ``--out``. Exit status: 0 recorded (the app may still have
raised inside its loop: the recording says so), 3 the app failed before its loop or handed over no
loop, or (FURY 0.12) the OpenGL driver cannot start (``--out`` + ``.error`` holds the paragraph), 4 the
kit's own code failed while it drove the app (``--out`` + ``.kit-error`` holds what and where). Run by :mod:`conformance.apps.launch`, in a process of
its own so that an app's globals, patches, crashes and hangs never reach the kit's.
"""

from __future__ import annotations

import argparse
import json
import os
import runpy
import sys
import traceback
from pathlib import Path

__all__ = ["main"]


def _fail(out: str, text: str) -> int:
    from conformance.files import write_atomically

    write_atomically(out + ".error", text.encode("utf-8"))
    return 3


def _kit_failed(out: str, fault) -> int:
    from conformance.files import write_atomically

    write_atomically(out + ".kit-error", fault.text.encode("utf-8"))
    return 4


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m conformance.apps.child")
    parser.add_argument("script")
    parser.add_argument("--out", required=True)
    parser.add_argument("--ticks", type=int, default=120)
    parser.add_argument("--events", default="[]")
    parser.add_argument("--tick", default=None)
    args = parser.parse_args(argv)

    from conformance import backends
    from conformance.apps import driver as app_driver, perturb, recording
    from conformance.apps.mapping import MappingError

    name = backends.NAME
    if name == "vtk":
        from conformance.backends.display import ensure_display
        from conformance.errors import DisplayUnavailable
        from conformance.backends.renderer_start import check_gl

        ensure_display()
        try:
            check_gl()  # the app's window would abort this process where the driver cannot start
        except DisplayUnavailable as err:
            return _fail(args.out, f"{args.script}: {err}")
        from conformance.apps import takeover_vtk as takeover
    else:
        os.environ.setdefault("XDG_RUNTIME_DIR", "/tmp")
        from conformance.apps import takeover_pygfx as takeover
    driver = app_driver.Driver(name, args.script, args.ticks, perturb.from_dicts(json.loads(args.events)),
                               args.tick, backend_module=backends)
    app_driver.install_pybullet(driver)
    takeover.install(driver)

    script = str(Path(args.script).resolve())
    sys.argv = [script]
    sys.path.insert(0, str(Path(script).parent))
    try:
        runpy.run_path(script, run_name="__main__")
    except app_driver.KitFault as fault:
        return _kit_failed(args.out, fault)
    except SystemExit as exc:
        if exc.code not in (None, 0) and driver.recording is None:
            return _fail(args.out, f"{args.script}: the app exited with status {exc.code} before its loop ran.")
    except (app_driver.AppLoopNotFound, MappingError) as err:
        return _fail(args.out, str(err))
    except Exception as exc:
        if driver.recording is None:
            lines = traceback.format_exception(exc)
            return _fail(args.out, f"{args.script}: the app raised before its loop ran: {type(exc).__name__}: {exc}\n"
                         + "".join(lines[-8:]))
        driver.recording.notes.append(f"the app raised after its loop: {type(exc).__name__}: {exc}")
    if driver.recording is None:
        try:
            driver.reached("")  # the script ended with callbacks registered and nothing to run them
        except app_driver.AppLoopNotFound as err:
            return _fail(args.out, str(err))
        except app_driver.KitFault as fault:
            return _kit_failed(args.out, fault)
    if driver.error:
        driver.recording.error = driver.error
    recording.save(driver.recording, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
