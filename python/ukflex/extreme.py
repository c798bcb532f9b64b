"""Deprecated: the catalogue moved to :mod:`ukflex.studies.extreme` (``beam=`` is ``theory=``)."""

from ._deprecation import moved_module

__getattr__, __dir__ = moved_module(__name__, "ukflex.studies.extreme", renamed={
    name: {"beam": "theory"} for name in ("stiff", "flexible", "high_speed", "long_run", "slider_crank_units")})
