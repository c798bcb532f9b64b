"""Independent NumPy/SciPy reference for ukflex (no Rust, no other ukflex modules).

* :class:`ReferenceModel` -- model terms M, Q, Phi, A, gamma of a scene description dict,
  evaluated element by element from the equations (``model.py``);
* :func:`uk_qdd`, :func:`uk_multipliers`, :func:`augmented_qdd` -- the paper's eq. (70),
  eq. (74) (with eq. (42)'s sign) and the saddle-point solve of eq. (42) (``uk.py``);
* :func:`simulate_cp` -- coordinate partitioning after Wehage and Haug (``cp.py``), and its
  per-call steps :class:`CPSystem` (recovery) and :func:`reduced_accelerations`;
* :func:`simulate_uk_numpy` -- UK accelerations driven by solve_ivp on ``y = [q, qd]``;
* :mod:`.paper_closed_form` -- the paper's printed single-element slider-crank terms;
* :func:`single_blas_thread` -- a context that limits BLAS to one thread (fair NumPy timings).
"""
from ._blas import single_blas_thread
from .model import ReferenceModel, ModelError, element_matrices, element_shape, section_properties
from .uk import (uk_qdd, uk_multipliers, augmented_qdd, inv_sqrt_spd, uk_rank,
                 simulate_uk_numpy, correct_initial_state, SimulationResult)
from .cp import simulate_cp, choose_partition, CPPartition, CPSystem, reduced_accelerations

__all__ = [
    "ReferenceModel", "ModelError", "element_matrices", "element_shape", "section_properties",
    "uk_qdd", "uk_multipliers", "augmented_qdd", "inv_sqrt_spd", "uk_rank",
    "simulate_uk_numpy", "simulate_cp", "correct_initial_state", "SimulationResult",
    "choose_partition", "CPPartition", "CPSystem", "reduced_accelerations", "single_blas_thread",
]
