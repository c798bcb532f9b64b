"""Every stage at scale (docs/scale.md, "Every stage"): the sparse Newton matrices of the
implicit methods through the public API, the sparse modal analysis against the dense one,
method="auto" on both paths, the initial-state correction of a long cable, the memory limit
on every dense n x n array and the wall-time budgets of build and simulate."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import Scene, scenes
from ukflex.run.choice import choose_method
from ukflex.model.scene import Circular


def wire(elements, angle=0.0):
    """A steel wire (1 m, d = 2 mm) of ANCF elements pinned at one end, at rest at ``angle``
    (0: horizontal)."""
    s = Scene(gravity=(0.0, -9.81))
    b = s.cable("wire", length=1.0, elements=elements, section=Circular(0.002),
               density=7850.0, youngs_modulus=2.1e11, angle=angle)
    s.revolute(s.ground.point(0.0, 0.0), b.at(0.0), name="pin")
    return s


@pytest.mark.parametrize("method", ["RADAU5M", "GENALPHA"])
def test_sparse_newton_runs_agree_with_dense_ones_through_the_api(method):
    s = wire(24).build()
    n = s.n_coords
    runs = {ls: s.integrate(0.0, s.y0, 2e-3, method=method, step=1e-4, linear_solver=ls) for ls in ("dense", "sparse")}
    yd, ys = np.asarray(runs["dense"]["y"]), np.asarray(runs["sparse"]["y"])
    assert runs["dense"]["status"] == runs["sparse"]["status"] == 0
    assert runs["dense"]["naccept"] == runs["sparse"]["naccept"]
    assert np.max(np.abs(ys[:n] - yd[:n])) <= 1e-13 * np.max(np.abs(yd[:n]))
    # the velocities carry the cable's axial vibration: rounding shows there as much as one ulp
    # of the initial state does (the run's own sensitivity)
    y0u = s.y0.copy()
    y0u[y0u != 0] = np.nextafter(y0u[y0u != 0], np.inf)
    yu = np.asarray(s.integrate(0.0, y0u, 2e-3, method=method, step=1e-4, linear_solver="dense")["y"])
    assert np.max(np.abs(ys[n:] - yd[n:])) <= 5 * np.max(np.abs(yu[n:] - yd[n:]))
    with pytest.raises(ValueError, match="linear_solver"):
        s.integrate(0.0, s.y0, 1e-3, method=method, step=1e-4, linear_solver="banded")
    # simulate passes it through
    res = ukflex.simulate(s, 1e-3, method=method, step=1e-4, linear_solver="sparse")
    assert res.status == 0


def test_the_sparse_newton_path_fits_where_the_dense_one_is_refused():
    s = wire(256).build(memory_limit=4e6)  # n = 1028: the dense Newton matrices need ~50 MB
    with pytest.raises(ukflex.MemoryLimitError, match="linear_solver='sparse'"):
        s.integrate(0.0, s.y0, 1e-3, method="RADAU5M", step=1e-4, linear_solver="dense")
    out = s.integrate(0.0, s.y0, 1e-3, method="RADAU5M", step=1e-4)
    assert out["status"] == 0


def _dense_reference(system):
    """The same system with the sparse modal analysis switched off (its class threshold)."""
    system.SPARSE_MODES_MIN = 10**9  # instance attribute: only this System
    return system


@pytest.mark.parametrize("make", [lambda: scenes.chain(links=40, angle=-0.3), lambda: wire(20),
                                  lambda: scenes.slider_crank(elements=24, formulation="ancf")])
def test_sparse_modes_are_the_dense_modes(make):
    sp = make().build()
    de = _dense_reference(make().build())
    assert sp.n_coords >= sp.SPARSE_MODES_MIN
    k = 6
    w_s, V_s = sp.frequencies(modes=True, count=k)
    w_d, V_d = de.frequencies(modes=True, count=k)
    scale = np.max(np.abs(w_d))
    keep = np.abs(w_d) > 1e-3 * scale  # modes near zero are rounding in both
    assert np.allclose(w_s[keep], w_d[keep], rtol=1e-6, atol=0.0), (w_s, w_d)
    M = np.asarray(de.M(de.q0))
    assert np.allclose(V_s.T @ M @ V_s, np.eye(k), atol=1e-8)  # mass-normalized
    A = np.asarray(de.A(de.q0))
    assert np.max(np.abs(A @ V_s)) <= 1e-8 * np.max(np.abs(A)) * np.max(np.abs(V_s))  # constrained
    for j in np.flatnonzero(keep):  # the same shapes (distinct frequencies here)
        assert abs(abs(V_s[:, j] @ M @ V_d[:, j]) - 1.0) < 1e-6
    # the fastest mode
    w_max = np.max(np.abs(de.frequencies()))
    assert abs(sp.max_frequency() - w_max) <= 1e-3 * w_max
    assert sp.max_frequency() <= w_max * (1 + 1e-9)  # Lanczos: from below


def test_auto_chooses_the_same_on_the_sparse_and_dense_modal_analysis():
    # the wire's swing at its undeformed start (no tension yet) is a mode near zero whose elastic
    # share is rounding on either path: its step is the run's span / 20 on both
    for make, t_end in [(lambda: wire(20), 0.05), (lambda: scenes.slider_crank(elements=24, formulation="ancf"), 0.02),
                        (lambda: scenes.chain(links=30, angle=-0.3), 1.0)]:
        sp, de = make().build(), _dense_reference(make().build())
        cs, cd = choose_method(sp, 0.0, t_end, 1e-6), choose_method(de, 0.0, t_end, 1e-6)
        assert cs.method == cd.method
        assert cs.step == pytest.approx(cd.step, rel=1e-6) if cd.step else cs.step is None
        assert cs.omega_max == pytest.approx(cd.omega_max, rel=1e-3)
        if cd.omega_elastic is not None and cd.omega_elastic > 1e-6 * cd.omega_max:
            assert cs.omega_elastic == pytest.approx(cd.omega_elastic, rel=1e-6)


def test_mass_matrix_of_a_large_system_is_refused_dense_and_given_sparse():
    s = Scene(gravity=None)
    for i in range(20000):
        s.point_mass(f"p{i}", mass=1.0 + i % 3, position=(0.1 * i, 0.0))
    system = s.build()
    with pytest.raises(ukflex.MemoryLimitError, match="M_sparse"):
        system.M(system.q0)  # 40,000 x 40,000: 12.8 GB
    Ms = system.M_sparse()
    assert Ms.shape == (40000, 40000) and Ms.nnz == 40000
    assert Ms.diagonal()[:6].tolist() == [1.0, 1.0, 2.0, 2.0, 3.0, 3.0]


def test_dense_square_arrays_are_checked_against_the_memory_limit():
    s = wire(300).build(memory_limit=5e6)  # n = 1204: an n x n array is 11.6 MB
    with pytest.raises(ukflex.MemoryLimitError):
        s.M(s.q0)
    with pytest.raises(ukflex.MemoryLimitError):
        s.tangent_stiffness("wire", s.q0)
    with pytest.raises(ukflex.MemoryLimitError):
        s.beam_matrices("wire")
    with pytest.raises(ukflex.MemoryLimitError, match="count"):
        s.frequencies()  # every mode of a system this large is dense work
    assert s.frequencies(count=3).shape == (3,)  # the lowest ones are not


def _inconsistent_cable_crank(elements):
    """The ANCF slider-crank with its crank turned 0.05 rad off the coupler's start: the build
    must correct the positions (the coupler follows the crank tip)."""
    d = scenes.slider_crank(elements=elements, formulation="ancf").to_dict()
    for b in d["bodies"]:
        if b["name"] == "crank":
            b["angle"] = 0.05
    return d


def test_correction_of_a_long_cable_stays_within_a_small_memory_limit():
    d = _inconsistent_cable_crank(4096)  # n = 16,391
    system = ukflex.System(d, memory_limit=64e6)  # its dense mass block alone would be 2.1 GB
    c = system.initial_correction
    assert c.iterations >= 1 and c.position_residual_after <= 1e-12
    assert np.max(np.abs(system.phi(0.0, system.q0))) <= 1e-12


def test_build_wall_time_budget_names_the_correction():
    d = _inconsistent_cable_crank(64)
    with pytest.raises(ukflex.BudgetError, match="initial-state correction"):
        ukflex.System(d, max_wall_time=1e-9)
    assert issubclass(ukflex.BudgetError, ukflex.SolverError)
    ok = ukflex.System(d, max_wall_time=60.0)
    assert ok.initial_correction.position_residual_after <= 1e-12


def test_a_budget_spent_in_autos_analysis_gives_status_minus_one_naming_it():
    s = wire(64).build()
    res = ukflex.simulate(s, 0.05, max_wall_time=1e-6)
    assert res.status == -1
    assert res.stop["cause"] == "max_wall_time"
    assert "method='auto'" in res.stop["stage"] and "method='auto'" in res.message
    assert res.t.size == 1 and np.array_equal(res.q[:, 0], s.q0)
    # with time to spare the same call runs to the end
    assert ukflex.simulate(s, 2e-3, max_wall_time=60.0).status == 0


def test_a_scene_given_to_simulate_is_built_within_the_budget():
    with pytest.raises(ukflex.BudgetError, match="initial-state correction"):
        ukflex.simulate(_inconsistent_cable_crank(64), 1e-3, max_wall_time=1e-9)


@pytest.mark.parametrize("make", [lambda: scenes.cantilever(elements=40, tip_force=(0.0, -2.0), strain="linear"),
                                  lambda: scenes.chain(links=30, angle=-0.5),
                                  lambda: scenes.pinned_beam(elements=40, gravity=True)])
def test_sparse_equilibrium_is_the_dense_one(make):
    sp, de = make().build(), _dense_reference(make().build())
    assert sp.n_coords >= sp.SPARSE_MODES_MIN
    a, b = sp.equilibrium(), de.equilibrium()
    assert np.max(np.abs(a.q - b.q)) <= 1e-8 * max(1.0, np.max(np.abs(b.q)))
    assert np.allclose(a.multipliers, b.multipliers, rtol=1e-6, atol=1e-8 * np.max(np.abs(b.multipliers)))
    assert a.position_residual <= 1e-10 and a.force_residual <= 1e-8 * max(1.0, np.max(np.abs(b.multipliers)))


@pytest.mark.parametrize("method", ["GENALPHA", "RADAU5M"])
def test_redundant_rows_on_the_sparse_newton_path(method):
    """The parallel-crank lattice (W - 1 redundant rows a level): the singular saddle point is
    regularized on the multiplier block as on the dense path, with the same answer."""
    s = scenes.lattice(columns=4, rows=3, beams="continuous").build()
    assert s.core.rank_info(0.0, s.q0, s.qd0)["rank"] < s.n_constraints
    out = {ls: s.integrate(0.0, s.y0, 0.05, method=method, step=1e-3, linear_solver=ls) for ls in ("dense", "sparse")}
    assert out["dense"]["status"] == out["sparse"]["status"] == 0
    yd, ys = np.asarray(out["dense"]["y"]), np.asarray(out["sparse"]["y"])
    assert np.max(np.abs(ys - yd)) <= 1e-12 * np.max(np.abs(yd))
    # the constraints hold (the projection after every step)
    assert np.max(np.abs(s.phi(0.05, ys[: s.n_coords, -1]))) <= 1e-10


def test_the_sparse_lu_with_kept_pivots_is_radau5ms_only():
    """The continuous-beam lattice 8 x 2 (132 unknowns, a wide band, little fill): RADAU5M's
    default takes the sparse LU with kept pivots (another pivot order: not the dense run to the
    bit, but its answer), RADAU5's keeps the dense LU (`STATIC_LU_METHODS`: measured slower)."""
    t = np.linspace(0.0, 0.02, 5)
    run = {(m, ls): ukflex.simulate(scenes.lattice(8, 2, beams="continuous").build(), 0.02, method=m,
                                    linear_solver=ls, t_eval=t).q
           for m in ("RADAU5M", "RADAU5") for ls in ("dense", "auto")}
    assert np.array_equal(run["RADAU5", "auto"], run["RADAU5", "dense"])
    d = np.max(np.abs(run["RADAU5M", "auto"] - run["RADAU5M", "dense"]))
    assert 0.0 < d <= 1e-10


def test_a_budget_spent_before_a_native_runs_first_step_names_it():
    s = wire(64).build()
    res = ukflex.simulate(s, 0.05, method="RADAU5M", step=1e-4, max_wall_time=1e-9)
    assert res.status == -1 and res.stop["cause"] == "max_wall_time"
    assert "before its first step" in res.stop["stage"] and "RADAU5M" in res.message
    assert res.t.size == 1
