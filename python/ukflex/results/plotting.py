"""Matplotlib is optional (``pip install ukflex[plot]``): every plot goes through here.

:func:`figure` returns a headless Agg figure or raises :class:`ukflex.MissingDependencyError`
naming what needed it and how to install it.
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

from ..errors import require

__all__ = ["figure"]


def figure(figsize: Tuple[float, float], what: str, dpi: Optional[float] = None) -> Any:
    """A matplotlib ``Figure`` with an Agg canvas (no display needed) for ``what`` (a plot's name)."""
    backend = require("matplotlib.backends.backend_agg", what)
    Figure = require("matplotlib.figure", what).Figure
    fig = Figure(figsize=figsize, dpi=dpi) if dpi is not None else Figure(figsize=figsize)
    backend.FigureCanvasAgg(fig)
    return fig
