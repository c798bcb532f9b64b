"""Loads of a beam's strains and internal forces (docs/loads.md, "Load values"): ``N``, ``V``,
``M``, ``eps``, ``kappa(BEAM, XI)`` and their rates, equal to the outputs of the same spelling,
and a root-moment feedback on a cantilever against its closed forms."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import Scene, scenes

# a clamped Euler-Bernoulli FFRF cantilever: 1 m steel strip 20 x 10 mm
L, E, RHO, B, H = 1.0, 2e11, 7800.0, 0.02, 0.01
EI, RHOA = E * B * H**3 / 12, RHO * B * H


def _cantilever(fy, elements=8):
    """The cantilever with the tip load ``fy`` (a number or an expression)."""
    s = Scene()
    b = s.beam("bar", length=L, section={"rectangular": {"width": B, "height": H}}, density=RHO, youngs_modulus=E,
               elements=elements, theory="euler-bernoulli", strain="linear", frame="clamped", rotary_inertia=False)
    s.weld(s.ground.frame(), b.at(0.0), name="clamp")
    s.point_load(b.at(1.0), fx=0.0, fy=fy)
    return s.build()


def _with_load(scene, fx):
    """``scene()`` with a point load ``fx`` on the coupler's end."""
    s = scene()
    s.point_load(s["coupler"].at(1.0), fx=fx)
    return s.build(correct=False)


def _ffrf_crank():
    """The paper's slider-crank, its FFRF Timoshenko coupler of 2 elements with nonlinear strain."""
    return scenes.slider_crank(elements=2, strain="nonlinear")


def _cable_crank():
    """The paper's slider-crank with an ANCF cable coupler (4 elements)."""
    return scenes.slider_crank(formulation="ancf", elements=4)


@pytest.mark.parametrize("scene", [_ffrf_crank, _cable_crank], ids=["ffrf", "cable"])
def test_section_inputs_are_the_outputs_on_the_slider_crank(scene):
    # Q of a load of N, V, M, eps, kappa (and d:M) equals Q of a constant force of the value
    # that System.beam_internal_forces gives (its rate by central differences along qd)
    zero = _with_load(scene, 0.0)
    rng = np.random.default_rng(5)
    for k in range(3):
        q = zero.q0 + 2e-3 * rng.standard_normal(zero.n_coords)
        qd = rng.standard_normal(zero.n_coords)
        base = zero.core.Q(0.0, q, qd)
        for j, name in enumerate(["N", "V", "M", "eps", "kappa", "d:M"]):
            xi = [0.3, 0.5, 0.0, 0.8, 1.0, 0.45][(j + k) % 6]
            col = ["N", "V", "M", "eps", "kappa"].index(name.removeprefix("d:"))
            scale = {"N": 1e-3, "V": 1e-2, "M": 1.0, "eps": 1e6, "kappa": 10.0}[name.removeprefix("d:")]
            at = lambda x: zero.core.beam_internal_forces("coupler", np.array([xi]), x[None, :])[0, 0, col]
            h = 1e-6
            value = (at(q + h * qd) - at(q - h * qd)) / (2 * h) if name.startswith("d:") else at(q)
            got = _with_load(scene, f"{scale!r} * {name}(coupler, {xi})").core.Q(0.0, q, qd) - base
            const = scene()
            const.point_force(const["coupler"].at(1.0), (scale * value, 0.0))
            want = const.build(correct=False).core.Q(0.0, q, qd) - base
            assert abs(scale * value) > 1e-3, (name, value)
            tol = 1e-6 if name.startswith("d:") else 1e-10
            assert np.max(np.abs(got - want)) <= tol * np.max(np.abs(want)), (name, xi, got, want)


@pytest.mark.parametrize("gain", [2.0, -0.5])
def test_root_moment_feedback_changes_the_static_tip_deflection_as_the_closed_form(gain):
    # fy = F0 - g M(bar, 0): the tip force P has M(0) = P L, so P = F0 / (1 + g L) and the tip
    # deflection is P L^3 / (3 EI); the cubic elements are exact for a tip load
    f0 = 50.0
    system = _cantilever(f"{f0} - {gain!r} * M(bar, 0)")
    eq = system.equilibrium()
    v = system.core.beam_point("bar", 1.0, eq.q)[3]
    closed = f0 / (1 + gain * L) * L**3 / (3 * EI)
    plain = f0 * L**3 / (3 * EI)
    assert abs(v / plain - 1) > 0.3
    assert abs(v / closed - 1) < 1e-8, (v, closed)  # measured 7e-16 (g L = 2), 1.2e-13 (-0.5)
    m0 = system.core.beam_internal_forces("bar", np.array([0.0]), eq.q[None, :])[0, 0, 2]
    assert abs(m0 / (f0 / (1 + gain * L) * L) - 1) < 1e-8


@pytest.mark.parametrize("gain", [1.0, -0.5])
def test_root_moment_feedback_moves_the_first_frequency_to_the_closed_form(gain):
    # EI w'''' + rho A w_tt = 0, w(0) = w'(0) = 0, w''(L) = 0, EI w'''(L) = -F = g EI w''(0):
    # with lam = beta L and G = g L, lam (1 + cosh lam cos lam) + G (sinh lam + sin lam) = 0
    # (G = 0: the free cantilever's 1.8751; the load is not conservative, so the eigenvalue of
    # the linearized motion, System.jac, not the symmetric modal analysis)
    from scipy.optimize import brentq

    G = gain * L
    f = lambda lam: lam * (1 + math.cosh(lam) * math.cos(lam)) + G * (math.sinh(lam) + math.sin(lam))
    lam = brentq(f, 0.5, 3.0)
    closed = lam**2 * math.sqrt(EI / (RHOA * L**4))
    free = 1.8751041**2 * math.sqrt(EI / (RHOA * L**4))
    system = _cantilever(f"-{gain!r} * M(bar, 0)", elements=16)
    ev = np.linalg.eigvals(np.asarray(system.jac(0.0, system.y0)))
    w = ev[np.argmin(np.abs(ev - 1j * closed))]
    assert abs(closed / free - 1) > 0.1
    # measured 9.1e-7 (G = 1) and 4.5e-7 (G = -0.5); 8 elements: 1.4e-5, 7.1e-6 (h^4)
    assert abs(w.real) < 1e-6 * closed and abs(w.imag / closed - 1) < 1e-5, (w, closed)


def test_strain_rate_input_runs_with_radau5m():
    # a strain and strain-rate (piezo-like) feedback on the paper's coupler: a short RADAU5M run
    # (its Newton matrices take the inputs' analytic K) agrees with DOPRI5, and the feedback
    # changes the coupler's deflection
    def scene(feedback):
        s = scenes.slider_crank()
        s.point_load(s["coupler"].at(1.0), fx=f"-2000 * (1 + cos(crank.theta))^2{feedback}")
        return s.build()

    fb = " - 1e6 * eps(coupler, 0.5) - 50 * d:kappa(coupler, 0.5)"
    a = ukflex.simulate(scene(fb), 0.02, method="RADAU5M", rtol=1e-8, atol=1e-10)
    b = ukflex.simulate(scene(fb), 0.02, method="DOPRI5", rtol=1e-10, atol=1e-12)
    c = ukflex.simulate(scene(""), 0.02, method="DOPRI5", rtol=1e-10, atol=1e-12)
    assert a.success and b.success
    qa, qb, qc = (r.coordinate("coupler.qf2")[-1] for r in (a, b, c))
    assert abs(qa - qb) < 1e-5 * abs(qb), (qa, qb)  # measured 3e-12 of 1.2e-3
    assert abs(qb - qc) > 1e-3 * abs(qb), (qb, qc)


@pytest.mark.parametrize("fx, error, match, position", [
    ("M(rod, 0.5)", ukflex.InvalidSceneError, "unknown body 'rod'", None),
    ("1 + kappa(coupler, 1.2)", ukflex.ExpressionError, r"XI must be a number in \[0, 1\]", 4),
    ("eps(crank, 0.5)", ukflex.ExpressionError, r"body 'crank' \(rigid\) has no beam axis; N, V, M, eps, kappa", 0),
    ("0.1 * reaction(slider).fx", ukflex.ExpressionError, "algebraic loop.*joint_friction", 6),
    ("coupler.kappa", ukflex.ExpressionError, r"unknown state quantity 'coupler.kappa'.*N\(BEAM, XI\).*kappa\(\.\.\.\)", 0),
])
def test_section_inputs_bad_input_is_named(fx, error, match, position):
    s = scenes.slider_crank()
    with pytest.raises(error, match=match) as e:
        s.point_load(s["coupler"].at(1.0), fx=fx)
    if position is not None:
        assert e.value.position == position
