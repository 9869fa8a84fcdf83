"""What the figures were measured on: CPU, cores, load, Python and the libraries that do the work."""

from __future__ import annotations

import os
import platform
import sys
from importlib import metadata

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
    OS, Python, and the versions of pybullet, VTK, FURY, numpy and scipy."""
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
        "vtk": _version("vtk"),
        "fury": _version("fury"),
        "numpy": _version("numpy"),
        "scipy": _version("scipy"),
    }


def describe(info: dict) -> str:
    """One line for the top of the table."""
    load = f", load average {info['load_average']} at start" if info.get("load_average") is not None else ""
    return (f"{info['cpu']}, {info['cores']} cores ({info['usable_cores']} usable){load}; {info['os']}; "
            f"Python {info['python']}, pybullet {info['pybullet']}, VTK {info['vtk']}, FURY {info['fury']}, "
            f"numpy {info['numpy']}, scipy {info['scipy']}")
