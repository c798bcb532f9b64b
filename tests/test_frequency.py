"""The paper's coupler as a simply supported beam: the first bending frequency from the elastic
blocks M_ff, K_ff of the compiled model converges with the mesh to the analytic values."""

import math

import numpy as np
import pytest
from scipy.linalg import eigh

from ukflex import NonFiniteError, scenes
from ukflex.model.scenes import PAPER

LB = PAPER["coupler_length"]
D = PAPER["diameter"]
RHO = PAPER["density"]
E = PAPER["youngs_modulus"]
NU = PAPER["poisson_ratio"]
KAPPA = PAPER["shear_factor"]
AREA = math.pi * D**2 / 4
I = math.pi * D**4 / 64
G = E / (2 * (1 + NU))

MESHES = (1, 2, 4, 8, 16)


def omega_euler_bernoulli():
    """Simply supported Euler-Bernoulli beam: (pi/L)^2 sqrt(EI / (rho a))."""
    return (math.pi / LB) ** 2 * math.sqrt(E * I / (RHO * AREA))


def omega_timoshenko():
    """Simply supported Timoshenko beam (shear + rotary inertia), mode sin(pi x / L):
    (rho a w^2 - k G a k^2)(rho I w^2 - E I k^2 - k G a) - (k G a k)^2 = 0, lowest root."""
    k = math.pi / LB
    kGa = KAPPA * G * AREA
    a2 = RHO * AREA * RHO * I
    a1 = -(RHO * AREA * (E * I * k**2 + kGa) + RHO * I * kGa * k**2)
    a0 = kGa * k**2 * (E * I * k**2 + kGa) - (kGa * k) ** 2
    roots = np.roots([a2, a1, a0])
    return math.sqrt(min(r.real for r in roots if r.real > 0))


def first_bending_frequency(theory, n):
    sys_ = scenes.pinned_beam(theory=theory, elements=n).build()
    el = sys_.elastic_slice("beam")
    # at the undeformed rest state the supports fix x, y, theta and do not involve q_f, so the
    # constrained eigenproblem is the elastic block alone
    A = sys_.A(sys_.q0)
    assert np.abs(A[:, el]).max() < 1e-12
    assert np.linalg.matrix_rank(A[:, : el.start]) == 3
    M_ff = sys_.mass_matrix_elastic("beam")  # elastic block of the full M(q0)
    K_ff = sys_.stiffness_matrix("beam", finite_difference=True)  # -dQ/dq_f
    # the core's constant blocks agree with what the kernels produce
    M_core, K_core = sys_.beam_matrices("beam")
    assert np.allclose(M_ff, M_core, rtol=1e-12, atol=1e-15 * np.abs(M_core).max())
    assert np.allclose(K_ff, K_core, rtol=1e-5, atol=1e-6 * np.abs(K_core).max())
    w2 = eigh(K_ff, M_ff, eigvals_only=True)
    assert np.all(w2 > 0)
    # the lowest modes are bending; pick the lowest
    return math.sqrt(w2.min())


@pytest.fixture(scope="module")
def frequencies():
    return {(th, n): first_bending_frequency(th, n) for th in ("euler-bernoulli", "timoshenko") for n in MESHES}


def test_analytic_values_are_distinct():
    w_eb, w_t = omega_euler_bernoulli(), omega_timoshenko()
    assert 860 < w_eb < 875  # rad/s, ~138 Hz
    assert w_t < w_eb and (w_eb - w_t) / w_eb > 1e-5


@pytest.mark.parametrize("theory,exact", [("euler-bernoulli", omega_euler_bernoulli), ("timoshenko", omega_timoshenko)])
def test_first_frequency_converges(frequencies, theory, exact):
    w = exact()
    errors = [abs(frequencies[(theory, n)] - w) / w for n in MESHES]
    print(theory, ["%.3e" % e for e in errors])
    for coarse, fine in zip(errors, errors[1:]):
        assert fine < coarse, errors
    assert errors[-1] < 1e-4, errors
    # consistent-mass cubic elements converge from above, at about h^4
    assert all(frequencies[(theory, n)] > w * (1 - 1e-9) for n in MESHES)
    assert errors[2] / errors[3] > 8.0, errors


def test_stiffness_matrix_is_symmetric_positive_definite():
    sys_ = scenes.pinned_beam(theory="timoshenko", elements=4).build()
    K = sys_.stiffness_matrix("beam")
    assert K.shape == (12, 12)
    assert np.array_equal(K, K.T)
    assert np.all(np.linalg.eigvalsh(K) > 0)


# ------------------------------------------------------------------ System.frequencies (the modal analysis)

def test_constrained_frequencies_of_the_simply_supported_beam_match_the_elastic_block(frequencies):
    """The whole constrained system (supports as joints, not as a hand-picked block) gives the
    same lowest bending frequency as the elastic block above."""
    for theory in ("euler-bernoulli", "timoshenko"):
        w = scenes.pinned_beam(theory=theory, elements=8).build().frequencies()
        assert w[0] == pytest.approx(frequencies[(theory, 8)], rel=1e-6)


def test_pendulum_frequency_comes_from_the_constraint_force():
    """A rigid rod on a pivot has no stiffness of its own: sqrt(m g c / I_O) comes entirely from
    the multiplier (constraint) force's geometric stiffness.  Inverted, it is unstable: negative."""
    L, g = 1.0, 9.81
    exact = math.sqrt(g * (L / 2) / (L**2 / 3))
    w = scenes.pendulum(length=L, angle=-math.pi / 2).build().frequencies()
    assert w.shape == (1,) and w[0] == pytest.approx(exact, rel=1e-6)
    w_up = scenes.pendulum(length=L, angle=math.pi / 2).build().frequencies()
    assert w_up[0] == pytest.approx(-exact, rel=1e-6)


def test_cantilever_frequencies_and_mode_shapes():
    """Clamped-free Euler-Bernoulli beam, 8 cubic elements: beta_k^2 sqrt(EI / (rho a)) / L^2;
    the mode shapes are mass-normalized and satisfy the clamp."""
    b, h, E, rho = 0.02, 0.01, 2.1e11, 7850.0
    EI, rA = E * b * h**3 / 12, rho * b * h
    sys_ = scenes.cantilever(length=1.0, elements=8, strain="linear", gravity=False).build()
    w, V = sys_.frequencies(modes=True)
    assert w.shape == (sys_.n_dof,) and V.shape == (sys_.n_coords, sys_.n_dof)
    for k, beta in enumerate((1.8751041, 4.6940911, 7.8547574)):
        assert w[k] == pytest.approx(beta**2 * math.sqrt(EI / rA), rel=1e-3)
    assert np.all(np.diff(w) >= 0)
    M = sys_.M(sys_.q0)
    assert np.allclose(V.T @ M @ V, np.eye(V.shape[1]), atol=1e-9)
    assert np.abs(sys_.A(sys_.q0) @ V).max() < 1e-10


def test_slider_crank_frequencies_include_the_axial_mode():
    """The paper's slider-crank (driven crank, N = 1 coupler): three elastic frequencies, the
    first bending near the simply supported beam's, the axial one near 29,000 rad/s (the mode
    that makes explicit integrators slow), and bad input is a named error."""
    sys_ = scenes.slider_crank().build()
    w = sys_.frequencies()
    assert w.shape == (3,)
    assert 0.9 * omega_euler_bernoulli() < w[0] < 1.2 * omega_euler_bernoulli()
    assert 2.5e4 < w[-1] < 3.5e4
    with pytest.raises(ValueError, match="q: expected shape"):
        sys_.frequencies(q=np.zeros(2))
    with pytest.raises(NonFiniteError):
        sys_.frequencies(qd=np.full(sys_.n_coords, np.nan))
