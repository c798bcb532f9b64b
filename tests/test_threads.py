"""System is safe to use from several threads: concurrent calls give the same results as serial
ones, and independent native simulations can run in parallel threads (the GIL is released)."""
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import ukflex


@pytest.fixture(scope="module")
def system():
    return ukflex.System(ukflex.scenes.slider_crank(elements=2))


def _states(system, k=16, seed=3):
    rng = np.random.default_rng(seed)
    n = system.n_coords
    out = []
    for i in range(k):
        y = system.y0.copy()
        y[:n] += 1e-3 * rng.standard_normal(n) * np.where(system.elastic_mask(), 1e-2, 1.0)
        y[n:] += 0.1 * rng.standard_normal(n)
        out.append((0.01 * i, y))
    return out


def test_concurrent_per_step_calls_match_serial(system):
    n = system.n_coords
    states = _states(system)

    def work(s):
        t, y = s
        return (system.rhs(t, y), system.qdd(t, y[:n], y[n:]), system.core.jac(t, y), system.multipliers(t, y[:n], y[n:]))

    serial = [work(s) for s in states]
    with ThreadPoolExecutor(4) as ex:
        for _ in range(3):
            threaded = list(ex.map(work, states * 4))
            for k, res in enumerate(threaded):
                for a, b in zip(serial[k % len(states)], res):
                    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("method", ["DOPRI5", "RADAU5"])
def test_parallel_native_runs_match_serial(method):
    omegas = [124.8, 110.0, 140.0, 95.0]
    systems = [ukflex.System(ukflex.scenes.slider_crank(omega=w)) for w in omegas]
    shared = systems[0]
    te = np.linspace(0.0, 0.01, 11)

    def run(k, use_shared):
        s = shared if use_shared else systems[k]
        r = s.core.integrate(0.0, systems[k].y0, 0.01, method, 1e-5, None, te)
        assert r["status"] == 0, r["message"]
        return r["y"]

    # the same runs in threads: on their own systems, and all on one shared system (whose
    # driver speed the projection after each step imposes: its serial runs are the reference)
    serial = {use_shared: [run(k, use_shared) for k in range(len(omegas))] for use_shared in (False, True)}
    with ThreadPoolExecutor(len(omegas)) as ex:
        for use_shared in (False, True):
            threaded = list(ex.map(lambda k: run(k, use_shared), range(len(omegas))))
            for a, b in zip(serial[use_shared], threaded):
                np.testing.assert_array_equal(a, b)
    serial = serial[False]
    # different crank speeds really give different trajectories (the runs are independent)
    assert not np.allclose(serial[0], serial[1])


def test_per_step_calls_while_a_native_run_is_in_flight(system):
    """A long native run (GIL released, private workspace) and concurrent rhs calls on the same
    System do not interfere."""
    n = system.n_coords
    states = _states(system, k=8)
    expected = [system.rhs(t, y) for t, y in states]
    ref = system.core.integrate(0.0, system.y0, 0.02, "DOPRI5", 1e-6, None, np.linspace(0, 0.02, 5))
    with ThreadPoolExecutor(2) as ex:
        fut = ex.submit(system.core.integrate, 0.0, system.y0, 0.02, "DOPRI5", 1e-6, None, np.linspace(0, 0.02, 5))
        for _ in range(50):
            for (t, y), e in zip(states, expected):
                np.testing.assert_array_equal(system.rhs(t, y), e)
        r = fut.result()
    np.testing.assert_array_equal(r["y"], ref["y"])
    assert n == system.n_coords


def test_native_run_releases_the_gil():
    """While a native run is in flight in one thread, pure-Python code keeps running in another
    (if the GIL were held for the whole run, no main-thread iteration could fall inside it)."""
    s = ukflex.System(ukflex.scenes.slider_crank())
    box = {}

    def long_run():
        box["t0"] = time.perf_counter()
        r = s.core.integrate(0.0, s.y0, 0.03, "DOPRI5", 1e-7, None, None)
        box["t1"] = time.perf_counter()
        return r["status"]

    stamps = []
    with ThreadPoolExecutor(1) as ex:
        fut = ex.submit(long_run)
        while not fut.done():
            stamps.append(time.perf_counter())
        assert fut.result() == 0
    inside = sum(1 for t in stamps if box["t0"] < t < box["t1"])
    assert inside >= 3, f"main thread made {inside} iterations during a {box['t1'] - box['t0']:.3f} s native run"


def test_concurrent_runs_with_different_settings_on_one_system_match_serial():
    # issue 15: settings used to live on the shared System, so two threads with different
    # stabilizations got each other's (35 of 40 scipy runs wrong here without the copy); simulate's
    # stabilization= now works on a copy
    shared = ukflex.System(ukflex.scenes.slider_crank(elements=2))
    settings = [None, ("baumgarte", 50.0, 50.0), ("baumgarte", 500.0, 500.0), "projection"] * 2
    te = np.linspace(0.0, 0.004, 5)

    def run(st):
        r = ukflex.simulate(shared, 0.004, "RK45", rtol=1e-6, t_eval=te, stabilization=st or "none", raise_on_failure=True)  # rhs reads settings per call
        return r.y

    serial = [run(st) for st in settings]
    with ThreadPoolExecutor(len(settings)) as ex:
        threaded = list(ex.map(run, settings))
    for a, b in zip(serial, threaded):
        np.testing.assert_array_equal(a, b)
    # and the shared System itself was not reconfigured
    assert "set_stabilization" not in shared._settings


def test_rank_info_with_a_state_is_that_states(system):
    n = system.n_coords
    states = _states(system)
    serial = [system.rank_info(t, y[:n], y[n:]) for t, y in states]
    with ThreadPoolExecutor(4) as ex:
        threaded = list(ex.map(lambda s: system.rank_info(s[0], s[1][:n], s[1][n:]), states * 4))
    for k, info in enumerate(threaded):
        assert info == serial[k % len(states)]
