"""The revolute joint with clearance (docs/loads.md, "Revolute joint with clearance"): the contact
law against the restitution it is built for, the energy balance with its dissipation, the
convergence of the slider-crank to the ideal joint as the clearance goes to 0, the scene files,
the sensors and the bad input, through the public API."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import Scene
from ukflex.model.scenefile import dumps, loads
from studies.clearance import FLORES, flores_scene

R, C = 0.01, 1e-3


def _journal(law="lankarani_nikravesh", ce=0.9, v=1.0, v0=1.0, friction=0.0, spin=0.0, vy=0.0):
    """A free journal (1 kg) launched from the centre of a bearing fixed to the ground."""
    s = Scene()
    j = s.rigid_body("j", mass=1.0, inertia=1e-3, velocity=(v, vy), angular_velocity=spin)
    s.revolute_clearance(j.point(0, 0), s.ground.point(0, 0), clearance=C, journal_radius=R, stiffness=1e9,
                         restitution=ce, impact_velocity=v0, law=law, friction=friction, name="pin")
    return s


def _rebound(scene, t_end=2.5e-3):
    res = ukflex.simulate(scene, t_end, method="DOPRI5", rtol=1e-9, t_eval=np.linspace(0, t_end, 501))
    return res


@pytest.mark.parametrize("law, ce, expected, tol", [
    # the law's own restitution at its reference velocity, and its known deviation (the scalar
    # 1-DOF law integrated apart: LN 0.9535 at 0.95, Flores 0.8939 at 0.9 and 0.4704 at 0.5)
    ("lankarani_nikravesh", 0.95, 0.95, 5e-3),
    ("flores", 0.9, 0.9, 8e-3),
    ("flores", 0.5, 0.5, 6e-2),
])
def test_rebound_velocity_ratio_is_the_restitution(law, ce, expected, tol):
    res = _rebound(_journal(law, ce))
    vx = res.velocity("j.x")
    pen = res.sensors.clearance("pin")["penetration"]
    assert pen.max() > 0 and pen[-1] < 0  # it hit, and left the wall
    assert -vx[-1] == pytest.approx(expected, rel=tol)


def test_restitution_scales_with_the_impact_velocity_as_the_hunt_crossley_law():
    # D is fixed by (c_e, v_0): the dimensionless law depends on D v only, so an impact at 2 v_0
    # with v_0' = 2 v_0 rebounds with the same ratio, and at 2 v_0 with v_0 it loses more
    same = -_rebound(_journal("flores", 0.8, v=2.0, v0=2.0), 1.5e-3).velocity("j.x")[-1] / 2.0
    ref = -_rebound(_journal("flores", 0.8, v=1.0, v0=1.0)).velocity("j.x")[-1]
    faster = -_rebound(_journal("flores", 0.8, v=2.0, v0=1.0), 1.5e-3).velocity("j.x")[-1] / 2.0
    assert same == pytest.approx(ref, rel=1e-6)
    assert faster < ref - 0.05


def test_energy_balance_closes_with_contact_and_friction_dissipation():
    # an oblique impact of a spinning journal: normal damping and friction both dissipate
    s = _journal("lankarani_nikravesh", 0.8, v=1.0, vy=0.6, friction=0.2, spin=30.0)
    res = ukflex.simulate(s, 4e-3, method="DOPRI5", rtol=1e-10, t_eval=np.linspace(0, 4e-3, 4001))
    eb = res.sensors.energy_balance()
    e = res.sensors.energies()
    lost = e["total"][0] - e["total"][-1]
    assert lost > 0.2 * e["total"][0]  # a real loss ...
    assert res.sensors.dissipated()[-1] == pytest.approx(lost, rel=1e-6)  # ... all of it dissipated
    assert eb["relative_error"] < 1e-6
    # friction acted: the spin changed
    assert abs(res.velocity("j.theta")[-1] - 30.0) > 1.0


def test_contact_force_is_the_gradient_of_the_potential_at_rest():
    s = _journal()
    system = s.build()
    q = np.array([0.6e-3 + C, 0.2e-3, 0.3])  # eccentricity 1.61 mm: penetration 0.61 mm
    qd = np.zeros(3)
    h = 1e-9
    grad = [(system.potential_energy(q + h * e) - system.potential_energy(q - h * e)) / (2 * h) for e in np.eye(3)]
    force = system.Q(0.0, q, qd)
    assert np.abs(force).max() > 1e4  # in contact: K delta^1.5 is 1.5e4 N
    assert np.allclose(force, -np.array(grad), rtol=1e-5, atol=1e-6)


def test_slider_crank_converges_to_the_ideal_joint():
    # slider acceleration over the third crank turn, max |a - a_ideal| / max |a_ideal| (no
    # friction: the ideal joint has none)
    period = 2 * math.pi / FLORES["omega"]
    te = np.linspace(0, 3 * period, 6001)
    last = te >= 2 * period

    def acc(clearance):
        system = flores_scene(clearance, friction=0.0).build()
        res = ukflex.simulate(system, 3 * period, rtol=1e-8, t_eval=te)
        return res.qdd()[system.coordinate_names.index("slider.x")]

    ideal = acc(None)
    scale = np.abs(ideal[last]).max()
    err = {c: np.abs(acc(c) - ideal)[last].max() / scale for c in (1e-5, 1e-6)}
    assert err[1e-6] < 0.01
    assert err[1e-5] > err[1e-6]  # and it is a convergence: a larger clearance is further off


def test_slider_crank_energy_balance_with_clearance_closes():
    period = 2 * math.pi / FLORES["omega"]
    res = ukflex.simulate(flores_scene(0.5e-3).build(), period, rtol=1e-8, t_eval=np.linspace(0, period, 8001))
    eb = res.sensors.energy_balance()
    dissipated = res.sensors.dissipated()[-1]
    assert dissipated > 1.0  # joules, a real loss
    assert np.abs(eb["residual"]).max() < 0.01 * dissipated
    assert np.abs(eb["residual"]).max() <= eb["quadrature_error"]  # what is left is the sampling's


def test_scene_file_round_trip_and_defaults():
    s = _journal("flores", 0.7, friction=0.1)
    d = s.to_dict()
    f = d["forces"][0]
    assert f["kind"] == "revolute_clearance" and f["exponent"] == 1.5 and f["friction_velocities"] == [1e-4, 1e-3]
    assert loads(dumps(s)).scene.to_dict() == d
    # the core fills what is not given
    bare = Scene()
    j = bare.rigid_body("j", mass=1.0, inertia=1e-3)
    bare.revolute_clearance(j.point(0, 0), bare.ground.point(0, 0), clearance=C, journal_radius=R, stiffness=1e9,
                            restitution=0.9, impact_velocity=1.0)
    f = bare.to_dict()["forces"][0]
    assert (f["law"], f["exponent"], f["friction"], f["friction_velocities"]) == ("lankarani_nikravesh", 1.5, 0.0, [1e-4, 1e-3])
    assert Scene.from_dict(d).to_dict() == d


def test_sensors_name_the_joint():
    res = _rebound(_journal())
    with pytest.raises(ukflex.UnknownNameError):
        res.sensors.clearance("nope")
    c = res.sensors.clearance("pin")
    assert set(c) == {"eccentricity", "penetration", "normal_force", "tangential_force", "force"}
    assert np.allclose(c["penetration"], c["eccentricity"] - C)


@pytest.mark.parametrize("change, word", [
    (dict(clearance=-1e-4), "clearance"),
    (dict(journal_radius=-0.01), "journal_radius"),
    (dict(stiffness=0.0), "stiffness"),
    (dict(stiffness=-1e9), "stiffness"),
    (dict(restitution=0.0), "restitution"),
    (dict(restitution=1.2), "restitution"),
    (dict(friction=-0.1), "friction"),
    (dict(impact_velocity=0.0), "impact_velocity"),
    (dict(friction_velocities=(1e-3, 1e-4)), "friction_velocities"),
    (dict(exponent=0.5), "exponent"),
    (dict(law="hertz"), "law"),
])
def test_bad_input_is_refused_by_name(change, word):
    s = Scene()
    j = s.rigid_body("j", mass=1.0, inertia=1e-3)
    kw = dict(clearance=C, journal_radius=R, stiffness=1e9, restitution=0.9, impact_velocity=1.0)
    kw.update(change)
    with pytest.raises(ukflex.InvalidSceneError, match=word):
        s.revolute_clearance(j.point(0, 0), s.ground.point(0, 0), **kw)

def test_contact_is_an_output_expression():
    from ukflex.results import outputs

    res = _rebound(_journal())
    label, force = outputs.evaluate(res, "clearance(pin).force")
    assert label == "clearance(pin).force [N]" and np.array_equal(force, res.sensors.clearance("pin")["force"])
    assert force.max() > 0
    with pytest.raises(ValueError, match="unknown revolute joint with clearance"):
        outputs.validate(res.system, "clearance(nope).force")


def test_auto_takes_an_error_controlled_step_with_contacts():
    # the flexible coupler is stiff (a fixed RADAU5M step on its lowest mode without a
    # contact); an a-priori step would step over the impacts, so auto keeps step control
    from studies.clearance import coupler_scene
    from ukflex.run.choice import choose_method

    fixed = choose_method(coupler_scene(None).build(), 0.0, 0.08, 1e-7)
    contact = choose_method(coupler_scene(5e-4).build(), 0.0, 0.08, 1e-7)
    assert fixed.method == "RADAU5M" and "step" in fixed.options
    assert contact.method == "RADAU5M" and "step" not in contact.options and contact.rtol is None
    # a rigid scene with a contact: DOPRI5 at the user's tolerances
    assert choose_method(flores_scene(5e-4).build(), 0.0, 0.01, 1e-7).method == "DOPRI5"


@pytest.mark.parametrize("method, options", [("RADAU5", dict(rtol=1e-8)), ("RADAU5M", dict(rtol=1e-8)),
                                             ("GENALPHA", dict(step=2e-7))])
def test_native_integrators_agree_on_an_oblique_impact_with_friction(method, options):
    scene = _journal("flores", 0.9, friction=0.2, vy=0.5, spin=20.0)
    te = np.linspace(0, 2.5e-3, 501)
    ref = ukflex.simulate(scene, 2.5e-3, method="DOPRI5", rtol=1e-10, t_eval=te)
    res = ukflex.simulate(scene, 2.5e-3, method=method, t_eval=te, **options)
    for name in ("j.x", "j.theta"):
        assert res.velocity(name)[-1] == pytest.approx(ref.velocity(name)[-1], rel=1e-5)
    assert res.sensors.energy_balance()["relative_error"] < 1e-5


def test_study_command_takes_its_options(capsys):
    # python -m studies clearance [coupler|flores] [--figure PNG]: the options reach the study
    # (an argparse.REMAINDER refused arguments that start with "-")
    from studies.__main__ import main

    with pytest.raises(SystemExit) as e:
        main(["clearance", "--help"])
    assert e.value.code == 0 and "--figure PNG" in capsys.readouterr().out
    with pytest.raises(SystemExit) as e:
        main(["clearance", "nope"])
    assert e.value.code == 2
