"""Self-tests of the NumPy coordinate-partitioning integrator (no Rust needed)."""
import copy
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))

import _ref_scenes as scenes  # noqa: E402
from ukflex.reference import ReferenceModel, simulate_uk_numpy  # noqa: E402
from ukflex.reference.cp import choose_partition, reduced_accelerations, simulate_cp  # noqa: E402
from ukflex.reference import augmented_qdd, correct_initial_state  # noqa: E402


def test_partition_choice_pendulum():
    m = ReferenceModel(scenes.pendulum())
    q, _ = m.initial_guess()                       # hanging: theta = -pi/2
    p = choose_partition(m.A(q))
    assert p.dep.tolist() == [1, 2] and p.ind.tolist() == [0]     # x independent
    q[2] = 0.0                                      # horizontal: x is now a bad choice
    q[:2] = [2.0, 0.0]
    p = choose_partition(m.A(q))
    assert p.dep.tolist() == [0, 2] and p.ind.tolist() == [1]     # y independent


def test_partition_with_redundant_rows_and_reduced_accelerations():
    d = scenes.rigid_slider_crank()
    d["joints"].append(copy.deepcopy(d["joints"][1]))            # duplicated crank pin
    m = ReferenceModel(d)
    q, qd = correct_initial_state(m)
    A = m.A(q)
    p = choose_partition(A)
    assert p.dep.size == np.linalg.matrix_rank(A) == m.m - 2
    assert p.rows.size == p.dep.size
    assert np.linalg.matrix_rank(A[p.rows]) == p.rows.size
    qddI, qdd = reduced_accelerations(m, p, 0.0, q, qd)
    M, Q, A, b = m.terms(0.0, q, qd)
    qdd2, _ = augmented_qdd(M, Q, A, b)
    np.testing.assert_allclose(qdd, qdd2, atol=1e-10 * np.abs(qdd2).max())


def test_pendulum_through_horizontal_repartitions_and_matches_uk():
    m = ReferenceModel(scenes.pendulum())
    te = np.linspace(0, 3.0, 31)
    cp = simulate_cp(m, 3.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=te)
    uk = simulate_uk_numpy(m, 3.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=te)
    assert cp.success and uk.success
    # it swings through both horizontals: x independent -> y -> x ... at least 2 repartitions
    assert cp.q[2].max() > 0.3 and cp.q[2].min() < -np.pi - 0.05
    assert cp.repartitions >= 2
    deps = [tuple(d) for _, d, _ in cp.extra["partitions"]]
    assert (1, 2) in deps and (0, 2) in deps
    np.testing.assert_allclose(cp.q, uk.q, atol=1e-7)
    np.testing.assert_allclose(cp.qd, uk.qd, atol=1e-6)
    # CP satisfies the position and velocity constraints to Newton tolerance, always
    for i in range(te.size):
        assert np.abs(m.phi(te[i], cp.q[:, i])).max() < 1e-11
        assert np.abs(m.A(cp.q[:, i]) @ cp.qd[:, i]).max() < 1e-10
    E = [m.kinetic_energy(cp.q[:, i], cp.qd[:, i]) + m.potential_energy(cp.q[:, i])
         for i in range(te.size)]
    assert np.ptp(E) < 1e-7 * abs(E[0])


def test_pendulum_without_repartitioning_fails():
    """The repartition is necessary: with an absurd threshold the fixed partition (x
    independent) runs into the singular dependent block at the horizontal, where x has a
    turning point, and the run breaks down there."""
    m = ReferenceModel(scenes.pendulum())
    res = simulate_cp(m, 0.6, method="DOP853", rtol=1e-8, atol=1e-10, repartition_factor=1e30)
    assert res.status == -1 and "Newton" in res.message and res.repartitions == 0
    good = simulate_cp(m, 0.6, method="DOP853", rtol=1e-8, atol=1e-10)
    assert good.success and good.repartitions == 1


def test_every_call_mode_matches_and_counts_changes():
    m = ReferenceModel(scenes.pendulum())
    te = np.linspace(0, 3.0, 16)
    cp = simulate_cp(m, 3.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=te,
                     partition="every_call")
    uk = simulate_uk_numpy(m, 3.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=te)
    assert cp.success and cp.repartitions >= 2
    np.testing.assert_allclose(cp.q, uk.q, atol=1e-8)


def test_output_without_t_eval_is_monotonic_and_constraint_satisfying():
    m = ReferenceModel(scenes.pendulum())
    cp = simulate_cp(m, 3.0, method="DOP853", rtol=1e-8, atol=1e-10)
    assert cp.repartitions >= 2
    assert np.all(np.diff(cp.t) > 0) and cp.t[0] == 0.0 and cp.t[-1] == 3.0
    assert cp.q.shape == (3, cp.t.size) and cp.qd.shape == (3, cp.t.size)
    res = np.array([np.abs(m.phi(t, cp.q[:, i])).max() for i, t in enumerate(cp.t)])
    assert res.max() < 1e-11


def test_rigid_slider_crank_cp_matches_uk():
    m = ReferenceModel(scenes.rigid_slider_crank())
    te = np.linspace(0, 1.0, 11)
    cp = simulate_cp(m, 1.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=te)
    uk = simulate_uk_numpy(m, 1.0, method="DOP853", rtol=1e-10, atol=1e-12, t_eval=te)
    assert cp.success and uk.success
    assert np.ptp(cp.q[2]) > 0.5                         # the crank turned
    np.testing.assert_allclose(cp.q, uk.q, atol=1e-7)


def test_paper_scene_cp_matches_uk_numpy_short():
    for theory in ("euler-bernoulli", "timoshenko"):
        m = ReferenceModel(scenes.slider_crank(theory, 1))
        b = m.body("coupler")
        te = np.linspace(0, 2e-3, 5)
        cp = simulate_cp(m, 2e-3, method="DOP853", rtol=1e-10, atol=1e-13, t_eval=te)
        uk = simulate_uk_numpy(m, 2e-3, method="DOP853", rtol=1e-10, atol=1e-13, t_eval=te)
        assert cp.repartitions == 0
        # the partition keeps the six rigid coordinates dependent: only q_f is integrated
        assert cp.extra["partitions"][0][1] == [0, 1, 2, 3, 4, 5]
        S, _ = m.beam_shape("coupler", 0.5)
        v_cp = (S @ cp.q[b.offset + 3:])[1] / b.length
        v_uk = (S @ uk.q[b.offset + 3:])[1] / b.length
        assert np.abs(v_cp).max() > 1e-4
        np.testing.assert_allclose(v_cp, v_uk, rtol=0, atol=1e-8 * np.abs(v_uk).max())
        assert cp.accel_time > 0 and cp.nfev > 0 and cp.wall_time >= cp.accel_time


def test_scipy_num_jac_step_overflows_on_a_dead_column_and_fd_jacobian_does_not():
    """Root cause of NaN states in long implicit runs: scipy's num_jac multiplies the step of
    a column that the rhs does not depend on (translation invariance: the crank pivot's x, y)
    by 10 at every Jacobian evaluation, without bound."""
    import warnings
    from scipy.integrate._ivp.common import num_jac
    from ukflex.reference.uk import fd_jacobian
    m = ReferenceModel(scenes.slider_crank("euler-bernoulli", 1))
    q, qd = correct_initial_state(m)
    n = m.n

    def rhs(t, y):
        M, Q, A, b = m.terms(t, y[:n], y[n:])
        from ukflex.reference import uk_qdd
        return np.concatenate([y[n:], uk_qdd(M, Q, A, b)])

    def vec(t, Y):
        return np.column_stack([rhs(t, Y[:, k]) for k in range(Y.shape[1])])

    y = np.r_[q, qd]
    y[0], y[n] = 1e-12, 1e-13              # the few-ulp drift of a UK run: f[0] != 0
    f = rhs(0.0, y)
    _, factor = num_jac(vec, 0.0, y, f, 1e-9, None)
    for _ in range(3):                      # the pivot's x, y steps: x10 per Jacobian
        prev = factor.copy()
        _, factor = num_jac(vec, 0.0, y, f, 1e-9, factor)
        np.testing.assert_allclose(factor[:2] / prev[:2], 10.0)
    assert np.all(factor[n + 6:] <= 1.5e-6)    # live (elastic rate) columns do not keep growing
    factor[:2] = 1.49e308                   # where it is after ~316 Jacobians
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, factor = num_jac(vec, 0.0, y, f, 1e-9, factor)
        assert np.all(np.isinf(factor[:2]))
        seen = []

        def spy(t, Y):
            seen.append(np.all(np.isfinite(Y)))
            return vec(t, np.nan_to_num(Y))
        num_jac(spy, 0.0, y, f, 1e-9, factor)
        assert not all(seen)            # the next Jacobian hands the rhs y = inf (Rust:
        #                                 NonFiniteError "y[:n]: contains NaN or infinity")
    J = fd_jacobian(rhs, 1e-9)(0.0, y)
    assert np.all(np.isfinite(J))
    # fd_jacobian itself on a function with a known Jacobian
    g = lambda t, z: np.array([np.sin(z[0]) * z[1], z[0] ** 2 + np.exp(z[1]), 0.0 * z[2]])  # noqa
    z = np.array([0.3, -1.2, 5.0])
    Jz = fd_jacobian(g, 1e-9)(0.0, z)
    exact = np.array([[np.cos(0.3) * -1.2, np.sin(0.3), 0], [0.6, np.exp(-1.2), 0], [0, 0, 0]])
    np.testing.assert_allclose(Jz, exact, rtol=0, atol=1e-7)
