"""ukflex: planar flexible multibody dynamics with the Udwadia-Kalaba formulation.

Rust core (``ukflex._core``, private) + Python API:

* :class:`Scene` -- scene description builder (bodies, joints, drivers, forces, initial guess);
* :class:`System` -- compiled Rust-backed system with a consistent initial state;
* :func:`simulate` -- time integration with ``scipy.integrate.solve_ivp``;
* :mod:`ukflex.scenes` -- built-in scenes (the paper's slider-crank, pendulums, ...);
* :mod:`ukflex.stability` -- stabilization and diagnostics (rank loss, drift, buckling, FFRF
  validity);
* :mod:`ukflex.studies` -- studies on the public API: the paper's reproduction, work-precision,
  the extreme catalogue and its stability report, cross-checks against :mod:`ukflex.reference`;
* ``ukflex`` (also ``python -m ukflex``) -- the command line (:mod:`ukflex.cli`).
"""

from .errors import (
    InconsistentInitialStateError,
    InvalidArgumentError,
    InvalidSceneError,
    NonFiniteError,
    SingularMassError,
    SolverError,
    UkflexError,
    UnknownOptionError,
)
from .scene import (
    BeamRef,
    Circular,
    ConstantSpeed,
    CustomSection,
    GroundRef,
    Harmonic,
    Marker,
    PointMassRef,
    Polynomial,
    Rectangular,
    RigidBodyRef,
    Scene,
)
from .system import InitialCorrection, System
from .results import SimulationResult
from .simulate import simulate
from . import scenes

__version__ = "0.1.0"

__all__ = [
    "Scene",
    "Marker",
    "RigidBodyRef",
    "PointMassRef",
    "BeamRef",
    "GroundRef",
    "Circular",
    "Rectangular",
    "CustomSection",
    "ConstantSpeed",
    "Polynomial",
    "Harmonic",
    "System",
    "InitialCorrection",
    "SimulationResult",
    "simulate",
    "scenes",
    "UkflexError",
    "InvalidSceneError",
    "SingularMassError",
    "SolverError",
    "NonFiniteError",
    "InconsistentInitialStateError",
    "InvalidArgumentError",
    "UnknownOptionError",
]
