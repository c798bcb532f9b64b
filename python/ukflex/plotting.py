"""Matplotlib is optional (``pip install ukflex[plot]``): every plot goes through here.

:func:`figure` returns a headless Agg figure or raises :class:`ukflex.errors.MissingDependencyError`
naming what needed it and how to install it.
"""

from __future__ import annotations

import importlib
from typing import Any, Optional, Tuple

from .errors import MissingDependencyError

__all__ = ["figure", "require"]


def require(module: str, what: str, extra: str = "plot") -> Any:
    """Import ``module`` or raise :class:`MissingDependencyError` saying that ``what`` needs it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        pkg = {"PIL": "pillow", "skfem": "scikit-fem"}.get(module.split(".")[0], module.split(".")[0])
        raise MissingDependencyError(
            f"{what} needs {pkg!r}, which is not installed: pip install 'ukflex[{extra}]' (or {pkg} alone)"
        ) from None


def figure(figsize: Tuple[float, float], what: str, dpi: Optional[float] = None) -> Any:
    """A matplotlib ``Figure`` with an Agg canvas (no display needed) for ``what`` (a plot's name)."""
    backend = require("matplotlib.backends.backend_agg", what)
    Figure = require("matplotlib.figure", what).Figure
    fig = Figure(figsize=figsize, dpi=dpi) if dpi is not None else Figure(figsize=figsize)
    backend.FigureCanvasAgg(fig)
    return fig
