"""ukflex: planar flexible multibody dynamics with the Udwadia-Kalaba formulation.

Rust core (``ukflex._core``, private) + Python API:

* :class:`Scene` -- scene description builder (bodies, joints, drivers, forces, initial guess);
* :class:`System` -- compiled Rust-backed system with a consistent initial state;
* :func:`simulate` -- time integration with ``scipy.integrate.solve_ivp``;
* :func:`sweep` -- parameter sweeps (serial, a process pool or Dask), a DataFrame per sweep;
* :mod:`ukflex.scenes` -- built-in scenes (the paper's slider-crank, pendulums, ...);
  :mod:`ukflex.spatial_scenes` -- the spatial benchmarks (A04, A05, the spatial slider-crank);
* :mod:`ukflex.stability` -- diagnostics of runs (rank loss, drift, buckling, FFRF validity);
  stabilization is :func:`simulate`'s ``stabilization=``;
* :mod:`ukflex.benchmarks` -- the paper's reproduction and the work-precision bench (``ukflex
  paper``, ``ukflex bench``); the other studies are the repository's ``studies/`` package;
* ``ukflex`` (also ``python -m ukflex``) -- the command line (:mod:`ukflex.cli`).
"""

from .errors import (
    BudgetError,
    ExpressionError,
    InconsistentInitialStateError,
    InitialCorrectionWarning,
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
from .model.scene import (
    BeamRef,
    Circular,
    ConstantSpeed,
    CustomSection,
    Expression,
    FlexibleBodyRef,
    GroundRef,
    Harmonic,
    LoadTable,
    Marker,
    PointMassRef,
    Polynomial,
    Rectangular,
    RigidBodyRef,
    Scene,
    Spline,
)
from .model.flexible import FlexibleData, InterfacePoint
from .model.system import InitialCorrection, System
from .results.simulation import SimulationResult
from .run.simulate import simulate
from .run.sweep import sweep
from .model import scenes
from .model.spatial import CustomSection3, SpatialScene
from .model import spatial_scenes
from .results.spatial import outputs as spatial_outputs
from .results.vtk import export_vtk

#: Public modules of the rooms, loaded on first use: ``ukflex.fe`` (flexible bodies from FE
#: data, :mod:`ukflex.model.fe`), ``ukflex.fe3`` (spatial flexible bodies from 3D FE data,
#: :mod:`ukflex.model.fe3`) and ``ukflex.stability`` (diagnostics of runs,
#: :mod:`ukflex.analysis.stability`).
_LAZY = {"fe": "ukflex.model.fe", "fe3": "ukflex.model.fe3", "stability": "ukflex.analysis.stability"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        module = importlib.import_module(_LAZY[name])
        globals()[name] = module
        return module
    raise AttributeError(f"module 'ukflex' has no attribute {name!r}")

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
    "CustomSection3",
    "spatial_outputs",
    "export_vtk",
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
    "LoadTable",
    "System",
    "InitialCorrection",
    "SimulationResult",
    "simulate",
    "sweep",
    "scenes",
    "spatial_scenes",
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
    "InitialCorrectionWarning",
]
