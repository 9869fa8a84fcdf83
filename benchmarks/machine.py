"""What the figures were measured on: CPU, cores, load, Python, the libraries that do the work, and the
renderer backend in force with its own (FURY 0.12 on VTK, or FURY 2 on pygfx and wgpu)."""

from __future__ import annotations

import os
import platform
import sys
from importlib import metadata

from conformance import backends

from . import backend

__all__ = ["describe", "machine"]


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as cpuinfo:
            for line in cpuinfo:
                if line.lower().startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown CPU"


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def machine() -> dict:
    """CPU model, cores (all, and those this process may use), load average when measuring started,
    OS, Python, the versions of pybullet, FURY, numpy and scipy, and the backend in force (``backend``,
    ``"vtk"`` or ``"pygfx"``; ``backend_description``, as the pytest header gives it) with the
    versions of its libraries (VTK's, or pygfx's and wgpu's). Reads package metadata only: the
    GPU is named by the pictures part, which starts the renderer (:func:`describe`'s ``renderer``)."""
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        usable = os.cpu_count()
    try:
        load = round(os.getloadavg()[0], 2)
    except OSError:
        load = None
    return {
        "cpu": _cpu_model(),
        "cores": os.cpu_count(),
        "usable_cores": usable,
        "load_average": load,
        "os": f"{platform.system()} {platform.release()} {platform.machine()}",
        "python": platform.python_version(),
        "executable": sys.executable,
        "pybullet": _version("pybullet"),
        "fury": _version("fury"),
        "numpy": _version("numpy"),
        "scipy": _version("scipy"),
        "backend": backends.NAME,
        "backend_description": backends.describe(),
        **{library: _version(library) for library in backend.LIBRARIES},
    }


def describe(info: dict, renderer: dict | None = None) -> str:
    """One line for the top of the table; ``renderer``, a ``backends.renderer_info()`` dict if one was
    made (the pictures part makes it), adds the GPU or adapter that drew the pictures."""
    load = f", load average {info['load_average']} at start" if info.get("load_average") is not None else ""
    gpu = f"; GPU: {backends.renderer_label(renderer)}" if renderer else ""
    return (f"{info['cpu']}, {info['cores']} cores ({info['usable_cores']} usable){load}; {info['os']}; "
            f"Python {info['python']}, pybullet {info['pybullet']}, numpy {info['numpy']}, scipy {info['scipy']}; "
            f"{info['backend_description']}{gpu}")
