"""Deprecated: the work-precision studies moved to :mod:`ukflex.studies.workprecision`
(``beam=`` is ``theory=``)."""

from ._deprecation import moved_module

__getattr__, __dir__ = moved_module(__name__, "ukflex.studies.workprecision", renamed={
    "run_work_precision": {"beam": "theory"}, "run_elements": {"beam": "theory"}})
