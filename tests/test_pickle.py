"""Scenes, systems and results pickle (a process pool or Dask can ship and return them)."""

import pickle

import numpy as np
import pytest

import ukflex


def _same_system(a, b):
    assert type(a) is type(b) is ukflex.System
    assert a.description == b.description
    assert a.coordinate_names == b.coordinate_names and a.constraint_names == b.constraint_names
    for name in ("q0", "qd0", "q_guess", "qd_guess"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.t0 == b.t0
    np.testing.assert_array_equal(a.initial_correction.dq, b.initial_correction.dq)
    y = a.y0 + 1e-3
    np.testing.assert_array_equal(a.rhs(0.01, y), b.rhs(0.01, y))  # the rebuilt core computes the same
    assert b.core is not a.core


def test_scene_pickles_to_the_same_description():
    s = ukflex.scenes.slider_crank(elements=2)
    s2 = pickle.loads(pickle.dumps(s))
    assert isinstance(s2, ukflex.Scene) and s2.to_dict() == s.to_dict()
    assert s2.build().n_coords == s.build().n_coords


def test_system_pickles_with_build_options_and_settings():
    scene = ukflex.scenes.four_bar()
    a = ukflex.System(scene, hold=None, position_tol=1e-11)
    a.set_rank_tolerance(1e-9)
    a.set_stabilization("baumgarte", 5.0, 5.0)
    b = pickle.loads(pickle.dumps(a))
    _same_system(a, b)
    assert b._build_options == a._build_options and b._settings == a._settings
    # the settings reached the rebuilt core: same accelerations as the original, not as a plain build
    y = a.y0 + 1e-3
    plain = ukflex.System(scene, hold=None, position_tol=1e-11)
    assert not np.array_equal(plain.rhs(0.0, y), a.rhs(0.0, y))
    np.testing.assert_array_equal(b.rhs(0.0, y), a.rhs(0.0, y))


def test_system_with_a_modified_initial_state_keeps_it():
    a = ukflex.scenes.pendulum().build()
    a.q0 = a.q0 + 0.0  # a user may replace the state; the pickle carries what is there
    a.qd0 = a.qd0 + 0.5
    b = pickle.loads(pickle.dumps(a))
    np.testing.assert_array_equal(b.qd0, a.qd0)


@pytest.mark.parametrize("method", ["DOPRI5", "RK45"])
def test_result_pickles_with_its_system(method):
    res = ukflex.simulate(ukflex.scenes.pendulum(), 0.2, method=method)
    r2 = pickle.loads(pickle.dumps(res))
    assert isinstance(r2, ukflex.SimulationResult)
    for f in ("t", "q", "qd"):
        np.testing.assert_array_equal(getattr(r2, f), getattr(res, f))
    for k in res.residuals:
        np.testing.assert_array_equal(r2.residuals[k], res.residuals[k])
    assert (r2.method, r2.status, r2.nfev, r2.rtol) == (res.method, res.status, res.nfev, res.rtol)
    _same_system(res.system, r2.system)
    np.testing.assert_array_equal(r2.energy(), res.energy())  # post-processing works on the rebuilt system
