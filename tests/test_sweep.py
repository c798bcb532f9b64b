"""ukflex.sweep: serial, a process pool and a real dask.distributed LocalCluster."""

import math

import numpy as np
import pytest

import ukflex
from ukflex.run.sweep import cases_of

pd = pytest.importorskip("pandas")


def build(mass, angle):
    """A pendulum case; mass <= 0 fails in the scene builder (a failed case, not a failed sweep)."""
    return ukflex.scenes.pendulum(mass=mass, angle=angle), {"t_end": 0.3, "method": "DOPRI5", "rtol": 1e-9}


def outputs(res):
    return {"theta_end": res.coordinate("rod.theta")[-1], "steps": len(res.t)}


GRID = {"mass": [0.5, 1.0, -1.0], "angle": [-1.0, -0.5]}


def _check(df):
    assert list(df.columns[:4]) == ["mass", "angle", "theta_end", "steps"]
    assert len(df) == 6 and list(df["mass"]) == [0.5, 0.5, 1.0, 1.0, -1.0, -1.0]  # case order
    ok = df[df["mass"] > 0]
    assert (ok["status"] == "ok").all() and (ok["error"] == "").all() and (ok["method"] == "DOPRI5").all()
    bad = df[df["mass"] < 0]
    assert (bad["status"] == "failed").all() and bad["theta_end"].isna().all()
    assert all("InvalidSceneError" in e and "mass" in e for e in bad["error"])
    assert df.attrs["failed"] == 2 and (df["wall_time"] > 0).all()
    # the physics, independently: the same case simulated here
    for _, r in ok.iterrows():
        res = ukflex.simulate(ukflex.scenes.pendulum(mass=r["mass"], angle=r["angle"]), 0.3, method="DOPRI5",
                              rtol=1e-9)
        assert r["theta_end"] == pytest.approx(res.coordinate("rod.theta")[-1], abs=1e-12)
        assert r["theta_end"] < r["angle"]  # released from rest below the horizontal: it falls


def test_cases_of_grids():
    assert cases_of({"a": [1, 2], "b": "x"}) == [{"a": 1, "b": "x"}, {"a": 2, "b": "x"}]
    assert cases_of({"a": [1, 2], "b": [3, 4]})[1] == {"a": 1, "b": 4}  # last key fastest
    assert cases_of([{"a": 1}, {"a": 5, "b": 2}]) == [{"a": 1}, {"a": 5, "b": 2}]
    for bad, exc in (({}, ValueError), ([], ValueError), ({"a": []}, ValueError), ([1], TypeError),
                     ("ab", TypeError), ({"status": [1]}, ValueError), ({"not a name": [1]}, ValueError)):
        with pytest.raises(exc):
            cases_of(bad)


def test_serial():
    _check(ukflex.sweep(build, GRID, outputs))


def test_process_pool_with_lambdas():
    df = ukflex.sweep(lambda **c: build(**c), GRID, lambda r: outputs(r), "processes", workers=2)
    _check(df)
    assert df.attrs["executor"] == "processes" and df.attrs["workers"] == 2


def test_dask_local_cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            df = ukflex.sweep(build, GRID, outputs, client)
    _check(df)
    assert df.attrs["executor"] == "dask" and df.attrs["workers"] == 2


def test_simulate_options_defaults_and_bad_outputs():
    df = ukflex.sweep(lambda length: ukflex.scenes.pendulum(length=length), [{"length": 1.0}],
                      lambda r: {"n": len(r.t), "arr": np.ones(3)}, t_end=0.1, method="RK45")
    assert df.loc[0, "status"] == "failed" and "'arr' must be a scalar" in df.loc[0, "error"]
    df = ukflex.sweep(lambda length: ukflex.scenes.pendulum(length=length), [{"length": 1.0}],
                      lambda r: {"tf": float(r.t[-1])}, t_end=0.1, method="RK45")
    assert df.loc[0, "status"] == "ok" and df.loc[0, "tf"] == pytest.approx(0.1) and df.loc[0, "method"] == "RK45"
    df = ukflex.sweep(lambda length: ukflex.scenes.pendulum(length=length), [{"length": 1.0}], lambda r: {})
    assert df.loc[0, "status"] == "failed" and "t_end" in df.loc[0, "error"]
    with pytest.raises(ValueError, match="executor"):
        ukflex.sweep(build, GRID, outputs, "threads")


def test_blas_threads_limited_in_each_case():
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def probe(res):
        blas = [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]
        return {"max_blas_threads": max(blas) if blas else 1}

    df = ukflex.sweep(lambda x: ukflex.scenes.pendulum(), [{"x": 0}], probe, t_end=0.05, method="DOPRI5")
    assert df.loc[0, "max_blas_threads"] == 1


def test_study_tiny():
    from studies.sweeps import crank_study

    df = crank_study(omegas=[60.0, 120.0], diameters=[0.005, 0.008], executor="serial")
    assert (df["status"] == "ok").all()
    # a faster crank bends the coupler more (inertia loads grow like omega^2)
    for d in (0.005, 0.008):
        sub = df[df["diameter"] == d].sort_values("omega")
        assert sub["peak_deflection"].iloc[1] > 2 * sub["peak_deflection"].iloc[0]
        assert sub["max_axial_force"].iloc[1] > sub["max_axial_force"].iloc[0]
    assert all(math.isfinite(v) for v in df["peak_deflection"])


def test_progress_bar_on_request(capsys):
    pytest.importorskip("tqdm")
    ukflex.sweep(lambda x: ukflex.scenes.pendulum(), [{"x": 0}, {"x": 1}], lambda r: {}, t_end=0.01,
                 method="DOPRI5", progress=True)
    err = capsys.readouterr().err
    assert "sweep (serial)" in err and "2/2" in err
    ukflex.sweep(lambda x: ukflex.scenes.pendulum(), [{"x": 0}], lambda r: {}, t_end=0.01, method="DOPRI5")
    assert "sweep" not in capsys.readouterr().err  # not a terminal: quiet by default
