"""System.equilibrium: static equilibrium by Newton on Q = A^T lambda, Phi = 0, checked against
closed-form beam deflections, a pendulum, a run that starts from it, and named errors."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import NonFiniteError, SolverError, scenes
from ukflex.model.scenes import PAPER


def test_cantilever_under_tip_load_and_weight():
    """Cubic elements are nodally exact: P L^3 / (3 EI) + w L^4 / (8 EI) at the tip."""
    L, P, b, h, E, rho = 1.0, -2.0, 0.02, 0.01, 2.1e11, 7850.0
    EI, w = E * b * h**3 / 12, -rho * b * h * 9.81
    system = scenes.cantilever(length=L, elements=4, tip_force=(0.0, P), strain="linear").build()
    eq = system.equilibrium()
    tip = np.asarray(system.beam_point("beam", 1.0, eq.q))
    assert tip[1] == pytest.approx(P * L**3 / (3 * EI) + w * L**4 / (8 * EI), rel=1e-9)
    assert eq.position_residual <= 1e-10 and eq.iterations <= 5


def test_simply_supported_coupler_under_its_weight():
    """The paper's coupler, pinned and on a roller, sags 5 w L^4 / (384 EI) at midspan."""
    d, Lb, E = PAPER["diameter"], PAPER["coupler_length"], PAPER["youngs_modulus"]
    a, I = math.pi * d**2 / 4, math.pi * d**4 / 64
    w = PAPER["density"] * a * 9.81
    system = scenes.pinned_beam(elements=8, theory="euler-bernoulli", gravity=True).build()
    eq = system.equilibrium()
    mid = np.asarray(system.beam_point("beam", 0.5, eq.q))
    assert mid[1] == pytest.approx(-5 * w * Lb**4 / (384 * E * I), rel=1e-6)


def test_pendulum_hangs_down_and_the_pivot_carries_its_weight():
    system = scenes.pendulum(length=1.0, mass=1.0, angle=-math.pi / 4).build()
    eq = system.equilibrium()
    assert eq.q[2] == pytest.approx(-math.pi / 2, abs=1e-9)
    assert eq.q[:2] == pytest.approx([0.0, -0.5], abs=1e-9)
    assert eq.multipliers == pytest.approx([0.0, 9.81], abs=1e-9)  # M qdd + A^T lambda = Q


def test_a_run_from_the_equilibrium_stays_there():
    """Starting from the preloaded state instead of the undeformed one: no vibration."""
    system = scenes.cantilever(elements=4, tip_force=(0.0, -2.0), strain="linear").build()
    eq = system.equilibrium()
    res = ukflex.simulate(system, 0.05, method="DOPRI5", rtol=1e-10, q0=eq.q, qd0=np.zeros(system.n_coords),
                          t_eval=np.linspace(0, 0.05, 11))
    tip0 = system.beam_point("beam", 1.0, eq.q)[1]
    tips = np.asarray(system.beam_point("beam", 1.0, res.q))[1]
    assert np.max(np.abs(tips - tip0)) < 1e-8 * abs(tip0)
    # from the undeformed state it swings through the whole deflection
    free = ukflex.simulate(system, 0.05, method="DOPRI5", rtol=1e-10, t_eval=np.linspace(0, 0.05, 11))
    assert np.max(np.abs(np.asarray(system.beam_point("beam", 1.0, free.q))[1] - tip0)) > 0.1 * abs(tip0)


def test_bad_input_and_no_equilibrium_are_named():
    system = scenes.pendulum().build()
    with pytest.raises(ValueError, match="q: expected shape"):
        system.equilibrium(q=[1.0, 2.0])
    with pytest.raises(NonFiniteError):
        system.equilibrium(q=[np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="tol"):
        system.equilibrium(tol=0.0)
    s = ukflex.Scene(gravity=(0.0, -9.81))
    s.point_mass("m", mass=1.0, position=(0.0, 0.0))
    with pytest.raises(SolverError, match="no convergence"):
        s.build().equilibrium(max_iterations=5)
