"""Conservative rigid mechanisms: energy is conserved to the integration tolerance, and the
pendulum swings with the exact (elliptic-integral) period."""

import math

import numpy as np
import pytest
from scipy.special import ellipk

from ukflex import scenes, simulate

G = 9.81
L = 1.0
M = 1.0
PHI0 = math.pi / 4  # amplitude from the hanging position (released at angle -pi/4 from +X)


def _relative_energy_drift(res, scale):
    e = res.energy()
    return np.abs(e - e[0]).max() / scale


@pytest.fixture(scope="module")
def drifts():
    out = {}
    scene = scenes.pendulum(length=L, mass=M, angle=-math.pi / 2 + PHI0, gravity=G)
    for rtol in (1e-5, 1e-7, 1e-9, 1e-11):
        res = simulate(scene, 5.0, rtol=rtol, atol=1e-3 * rtol, t_eval=np.linspace(0, 5, 501))
        assert res.success
        out[rtol] = (_relative_energy_drift(res, M * G * L / 2), res)
    return out


def test_energy_drift_small_at_tight_tolerance(drifts):
    drift, res = drifts[1e-11]
    assert drift < 1e-8, drift
    assert res.max_residual("position") < 1e-8


def test_energy_drift_decreases_with_rtol(drifts):
    values = [drifts[r][0] for r in (1e-5, 1e-7, 1e-9, 1e-11)]
    for loose, tight in zip(values, values[1:]):
        assert tight < loose, values
    assert values[-1] < 1e-3 * values[0], values


def test_energy_is_not_trivially_constant(drifts):
    """Kinetic and potential energy both vary by the full swing (the check above is not vacuous)."""
    _, res = drifts[1e-9]
    sys_ = res.system
    T = np.array([sys_.kinetic_energy(q, qd) for q, qd in zip(res.q.T, res.qd.T)])
    swing = M * G * (L / 2) * (1 - math.cos(PHI0))
    # sampled every 0.01 s, so the maximum is caught to about (omega dt)^2 ~ 1e-4
    assert T.max() == pytest.approx(swing, rel=1e-4)
    assert T.min() < 1e-3 * swing


def test_period_matches_elliptic_integral():
    """Uniform rod pivoted at one end: T = 4 sqrt(I_p / (m g h)) K(sin^2(phi0 / 2))."""
    scene = scenes.pendulum(length=L, mass=M, angle=-math.pi / 2 + PHI0, gravity=G)
    t = np.linspace(0.0, 4.0, 40001)
    res = simulate(scene, 4.0, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=t)
    w = res.velocity("rod.theta")
    # turning points: angular velocity changes sign; interpolate linearly
    idx = np.flatnonzero(np.sign(w[1:]) * np.sign(w[:-1]) < 0)
    crossings = t[idx] - w[idx] * (t[idx + 1] - t[idx]) / (w[idx + 1] - w[idx])
    assert crossings.size >= 3
    period = 2 * np.mean(np.diff(crossings))
    I_p = M * L**2 / 3
    h = L / 2
    exact = 4 * math.sqrt(I_p / (M * G * h)) * ellipk(math.sin(PHI0 / 2) ** 2)
    assert period == pytest.approx(exact, rel=1e-6)
    # and it is not the small-angle period
    assert abs(period - 2 * math.pi * math.sqrt(I_p / (M * G * h))) > 1e-2


def test_double_pendulum_energy():
    scene = scenes.double_pendulum()
    res = simulate(scene, 3.0, rtol=1e-10, atol=1e-13, t_eval=np.linspace(0, 3, 301))
    e = res.energy()
    scale = 9.81 * (1.0 * 1.0 + 0.5 * 1.7)
    assert np.abs(e - e[0]).max() / scale < 1e-7
    assert np.ptp(res.coordinate("rod2.theta")) > 1.0  # it really moves
