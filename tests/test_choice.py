"""method="auto" (ukflex.choice): the integrator is picked from the constrained system's natural
frequencies, the choice and its reason are in the result, and the user's settings win."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import scenes, simulate
from ukflex.run import choice
from ukflex.run.choice import DOPRI5_RTOL_PER_RTOL, choose_method, elastic_shares


def test_rigid_scenes_go_explicit():
    res = simulate(scenes.pendulum(), 1.0)
    assert res.method == "DOPRI5" and res.success
    assert "no elastic mode" in res.extra["auto"]["reason"]
    res = simulate(scenes.four_bar(), 0.5)  # driven: no degree of freedom
    assert res.method == "DOPRI5" and "no degrees of freedom" in res.extra["auto"]["reason"]


def test_the_paper_scene_is_stiff_and_gets_radau_with_a_step_from_its_frequencies():
    sys_ = scenes.slider_crank().build()
    w = sys_.frequencies()
    c = choose_method(sys_, 0.0, 0.1, 1e-6)
    assert c.method == "RADAU5M"
    assert c.omega_elastic == pytest.approx(w[0]) and c.omega_max == pytest.approx(w[-1])
    # the amplitude budget 20 rtol over the run: y = (phi / (RADAU_DECAY omega_1 T))^(1/5) (0.28 here)
    y = (20 * 1e-6 / (choice.RADAU_DECAY * w[0] * 0.1)) ** 0.2
    assert y < choice.RADAU_MAX_STEP_OMEGA and c.step == pytest.approx(y / w[0])
    # the step follows rtol: tighter, shorter; looser, up to the cap of 1 rad per step
    tight = choose_method(sys_, 0.0, 0.1, 1e-10)
    assert tight.step == pytest.approx((20 * 1e-10 / (choice.RADAU_DECAY * w[0] * 0.1)) ** 0.2 / w[0])
    assert tight.step < c.step and tight.method == "RADAU5M"
    loose = choose_method(sys_, 0.0, 0.1, 1e-3)
    assert loose.step == pytest.approx(choice.RADAU_MAX_STEP_OMEGA / w[0]) and loose.step > c.step
    assert c.step * c.omega_max > choice.EXPLICIT_STEP_OMEGA * choice.RADAU_COST_RATIO
    res = simulate(sys_, 0.1)
    assert res.method == "RADAU5M" and res.success
    assert res.extra["auto"]["step"] == pytest.approx(c.step) and "stiff" in res.extra["auto"]["reason"]
    assert res.extra["naccept"] == math.ceil(0.1 / c.step)
    assert res.max_residual("position") < 1e-9


def test_a_lone_spring_mode_goes_explicit():
    """A slider on a spring (one elastic mode, 10 rad/s): the step that resolves it resolves the
    fastest mode too (h omega_max = 0.3 < 0.8): not stiff, DOPRI5."""
    s = ukflex.Scene(gravity=None)
    slider = s.rigid_body("slider", mass=1.0, inertia=0.01, position=(1.0, 0.0))
    s.prismatic(slider.frame(), s.ground.line((0, 0), angle=0.0), name="slide")
    s.spring_damper(slider.point(0, 0), s.ground.point(0.0, 0.0), stiffness=100.0, rest_length=0.9, name="spring")
    c = choose_method(s.build(), 0.0, 1.0, 1e-6)
    assert c.method == "DOPRI5" and "not stiff" in c.reason, c
    assert c.omega_elastic == pytest.approx(10.0, rel=1e-6)


def test_a_pendulum_swing_is_not_elastic_but_a_bending_mode_is():
    pend = scenes.pendulum(angle=-math.pi / 2).build()
    w, V = pend.frequencies(modes=True)
    assert elastic_shares(pend, w, V, pend.q0)[0] < 0.01
    cant = scenes.cantilever(elements=2, strain="linear").build()
    w, V = cant.frequencies(modes=True)
    assert np.all(elastic_shares(cant, w, V, cant.q0) > 0.99)


def test_every_flexible_body_keeps_its_first_mode_resolved():
    """every_joint has a soft spring mode (~10 rad/s) and two beams (~500-1000 rad/s): the step
    resolves the beams' first modes, not only the spring's."""
    c = choose_method(scenes.every_joint().build(), 0.0, 0.3, 1e-6)
    assert c.method == "RADAU5M" and c.omega_elastic > 400.0


def test_auto_gives_the_physical_answer_on_the_nonlinear_coupler():
    """Default settings on the physically right model (nonlinear FFRF, N = 4, E-B): the peak
    midpoint deflection within 0.1 % of Exudyn's converged ANCF peak 9.8036e-3 Lb
    (benches/data/exudyn_ref_ancf.csv; measured 0.003 %; docs/integrators.md has the timing
    side by side)."""
    sc = scenes.slider_crank(strain="nonlinear", theory="euler-bernoulli", elements=4)
    t = np.linspace(0.0, 0.07, 7001)
    res = simulate(sc, 0.07, t_eval=t)
    assert res.method == "RADAU5M"
    _, v = res.beam_displacement("coupler", 0.5)
    peak = np.abs(v).max() / scenes.PAPER["coupler_length"]
    assert peak == pytest.approx(9.8036e-3, rel=1e-3)


def test_user_settings_win_and_scipy_options_map_to_scipy():
    sys_ = scenes.slider_crank().build()
    res = simulate(sys_, 0.01, step=5e-5)
    assert res.method == "RADAU5M" and res.extra["naccept"] == 200
    res = simulate(sys_, 0.01, rho_inf=0.8)  # GENALPHA's own option
    assert res.method == "GENALPHA" and "GENALPHA because" in res.extra["auto"]["reason"]
    res = simulate(sys_, 0.01, jac=sys_.jac)  # a scipy-only option: scipy Radau for a stiff scene
    assert res.method == "Radau" and "scipy" in res.extra["auto"]["reason"]
    assert res.rtol == 1e-6
    res = simulate(sys_, 0.01, formulation="uk-numpy")
    assert res.method == "Radau"
    res = simulate(scenes.pendulum(), 0.1, step=1e-3)  # a fixed step on a scene auto runs with DOPRI5
    assert res.method == "RADAU5M" and res.extra["naccept"] == 100 and res.rtol == 1e-6  # not DOPRI5's rtol


def test_auto_on_the_papers_linear_scene_against_a_tight_explicit_run():
    """The paper's own scene (linear FFRF, N = 1, 0..0.07 s, RADAU5M h = 3.1e-4): the peak
    within 0.1 % of DOP853 at rtol 1e-9 (measured 0.001 %); the history within 0.3 % of the peak
    (measured 0.08 %; GENALPHA, the former default, was 2.1 % off): Radau IIA damps the 29 krad/s
    axial ripple that the undeformed start sets off instead of tracking its phase
    (docs/integrators.md)."""
    t = np.linspace(0.0, 0.07, 7001)
    sc = scenes.slider_crank()
    a = simulate(sc, 0.07, t_eval=t)
    d = simulate(sc, 0.07, method="DOP853", rtol=1e-9, t_eval=t)
    _, va = a.beam_displacement("coupler", 0.5)
    _, vd = d.beam_displacement("coupler", 0.5)
    peak = np.abs(vd).max()
    assert a.method == "RADAU5M"
    assert abs(np.abs(va).max() - peak) < 1e-3 * peak
    assert np.abs(va - vd).max() < 3e-3 * peak


@pytest.mark.parametrize("kw,match", [(dict(t_end=0.0), "t_end"), (dict(t_end=float("nan")), "t_end"),
                                      (dict(rtol=0.0), "rtol"), (dict(rtol=float("inf")), "rtol")])
def test_bad_arguments_are_named(kw, match):
    args = dict(t0=0.0, t_end=0.1, rtol=1e-6)
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        choose_method(scenes.pendulum().build(), **args)


def test_the_looser_newton_test_of_genalpha_only_on_coarse_steps():
    """GENALPHA by hand with ``newton_local_error`` (Newton stops at a fraction of the local
    error estimate): on a step fine against the fastest mode (ANCF coupler N = 4, h = 1.4e-6,
    h omega_max ~ 1.2) that test fed on its own error: the run drifts far off the strict one
    (measured 7.8 % of the deflection within 0.05 s), which ``choice.local_newton_ok`` says."""
    system = scenes.slider_crank(formulation="ancf", elements=4).build()
    h, t_end = 1.36e-6, 0.05
    omega_max = float(np.abs(system.frequencies()).max())
    assert not choice.local_newton_ok(h, omega_max) and choice.local_newton_ok(1.36e-4, omega_max)
    t = np.linspace(0.0, t_end, 501)
    strict = simulate(system, t_end, method="GENALPHA", step=h, rtol=1e-10, t_eval=t)
    loose = simulate(system, t_end, method="GENALPHA", step=h, rtol=1e-10, t_eval=t,
                     newton_local_error=choice.NEWTON_LOCAL_ERROR)
    v_strict = strict.beam_displacement("coupler", 0.5)[1]
    v_loose = loose.beam_displacement("coupler", 0.5)[1]
    assert np.max(np.abs(v_loose - v_strict)) > 2e-2 * np.max(np.abs(v_strict))


@pytest.mark.parametrize("make", [scenes.cantilever, scenes.spin_up, scenes.flexible_pendulum,
                                  lambda formulation: scenes.pinned_beam(formulation=formulation, elements=4, gravity=True)])
def test_an_ffrf_and_an_ancf_model_of_one_body_get_the_same_step(make):
    """Elastic and rigid modes are told apart by their material strain energy, so the FFRF and
    the ANCF models of one body get one rule: the same lowest elastic mode and step (an ANCF
    pendulum's swing was taken for its lowest elastic mode: a 0.05 s step against 0.0047 s for
    the FFRF beam)."""
    a = {f: simulate(make(formulation=f), 1e-2).extra["auto"] for f in ("ffrf", "ancf")}
    assert a["ffrf"]["omega_elastic"] == pytest.approx(a["ancf"]["omega_elastic"], rel=1e-2), a
    assert a["ffrf"]["step"] == pytest.approx(a["ancf"]["step"], rel=1e-2), a


def test_auto_states_its_floor_within_3x_of_the_error_it_reaches():
    """RADAU5M at auto's step damps the fast modes the start sets off; ``extra["auto"]["floor"]``
    states the error that leaves at a body point and it is what the run shows (against native
    DOPRI5 at rtol 1e-11, which keeps every mode; benches/auto_rtol.py): paper scene, nonlinear
    FFRF N = 4: 8.0e-6 m stated, 7.6e-6 m measured; the undamped cantilever 6.1e-5 / 5.8e-5;
    both flat in rtol below 1e-5 on the paper scene (the axial mode, 26.7 krad/s)."""
    from ukflex.run.choice import FLOOR_POINTS

    for make, T in ((lambda: scenes.slider_crank(strain="nonlinear", elements=4), 0.1), (scenes.cantilever, 0.8)):
        te = np.linspace(0.0, T, 401)
        ref = simulate(make().build(), T, method="DOPRI5", rtol=1e-11, atol=1e-14, t_eval=te)
        res = simulate(make().build(), T, t_eval=te)
        body = res.system.body_names[-1]
        err = max(np.hypot(*(np.vstack(res.beam_position(body, xi)) - np.vstack(ref.beam_position(body, xi)))).max()
                  for xi in FLOOR_POINTS)
        floor = res.extra["auto"]["floor"]
        assert err / 3 < floor < 3 * err, (floor, err)
        assert "whatever rtol" in res.extra["auto"]["reason"]


def test_a_spinning_cable_does_not_reject_most_of_its_steps():
    """Kane's spin-up with the ANCF cable: the stiff axial directions turn between the stages,
    and RADAU5M's Newton takes steps ~16 times shorter than auto's at full speed; a fixed step
    that Newton could not take is kept shorter, and a failed return doubles the wait
    (rejections: 686 of 6,179 attempts with a fixed wait of 8 steps, 50 of 6,709 now)."""
    res = simulate(scenes.spin_up(formulation="ancf"), 30.0)
    assert res.success and res.method == "RADAU5M"
    assert res.extra["nreject"] < 0.03 * res.extra["naccept"], res.extra


def _beam3_pendulum(elements=4):
    """A geometrically exact beam on a spherical joint, spun and falling: its elements, not its
    node bodies, are elastic (4 elements: 35 coordinates, the dense analysis; 10 elements: 77
    coordinates, the sparse analysis)."""
    s = ukflex.SpatialScene(gravity=(0, 0, -9.81))
    bar = s.beam("bar", (0, 0, 0), (0.5, 0, 0), ukflex.Rectangular(0.02, 0.02), elements=elements, density=7850,
                 youngs_modulus=2.1e9, poisson_ratio=0.3, angular_velocity=(0, 0, 3))
    s.spherical(s.ground.marker((0, 0, 0)), bar.node(0))
    return s


def _scenes_for_the_core_check():
    """Built-in scenes, ANCF and FFRF, spinning and falling beams, damped and overdamped ones:
    (label, system, t_end)."""
    from ukflex import spatial_scenes

    s = ukflex.Scene(gravity=None)  # a lone spring mode (DOPRI5)
    slider = s.rigid_body("slider", mass=1.0, inertia=0.01, position=(1.0, 0.0))
    s.prismatic(slider.frame(), s.ground.line((0, 0), angle=0.0), name="slide")
    s.spring_damper(slider.point(0, 0), s.ground.point(0.0, 0.0), stiffness=100.0, rest_length=0.9, name="spring")
    out = [("spring", s, 1.0), ("pendulum", scenes.pendulum(), 1.0), ("four_bar", scenes.four_bar(), 0.5),
           ("paper", scenes.slider_crank(), 0.1), ("paper NL N=4", scenes.slider_crank(strain="nonlinear", elements=4), 0.1),
           ("paper ANCF N=4", scenes.slider_crank(formulation="ancf", elements=4), 0.1),
           ("every_joint", scenes.every_joint(), 0.3),
           ("damped cantilever", scenes.cantilever(damping=1e-3), 0.8),
           ("flyball governor", spatial_scenes.flyball_governor(), 0.2),
           ("beam3 pendulum", _beam3_pendulum(), 0.3)]
    for f in ("ffrf", "ancf"):
        out += [(f"cantilever {f}", scenes.cantilever(formulation=f), 0.8),
                (f"spin_up {f}", scenes.spin_up(formulation=f), 2.0),
                (f"falling {f}", scenes.flexible_pendulum(formulation=f), 1.5),
                (f"pinned {f}", scenes.pinned_beam(formulation=f, elements=4, gravity=True), 0.1)]
    return [(label, sc.build() if isinstance(sc, ukflex.Scene) else ukflex.System(sc), t) for label, sc, t in out]


def test_the_cores_decision_is_the_former_python_ones():
    """auto's analysis moved into the core (rust/integrate/choice/): on every kind of scene its
    decision (method, step, Newton tolerance, frequencies, floor and its modes, reason) is the
    one the former Python analysis (tests/_auto_reference.py, kept only here) gave, to the
    round-off of two eigensolvers."""
    import re
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import _auto_reference as former

    numbers = re.compile(r"[-+]?\d+(\.\d+)?(e[-+]?\d+)?")
    methods = set()
    for label, system, t_end in _scenes_for_the_core_check():
        for rtol in (1e-3, 1e-6, 1e-9):
            new, old = choose_method(system, 0.0, t_end, rtol), former.choose_method(system, 0.0, t_end, rtol)
            methods.add((new.method, new.step is not None))
            where = (label, rtol, new, old)
            assert new.method == old.method and new.options.keys() == old.options.keys(), where
            reason, keys = new.reason, ("step", "omega_elastic", "omega_max", "rtol")
            if new.method == "DOPRI5":
                # new in the core (not a former decision): DOPRI5 runs at DOPRI5_RTOL_PER_RTOL rtol
                assert old.rtol is None and new.rtol == pytest.approx(DOPRI5_RTOL_PER_RTOL * rtol, rel=1e-12), where
                reason, tight = reason.split("; DOPRI5 at rtol ")
                assert tight.startswith(f"{new.rtol:.3g} "), where
                keys = keys[:3]
            if label.startswith("beam3"):
                # the former analysis moved each node body of a geometrically exact beam alone and
                # read no node: its floor was 0 (not stated); the core's sees the node chain
                # (test_auto_states_a_beam3_floor_within_3x_of_the_error_it_reaches)
                reason, said = reason.split("; the fast modes the start sets off")
                assert old.floor == 0.0 and new.floor > 0.0 and "whatever rtol" in said, where
            assert numbers.sub("#", reason) == numbers.sub("#", old.reason), where
            for key in keys:
                a, b = getattr(new, key), getattr(old, key)
                assert (a is None) == (b is None) and (a is None or a == pytest.approx(b, rel=1e-6)), (key, where)
            assert (new.floor is None) == (old.floor is None), where
            if old.floor is not None and not label.startswith("beam3"):
                assert new.floor == pytest.approx(old.floor, rel=1e-3, abs=1e-15), where
                assert len(new.floor_modes) == len(old.floor_modes), where
                for a, b in zip(new.floor_modes, old.floor_modes):
                    assert a == pytest.approx(b, rel=1e-3), where
    # every branch of the rule was taken: DOPRI5, fixed-step and adaptive RADAU5M
    assert methods >= {("DOPRI5", False), ("RADAU5M", True), ("RADAU5M", False)}, methods


def test_auto_states_a_beam3_floor_within_3x_of_the_error_it_reaches():
    """A geometrically exact beam's rigid motion is its node chain's as one body, and its floor is
    read at the nodes (rust/integrate/choice/chains.rs): the spun falling pendulum on 4 elements
    states 2.7e-6 m, its nodes are 4.6e-6 m off DOPRI5 at rtol 1e-10 (benches/beam3_floor.py;
    10 elements: 3.3e-6 / 1.9e-6). Before, moving each node alone rigidified nothing: floor 0.
    A large system (77 coordinates, the sparse analysis) states the dense analysis' floor."""
    te = np.linspace(0.0, 0.3, 601)
    runs = [simulate(ukflex.System(_beam3_pendulum()), 0.3, t_eval=te, **kw)
            for kw in ({}, dict(method="DOPRI5", rtol=1e-10, atol=1e-12))]
    nodes = [np.stack([np.asarray(r.q)[7 * i:7 * i + 3] for i in range(5)]) for r in runs]
    err = np.linalg.norm(nodes[0] - nodes[1], axis=1).max()
    floor = runs[0].extra["auto"]["floor"]
    assert err / 3 < floor < 3 * err, (floor, err)
    assert "whatever rtol" in runs[0].extra["auto"]["reason"]

    system = ukflex.System(_beam3_pendulum(elements=10))
    assert system.n_coords >= system.SPARSE_MODES_MIN
    sparse = choose_method(system, 0.0, 0.3, 1e-6)
    dense = system.core.auto_choice(0.0, system.q0, system.qd0, 0.3, 1e-6)
    assert sparse.floor == pytest.approx(dense["floor"], rel=1e-6) and sparse.floor > 1e-6, (sparse, dense["floor"])


def test_the_floor_is_stated_when_read_and_is_the_choosers():
    """``simulate`` leaves auto's floor (which decides nothing) to the reader: ``extra["auto"]``
    computes ``floor``, ``floor_modes`` and the reason's floor clause on their first read, the
    same as ``choose_method``'s, through every way of reading the dict; a scipy mapping's own
    clause stays after it."""
    import copy
    import json
    import pickle

    system = scenes.pinned_beam(elements=4, formulation="ancf", gravity=True).build()
    full = choose_method(system, 0.0, 0.02, 1e-6)
    bare = choose_method(system, 0.0, 0.02, 1e-6, floor=False)
    assert full.floor > 0.0 and bare.floor is None and "whatever rtol" not in bare.reason
    assert (bare.method, bare.step, bare.omega_elastic, bare.omega_max) == (full.method, full.step, full.omega_elastic,
                                                                             full.omega_max)
    want = dict(full.as_dict(), time=0.0)
    for read in (lambda d: d["floor"], lambda d: d.get("reason"), dict, lambda d: json.loads(json.dumps(d)),
                 lambda d: pickle.loads(pickle.dumps(d)), copy.deepcopy, lambda d: dict(d.items()), repr,
                 lambda d: d == want):
        auto = simulate(system, 0.02).extra["auto"]
        assert isinstance(auto, choice.AutoReport) and dict.__getitem__(auto, "floor") is None
        read(auto)
        auto["time"] = 0.0
        assert dict(auto) == want and dict.__getitem__(auto, "floor") == full.floor
    auto = simulate(system, 0.02, jac=system.jac, max_steps=3).extra["auto"]  # scipy's Radau
    assert auto["reason"] == full.reason + auto["reason"][len(full.reason):] and "; scipy Radau" in auto["reason"]
    assert auto["floor"] == full.floor and auto["floor_modes"] == full.floor_modes
    # a large system: the sparse analysis' modes, and the floor's dense spectrum when read
    system = ukflex.System(_beam3_pendulum(elements=10))
    auto = simulate(system, 0.3).extra["auto"]
    assert dict.__getitem__(auto, "floor") is None
    full = choose_method(system, 0.0, 0.3, 1e-6)
    assert auto["floor"] == full.floor > 0.0 and auto["reason"] == full.reason
