"""Native integrators (Rust DOPRI5 and RADAU5, selected with ukflex.simulate(method=...))
cross-checked against the scipy path on the same system, and the Rust Jacobian System.jac."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ukflex
from ukflex.results.simulation import SimulationResult


@pytest.fixture(scope="module")
def system():
    return ukflex.System(ukflex.scenes.slider_crank())


def _midpoint(res):
    _, v = res.beam_displacement("coupler", 0.5)
    return np.asarray(v)


T_END = 0.02
T_EVAL = np.linspace(0.0, T_END, 41)


@pytest.mark.parametrize("native, scipy_method, rtol, t_end", [("DOPRI5", "DOP853", 1e-8, T_END), ("RADAU5", "Radau", 1e-7, 0.005)])
def test_native_matches_scipy_path(system, native, scipy_method, rtol, t_end):
    t_eval = np.linspace(0.0, t_end, 41)
    a = ukflex.simulate(system, t_end, method=native, rtol=rtol, t_eval=t_eval)
    b = ukflex.simulate(system, t_end, method=scipy_method, rtol=rtol, t_eval=t_eval)
    assert isinstance(a, SimulationResult) and a.success, a.message
    assert b.success, b.message
    assert a.method == native and a.formulation == "uk"
    np.testing.assert_array_equal(a.t, b.t)
    assert a.q.shape == b.q.shape == (system.n_coords, t_eval.size)
    # same trajectory within the tolerances: coordinates scaled per column
    for x, y in ((a.q, b.q), (a.qd, b.qd)):
        scale = np.maximum(np.max(np.abs(y), axis=1, keepdims=True), 1e-6)
        assert np.max(np.abs(x - y) / scale) < 1e-5
    va, vb = _midpoint(a), _midpoint(b)
    assert np.max(np.abs(va - vb)) < 1e-6 * np.max(np.abs(vb)) + 1e-10
    # the result object is complete: residual histories and statistics
    assert set(a.residuals) == {"position", "velocity", "acceleration"}
    assert a.residuals["position"].shape == a.t.shape
    assert np.max(a.residuals["position"]) < 1e-6
    assert a.nfev > 0 and a.wall_time > 0
    if native == "RADAU5":
        assert a.njev >= 1 and a.nlu >= 2


def test_native_default_output_is_every_step_and_ends_at_t_end(system):
    r = ukflex.simulate(system, T_END, method="DOPRI5", rtol=1e-6)
    assert r.success
    assert r.t[0] == system.t0 and r.t[-1] == T_END
    assert np.all(np.diff(r.t) > 0)
    assert r.t.size == r.extra["naccept"] + 1


def test_native_tolerance_reduces_error(system):
    ref = ukflex.simulate(system, T_END, method="DOPRI5", rtol=1e-11, atol=1e-14, t_eval=T_EVAL)
    errs = []
    for rtol in (1e-4, 1e-7):
        r = ukflex.simulate(system, T_END, method="RADAU5", rtol=rtol, t_eval=T_EVAL)
        errs.append(np.max(np.abs(_midpoint(r) - _midpoint(ref))))
    assert errs[1] < 0.1 * errs[0]


def test_native_projection_keeps_constraints(system):
    r = ukflex.simulate(system, T_END, method="DOPRI5", rtol=1e-4, projection_tol=1e-12)
    free = ukflex.simulate(system, T_END, method="DOPRI5", rtol=1e-4, projection_tol=0)  # DOPRI5 projects by default
    assert r.success
    assert np.max(r.residuals["position"]) < 1e-11
    assert np.max(r.residuals["position"]) <= np.max(free.residuals["position"])


def test_native_argument_errors(system):
    with pytest.raises(ValueError):
        ukflex.simulate(system, T_END, method="DOPRI5", t_eval=[0.01, 0.005])
    with pytest.raises(ValueError):
        ukflex.simulate(system, T_END, method="RADAU5", rtol=-1.0)
    with pytest.raises(ValueError):
        ukflex.simulate(system, T_END, method="DOPRI5", formulation="cp")
    with pytest.raises(TypeError):  # an option the native methods do not take (dense_output now works)
        ukflex.simulate(system, T_END, method="DOPRI5", max_stpe=1e-3)


def test_rust_jacobian_matches_scipy_finite_differences(system):
    n = system.n_coords
    rng = np.random.default_rng(1)
    y = system.y0.copy()
    y[:n] += 1e-4 * rng.standard_normal(n) * np.where(system.elastic_mask(), 1e-2, 1.0)
    y[n:] += 0.5 * rng.standard_normal(n)
    t = 0.003
    J = system.jac(t, y)
    assert J.shape == (2 * n, 2 * n)
    np.testing.assert_array_equal(J[:n, :n], 0.0)
    np.testing.assert_array_equal(J[:n, n:], np.eye(n))
    # independent central differences of rhs from Python, column by column
    f = lambda yy: system.rhs(t, yy)  # noqa: E731
    Jfd = np.empty_like(J)
    for j in range(2 * n):
        h = 1e-5 * max(abs(y[j]), 1e-2)
        e = np.zeros(2 * n)
        e[j] = h
        Jfd[:, j] = (f(y + e) - f(y - e)) / (2 * h)
    # per-row scale with a floor: some rows are exactly zero (the driven crank angle), where
    # both difference quotients are pure rounding noise
    scale = np.maximum(np.max(np.abs(Jfd), axis=1, keepdims=True), 1e-6 * np.max(np.abs(Jfd)))
    assert np.max(np.abs(J - Jfd) / scale) < 1e-5
    # forward scheme: same within its cruder accuracy
    Jf = system.core.jac(t, y, "forward")
    assert np.max(np.abs(Jf - J) / scale) < 1e-3


def test_scipy_implicit_methods_use_the_rust_jacobian(system):
    """simulate passes System.jac to Radau/BDF/LSODA, so scipy no longer calls rhs 2n times per
    Jacobian from Python; the trajectory matches a run with scipy's own FD Jacobian."""
    a = ukflex.simulate(system, 0.005, method="Radau", rtol=1e-6)
    calls = [0]

    def counted(t, y):
        calls[0] += 1
        return system.rhs(t, y)

    b = solve_ivp(counted, (system.t0, 0.005), system.y0, method="Radau", rtol=1e-6, atol=1e-9)
    assert a.success and b.success
    assert a.njev >= 1 and b.njev >= 1
    assert calls[0] >= b.nfev + 2 * system.n_coords * b.njev  # FD Jacobians went through rhs
    np.testing.assert_allclose(a.q[:, -1], b.y[: system.n_coords, -1], rtol=1e-5, atol=1e-9)
