"""One of the kit's scenes drawn by the kit's own actors and synced by a sync implementation, as a whole
program: build, register a per-frame callback on FURY's ShowManager that steps and syncs, start.

The scene and the sync come from the environment (``KIT_SCENE``, ``KIT_SYNC`` as ``--sync`` takes it,
``KIT_STEPS``, and the scene's parameters as JSON in ``KIT_PARAMS``), so one file wraps every pair; ``tests/test_app_wrapped.py`` runs it through app mode to show
that app mode and the scene checks agree on the kit's own syncs.
"""
import itertools
import json
import os

import fury
from fury import window

from conformance import sync
from conformance.sync import runner

SCENE = os.environ["KIT_SCENE"]
STEPS = int(os.environ.get("KIT_STEPS", "60"))
PARAMS = json.loads(os.environ.get("KIT_PARAMS", "{}"))
implementation = sync.load(os.environ.get("KIT_SYNC", "reference"))
counter = itertools.count(1)

with runner.running(SCENE, implementation, **PARAMS) as run:
    scene = window.Scene()
    for drawn in run.drawing.actors.values():
        scene.add(drawn)
    if fury.__version__.startswith("0."):
        showm = window.ShowManager(scene, size=(300, 300))
        showm.initialize()

        def timer_callback(_obj, _event):
            run.advance()
            showm.render()
            if next(counter) == STEPS:
                showm.exit()

        showm.add_timer_callback(True, 1, timer_callback)
    else:
        showm = window.ShowManager(scene=scene, size=(300, 300))

        def timer_callback():
            run.advance()
            showm.render()
            if next(counter) == STEPS:
                showm.cancel_callback("physics")
                showm.close()

        showm.register_callback(timer_callback, 1 / 240, True, "physics")
    showm.start()
