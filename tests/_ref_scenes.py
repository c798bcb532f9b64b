"""Scene description dicts used by the reference self-tests and the cross-validation suite.

Built by hand (not with ukflex.Scene) so the reference tests do not depend on the Python
scene builder. Format: docs/scene-format.md.
"""
import math

# The paper's data (section 7; DESIGN.md section 3)
L_CRANK = 0.1524
L_COUPLER = 0.3048
DIAMETER = 0.00635
RHO = 7834.56
E_MOD = 2.06843e11
NU = 0.285
K_SHEAR = 0.8
OMEGA = 124.8
AREA = math.pi * DIAMETER**2 / 4
M_CRANK = RHO * AREA * L_CRANK


def slider_crank(theory="timoshenko", elements=1, gravity=True, frame="pinned-pinned",
                 rotary_inertia=None, damping=0.0, omega=OMEGA, strain="linear"):
    """The paper's flexible slider-crank (crank frame at the ground pivot; the paper's linear
    strain unless ``strain`` says otherwise)."""
    coupler = {
        "name": "coupler", "kind": "beam", "length": L_COUPLER, "elements": elements,
        "theory": theory, "strain": strain, "density": RHO, "youngs_modulus": E_MOD, "poisson_ratio": NU,
        "shear_factor": K_SHEAR, "section": {"shape": "circular", "diameter": DIAMETER},
        "frame": frame, "position": [L_CRANK, 0.0], "angle": 0.0,
        "velocity": [0.0, 0.0], "angular_velocity": 0.0,
    }
    if rotary_inertia is not None:
        coupler["rotary_inertia"] = rotary_inertia
    if damping:
        coupler["damping"] = damping
    d = {
        "bodies": [
            {"name": "crank", "kind": "rigid", "mass": M_CRANK,
             "inertia": M_CRANK * L_CRANK**2 / 12, "com": [L_CRANK / 2, 0.0],
             "position": [0.0, 0.0], "angle": 0.0, "velocity": [0.0, 0.0],
             "angular_velocity": omega},
            coupler,
        ],
        "joints": [
            {"kind": "revolute", "name": "pivot", "a": {"body": "crank", "point": [0.0, 0.0]},
             "b": {"body": "ground", "point": [0.0, 0.0]}},
            {"kind": "revolute", "name": "crankpin", "a": {"body": "crank", "point": [L_CRANK, 0.0]},
             "b": {"body": "coupler", "xi": 0.0}},
            {"kind": "point_on_line", "name": "slot", "point": {"body": "coupler", "xi": 1.0},
             "line": {"body": "ground", "point": [0.0, 0.0], "angle": 0.0}},
        ],
        "drivers": [
            {"kind": "angle", "a": {"body": "crank", "point": [0.0, 0.0]},
             "motion": {"kind": "constant_speed", "initial": 0.0, "speed": omega}},
        ],
        "forces": [],
    }
    if gravity:
        d["gravity"] = [0.0, -9.81]
    return d


def rigid_slider_crank():
    """Rigid-only slider crank with a slider block (prismatic) and a free crank under gravity."""
    L, Lc = 0.2, 0.5
    return {
        "gravity": [0.0, -9.81],
        "bodies": [
            {"name": "crank", "kind": "rigid", "mass": 1.2, "inertia": 0.004, "com": [0.1, 0.01],
             "position": [0, 0], "angle": 0.3, "angular_velocity": 5.0},
            {"name": "rod", "kind": "rigid", "mass": 0.8, "inertia": 0.017, "com": [0.0, 0.0],
             "position": [0.35, 0.1], "angle": -0.2},
            {"name": "slider", "kind": "rigid", "mass": 0.5, "inertia": 1e-3,
             "position": [0.68, 0.0], "angle": 0.0},
        ],
        "joints": [
            {"kind": "revolute", "a": {"body": "ground", "point": [0, 0]},
             "b": {"body": "crank", "point": [0, 0]}},
            {"kind": "revolute", "a": {"body": "crank", "point": [L, 0]},
             "b": {"body": "rod", "point": [-Lc / 2, 0]}},
            {"kind": "revolute", "a": {"body": "rod", "point": [Lc / 2, 0]},
             "b": {"body": "slider", "point": [0, 0]}},
            {"kind": "prismatic", "a": {"body": "slider", "point": [0, 0]},
             "b": {"body": "ground", "point": [0, 0], "angle": 0.0}},
        ],
        "forces": [
            {"kind": "spring_damper", "a": {"body": "slider", "point": [0, 0]},
             "b": {"body": "ground", "point": [1.0, 0.0]}, "stiffness": 50.0, "damping": 0.5,
             "rest_length": 0.2},
            {"kind": "torque", "frame": {"body": "crank", "point": [0.0, 0.0]}, "torque": 0.3},
        ],
    }


def every_joint_scene(theory_a="timoshenko", theory_b="euler-bernoulli"):
    """Every joint, driver, motion and force kind, on rigid bodies, beams and ground."""
    L, Lb = 0.15, 0.3
    ang = 0.3
    blk = [0.5, -0.2]
    arm_pos = [blk[0] + 0.05 * math.cos(ang), blk[1] + 0.05 * math.sin(ang)]
    beam = dict(density=7800.0, youngs_modulus=2.0e11, poisson_ratio=0.3, shear_factor=5 / 6)
    return {
        "gravity": [0.0, -9.81],
        "bodies": [
            {"name": "crank", "kind": "rigid", "mass": 0.3, "inertia": 6e-4,
             "com": [L / 2, 0.0], "position": [0, 0], "angle": 0.0},
            {"name": "coupler", "kind": "beam", "length": Lb, "elements": 2, "theory": theory_a,
             "section": {"shape": "rectangular", "width": 0.01, "height": 0.006},
             "frame": "pinned-pinned", "damping": 1e-5, "position": [L, 0.0], "angle": 0.0,
             **beam},
            {"name": "block", "kind": "rigid", "mass": 0.4, "inertia": 2e-4, "com": [0.01, 0.0],
             "position": blk, "angle": ang},
            {"name": "arm", "kind": "beam", "length": 0.25, "elements": 2, "theory": theory_b,
             "section": {"shape": "custom", "area": 3e-5, "second_moment": 8e-11},
             "frame": "clamped", "rotary_inertia": True, "position": arm_pos, "angle": ang,
             **beam},
        ],
        "joints": [
            {"kind": "revolute", "name": "pivot", "a": {"body": "ground", "point": [0, 0]},
             "b": {"body": "crank", "point": [0, 0]}},
            {"kind": "revolute", "name": "pin", "a": {"body": "crank", "point": [L, 0]},
             "b": {"body": "coupler", "xi": 0.0}},
            {"kind": "point_on_line", "name": "slot", "point": {"body": "coupler", "xi": 1.0},
             "line": {"body": "ground", "point": [0.0, 0.0], "angle": 0.0}},
            {"kind": "prismatic", "name": "guide", "a": {"body": "block", "point": [0, 0]},
             "b": {"body": "ground", "point": blk, "angle": ang}},
            {"kind": "weld", "name": "mount", "a": {"body": "block", "point": [0.05, 0.0]},
             "b": {"body": "arm", "xi": 0.0}},
        ],
        "drivers": [
            {"kind": "angle", "a": {"body": "crank", "point": [0.0, 0.0]},
             "motion": {"kind": "harmonic", "offset": 0.0, "amplitude": 0.8, "frequency": 20.0,
                        "phase": 0.0}},
            {"kind": "coordinate", "point": {"body": "block", "point": [0, 0]}, "axis": "x",
             "motion": {"kind": "polynomial", "coefficients": [blk[0], 0.1, 0.2]}},
        ],
        "forces": [
            {"kind": "spring_damper", "a": {"body": "block", "point": [0.0, 0.0]},
             "b": {"body": "coupler", "xi": 0.5}, "stiffness": 200.0, "damping": 0.3,
             "rest_length": 0.25},
            {"kind": "point_force", "point": {"body": "coupler", "xi": 0.25}, "force": [0.5, -1.0]},
            {"kind": "torque", "frame": {"body": "arm", "xi": 1.0}, "torque": 0.02},
            {"kind": "point_force", "point": {"body": "arm", "xi": 0.7, "angle": 0.1},
             "force": [0.0, -0.3]},
            {"kind": "torque", "frame": {"body": "crank", "point": [0.0, 0.0]}, "torque": -0.1},
        ],
    }


def line_and_beam_scene():
    """A beam carrying a line (point_on_line / prismatic with the line marker on a beam, whose
    direction turns with psi), a beam-to-beam revolute and an angle driver between two bodies."""
    beam = dict(density=7800.0, youngs_modulus=7.0e10, poisson_ratio=0.33, shear_factor=0.85,
                section={"shape": "rectangular", "width": 0.02, "height": 0.004})
    return {
        "bodies": [
            {"name": "rail", "kind": "beam", "length": 0.6, "elements": 3, "theory": "timoshenko",
             "frame": "clamped", "position": [0, 0], "angle": 0.1, **beam},
            {"name": "runner", "kind": "rigid", "mass": 0.2, "inertia": 1e-4,
             "position": [0.3 * math.cos(0.1), 0.3 * math.sin(0.1)], "angle": 0.1},
            {"name": "link", "kind": "beam", "length": 0.3, "elements": 2,
             "theory": "euler-bernoulli", "frame": "pinned-pinned",
             "position": [0.6 * math.cos(0.1), 0.6 * math.sin(0.1)], "angle": 1.2, **beam},
        ],
        "joints": [
            {"kind": "weld", "a": {"body": "ground", "point": [0, 0], "angle": 0.1},
             "b": {"body": "rail", "xi": 0.0}},
            {"kind": "prismatic", "a": {"body": "runner", "point": [0, 0], "angle": 0.0},
             "b": {"body": "rail", "xi": 0.5, "angle": 0.0}},
            {"kind": "revolute", "a": {"body": "rail", "xi": 1.0}, "b": {"body": "link", "xi": 0.0}},
        ],
        "drivers": [
            {"kind": "angle", "a": {"body": "link", "xi": 0.0}, "b": {"body": "rail", "xi": 1.0},
             "motion": {"kind": "polynomial", "coefficients": [1.1, 0.5, -0.3]}},
        ],
        "forces": [
            {"kind": "spring_damper", "a": {"body": "runner", "point": [0.0, 0.0]}, "b": {"body": "link", "xi": 1.0},
             "stiffness": 30.0, "damping": 0.1, "rest_length": 0.1},
        ],
        "gravity": [0.0, -9.81],
    }


def pendulum(length=4.0, theta0=-math.pi / 2, omega0=3.5):
    """Rigid bar with its frame at the centre of mass, pinned to ground at its end (-l/2, 0).

    With l/2 > 1 the column-pivoted QR of A puts theta and y among the dependent coordinates
    while hanging (x independent); swinging through the horizontal makes that block singular,
    so coordinate partitioning must repartition.
    """
    m = 1.0
    c, s = math.cos(theta0), math.sin(theta0)
    h = length / 2
    return {
        "gravity": [0.0, -9.81],
        "bodies": [
            {"name": "bar", "kind": "rigid", "mass": m, "inertia": m * length**2 / 12,
             "position": [h * c, h * s], "angle": theta0,
             "velocity": [-h * s * omega0, h * c * omega0], "angular_velocity": omega0},
        ],
        "joints": [
            {"kind": "revolute", "a": {"body": "ground", "point": [0, 0]},
             "b": {"body": "bar", "point": [-h, 0.0]}},
        ],
    }


def free_beam(theory="timoshenko", elements=3, frame="clamped", youngs_modulus=7e10):
    """An unconstrained spinning beam with initial deformation (energy conservation check)."""
    b = {"name": "b", "kind": "beam", "length": 0.5, "elements": elements, "theory": theory,
         "density": 2700.0, "youngs_modulus": youngs_modulus, "poisson_ratio": 0.33, "shear_factor": 0.85,
         "section": {"shape": "rectangular", "width": 0.01, "height": 0.01}, "frame": frame,
         "position": [0.1, 0.2], "angle": 0.4, "velocity": [0.3, -0.2], "angular_velocity": 6.0}
    return {"bodies": [b]}


def misc_scene():
    """Remaining options: shear_modulus instead of poisson_ratio, Timoshenko without rotary
    inertia, a coordinate driver along y with a phased harmonic motion, a spring-damper and
    a weld between two beams, a rigid body with an offset centre of mass, gravity null."""
    beam = dict(density=2700.0, youngs_modulus=7e10, shear_factor=0.85,
                section={"shape": "rectangular", "width": 0.012, "height": 0.005})
    return {
        "gravity": None,
        "bodies": [
            {"name": "b1", "kind": "beam", "length": 0.4, "elements": 3, "theory": "timoshenko",
             "shear_modulus": 2.6e10, "rotary_inertia": False, "frame": "clamped",
             "position": [0.0, 0.0], "angle": 0.5, **beam},
            {"name": "b2", "kind": "beam", "length": 0.3, "elements": 2, "theory": "timoshenko",
             "poisson_ratio": 0.33, "frame": "pinned-pinned", "damping": 2e-5,
             "position": [0.4 * math.cos(0.5), 0.4 * math.sin(0.5)], "angle": -0.4,
             "elastic": [1e-3, -2e-5, 1e-3, 5e-4, -1e-5, 2e-4, 1e-5, 0.0, -3e-4][:6],
             **beam},
            {"name": "box", "kind": "rigid", "mass": 0.7, "inertia": 3e-3, "com": [0.02, -0.01],
             "position": [0.1, -0.3], "angle": 0.2, "velocity": [0.1, 0.0],
             "angular_velocity": -1.0},
        ],
        "joints": [
            {"kind": "revolute", "a": {"body": "ground", "point": [0.0, 0.0]},
             "b": {"body": "b1", "xi": 0.0}},
            {"kind": "weld", "a": {"body": "b1", "xi": 1.0, "angle": 0.1},
             "b": {"body": "b2", "xi": 0.0, "angle": 0.2}},
            {"kind": "point_on_line", "point": {"body": "box", "point": [0.05, 0.0]},
             "line": {"body": "b2", "xi": 0.6, "angle": 0.3}},
        ],
        "drivers": [
            {"kind": "coordinate", "point": {"body": "box", "point": [0.0, 0.02]}, "axis": "y",
             "motion": {"kind": "harmonic", "offset": -0.28, "amplitude": 0.02,
                        "frequency": 9.0, "phase": 1.3}},
        ],
        "forces": [
            {"kind": "spring_damper", "a": {"body": "b1", "xi": 0.5}, "b": {"body": "b2", "xi": 1.0},
             "stiffness": 80.0, "damping": 0.2, "rest_length": 0.05},
            {"kind": "torque", "frame": {"body": "b2", "xi": 0.3}, "torque": 0.05},
            {"kind": "point_force", "point": {"body": "box", "point": [0.0, 0.05], "angle": 0.3},
             "force": [1.0, 2.0]},
        ],
    }
