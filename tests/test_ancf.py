"""The ANCF cable (``Scene.cable(...)``, rust/body/ancf_cable.rs).

* Rust against the independent NumPy reference (python/ukflex/reference/ancf.py): mass matrix,
  generalized forces (gravity, elastic, damping), tangent stiffness, energies, and the constraint
  terms of joints on cable markers, to 1e-12;
* the analytic tangent stiffness against central differences of the core's forces;
* statics (Newton on the welded cantilever): a small tip load against the Euler-Bernoulli
  formulas, and a tip moment that rolls the beam into a half circle (the exact elastica) with
  fourth-order element convergence that does not depend on the slenderness (no membrane locking);
* dynamics: an undamped free pendulum-beam conserves T + V (native DOPRI5), the ANCF slider-crank
  runs with small residuals and matches the NumPy reference (uk-numpy) on the same description;
* the chord-frame displacement of an ANCF beam equals the FFRF pinned-pinned frame's;
* bad input: named errors.
"""

import math

import numpy as np
import pytest

import ukflex
from ukflex import Circular, InvalidSceneError, Scene, scenes
from ukflex.results import outputs
from ukflex.reference import ReferenceModel
from ukflex.reference import ancf as ref

STEEL = dict(density=7800.0, youngs_modulus=2.1e11)


def _rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def _cable_scene(elements=3, damping=2e-4, gravity=(0.3, -9.81), angle=0.6):
    s = Scene(gravity=gravity)
    s.cable("c", length=0.4, elements=elements, section=Circular(0.008), damping=damping,
           position=(0.1, -0.2), angle=angle, velocity=(0.5, 0.2), angular_velocity=2.0, **STEEL)
    return s


def _deformed(system, rng, amp=5e-3):
    """The guess moved and deformed: positions by ``amp``, slopes by ``10 amp``."""
    q = system.q_guess.copy()
    slope = (np.arange(q.size) % 4) >= 2
    q += np.where(slope, 10 * amp, amp) * rng.standard_normal(q.size)
    return q, rng.standard_normal(q.size)


# ------------------------------------------------------------------ Rust against the NumPy reference
def test_mass_forces_energies_and_tangent_match_the_numpy_reference():
    scene = _cable_scene()
    system = scene.build(correct=False)
    model = ReferenceModel(system.description)
    rng = np.random.default_rng(1)
    l, EA, EI = 0.4 / 3, 2.1e11 * math.pi * 0.008**2 / 4, 2.1e11 * math.pi * 0.008**4 / 64
    errs = {}
    for _ in range(4):
        q, qd = _deformed(system, rng)
        errs["M"] = max(errs.get("M", 0), _rel(system.M(q), model.M(q)))
        errs["Q"] = max(errs.get("Q", 0), _rel(system.Q(0.0, q, qd), model.Q(0.0, q, qd)))
        errs["T"] = max(errs.get("T", 0), abs(system.kinetic_energy(q, qd) / model.kinetic_energy(q, qd) - 1))
        errs["V"] = max(errs.get("V", 0), abs(system.potential_energy(q) / model.potential_energy(q) - 1))
        K = np.zeros((q.size, q.size))
        for k in range(3):
            K[4 * k:4 * k + 8, 4 * k:4 * k + 8] += ref.element_tangent_stiffness(q[4 * k:4 * k + 8], l, EA, EI)
        errs["K_t"] = max(errs.get("K_t", 0), _rel(system.tangent_stiffness("c", q), K))
    assert max(errs.values()) <= 1e-12, errs


def test_joint_terms_on_cable_markers_match_the_numpy_reference():
    """Every joint kind the reference knows (revolute, weld, prismatic, point-on-line, angle
    driver) on cable markers, including the angle rows' velocity term h_phi."""
    s = Scene(gravity=(0.0, -9.81))
    a = s.cable("a", length=0.3, elements=2, section=Circular(0.01), angle=0.3, **STEEL)
    b = s.cable("b", length=0.25, elements=3, section=Circular(0.006), position=(0.3, 0.1),
               angle=2.0, **STEEL)
    r = s.rigid_body("r", mass=0.2, inertia=1e-3, position=(0.1, 0.3))
    s.revolute(s.ground.point(0, 0), a.at(0.0))
    s.weld(a.at(0.7, angle=0.2), b.at(0.1))
    s.prismatic(r.frame(), b.at(0.5, angle=-0.3))
    s.point_on_line(b.at(1.0), a.line(0.4, angle=0.5))
    s.angle_driver(a.at(1.0), ukflex.Harmonic(amplitude=0.2, frequency=3.0), b=b.at(0.9))
    system = s.build(correct=False)
    model = ReferenceModel(system.description)
    rng = np.random.default_rng(2)
    for _ in range(3):
        q, qd = _deformed(system, rng)
        t = 0.13
        assert _rel(system.phi(t, q), model.phi(t, q)) <= 1e-12
        assert _rel(system.A(q), model.A(q)) <= 1e-12
        assert _rel(system.b(t, q, qd), model.b(t, q, qd)) <= 1e-12
        assert _rel(system.Q(t, q, qd), model.Q(t, q, qd)) <= 1e-12


def test_tangent_stiffness_matches_central_differences_of_the_core_forces():
    system = _cable_scene(elements=4, damping=0.0, gravity=None).build(correct=False)
    rng = np.random.default_rng(3)
    q, _ = _deformed(system, rng, amp=2e-2)
    zero = np.zeros_like(q)
    K = system.tangent_stiffness("c", q)
    K_fd = np.empty_like(K)
    for j in range(q.size):
        h = 1e-6 * (1 + abs(q[j]))
        e = np.zeros_like(q)
        e[j] = h
        K_fd[:, j] = -(system.Q(0.0, q + e, zero) - system.Q(0.0, q - e, zero)) / (2 * h)
    assert _rel(K, K_fd) <= 1e-6
    assert np.allclose(K, K.T, rtol=0, atol=1e-12 * np.abs(K).max())


# ------------------------------------------------------------------ statics
def _cantilever(elements, diameter=0.00635, length=0.3048):
    """A horizontal ANCF cantilever welded to the ground at xi = 0 (no gravity)."""
    s = Scene()
    b = s.cable("b", length=length, elements=elements, section=Circular(diameter), density=7834.56,
               youngs_modulus=2.06843e11)
    s.weld(s.ground.frame(), b.at(0.0), name="clamp")
    return s, b


def _static(loaded, unloaded=None, steps=1, tol=1e-13):
    """Newton on ``Q(q) - A^T lambda = 0``, ``Phi = 0`` from the guess; with ``unloaded`` (the
    same scene without its load) in ``steps`` load steps ``Q = Q_0 + s (Q_1 - Q_0)``. The
    Jacobian of the residual by central differences of the core's terms."""
    system = loaded
    q = system.q0.copy()
    n, m = system.n_coords, system.n_constraints
    zero = np.zeros(n)
    lam = np.zeros(m)

    def residual(q, lam, s):
        Q = system.Q(0.0, q, zero)
        if unloaded is not None:
            Q0 = unloaded.Q(0.0, q, zero)
            Q = Q0 + s * (Q - Q0)
        return Q - system.A(q).T @ lam

    for k in range(1, steps + 1):
        s = k / steps
        for _ in range(50):
            r = residual(q, lam, s)
            J = np.empty((n, n))
            for j in range(n):
                e = np.zeros(n)
                e[j] = 1e-7
                J[:, j] = (residual(q + e, lam, s) - residual(q - e, lam, s)) / 2e-7
            A = system.A(q)
            K = np.block([[-J, A.T], [A, np.zeros((m, m))]])
            step = np.linalg.solve(K, np.concatenate([r, -system.phi(0.0, q)]))
            q += step[:n]
            lam += step[n:]
            if np.max(np.abs(step[:n])) < tol:
                break
        else:
            raise AssertionError("static Newton did not converge")
    return q


def test_static_tip_load_matches_euler_bernoulli_for_every_mesh():
    """Tip load P with P L^3 / (3 E I) = 1e-4 L: deflection and rotation of small-deflection
    theory (cubic Hermite elements are exact for it; the nonlinearity is O(1e-8))."""
    for N in (1, 2, 4, 8):
        scene, beam = _cantilever(N)
        info = scene.build().body_info("b")
        L, EI = info["length"], info["youngs_modulus"] * info["second_moment"]
        P = 1e-4 * L * 3 * EI / L**3
        scene.point_force(beam.at(1.0), (0.0, -P), name="tip")
        system = scene.build()
        q = _static(system)
        x, y, u, v, psi = system.beam_point("b", 1.0, q)
        assert abs(-y / (P * L**3 / (3 * EI)) - 1) < 1e-6, (N, y)
        slope = np.asarray(system.beam_shape("b", 1.0)[1]) @ q
        assert abs(-math.atan2(slope[1], slope[0]) / (P * L**2 / (2 * EI)) - 1) < 1e-6, N
        _, ym, *_ = system.beam_point("b", 0.5, q)
        assert abs(-ym / (5 * P * L**3 / (48 * EI)) - 1) < 1e-6, N


def _half_circle_error(N, diameter):
    """Tip moment pi E I / L: the exact (inextensional, axial force free) elastica is a half
    circle with its tip at (0, 2 L / pi). Returns |tip - exact| / L."""
    scene, beam = _cantilever(N, diameter)
    unloaded = scene.build()
    info = unloaded.body_info("b")
    L, EI = info["length"], info["youngs_modulus"] * info["second_moment"]
    scene.torque(beam.at(1.0), math.pi * EI / L, name="moment")
    q = _static(scene.build(), unloaded, steps=10, tol=1e-12)
    x, y, *_ = unloaded.beam_point("b", 1.0, q)
    return math.hypot(x, y - 2 * L / math.pi) / L


def test_half_circle_converges_at_fourth_order_without_membrane_locking():
    thick = {N: _half_circle_error(N, 0.00635) for N in (2, 4, 8)}   # d / L = 0.021 (the coupler)
    thin = {N: _half_circle_error(N, 0.000635) for N in (2, 4)}      # d / L = 0.0021
    assert thick[8] < 3e-4, thick
    assert thick[2] / thick[4] > 10 and thick[4] / thick[8] > 13, thick   # ~h^4 (12.3, 15.3)
    # locking free: ten times thinner, the same error (Gauss 5/3 integration, Exudyn's default,
    # gives 4.6x / 21x larger errors for the thin beam at N = 2 / 4)
    for N in (2, 4):
        assert abs(thin[N] / thick[N] - 1) < 0.05, (N, thin, thick)


def _large_tip_load(N, diameter):
    """Tip (x, y) / L under the tip load P = 2 E I / L^2 (large deflection, axial force and
    bending together)."""
    scene, beam = _cantilever(N, diameter)
    unloaded = scene.build()
    info = unloaded.body_info("b")
    L, EI = info["length"], info["youngs_modulus"] * info["second_moment"]
    scene.point_force(beam.at(1.0), (0.0, -2.0 * EI / L**2), name="tip")
    q = _static(scene.build(), unloaded, steps=10, tol=1e-12)
    return np.asarray(unloaded.beam_point("b", 1.0, q)[:2]) / L


def test_large_tip_load_is_accurate_on_coarse_meshes_for_any_slenderness():
    """Membrane locking shows where axial force and bending act together: with the axial strain
    at Gauss points (3 or Exudyn's default 5) the N = 4 tip is 1.8e-3 / 2.5e-3 L off for the
    coupler's d / L = 0.021 and 6e-3 L (Gauss 5) for d / L = 0.0021; the Lobatto rule gives
    2.0e-4 L for both (docs/scene-format.md)."""
    for diameter in (0.00635, 0.000635):
        fine = _large_tip_load(16, diameter)
        err = {N: float(np.linalg.norm(_large_tip_load(N, diameter) - fine)) for N in (2, 4)}
        assert err[4] < 3e-4 and err[2] < 3e-3, (diameter, err)


# ------------------------------------------------------------------ dynamics
def test_free_pendulum_beam_conserves_energy_with_native_dopri5():
    s = Scene(gravity=(0.0, -9.81))
    rod = s.cable("rod", length=0.5, elements=6, section=Circular(0.01), density=1200.0, youngs_modulus=5e7)
    s.revolute(s.ground.point(0, 0), rod.at(0.0), name="pin")
    system = s.build()
    res = ukflex.simulate(system, 1.0, method="DOPRI5", rtol=1e-10, t_eval=np.linspace(0, 1, 201))
    assert res.success
    E = res.energy()
    T = np.array([system.kinetic_energy(q, qd) for q, qd in zip(res.q.T, res.qd.T)])
    assert np.max(np.abs(E - E[0])) / T.max() <= 1e-8
    # the beam swings through the bottom and bends visibly: elastic forces matter
    _, v = res.beam_displacement("rod", 0.5)
    assert T.max() > 0.1 and np.max(np.abs(v)) / 0.5 > 1e-2
    assert res.max_residual("position") < 1e-9


def test_ancf_slider_crank_runs_with_small_residuals_and_outputs():
    scene = scenes.slider_crank(formulation="ancf", elements=4)
    coupler = scene.to_dict()["bodies"][1]
    assert coupler["kind"] == "cable" and "theory" not in coupler
    system = scene.build()
    assert system.body_kind("coupler") == "cable" and system.n_coords == 3 + 4 * 5
    info = system.body_info("coupler")
    assert info["formulation"] == "ancf" and info["elements"] == 4 and info["length"] == pytest.approx(0.3048)
    res = ukflex.simulate(system, 0.01, method="DOPRI5", rtol=1e-9, t_eval=np.linspace(0, 0.01, 51))
    assert res.success
    assert res.max_residual("position") < 1e-10 and res.max_residual("velocity") < 1e-7
    u, v = res.beam_displacement("coupler", 0.5)
    assert abs(v[0]) < 1e-15 and 1e-3 < np.max(np.abs(v)) / 0.3048 < 2e-2
    assert outputs.beam_names(system) == ["coupler"]
    assert outputs.default_outputs(system) == ["v(coupler, 0.5)/L"]
    _, vl = outputs.evaluate(res, "v(coupler, 0.5)/L")
    assert np.array_equal(vl, v / 0.3048)
    _, x = outputs.evaluate(res, "x(coupler, 1.0)")
    assert np.allclose(x, res.q[system.coordinate_index("coupler.x4")], rtol=0, atol=1e-15)


def test_numpy_reference_integrates_the_same_ancf_slider_crank():
    system = scenes.slider_crank(formulation="ancf", elements=1).build()
    t = np.linspace(0, 4e-4, 5)
    native = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, t_eval=t)
    numpy = ukflex.simulate(system, t[-1], formulation="uk-numpy", method="RK45", rtol=1e-10, t_eval=t)
    assert numpy.success and native.success
    _, vn = native.beam_displacement("coupler", 0.5)
    _, vr = numpy.beam_displacement("coupler", 0.5)
    assert np.max(np.abs(vn - vr)) <= 1e-6 * np.max(np.abs(vn)) and np.max(np.abs(vn)) > 1e-6
    assert np.max(np.abs(native.q - numpy.q)) < 1e-9


def test_chord_frame_displacement_equals_the_ffrf_pinned_pinned_frame():
    """Same node positions: an ANCF beam's chord-frame (u, v) at the nodes equals an FFRF
    pinned-pinned beam's elastic displacement there (the frame through its end nodes)."""
    N, L = 4, 0.3048
    ffrf = scenes.slider_crank(theory="euler-bernoulli", elements=N).build(correct=False)
    ancf = scenes.slider_crank(formulation="ancf", elements=N).build(correct=False)
    rng = np.random.default_rng(5)
    qf = ffrf.q_guess.copy()
    qf[ffrf.body_slice("coupler")] += np.r_[0.01, -0.02, 0.4, 1e-3 * rng.standard_normal(3 * N)]
    qa = ancf.q_guess.copy()
    sl = ancf.body_slice("coupler")
    for j in range(N + 1):
        x, y, *_ = ffrf.beam_point("coupler", j / N, qf)
        qa[sl.start + 4 * j:sl.start + 4 * j + 2] = (x, y)
    for j in range(N + 1):
        pf, pa = ffrf.beam_point("coupler", j / N, qf), ancf.beam_point("coupler", j / N, qa)
        assert np.allclose(pa[:4], pf[:4], rtol=0, atol=1e-15), (j, pa, pf)
    # and the whole history form (nt, 5)
    assert ancf.beam_point("coupler", 0.5, np.column_stack([qa, qa])).shape == (5, 2)


def test_beam_shape_of_an_ancf_beam_maps_its_coordinates_to_position_and_slope():
    system = _cable_scene().build(correct=False)
    q, _ = _deformed(system, np.random.default_rng(6))
    for xi in (0.0, 0.37, 1.0):
        S, Sx = (np.asarray(a) for a in system.beam_shape("c", xi))
        assert S.shape == Sx.shape == (2, 16)
        x, y, *_ = system.beam_point("c", xi, q)
        assert np.allclose(S @ q, (x, y), rtol=0, atol=1e-15)
    S, Sx = (np.asarray(a) for a in system.beam_shape("c", 0.0))
    assert np.array_equal(Sx @ q, q[2:4])  # the slope of node 0


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize("field", [dict(theory="timoshenko"), dict(frame="clamped"), dict(rotary_inertia=True),
                                   dict(elastic=[0.0] * 8), dict(strain="linear"), dict(formulation="ancf")])
def test_a_cable_description_refuses_the_ffrf_beams_fields(field):
    item = dict(name="cable", kind="cable", length=0.3, elements=2, section=dict(shape="circular", diameter=0.01),
                **STEEL, **field)
    with pytest.raises(InvalidSceneError, match=next(iter(field))) as exc:
        Scene.from_dict({"bodies": [item]})
    assert "cable" in str(exc.value)


def test_scenes_refuse_a_theory_the_cable_does_not_have():
    with pytest.raises(InvalidSceneError, match="Euler-Bernoulli"):
        scenes.slider_crank(formulation="ancf", theory="timoshenko")
    with pytest.raises(InvalidSceneError, match="formulation"):
        scenes.slider_crank(formulation="ancff")


@pytest.mark.parametrize("change, message", [
    (dict(length=0.0), "length must be positive"),
    (dict(length=-1.0), "length must be positive"),
    (dict(density=0.0), "density must be positive"),
    (dict(youngs_modulus=-2e11), "youngs_modulus must be positive"),
    (dict(section=Circular(0.0)), "section diameter must be positive"),
    (dict(elements=0), "elements must be in 1..=4096"),
    (dict(elements=4097), "elements must be in 1..=4096"),
    (dict(density=float("nan")), "density must be finite"),
    (dict(damping=-1e-3), "damping must be >= 0"),
])
def test_bad_input_gives_named_errors(change, message):
    kw = dict(length=0.3, elements=2, section=Circular(0.01), **STEEL)
    kw.update(change)
    with pytest.raises(InvalidSceneError, match=message) as exc:
        Scene().cable("cable", **kw)
    assert "cable" in str(exc.value)


def test_ffrf_descriptions_are_unchanged_and_the_cable_is_its_own_kind():
    d = scenes.slider_crank().to_dict()["bodies"][1]
    assert "formulation" not in d and d["theory"] == "timoshenko"
    a = scenes.slider_crank(formulation="ancf").to_dict()["bodies"][1]
    assert a["kind"] == "cable" and "theory" not in a and "frame" not in a
    assert ukflex.System(scenes.slider_crank(formulation="ancf").to_dict()).body_kind("coupler") == "cable"
    assert ukflex.System(scenes.slider_crank().to_dict()).body_info("coupler")["formulation"] == "ffrf"


def test_animate_draws_an_ancf_beam_through_its_axis_points(tmp_path):
    from ukflex.results.animate import MechanismDrawer, snapshots

    system = scenes.slider_crank(formulation="ancf", elements=2).build()
    res = ukflex.simulate(system, 2e-3, method="DOPRI5", rtol=1e-8, t_eval=np.linspace(0, 2e-3, 5))
    q = res.q[:, -1]
    line = MechanismDrawer(system).body_polyline(q, "coupler")
    xi = np.linspace(0, 1, line.shape[0])
    want = np.array([system.beam_point("coupler", x, q)[:2] for x in xi])
    assert np.allclose(line, want, rtol=0, atol=1e-15)
    big = MechanismDrawer(system, deform_scale=50.0).body_polyline(q, "coupler")
    # magnified about the chord: the xi = 0 end stays, the xi = 1 end stays on the chord line
    c_big, c_true = big[-1] - big[0], want[-1] - want[0]
    assert np.allclose(big[0], want[0], rtol=0, atol=1e-15)
    assert abs(c_big[0] * c_true[1] - c_big[1] * c_true[0]) < 1e-15
    v_mid = system.beam_point("coupler", 0.5, q)[3]
    assert np.max(np.abs(big - want)) > 40 * abs(v_mid) > 0
    snapshots(res, str(tmp_path / "s.png"))
    assert (tmp_path / "s.png").stat().st_size > 0


def test_the_initial_correction_moves_a_cable_rigidly():
    """Holding the deformation (the default ``hold="elastic"``) moves an ANCF cable only
    rigidly: a four-bar whose flexible coupler is given no velocity starts it with the rigid
    motion the crank imposes, as the FFRF coupler does. The velocity projection in every nodal
    coordinate gave the cable's slopes rates of 86 1/s (a deformation rate) and a coupler
    deflection 20 times the FFRF one (peak 0.67 mm against 36 um); now the two agree within
    0.2 %. A crank 0.05 rad off is turned back without stretching the cable."""
    te = np.linspace(0.0, 0.2, 201)
    peaks = {}
    for f in ("ffrf", "ancf"):
        system = scenes.four_bar(theory="euler-bernoulli", elements=4, formulation=f).build()
        res = ukflex.simulate(system, 0.2, t_eval=te)
        assert res.success
        peaks[f] = np.abs(res.beam_displacement("coupler", 0.5)[1]).max()
        if f == "ancf":
            B, _ = system.core.rigid_motions(system.q0, system.qd0)
            sl = system.body_slice("coupler")
            B = np.asarray(B)[sl]
            B = B[:, np.abs(B).max(axis=0) > 0.0]  # the coupler's own rigid motions
            v = system.qd0[sl]
            rigid = B @ np.linalg.lstsq(B, v, rcond=None)[0]
            assert np.abs(v - rigid).max() < 1e-9 * np.abs(v).max()
    assert abs(peaks["ancf"] - peaks["ffrf"]) < 2e-3 * peaks["ffrf"], peaks
    d = scenes.slider_crank(elements=8, formulation="ancf").to_dict()
    d["bodies"][0]["angle"] = 0.05
    system = ukflex.System(d)
    assert system.initial_correction.position_residual_after < 1e-12
    p0, p1 = system.beam_point("coupler", 0.0, system.q0), system.beam_point("coupler", 1.0, system.q0)
    assert abs(math.hypot(p1[0] - p0[0], p1[1] - p0[1]) - scenes.PAPER["coupler_length"]) < 1e-12
    q = system.q0[system.body_slice("coupler")].reshape(-1, 4)  # nodes: x, y, x', y'
    assert np.abs(np.hypot(q[:, 2], q[:, 3]) - 1.0).max() < 1e-12  # unstretched slopes
    assert np.abs(np.diff(q[:, 0]) ** 2 + np.diff(q[:, 1]) ** 2 - (scenes.PAPER["coupler_length"] / 8) ** 2).max() < 1e-12
