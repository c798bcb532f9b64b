"""Simeon's flexible slider crank (Test Set for IVP Solvers, problem ``crank``) through the public
API: the rod as a general flexible body with the Test Set's own FE invariants, compared at
t = 0.1 with the Test Set's published reference (mixed-error significant correct digits)."""

import numpy as np
import pytest

from ukflex.reference import testset_crank as ts
from studies import simeon_crank as sc


def test_initial_state_maps_onto_the_constraints():
    system = sc.crank_scene().build(correct=False)
    q0, qd0 = sc.crank_state(system, ts.Y0[:14])
    phi, phid, _ = system.core.residuals(0.0, q0, qd0)
    # the Test Set's x3 is given to 9 digits: its position residual is 2e-10
    assert np.max(np.abs(phi)) < 5e-10
    assert np.max(np.abs(phid)) < 1e-9


def test_accelerations_match_the_test_set_equations():
    """The ukflex model (rigid crank + flexible body + slider, maximal coordinates, UK) gives the
    Test Set's accelerations (its RESMBS in minimal coordinates) at its initial state."""
    for nonlinear in (False, True):
        system = sc.crank_scene(nonlinear).build(correct=False)
        q0, qd0 = sc.crank_state(system, ts.Y0[:14])
        qdd = system.core.qdd(0.0, q0, qd0)
        w, _ = ts.accelerations(0.0, ts.Y0[:7], ts.Y0[7:14], nonlinear=nonlinear)
        idx = system.coordinate_index
        names = ["crank.theta", "rod.theta", "slider.x"] + [f"rod.qf{i}" for i in range(4)]
        ours = np.array([qdd[idx(n)] for n in names])
        assert np.allclose(ours, w, rtol=1e-9, atol=1e-9 * np.max(np.abs(w))), (nonlinear, ours - w)
    # and the Test Set's own consistent accelerations (y(15..21)) for the linear model
    assert np.allclose(ts.accelerations(0.0, ts.Y0[:7], ts.Y0[7:14])[0], ts.Y0[14:21], rtol=1e-8, atol=1e-6)


def test_linear_crank_matches_the_published_reference_to_8_digits():
    r = sc.run(nonlinear=False, rtol=1e-10)
    assert r["min_scd"] >= 8.0, sc.report(False, rtol=1e-10)


def test_nonlinear_stiffness_variant():
    r = sc.run(nonlinear=True, rtol=1e-10, direct=ts.integrate(nonlinear=True, rtol=1e-11, atol=1e-13))
    assert r["min_scd"] >= 8.0
    # the nonlinear term changes the answer (it is not a no-op)
    lin = sc.run(nonlinear=False, rtol=1e-9)
    assert np.min(ts.mixed_scd(lin["y"], r["y"])) < 2.0


@pytest.mark.parametrize("bad", ["k3_unsymmetric", "k3_missing"])
def test_nonlinear_option_needs_a_symmetric_k3(bad):
    import ukflex

    data = sc.rod_data(nonlinear=True)
    if bad == "k3_missing":
        data.k3 = None
    else:
        data.k3 = data.k3.copy()
        data.k3[0, 0, 3] *= 2.0
    s = ukflex.Scene()
    with pytest.raises(ukflex.InvalidSceneError, match="k3"):
        s.flexible_body("rod", data, strain="nonlinear")
