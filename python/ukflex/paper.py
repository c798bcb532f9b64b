"""Deprecated: the paper reproduction moved to :mod:`ukflex.studies.paper`."""

from ._deprecation import moved_module

__getattr__, __dir__ = moved_module(__name__, "ukflex.studies.paper", renamed={"table1": {"beams": "theories"}})
