"""Exception classes of ukflex.

The classes raised by the compiled core (``ukflex._core``) are re-exported here unchanged, so
``except ukflex.InvalidSceneError`` catches every scene error (the core is the only place that
validates a scene).  :class:`InconsistentInitialStateError` is defined in Python (raised by the
initial-state correction in :mod:`ukflex.model.system` from the core's report) as a subclass of the
core's base class :class:`UkflexError`.
"""

from __future__ import annotations

from typing import Any, Sequence

try:
    from . import _core as core  # type: ignore[attr-defined]
except ImportError as exc:  # pragma: no cover - depends on the build
    raise ImportError(
        "ukflex._core (the compiled Rust extension) is not available; build it with "
        "`bash scripts/dev-build.sh` (or `pip install .`)"
    ) from exc

__all__ = [
    "UkflexError",
    "InvalidSceneError",
    "SingularMassError",
    "SolverError",
    "IntegrationFailure",
    "NonFiniteError",
    "MemoryLimitError",
    "BudgetError",
    "InconsistentInitialStateError",
    "ExpressionError",
    "MissingDependencyError",
    "InvalidArgumentError",
    "UnknownOptionError",
    "UnknownNameError",
    "StabilityWarning",
    "RankDeficiencyWarning",
    "DriftWarning",
    "SingularConfigurationWarning",
    "BucklingWarning",
    "ModelValidityWarning",
    "InitialCorrectionWarning",
]

UkflexError = core.UkflexError
InvalidSceneError = core.InvalidSceneError
SingularMassError = core.SingularMassError
SolverError = core.SolverError
ExpressionError = core.ExpressionError
NonFiniteError = core.NonFiniteError
#: An allocation would exceed the System's ``memory_limit`` (refused before allocating; the
#: message names the buffers and a way out).
MemoryLimitError = core.MemoryLimitError
#: A work budget ran out before the work was done: ``max_wall_time`` of a build's initial-state
#: correction (a :class:`SolverError`; a run that spends its budget returns ``status = -1``).
BudgetError = core.BudgetError


class InconsistentInitialStateError(UkflexError):  # type: ignore[misc, valid-type]
    """The initial guess cannot be corrected onto the constraint manifold.

    Attributes
    ----------
    rows : list of str
        Names of the constraint rows with the largest residual, largest first.
    residuals : numpy.ndarray, shape (m,)
        The constraint residual (position ``Phi`` or velocity ``A qd + Phi_t``) at the point
        where the correction gave up.
    """

    def __init__(self, message: str, rows: Sequence[str] = (), residuals=None):
        super().__init__(message)
        self.rows = list(rows)
        self.residuals = residuals


class MissingDependencyError(UkflexError, ImportError):  # type: ignore[misc, valid-type]
    """An optional dependency is not installed (matplotlib for plots, pandas/dask for sweeps);
    the message names the feature, the package to install and ukflex's extra that holds it
    (``[project.optional-dependencies]`` of pyproject.toml)."""


def require(module: str, what: str, extra: str = "plot") -> Any:
    """Import ``module`` or raise :class:`MissingDependencyError` saying that ``what`` needs it
    (the one place that names a missing optional dependency)."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        pkg = {"PIL": "pillow", "skfem": "scikit-fem"}.get(module.split(".")[0], module.split(".")[0])
        raise MissingDependencyError(
            f"{what} needs {pkg!r}, which is not installed: pip install {pkg} (one of ukflex's extra [{extra}])"
        ) from None


class IntegrationFailure(SolverError):  # type: ignore[misc, valid-type]
    """The integration failed; ``result`` holds everything computed up to the failure.

    Attributes
    ----------
    result : ukflex.SimulationResult
        Accepted steps (or requested outputs) up to the failure, ``status = -1``.
    reason : str
        The integrator's or the core's message.
    t_fail : float
        Last time reached.
    """

    def __init__(self, message: str, result: Any = None, reason: str = "", t_fail: float = float("nan")):
        super().__init__(message)
        self.result = result
        self.reason = reason
        self.t_fail = t_fail


class InvalidArgumentError(UkflexError, ValueError, TypeError):  # type: ignore[misc, valid-type]
    """A function argument of the Python API is invalid (wrong type, out of range, masked or
    complex array, ...).  A ``ValueError`` and a ``TypeError`` too, so code written against
    the built-in exceptions keeps working.

    Attributes
    ----------
    argument : str
        The argument's name (e.g. ``"t_end"``, ``"rtol"``, ``"q0"``); ``where`` (optional) names
        the function it was given to.
    """

    def __init__(self, argument: str, message: str, where: str = ""):
        # "rtol: must be positive, got 0"; with where: "slider_crank: elements must be an integer, got 1.5"
        super().__init__(f"{where}: {argument} {message}" if where else f"{argument}: {message}")
        self.argument = argument


class UnknownOptionError(InvalidArgumentError):
    """An option that the function (or the chosen method) does not take, e.g. a misspelt
    ``max_stpe``.

    Attributes
    ----------
    valid : list of str
        The options that are accepted.
    """

    def __init__(self, argument: str, message: str, valid: Sequence[str] = ()):
        super().__init__(argument, message)
        self.valid = list(valid)


class UnknownNameError(UkflexError, KeyError):  # type: ignore[misc, valid-type]
    """A name that is not one of its kind's valid names: a body, coordinate, joint or driver,
    residual kind, ... (``System.body_info("nope")``, ``res.coordinate("nope")``,
    ``res.sensors.reaction("nope")``).  A ``KeyError`` too, so ``except KeyError`` keeps
    working; its message is the text, not the quoted repr a plain ``KeyError`` prints.

    Attributes
    ----------
    what : str
        The kind of name (``"body"``, ``"coordinate"``, ``"joint"``, ...).
    name : str
        The name that was asked for.
    valid : list of str
        The valid names.
    """

    def __init__(self, message: str, what: str = "", name: str = "", valid: Sequence[str] = ()):
        super().__init__(message)
        self.what, self.name, self.valid = what, name, list(valid)

    __str__ = BaseException.__str__

    @classmethod
    def of(cls, what: str, name: Any, valid: Sequence[str]) -> "UnknownNameError":
        """The error for an unknown ``name`` of kind ``what``; the message lists (up to 20 of)
        the valid names."""
        names = [str(v) for v in valid]
        listed = repr(names) if len(names) <= 20 else f"{names[:20]!r} ... ({len(names)} in all)"
        return cls(f"unknown {what} {name!r}; valid: {listed}", what, str(name), names)


# ------------------------------------------------------------------------------------ warnings
class StabilityWarning(UserWarning):
    """Base class of the numerical-stability warnings of ukflex (reports: ``ukflex.stability``)."""


class RankDeficiencyWarning(StabilityWarning):
    """The constraint Jacobian lost rank (in the mass metric) during the run."""


class DriftWarning(StabilityWarning):
    """The constraint residual (drift) passed the threshold."""


class SingularConfigurationWarning(StabilityWarning):
    """The run passed a singular configuration of its constraints (the Jacobian came close to
    losing rank) with a method that may leave the mechanism's branch or lose accuracy there
    (``res.extra["singular"]``, docs/integrators.md)."""


class BucklingWarning(StabilityWarning):
    """A beam's compressive axial force approaches (or exceeds) its Euler buckling load."""


class ModelValidityWarning(StabilityWarning):
    """The linear-elastic FFRF model (small deformations) is outside its range of validity."""


class InitialCorrectionWarning(UserWarning):
    """The initial-state correction moved a driven coordinate (the angle of an angle or rotation
    driver, the position of a coordinate or translation driver) by more than
    :data:`ukflex.System.DRIVEN_MOVE_TOL`: the guess and the driver's value at ``t0`` disagree
    (e.g. a body placed at 90 degrees and ``ConstantSpeed(omega)`` without ``initial=``), and the
    correction moved the mechanism to the driver's value.

    Attributes
    ----------
    moves : dict
        Driver name -> the move of its driven coordinate (rad or m; value after minus guess).
    """

    def __init__(self, message: str, moves=None):
        super().__init__(message)
        self.moves = dict(moves or {})
