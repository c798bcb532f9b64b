"""Everything downstream of the spatial model (issue 30, item 4; docs/spatial.md, "Downstream"):
scene files with ``dim = 3``, the CLI on them, sensors of a spatial run (kinematics, 3D
reactions, energies and their balance), frequencies, equilibrium and rank reports, the
rotational spring-damper's turn counter, sweeps and the 3D animation."""

from __future__ import annotations

import copy
import os

import numpy as np
import pytest

import ukflex
from ukflex.model.scenefile import SceneFileError, dumps, load, loads
from ukflex.reference import spatial as sp

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLE = os.path.join(ROOT, "examples", "spatial_slider_crank.toml")
G = 9.81

PENDULUM_TOML = """
dim = 3
gravity = [0.0, 0.0, -9.81]

[[bodies]]
kind = "rigid3"
name = "rod"
mass = 2.0
inertia = [0.1, 0.12, 0.05]
position = [0.0, 0.0, -0.7]

[[joints]]
kind = "spherical"
name = "pivot"
a = { body = "ground", point = [0.0, 0.0, 0.0] }
b = { body = "rod", point = [0.0, 0.0, 0.7] }

[solver]
t_end = 0.5
"""


def _rotation(p):
    e0, e1, e2, e3 = p
    return np.array([[e0 * e0 + e1 * e1 - e2 * e2 - e3 * e3, 2 * (e1 * e2 - e0 * e3), 2 * (e1 * e3 + e0 * e2)],
                     [2 * (e1 * e2 + e0 * e3), e0 * e0 - e1 * e1 + e2 * e2 - e3 * e3, 2 * (e2 * e3 - e0 * e1)],
                     [2 * (e1 * e3 - e0 * e2), 2 * (e2 * e3 + e0 * e1), e0 * e0 - e1 * e1 - e2 * e2 + e3 * e3]])


# ---------------------------------------------------------------------------------------------
# 1. scene files
# ---------------------------------------------------------------------------------------------

def test_a_toml_scene_file_with_dim_3_loads_a_spatial_scene_and_round_trips():
    sf = loads(PENDULUM_TOML, path="pendulum.toml")
    assert isinstance(sf.scene, ukflex.SpatialScene)
    d = sf.scene.to_dict()
    assert d["dim"] == 3 and d["gravity"] == [0.0, 0.0, -9.81]
    system = sf.build()
    assert system.coordinate_names == ["rod.x", "rod.y", "rod.z", "rod.e0", "rod.e1", "rod.e2", "rod.e3"]
    np.testing.assert_allclose(system.q0, [0, 0, -0.7, 1, 0, 0, 0], atol=1e-14)
    text = dumps(sf.scene, solver=sf.solver)
    assert text.splitlines()[0] == "dim = 3"
    back = loads(text)
    assert back.scene.to_dict() == d and back.solver == {"t_end": 0.5}
    # the dict form and SpatialScene.from_dict give the same System
    assert ukflex.SpatialScene.from_dict(d).to_dict() == d
    np.testing.assert_array_equal(ukflex.System(d).q0, system.q0)


@pytest.mark.parametrize("edit, words", [
    (lambda t: t.replace("dim = 3", "dim = 5"), ["dim must be 2 (planar) or 3 (spatial)"]),
    (lambda t: t.replace('kind = "rigid3"', 'kind = "rigid"'), ["body 'rod'", "planar"]),
    (lambda t: t.replace("inertia = [0.1, 0.12, 0.05]", "inertia = [[0.1, 0.0, 0.0], [0.0, 0.12, 0.0], [0.0, 0.0, 0.5]]"), ["body 'rod'", "triangle inequality"]),
    (lambda t: t.replace('b = { body = "rod"', 'b = { body = "nope"'), ["nope"]),
    (lambda t: t.replace("dim = 3\n", "").replace("[0.0, 0.0, -9.81]", "[0.0, -9.81]"), ["[[bodies]] #1 (line 4)", "unknown kind 'rigid3'"]),
])
def test_a_bad_spatial_scene_file_names_the_file_and_the_item(edit, words):
    with pytest.raises(SceneFileError) as exc:
        loads(edit(PENDULUM_TOML), path="pendulum.toml")
    msg = str(exc.value)
    assert msg.startswith("pendulum.toml: "), msg
    for w in words:
        assert w in msg, msg


def test_the_spatial_slider_crank_example_runs_to_the_reference():
    """examples/spatial_slider_crank.toml runs the IFToMM spatial slider-crank: the slider
    position at 0.2 s is the reference run's (docs/spatial-design.md, section 8)."""
    sf = load(EXAMPLE)
    system = sf.build()
    assert system.initial_correction.max_position_change < 1e-12
    res = ukflex.simulate(system, 0.2, method="DOPRI5", rtol=1e-10, t_eval=[0.0, 0.2])
    assert res.success
    assert abs(res.coordinate("slider.x")[-1] - 0.263038973) < 2e-9


# ---------------------------------------------------------------------------------------------
# 2. the command line
# ---------------------------------------------------------------------------------------------

def test_cli_runs_and_exports_a_spatial_scene_file(tmp_path, capsys):
    from ukflex.cli import main

    out = tmp_path / "run"
    rc = main(["run", EXAMPLE, "--t-end", "0.1", "--samples", "21", "--no-plot", "--no-progress", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0, text
    assert "scene spatial_slider_crank: n = 21 coordinates, m = 20 constraints, 1 degree(s) of freedom" in text
    assert "energy T + V" in text and "balance closes" in text
    for f in ("spatial_slider_crank.csv", "spatial_slider_crank.npz", "spatial_slider_crank_spatial.csv",
              "spatial_slider_crank_spatial.npz", "spatial_slider_crank_outputs.csv"):
        assert (out / f).exists(), f
    z = np.load(out / "spatial_slider_crank_spatial.npz")
    assert z["t"].shape == (21,)
    assert abs(z["position(slider).x"][0] - 0.2) < 1e-12
    np.testing.assert_allclose(z["position(slider).y"], 0.0, atol=1e-9)  # the prismatic joint holds it on x
    header = (out / "spatial_slider_crank_spatial.csv").read_text().splitlines()[0].split(",")
    assert "quaternion(crank).e0" in header and "reaction(crank_rod).fz" in header and "balance" in header
    # export: the file written back (validated) loads to the same scene
    exported = tmp_path / "copy.toml"
    assert main(["export", EXAMPLE, "-o", str(exported)]) == 0
    assert load(str(exported)).scene.to_dict() == load(EXAMPLE).scene.to_dict()


# ---------------------------------------------------------------------------------------------
# 4. sensors
# ---------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def crank_run():
    system = load(EXAMPLE).build()
    res = ukflex.simulate(system, 0.3, method="DOPRI5", rtol=1e-11, t_eval=np.linspace(0.0, 0.3, 301))
    return system, res


def test_sensors_of_a_spatial_run_give_kinematics_reactions_and_energies(crank_run):
    system, res = crank_run
    s = res.sensors
    assert isinstance(s, ukflex.results.spatial.SpatialSensors)
    k = 150
    q = res.q[:, k]
    for body in ("crank", "rod"):
        o = system.body_slices[body][0]
        p = q[o + 3:o + 7]
        kin = s.body(body)
        np.testing.assert_allclose(kin["quaternion"][k], p / np.linalg.norm(p), atol=1e-14)
        np.testing.assert_allclose(kin["rotation"][k], _rotation(p / np.linalg.norm(p)), atol=1e-14)
        np.testing.assert_allclose(kin["position"][k], q[o:o + 3], atol=0)
        # angular velocity: R^T Rd = skew(omega_body), Rd by central differences of the samples
        Rd = (kin["rotation"][k + 1] - kin["rotation"][k - 1]) / (res.t[k + 1] - res.t[k - 1])
        W = kin["rotation"][k].T @ Rd
        np.testing.assert_allclose([W[2, 1], W[0, 2], W[1, 0]], kin["omega_body"][k], rtol=1e-3, atol=1e-4)
        np.testing.assert_allclose(kin["rotation"][k] @ kin["omega_body"][k], kin["omega"][k], atol=1e-12)
    # the crank turns about world x only (its revolute)
    np.testing.assert_allclose(s.body("crank")["omega"][:, 1:], 0.0, atol=1e-8)
    # reactions: the same numbers as ukflex.spatial_outputs; the prismatic joint (along world x)
    # transmits no force along x, the spherical one no torque
    out = ukflex.spatial_outputs(system, res)
    r = s.reaction("slider_ground")
    np.testing.assert_array_equal(r["force"], out["reactions"]["slider_ground"]["force"])
    assert np.abs(r["fz_joint"]).max() < 1e-8 * np.abs(r["force"]).max()
    assert np.abs(s.reaction("crank_rod")["torque"]).max() < 1e-9
    assert r["body"] is None and s.reaction("crank_rod")["body"] == "crank"
    assert "crank.normalization" not in s.joint_names
    # Newton for the slider: m a = sum of the constraint forces on it + gravity
    acc = np.gradient(s.body("slider")["velocity"], res.t, axis=0)[k]
    # the universal joint's first marker is on the slider: its force acts on the slider; the
    # prismatic joint's first marker is the ground's, so the slider receives minus it
    f = s.reaction("rod_slider")["force"][k] - r["force"][k] + 2.0 * np.array([0, 0, -G])
    np.testing.assert_allclose(2.0 * acc, f, rtol=1e-4, atol=1e-4 * np.abs(f).max())
    # energies: the free crank conserves T + V; the balance closes
    e = s.energies()
    np.testing.assert_allclose(e["total"], out["energy"], rtol=1e-13)
    assert np.ptp(e["total"]) < 1e-9 * np.abs(e["total"]).max()
    assert np.abs(e["gravity"] - sum(s.body_energies(b)["gravity"] for b in system.body_names)).max() < 1e-14
    slider_g = s.body_energies("slider")["gravity"]
    np.testing.assert_allclose(slider_g, -2.0 * -G * s.body("slider")["position"][:, 2], atol=1e-14)
    assert s.energy_balance()["relative_error"] < 1e-8
    # output expressions
    label, v = ukflex.results.outputs.evaluate(res, "omega(crank).x")
    assert label == "omega(crank).x [rad/s]" and abs(v[0] - 6.0) < 1e-9
    with pytest.raises(ValueError, match="components of quaternion"):
        ukflex.results.outputs.validate(system, "quaternion(crank).x")


def test_spatial_outputs_use_the_compiled_model_not_the_description(crank_run):
    """``ukflex.spatial_outputs`` asks the System's compiled model (no rebuild from JSON):
    a description edited after the build changes nothing."""
    system, res = crank_run
    before = ukflex.spatial_outputs(system, res.t[:3], res.q[:, :3].T, res.qd[:, :3].T)
    edited = copy.copy(system)
    edited.description = {"dim": 3, "bodies": []}
    after = ukflex.spatial_outputs(edited, res.t[:3], res.q[:, :3].T, res.qd[:, :3].T)
    np.testing.assert_array_equal(before["energy"], after["energy"])
    assert not hasattr(ukflex._core, "spatial_outputs")


def _driven_rotor(torque=None, spring=None, omega0=0.0, driver=None):
    s = ukflex.SpatialScene(gravity=(0, 0, -G))
    # the body frame's origin on the hinge axis, the centre of mass 0.1 m off it: J = 0.02 + 3 * 0.1^2
    rotor = s.rigid_body("rotor", 3.0, [0.05, 0.05, 0.02], com=(0.1, 0, 0), angular_velocity=(0, 0, omega0))
    a, b = s.ground.marker((0, 0, 0), z=(0, 0, 1)), rotor.marker((0, 0, 0), z=(0, 0, 1))
    s.revolute(a, b, name="hinge")
    if torque is not None:
        s.torque(rotor, torque, frame="world", name="motor")
    if spring is not None:
        s.rotational_spring_damper(a, b, *spring, name="spring")
    if driver is not None:
        s.rotation_driver(a, b, driver, name="drive")
    return ukflex.System(s)


def test_energy_balance_closes_with_a_torque_a_damper_and_a_driver():
    # a constant world torque spins the rotor up: its work (the integral of n . omega) is the kinetic energy
    res = ukflex.simulate(_driven_rotor(torque=(0, 0, 2.0)), 1.0, method="DOPRI5", rtol=1e-10, t_eval=np.linspace(0, 1, 201))
    bal = res.sensors.energy_balance()
    J = 0.02 + 3.0 * 0.1 ** 2
    np.testing.assert_allclose(bal["external_work"][-1], 0.5 * 2.0 ** 2 / J, rtol=1e-8)  # (n t)^2 / 2J at t = 1
    assert bal["relative_error"] < 1e-8
    # a damped rotational spring: dissipated energy = energy lost
    res = ukflex.simulate(_driven_rotor(spring=(4.0, 0.3), omega0=3.0), 2.0, method="DOPRI5", rtol=1e-10,
                          t_eval=np.linspace(0, 2, 401))
    bal = res.sensors.energy_balance()
    assert bal["dissipated"][-1] > 0.5 * abs(bal["change"][-1]) > 0
    assert bal["relative_error"] < 1e-7
    # a driver: its work is the change of energy (a constant speed needs no work; a harmonic one does)
    res = ukflex.simulate(_driven_rotor(driver=ukflex.Harmonic(1.0, 3.0)), 1.0, method="DOPRI5", rtol=1e-10,
                          t_eval=np.linspace(0, 1, 401))
    s = res.sensors
    bal = s.energy_balance()
    assert np.abs(bal["driver_work"]).max() > 0.01
    assert bal["relative_error"] < 1e-7
    np.testing.assert_allclose(s.driver_work("drive"), bal["driver_work"])


# ---------------------------------------------------------------------------------------------
# 5. frequencies, equilibrium, rank reports
# ---------------------------------------------------------------------------------------------

def test_spatial_pendulum_frequencies_match_the_closed_form():
    # a point mass on a distance constraint: two modes at sqrt(g / l)
    l = 0.7
    s = ukflex.SpatialScene(gravity=(0, 0, -G))
    bob = s.point_mass("bob", 2.0, position=(0, 0, -l))
    s.distance(s.ground.marker(), bob.marker(), length=l)
    np.testing.assert_allclose(ukflex.System(s).frequencies(), [np.sqrt(G / l)] * 2, rtol=1e-7)
    # a rigid body on a spherical joint: compound pendulum about x and y, a free spin about z
    system = loads(PENDULUM_TOML).build()
    m, d, Jx, Jy = 2.0, 0.7, 0.1, 0.12
    w = system.frequencies()
    np.testing.assert_allclose(w[1:], sorted([np.sqrt(m * G * d / (Jx + m * d * d)), np.sqrt(m * G * d / (Jy + m * d * d))]),
                               rtol=1e-7)
    assert abs(w[0]) < 1e-6


def test_equilibrium_of_a_hanging_body():
    """A body hung at a point off its centre of mass, started tilted: at equilibrium its centre of
    mass is straight below the pivot and the joint carries its weight."""
    s = ukflex.SpatialScene(gravity=(0, 0, -G))
    tilt = sp.rotations.matrix_from_axis_angle([1.0, 0.3, 0.0], 0.6)
    c = np.array([0.05, -0.02, -0.4])  # centre of mass in the body frame; the pivot at the frame origin
    body = s.rigid_body("body", 1.5, [[0.2, 0.01, 0], [0.01, 0.15, 0], [0, 0, 0.1]], com=c, orientation=tilt,
                        position=(0, 0, 0))
    s.spherical(s.ground.marker((0, 0, 0)), body.marker((0, 0, 0)), name="pivot")
    system = ukflex.System(s)
    eq = system.equilibrium()
    np.testing.assert_allclose(eq.q[:3], [0, 0, -np.linalg.norm(c)], atol=1e-9)
    res = ukflex.simulate(system, 1e-3, q0=eq.q, qd0=np.zeros(7), t_eval=[0, 1e-3], method="DOPRI5")
    r = ukflex.spatial_outputs(system, res)["reactions"]["pivot"]["force"]
    np.testing.assert_allclose(r[0], [0, 0, -1.5 * G], atol=1e-8)  # what the ground receives: the weight
    assert np.abs(system.qdd(0.0, eq.q, np.zeros(7))).max() < 1e-8


def test_rank_reports_find_bricards_redundant_row():
    model = sp.scenes.bricard()
    from test_spatial import to_description

    system = ukflex.System(to_description(model))
    info = system.rank_info(system.t0, system.q0, system.qd0)
    assert (system.n_constraints, info["rank"], system.n_coords - info["rank"]) == (35, 34, 1)
    res = ukflex.simulate(system, 0.2, t_eval=np.linspace(0, 0.2, 5))
    rh = ukflex.stability.rank_history(res)
    assert rh["full"] == 35 and rh["min_rank"] == 34 and not rh["changes"]
    kinds = [d.kind for d in ukflex.stability.check(res, warn=False)]
    assert "redundant" in kinds


# ---------------------------------------------------------------------------------------------
# 6. the rotational spring-damper's turn counter
# ---------------------------------------------------------------------------------------------

def test_rotational_spring_counts_turns_beyond_half_a_turn():
    """A rotor on a torsion spring swinging through +-3 pi: theta(t) = (w0 / W) sin(W t),
    W = sqrt(k / J). Read within half a turn, the spring's torque would flip at +-pi."""
    k, J = 4.0, 0.02 + 3.0 * 0.1 ** 2
    W = np.sqrt(k / J)
    w0 = 3.0 * np.pi * W  # amplitude 3 pi
    system = _driven_rotor(spring=(k, 0.0), omega0=w0)
    t = np.linspace(0.0, 2 * np.pi / W, 801)
    res = ukflex.simulate(system, t[-1], method="DOPRI5", rtol=1e-10, t_eval=t)
    R = res.sensors.body("rotor")["rotation"]
    theta = np.unwrap(np.arctan2(R[:, 1, 0], R[:, 0, 0]))
    np.testing.assert_allclose(theta, w0 / W * np.sin(W * t), atol=1e-6)
    e = res.sensors.energies()
    assert np.abs(e["springs"]).max() > 0.5 * k * (2.9 * np.pi) ** 2  # the potential of three half-turns
    assert np.ptp(e["total"]) < 1e-8 * np.abs(e["total"]).max()
    # the native and the scipy integrators agree
    system2 = _driven_rotor(spring=(k, 0.0), omega0=w0)
    res2 = ukflex.simulate(system2, t[-1], method="DOP853", rtol=1e-10, t_eval=t)
    np.testing.assert_allclose(res2.q, res.q, atol=1e-6)
    # the System counts on its workspace from call to call: walked along the run to the
    # wound-up state of t = T/4, the spring pulls back from 3 pi (angular acceleration -k theta / J),
    # and a sensors pass over another history leaves that count alone
    k4 = 200
    assert abs(theta[k4] - 3 * np.pi) < 1e-6
    for j in range(k4 + 1):
        before = system2.qdd(t[j], res2.q[:, j], res2.qd[:, j])
    p, pdd = res2.q[3:7, k4], before[3:7]
    alpha_z = 2 * (-p[3] * pdd[0] - p[2] * pdd[1] + p[1] * pdd[2] + p[0] * pdd[3])  # (2 E(p) pdd)_z
    np.testing.assert_allclose(alpha_z, -k * theta[k4] / J, rtol=1e-6)
    ukflex.spatial_outputs(system2, [0.0], system2.q0, system2.qd0)
    np.testing.assert_array_equal(system2.qdd(t[k4], res2.q[:, k4], res2.qd[:, k4]), before)


# ---------------------------------------------------------------------------------------------
# 3. sweeps, 7. animation
# ---------------------------------------------------------------------------------------------

def test_a_sweep_runs_a_spatial_scene_with_a_parameter_changed():
    pytest.importorskip("pandas")

    def build(length):
        s = ukflex.SpatialScene(gravity=(0, 0, -G))
        a = 0.05  # small swing: the period is 2 pi sqrt(l / g) (1 + a^2 / 16 + ...)
        bob = s.point_mass("bob", 1.0, position=(length * np.sin(a), 0, -length * np.cos(a)))
        s.distance(s.ground.marker(), bob.marker(), length=length)
        return s, {"t_end": 3.0, "method": "DOPRI5", "rtol": 1e-10, "t_eval": np.linspace(0, 3.0, 3001)}

    def outputs(res):
        x = res.coordinate("bob.x")
        k = np.nonzero((x[:-1] > 0) & (x[1:] <= 0))[0]
        tz = res.t[k] - x[k] * (res.t[k + 1] - res.t[k]) / (x[k + 1] - x[k])
        return {"period": float(np.mean(np.diff(tz)))}

    df = ukflex.sweep(build, {"length": [0.5, 1.0]}, outputs, progress=False)
    assert list(df["status"]) == ["ok", "ok"]
    closed = 2 * np.pi * np.sqrt(df["length"].to_numpy() / G) * (1 + 0.05 ** 2 / 16)
    np.testing.assert_allclose(df["period"].to_numpy(), closed, rtol=2e-5)


def test_a_spatial_run_animates_in_3d(tmp_path, crank_run):
    pytest.importorskip("matplotlib")
    from PIL import Image

    from ukflex.results.animate import animate
    from ukflex.results.animate3d import SpatialDrawer

    system, res = crank_run
    path = tmp_path / "crank.gif"
    assert animate(res, str(path), frames=4) == 4
    with Image.open(path) as im:
        assert im.format == "GIF" and im.n_frames == 4
    # the drawn geometry: the two bodies' points at each joint coincide (the crank pin of the
    # crank and of the rod, the universal joint of the rod and the slider)
    d = SpatialDrawer(res)
    for k in (0, 100, 300):
        crank, rod, slider = (d.body_points(k, b) for b in ("crank", "rod", "slider"))
        assert min(np.linalg.norm(rod - p, axis=1).min() for p in crank[1:]) < 1e-9
        assert min(np.linalg.norm(rod - p, axis=1).min() for p in slider) < 1e-9
        np.testing.assert_allclose(d.joint_points(k)[0], [0.0, 0.1, 0.12], atol=1e-9)  # the crank pivot
