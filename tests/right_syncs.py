"""Right sync implementations in other styles than the kit's reference, which the checks must accept, for the backend in force.

The same classes under the same names on both backends, so ``--sync right_syncs:<Name>`` means the
same style in either environment, and the kill-rate tables line up by name. Where each part lives:

* ``right_syncs_vtk`` (FURY 0.12) and ``right_syncs_pygfx`` (FURY 2), one of which this module
  re-exports: the classes (and the closure), with only what touches an actor (placing whole actors,
  where the vertex and normal arrays are, announcing what changed);
* ``sync_steps``: their renderer-free steps, written once (link-frame poses with scipy or pybullet,
  each base's inertial offset, link-frame geometry, the arithmetic of every vertex rewrite).
"""

from __future__ import annotations

import importlib

from conformance import backends

_module = importlib.import_module(f"right_syncs_{backends.NAME}")
__all__ = list(_module.__all__)
globals().update({name: getattr(_module, name) for name in __all__})
