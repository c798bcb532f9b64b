"""The geometrically exact 3D beam (``SpatialScene.beam``, kind ``beam3``; docs/spatial-flexible.md):
element forces against the NumPy reference, closed-form statics in two planes and in torsion, the
cantilever rolled into a full circle, section forces, energy conservation and bad input."""
from __future__ import annotations

import importlib.util
import pathlib

import numpy as np
import pytest

import ukflex
from ukflex.errors import InvalidSceneError

_REF = pathlib.Path(__file__).resolve().parents[1] / "python" / "ukflex" / "reference" / "spatial" / "beam3.py"
_spec = importlib.util.spec_from_file_location("ref_beam3", _REF)
ref = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ref)

# a section with different stiffnesses in every direction
EA, GAY, GAZ, GJ, EIY, EIZ = 2.0e5, 6.0e4, 4.0e4, 900.0, 1500.0, 2500.0
SEC = ukflex.CustomSection3(ea=EA, ga_y=GAY, ga_z=GAZ, gj=GJ, ei_y=EIY, ei_z=EIZ, mass_per_length=2.0,
                            rotary_inertia=(2e-4, 1e-4, 1.2e-4))


def _cantilever(n, length=1.0, loads=()):
    s = ukflex.SpatialScene()
    b = s.beam("b", (0, 0, 0), (length, 0, 0), SEC, elements=n)
    s.fixed(s.ground.marker((0, 0, 0)), b.node(0), name="clamp")
    for kind, v in loads:
        if kind == "force":
            s.point_force(b.node(-1), v)
        else:
            s.torque(ukflex.model.spatial.SpatialBodyRef(b.node_name(-1)), v)
    return s, b


def _node(sys, q, b, i, offset=None):
    """Point and Euler parameters of node ``i``: a node body's ``r`` is the centre of mass of its
    segment, a quarter element inwards at the two end nodes (``offset`` from the node, body x)."""
    k = sys.body_names.index(b.node_name(i))
    le = 1.0 / b.elements  # the tests' beams are 1 m long
    c = offset if offset is not None else (0.25 * le if k == 0 else -0.25 * le if k == b.elements else 0.0)
    p = q[7 * k + 3:7 * k + 7]
    return q[7 * k:7 * k + 3] - c * ref.rotation(p)[:, 0], p


def _tip(sys, q, b):
    return _node(sys, q, b, -1)


def test_element_forces_match_the_numpy_reference():
    s = ukflex.SpatialScene()
    s.beam("b", (0, 0, 0), (0.5, 0, 0), SEC, elements=1)  # both nodes are end nodes: offsets +-L/4
    sys = ukflex.System(s)
    rng = np.random.default_rng(3)
    c_n, c_m = (EA, GAY, GAZ), (GJ, EIY, EIZ)
    for _ in range(4):
        q = np.array(sys.q0, dtype=float)
        q[0:3] += 0.05 * rng.standard_normal(3)
        q[7:10] += 0.05 * rng.standard_normal(3)
        q[3:7] = q[3:7] * 1.3 + 0.3 * rng.standard_normal(4)  # not unit: R = A(p) / |p|^2
        q[10:14] = q[3:7] + 0.3 * rng.standard_normal(4)
        Q = np.asarray(sys.Q(0.0, q, np.zeros(14)))
        offsets = ((0.125, 0, 0), (-0.125, 0, 0))
        g = ref.gradient(q, 0.5, c_n, c_m, offsets)
        assert np.max(np.abs(Q + g)) <= 1e-12 * np.max(np.abs(g)), np.max(np.abs(Q + g)) / np.max(np.abs(g))
        u = ukflex.spatial_outputs(sys, np.array([0.0]), q[None, :], np.zeros((1, 14)), reactions=False)["potential_energy"][0]
        assert abs(u - ref.energy(q, 0.5, c_n, c_m, offsets)) <= 1e-12 * abs(u)


def _static(s, q=None):
    sys = ukflex.System(s)
    return sys, sys.equilibrium(q=q, tol=1e-12).q


@pytest.mark.parametrize("axis", [1, 2])
def test_cantilever_tip_deflection_in_two_planes(axis):
    # linear range (deflection 1e-4 L): Timoshenko's F L^3 / (3 EI) + F L / (k G A). Discretely
    # the element curvatures are the midpoint values of the exact M / EI (statically determinate),
    # so the nodal rotations are exact, and the deflection sums the elements' mean rotations: the
    # trapezoidal rule on the quadratic rotation, stiffer in bending by 1 / (4 N^2) exactly
    n, length, f = 8, 1.0, 1e-4 * 3 * 2000.0
    force = [0.0, 0.0, 0.0]
    force[axis] = f
    s, b = _cantilever(n, length, [("force", force)])
    sys, q = _static(s)
    r, _ = _tip(sys, q, b)
    ei, ga = (EIZ, GAY) if axis == 1 else (EIY, GAZ)
    exact = f * length**3 / (3 * ei) + f * length / ga
    discrete = f * length**3 / (3 * ei) * (1 - 1 / (4 * n * n)) + f * length / ga
    assert abs(r[axis] / discrete - 1) < 1e-6, (r[axis], discrete)
    assert abs(r[axis] / exact - 1) < 1.0 / (3 * n * n)
    # section forces at the element midpoints: Q = F, M = F (L - x) (statically determinate)
    out = ukflex.spatial_outputs(sys, np.array([0.0]), q[None, :], np.zeros((1, q.size)), reactions=False)
    for j, name in enumerate(b.element_names):
        sf = out["beams"][name][0]
        x_mid = (j + 0.5) * length / n
        shear, moment = (sf[1], sf[5]) if axis == 1 else (sf[2], -sf[4])
        assert abs(shear / f - 1) < 1e-6 and abs(moment / (f * (length - x_mid)) - 1) < 1e-6, (j, sf)


def test_cantilever_torsion_angle():
    n, length, t = 6, 1.0, 0.1
    s, b = _cantilever(n, length, [("torque", (t, 0, 0))])
    sys, q = _static(s)
    _, p = _tip(sys, q, b)
    angle = 2 * np.arctan2(p[1], p[0])
    assert abs(angle / (t * length / GJ) - 1) < 1e-6, angle


def test_end_moment_rolls_the_cantilever_into_a_circle():
    # M = 2 pi EI / L about z: uniform curvature 2 pi / L, the tip back at the root turned by 2 pi.
    # Discretely: each element's chord keeps its length (no axial force) and turns by 2 pi / N, a
    # closed regular polygon: exact for every N.
    n, length = 12, 1.0
    m = 2 * np.pi * EIZ / length
    q = None
    for frac in np.linspace(0.125, 1.0, 8):  # load steps
        s, b = _cantilever(n, length, [("torque", (0, 0, frac * m))])
        sys, q = _static(s, q)
        r, p = _tip(sys, q, b)
        turn = 2 * np.arctan2(p[3], p[0]) - 2 * np.pi * frac
        assert abs((turn + np.pi) % (2 * np.pi) - np.pi) < 1e-8, (frac, turn)
    assert np.linalg.norm(r) < 1e-9 * length, r
    assert abs(abs(p[0]) - 1) < 1e-12  # turned by 2 pi: p = -(1, 0, 0, 0)
    # every node on the polygon's circle, radius L / (2 n sin(pi / n)) about (0, radius, 0)
    rad = length / (2 * n * np.sin(np.pi / n))
    for i in range(n + 1):
        x, _ = _node(sys, q, b, i)
        assert abs(np.hypot(x[0], x[1] - rad) - rad) < 1e-9 and abs(x[2]) < 1e-12


@pytest.mark.parametrize("n", [1, 2, 5])
def test_rigid_motion_carries_the_exact_inertia_for_any_number_of_elements(n):
    # the node bodies are the rigid segments around the nodes: spinning about z through the
    # start, T = w^2 / 2 (mu L^3 / 3 + j_z L) exactly (point masses at the nodes: 1 / (2 N^2) more)
    w, length = 3.0, 1.0
    s = ukflex.SpatialScene()
    s.beam("b", (0, 0, 0), (length, 0, 0), SEC, elements=n, velocity=(0, 0, 0), angular_velocity=(0, 0, w))
    sys = ukflex.System(s)
    out = ukflex.spatial_outputs(sys, np.array([0.0]), np.asarray(sys.q0)[None, :], np.asarray(sys.qd0)[None, :],
                                 reactions=False)
    exact = 0.5 * w * w * (2.0 * length**3 / 3 + 1.2e-4 * length)
    assert abs(out["kinetic_energy"][0] / exact - 1) < 1e-14
    assert np.allclose(out["angular_momentum"][0], [0, 0, w * (2.0 * length**3 / 3 + 1.2e-4 * length)], rtol=1e-14, atol=0)


def test_free_tumbling_beam_conserves_energy():
    s = ukflex.SpatialScene()
    sec = ukflex.CustomSection3(ea=2e4, ga_y=1e4, ga_z=1e4, gj=5.0, ei_y=8.0, ei_z=12.0, mass_per_length=1.0,
                                rotary_inertia=(2e-3, 1e-3, 1e-3))
    s.beam("b", (0, 0, 0), (1, 0.2, 0.1), sec, elements=4, velocity=(0.1, 0, 0), angular_velocity=(1.0, 4.0, 7.0))
    sys = ukflex.System(s)
    res = ukflex.simulate(sys, 1.0, method="DOPRI5", rtol=1e-10, atol=1e-12)
    out = ukflex.spatial_outputs(sys, res, reactions=False)
    e, ke = out["energy"], np.max(out["kinetic_energy"])
    drift = np.max(np.abs(e - e[0])) / ke
    assert drift < 1e-8, drift
    strain = res.sensors.energies()["strain"]
    assert np.max(strain) > 1e-4 * ke  # it deformed (centrifugal stretch and bending)
    assert np.allclose(strain + res.sensors.energies()["kinetic"], e, rtol=0, atol=1e-12 * ke)


@pytest.mark.parametrize("change,match", [
    (dict(elements=0), "elements must be between"),
    (dict(end=(0, 0, 0)), "zero length"),
    (dict(section=ukflex.CustomSection3(ea=-1, ga_y=1, ga_z=1, gj=1, ei_y=1, ei_z=1, mass_per_length=1,
                                        rotary_inertia=(2, 1, 1))), "section ea"),
    (dict(section=ukflex.CustomSection3(ea=1, ga_y=1, ga_z=1, gj=1, ei_y=1, ei_z=1, mass_per_length=1,
                                        rotary_inertia=(3, 1, 1))), "triangle"),
    (dict(section=ukflex.Circular(0.0), density=1, youngs_modulus=1, poisson_ratio=0.3), "diameter"),
    (dict(section=ukflex.Rectangular(0.1, -0.1), density=1, youngs_modulus=1, poisson_ratio=0.3), "height"),
    (dict(section=ukflex.Circular(0.1), youngs_modulus=1, poisson_ratio=0.3), "needs density"),
    (dict(section=ukflex.Circular(0.1), density=1, youngs_modulus=1), "exactly one of"),
    (dict(section=SEC, density=7800.0), "custom3"),
    (dict(end=(float("nan"), 0, 0)), "finite"),
    (dict(y_axis=(1, 0, 0)), "parallel"),
])
def test_bad_input_is_refused_by_name(change, match):
    kw = dict(start=(0, 0, 0), end=(1, 0, 0), section=SEC, elements=2)
    kw.update(change)
    s = ukflex.SpatialScene()
    with pytest.raises(InvalidSceneError, match=match):
        s.beam("b", kw.pop("start"), kw.pop("end"), kw.pop("section"), **kw)
        ukflex.System(s)


def test_flexible_pendulum_against_the_modal_body():
    # the 3D flexible pendulum (spherical joint at the end, spin 3 rad/s about z, gravity -z) of
    # docs/spatial-flexible.md, built with the beam and with the modal body of the same bar from
    # a solid FE model: the tips agree to a fifth of the elastic part of the motion (0.24 L x 1e-3
    # at E = 2.1 GPa, `python -m studies spatial-beam-pendulum`: the linear modal body has no
    # stress stiffening, and the solid's clamped face is 0.3 % stiffer in the first mode); the
    # beam conserves energy with gravity and the joint
    from studies import spatial_beam_pendulum as sbp

    t = np.linspace(0.0, sbp.T_END, 31)
    data = sbp.modal((20, 2, 2), 8)
    ref, _ = sbp.ukflex_tip(data, t, **sbp.RUN)
    elastic = np.max(np.linalg.norm(ref - sbp.rigid_tip(data, t), axis=1))
    tip, _ = sbp.beam_tip(5, t)
    gap = np.max(np.linalg.norm(tip - ref, axis=1))
    assert elastic > 3e-4 and gap < 0.3 * elastic, (gap, elastic)
    s = ukflex.SpatialScene(gravity=sbp.GRAVITY)
    b = s.beam("bar", (0, 0, 0), (sbp.LENGTH, 0, 0), ukflex.Rectangular(sbp.SIDE, sbp.SIDE), elements=5, density=sbp.RHO,
               youngs_modulus=sbp.E, poisson_ratio=sbp.NU, angular_velocity=sbp.OMEGA0)
    s.spherical(s.ground.marker((0, 0, 0)), b.node(0))
    sys = ukflex.System(s)
    res = ukflex.simulate(sys, 0.1, method="DOPRI5", rtol=1e-10, atol=1e-12)
    out = ukflex.spatial_outputs(sys, res, reactions=False)
    e = out["energy"]
    assert np.max(np.abs(e - e[0])) < 1e-8 * np.max(out["kinetic_energy"])


def test_revolute_at_a_node_keeps_the_swing_in_its_plane():
    # a beam hinged at its first node about world y, welded at its last node to a rigid3 tip mass,
    # released horizontal under gravity: it swings in the x z plane, bends, and keeps its energy
    s = ukflex.SpatialScene(gravity=(0, 0, -9.81))
    b = s.beam("b", (0, 0, 0), (0.5, 0, 0), ukflex.Circular(0.01), elements=3, density=7850.0, youngs_modulus=2e9,
               shear_modulus=7.7e8)
    tip = s.rigid_body("tip", 0.05, (1e-5, 1e-5, 1e-5), position=(0.5, 0, 0))
    s.revolute(s.ground.marker((0, 0, 0), z=(0, 1, 0)), b.node(0, z=(0, 1, 0)), name="hinge")
    s.fixed(b.node(-1), tip.marker((0, 0, 0)), name="weld")
    sys = ukflex.System(s)
    res = ukflex.simulate(sys, 0.2, method="DOPRI5", rtol=1e-10, atol=1e-12, t_eval=np.linspace(0, 0.2, 21))
    q = np.asarray(res.q)
    ys = [q[7 * k + 1] for k in range(len(sys.body_names))]
    assert np.max(np.abs(ys)) < 1e-10
    assert np.min(q[7 * sys.body_names.index("tip") + 2]) < -0.05  # it fell
    out = ukflex.spatial_outputs(sys, res, reactions=False)
    e = out["energy"]
    assert np.max(np.abs(e - e[0])) < 1e-8 * np.max(out["kinetic_energy"])
    assert np.max(res.sensors.energies()["strain"]) > 1e-6 * np.max(out["kinetic_energy"])  # it bent


def test_spin_up_beam_stiffens_like_the_planar_ancf_cable():
    # Kane's spin-up (docs/spatial-flexible.md, `python -m studies spatial-beam-spin-up`): the 3D
    # beam on a driven rigid3 hub against the planar geometrically exact cable; both dip to
    # -0.571 m across and come back (a beam without geometric stiffening diverges). At 6 elements
    # the beam is 4.6e-3 m from the cable (second order: 1.3e-4 m at 32 elements)
    from studies import spatial_beam_spin_up as sbs

    t = np.linspace(0.0, sbs.T_END, 21)
    _, v_cable, _ = sbs.cable(t, 8)
    _, v, _ = sbs.beam3(t, 6)  # asserts the tip stays in its plane
    assert v_cable.min() < -0.5
    assert np.max(np.abs(v - v_cable)) < 6e-3, np.max(np.abs(v - v_cable))


def test_marker_at_a_material_point_between_nodes():
    # SpatialBeamRef.point(s): a marker on the node whose rigid segment holds the point, at its
    # offset along the axis. A force F (y) at a = 0.43 L (between nodes for N = 5 .. 40) of a
    # cantilever: the tip deflects by Timoshenko's F a^2 (3 L - a) / (6 EI) + F a / (kGA), the
    # point by F a^3 / (3 EI) + F a / (kGA). The point moves with its node's section, so it misses
    # the shear angle times its offset (this section is shear-flexible: F a / (kGA) is 40 % of the
    # point's deflection) and the curvature times the offset squared: measured -5.8 %, -3.6 %,
    # +1.7 %, -0.52 % at the point and -2.9 %, -1.9 %, +0.65 %, -0.25 % at the tip (N = 5, 10, 20,
    # 40; the offsets 0.03, 0.03, -0.02, 0.005; with a shear-rigid section second order: -0.084 %
    # at the point at N = 40)
    a, f = 0.43, 1e-4 * 3 * 2500.0
    errs = []
    for n in (5, 10, 20, 40):
        s = ukflex.SpatialScene()
        b = s.beam("b", (0, 0, 0), (1.0, 0, 0), SEC, elements=n)
        s.fixed(s.ground.marker((0, 0, 0)), b.node(0), name="clamp")
        m = b.point(a)
        k, off = int(m.body[2:-1]), m.point[0]
        assert abs(k / n + off - a) < 1e-12 and 0 < abs(off) <= 0.5 / n + 1e-12
        s.point_force(m, (0.0, f, 0.0))
        sys, q = _static(s)
        tip, _ = _tip(sys, q, b)
        r, p = _node(sys, q, b, k)
        point = r + off * ref.rotation(p)[:, 0]
        exact_tip = f * a * a * (3 - a) / (6 * EIZ) + f * a / GAY
        exact_point = f * a**3 / (3 * EIZ) + f * a / GAY
        errs.append((tip[1] / exact_tip - 1, point[1] / exact_point - 1))
    assert all(abs(et) < 0.04 and abs(ep) < 0.07 for et, ep in errs), errs
    assert abs(errs[-1][0]) < 4e-3 and abs(errs[-1][1]) < 8e-3, errs
    # on the beam only, named
    b = ukflex.SpatialScene().beam("b", (0, 0, 0), (2.0, 0, 0), SEC, elements=4)
    assert b.point(2.0).body == "b[4]" and b.point(0.0).point == (0.0, 0.0, 0.0)
    for bad in (-0.1, 2.1, float("nan")):
        with pytest.raises(ukflex.InvalidArgumentError) as e:
            b.point(bad)
        assert e.value.argument == "s"


def test_the_default_keeps_its_step_on_the_spinning_beam(monkeypatch):
    # RADAU5M's Newton matrices co-rotated with the beam's nodes (rust/integrate/radau_m/corotate.rs):
    # on Kane's spin-up (4 elements, rtol 1e-5) auto's fixed step of 0.12 s holds where one
    # matrix for the three stages cut it to a few ms at full speed (2,110 steps, 131 rejected,
    # before); the history within 1e-3 of the dip of a tight run at a sixth of the step (measured
    # 1.7e-4; that run is 4e-7 from RADAU5M at rtol 1e-9)
    from studies import spatial_beam_spin_up as sbs

    seen = {}
    run = ukflex.simulate

    def spy(*a, **kw):
        seen["res"] = run(*a, **kw)
        return seen["res"]

    monkeypatch.setattr(ukflex, "simulate", spy)
    t = np.linspace(0.0, sbs.T_END, 41)
    _, v, _ = sbs.beam3(t, 4, rtol=1e-5)
    res = seen["res"]
    assert res.method == "RADAU5M" and res.extra["auto"]["step"] > 0.1, res.extra["auto"]
    assert res.extra["naccept"] < 600 and res.extra["nreject"] < 30, res.extra
    _, v_ref, _ = sbs.beam3(t, 4, method="RADAU5M", step=0.02, rtol=1e-9)
    assert np.max(np.abs(v - v_ref)) < 1e-3 * np.max(np.abs(v_ref)), np.max(np.abs(v - v_ref))
