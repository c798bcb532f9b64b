"""Nonlinear (second-order, element-averaged) axial strain of the FFRF beam: the core against the
independent NumPy reference, its tangent stiffness against differences, energy conservation, and
the strain-rate damping that lets a bent beam foreshorten freely."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import Circular, Scene, scenes
from ukflex.reference import ReferenceModel

STEEL = dict(density=7834.56, youngs_modulus=2.06843e11, poisson_ratio=0.285, shear_factor=0.8)


def _beam_scene(theory, elements, strain="nonlinear", damping=0.0, frame="pinned-pinned", material=STEEL,
                length=0.3, diameter=0.006):
    s = Scene(gravity=(0.0, -9.81))
    kw = dict(material) if theory == "timoshenko" else {k: v for k, v in material.items() if k in ("density", "youngs_modulus")}
    b = s.beam("rod", length=length, elements=elements, theory=theory, strain=strain, section=Circular(diameter),
               frame=frame, damping=damping, **kw)
    s.revolute(s.ground.point(0, 0), b.at(0.0), name="pivot")
    return s


def _random_state(system, rng, elastic=2e-3):
    q = np.asarray(system.q0, float).copy()
    qd = rng.normal(size=system.n_coords)
    q[2] = rng.uniform(-math.pi, math.pi)
    sl = system.elastic_slice("rod")
    q[sl] = elastic * rng.normal(size=sl.stop - sl.start)
    return q, qd


@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
@pytest.mark.parametrize("damping", [0.0, 1e-3])
def test_forces_and_energy_match_the_numpy_reference(theory, damping):
    system = _beam_scene(theory, 3, damping=damping).build()
    ref = ReferenceModel(system.description)
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, qd = _random_state(system, rng)
        Qc, Qr = np.asarray(system.Q(0.0, q, qd)), ref.Q(0.0, q, qd)
        assert np.max(np.abs(Qc - Qr)) <= 1e-12 * np.max(np.abs(Qr))
        Vc, Vr = system.potential_energy(q), ref.potential_energy(q)
        assert abs(Vc - Vr) <= 1e-12 * max(abs(Vr), 1.0)
        sl = system.elastic_slice("rod")
        N_ref = ref.body("rod").axial_force(q[sl])
        np.testing.assert_allclose(system.axial_forces("rod", q), N_ref, rtol=1e-12, atol=1e-12 * np.max(np.abs(N_ref)))


def test_nonlinear_strain_changes_the_forces():
    """The check above would pass for a model that ignored the strain option: make sure the
    second-order term is really there (and equal to the reference's)."""
    lin = _beam_scene("euler-bernoulli", 3, strain="linear").build()
    nl = _beam_scene("euler-bernoulli", 3).build()
    q, qd = _random_state(nl, np.random.default_rng(3), elastic=2e-2)
    dQ = np.asarray(nl.Q(0.0, q, qd)) - np.asarray(lin.Q(0.0, q, qd))
    assert np.max(np.abs(dQ)) > 1e-3 * np.max(np.abs(lin.Q(0.0, q, qd)))


@pytest.mark.parametrize("strain", ["linear", "nonlinear"])
@pytest.mark.parametrize("theory", ["euler-bernoulli", "timoshenko"])
def test_tangent_stiffness_matches_central_differences(strain, theory):
    system = _beam_scene(theory, 4, strain=strain).build()
    sl = system.elastic_slice("rod")
    rng = np.random.default_rng(11)
    q, _ = _random_state(system, rng, elastic=1e-2)
    qd = np.zeros(system.n_coords)
    K = np.asarray(system.tangent_stiffness("rod", q))[3:, 3:]  # the elastic block
    nf = sl.stop - sl.start
    Kfd = np.empty((nf, nf))
    for j in range(nf):
        h = 1e-7
        qp, qm = q.copy(), q.copy()
        qp[sl.start + j] += h
        qm[sl.start + j] -= h
        Kfd[:, j] = -(np.asarray(system.Q(0.0, qp, qd))[sl] - np.asarray(system.Q(0.0, qm, qd))[sl]) / (2 * h)
    assert np.max(np.abs(K - Kfd)) <= 1e-6 * np.max(np.abs(K))
    assert np.max(np.abs(K - K.T)) <= 1e-12 * np.max(np.abs(K))
    if strain == "nonlinear":  # the geometric part is there at this deformation
        K_lin = np.asarray(system.beam_matrices("rod")[1])
        assert np.max(np.abs(K - K_lin)) > 1e-4 * np.max(np.abs(K_lin))


def test_free_pendulum_beam_conserves_energy():
    """An undamped flexible pendulum released horizontally (large rotation, bending, axial
    stretch): T + V stays constant to the integration tolerance.  A polymer rod (E = 2 GPa),
    so that an explicit method at rtol 1e-10 needs a few 10^4 steps, not 10^6."""
    polymer = dict(density=1200.0, youngs_modulus=2e9)
    system = _beam_scene("euler-bernoulli", 4, material=polymer, length=0.5, diameter=0.01).build()
    t = np.linspace(0.0, 1.0, 201)
    res = ukflex.simulate(system, 1.0, method="DOPRI5", rtol=1e-10, t_eval=t)
    assert res.success
    T = np.array([system.kinetic_energy(q, qd) for q, qd in zip(res.q.T, res.qd.T)])
    E = res.energy()
    assert np.max(np.abs(E - E[0])) / np.max(T) <= 1e-8
    # it did swing and bend
    assert np.max(T) > 0.1 and np.max(np.abs(res.q[system.elastic_slice("rod")])) > 1e-5


def test_bent_cantilever_foreshortens_freely_and_settles_at_the_linear_deflection():
    """Strain-rate damping acts on the averaged strain: a bent cantilever (free end) carries no
    axial force at rest and settles where linear theory says, its tip drawn in by the
    foreshortening ``-1/2 int v'^2``.  (Damping the linear ``u'`` rate instead keeps a viscous
    tension that stiffens the beam for seconds.)"""
    P, L = -2.0, 1.0
    scene = scenes.cantilever(length=L, elements=4, tip_force=(0.0, P), damping=2.0 / 52.0)
    system = scene.build()
    assert system.body_info("beam")["strain"] == "nonlinear"
    res = ukflex.simulate(system, 0.8, rtol=1e-6, atol=1e-10, t_eval=[0.6, 0.8])
    u, v = res.beam_displacement("beam", 1.0)
    EI = 2.1e11 * 0.02 * 0.01**3 / 12
    expected = P * L**3 / (3 * EI) + (-7850.0 * 0.02 * 0.01 * 9.81) * L**4 / (8 * EI)
    assert v[-1] == pytest.approx(expected, rel=1e-3)
    assert abs(v[-1] - v[0]) < 1e-4 * abs(expected)  # settled as fast as the linear model
    assert np.max(np.abs(system.axial_forces("beam", res.q[:, -1]))) < 1e-6 * abs(P)
    assert -u[-1] == pytest.approx(0.5 * 1.2 * (expected / L) ** 2 * L, rel=0.2)  # ~ (1/2) int v'^2, v' ~ 1.2-1.5 v/L


def test_slider_crank_option_and_default():
    assert scenes.slider_crank().to_dict()["bodies"][1]["strain"] == "linear"  # the paper's model
    assert scenes.slider_crank(strain="nonlinear").build().body_info("coupler")["strain"] == "nonlinear"
    s = Scene()
    s.beam("b", length=1.0, section=Circular(0.01), density=1.0, youngs_modulus=1.0, theory="euler-bernoulli")
    assert s.to_dict()["bodies"][0]["strain"] == "nonlinear"  # the core's default
    with pytest.raises(ukflex.InvalidSceneError, match="body 'c'.*strain.*unknown variant 'cubic'"):
        s.beam("c", length=1.0, section=Circular(0.01), density=1.0, youngs_modulus=1.0,
               theory="euler-bernoulli", strain="cubic")
