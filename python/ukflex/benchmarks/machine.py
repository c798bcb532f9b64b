"""The machine a study ran on (CPU, cores, load, library versions), for the reports' headers."""

from __future__ import annotations

import os
import platform
from typing import Any, Dict

import numpy as np

__all__ = ["machine_info", "machine_line"]


def machine_info() -> Dict[str, Any]:
    """CPU model, core count, load, OS and library versions of this machine."""
    import scipy

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.lower().startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        load = os.getloadavg()
    except (OSError, AttributeError):
        load = (float("nan"),) * 3
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "load_average": tuple(round(x, 2) for x in load),
        "os": f"{platform.system()} {platform.release()}",
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
    }


def machine_line(info: Dict[str, Any]) -> str:
    return (f"{info['cpu']}, {info['cores']} logical CPUs, load average {info['load_average'][0]:.2f} at the start, "
            f"{info['os']}, Python {info['python']}, NumPy {info['numpy']}, SciPy {info['scipy']}")
