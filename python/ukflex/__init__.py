"""ukflex: planar flexible multibody dynamics with the Udwadia-Kalaba formulation.

Rust core (``ukflex._core``, private) + Python API:

* :class:`Scene` -- scene description builder (bodies, joints, drivers, forces, initial guess);
* :class:`System` -- compiled Rust-backed system with a consistent initial state;
* :func:`simulate` -- time integration with ``scipy.integrate.solve_ivp``;
* :func:`sweep` -- parameter sweeps (serial, a process pool or Dask), a DataFrame per sweep;
* :mod:`ukflex.scenes` -- built-in scenes (the paper's slider-crank, pendulums, ...);
* :mod:`ukflex.stability` -- stabilization and diagnostics (rank loss, drift, buckling, FFRF
  validity);
* :mod:`ukflex.studies` -- studies on the public API: the paper's reproduction, work-precision,
  the extreme catalogue and its stability report, cross-checks against :mod:`ukflex.reference`;
* ``ukflex`` (also ``python -m ukflex``) -- the command line (:mod:`ukflex.cli`).
"""

from .errors import (
    BudgetError,
    ExpressionError,
    InconsistentInitialStateError,
    InvalidArgumentError,
    InvalidSceneError,
    MissingDependencyError,
    MemoryLimitError,
    NonFiniteError,
    SingularConfigurationWarning,
    SingularMassError,
    SolverError,
    UkflexError,
    UnknownNameError,
    UnknownOptionError,
)
from .scene import (
    BeamRef,
    Circular,
    ConstantSpeed,
    CustomSection,
    Expression,
    FlexibleBodyRef,
    GroundRef,
    Harmonic,
    Marker,
    PointMassRef,
    Polynomial,
    Rectangular,
    RigidBodyRef,
    Scene,
    Spline,
)
from .flexible import FlexibleData, InterfacePoint
from .system import InitialCorrection, System
from .results import SimulationResult
from .simulate import simulate
from .sweep import sweep
from . import scenes
from . import spatial
from .spatial import SpatialScene

def _version() -> str:
    """The installed distribution's version (single source: Cargo.toml, through maturin)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("ukflex")
    except PackageNotFoundError:  # pragma: no cover - imported from a source tree without installing
        return "0+unknown"


__version__ = _version()

__all__ = [
    "Scene",
    "SpatialScene",
    "Marker",
    "RigidBodyRef",
    "PointMassRef",
    "BeamRef",
    "FlexibleBodyRef",
    "FlexibleData",
    "InterfacePoint",
    "GroundRef",
    "Circular",
    "Rectangular",
    "CustomSection",
    "ConstantSpeed",
    "Polynomial",
    "Harmonic",
    "Expression",
    "Spline",
    "System",
    "InitialCorrection",
    "SimulationResult",
    "simulate",
    "sweep",
    "scenes",
    "UkflexError",
    "InvalidSceneError",
    "SingularMassError",
    "SolverError",
    "NonFiniteError",
    "MemoryLimitError",
    "BudgetError",
    "InconsistentInitialStateError",
    "ExpressionError",
    "MissingDependencyError",
    "InvalidArgumentError",
    "UnknownOptionError",
    "UnknownNameError",
    "SingularConfigurationWarning",
]
