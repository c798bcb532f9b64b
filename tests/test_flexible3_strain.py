"""The quadratic (Green-Lagrange) strain of the spatial modal body (docs/spatial-flexible.md,
"Quadratic strain"): the tension-stiffened cantilever against its closed form, the energy of an
undamped free body, bad input. The force and its tangent against differences of the cubic
energy: ``rust/body/flexible3_tests.rs``."""

import math

import numpy as np
import pytest

import ukflex
from ukflex import fe3
from ukflex.errors import InvalidArgumentError, InvalidSceneError

L, A, RHO, E, NU = 1.0, 0.02, 7850.0, 2.1e11, 0.3


def _bar(cells=(24, 2, 2), modes=6, **kw):
    return fe3.from_mesh(fe3.bar_mesh(L, A, A, cells), density=RHO, youngs_modulus=E, poisson_ratio=NU, modes=modes,
                         interfaces={"A": lambda x: x[:, 0] < 1e-9, "B": lambda x: x[:, 0] > L - 1e-9},
                         frame=("clamped", "A"), reduction="craig-bampton", **kw)


@pytest.fixture(scope="module")
def bars():
    return _bar(), _bar(quadratic_strain=True)


def _tip(data, tension, p):
    """Static tip deflection (z) of the cantilever under the axial tension and the tip load."""
    s = ukflex.SpatialScene()
    bar = s.flexible_body("bar", data)
    s.fixed(s.ground.marker((0, 0, 0)), bar.interface("A"), name="clamp")
    s.point_force(bar.interface("B"), (tension, 0.0, p), name="tip")
    eq = ukflex.System(s).equilibrium()
    phi = np.asarray(data.interfaces["B"].phi)
    return float((phi.T @ np.asarray(eq.q)[7:])[2])


def test_tension_stiffened_cantilever_against_the_closed_form(bars):
    # w_tip = P L / T (1 - tanh(k L) / (k L)), k = sqrt(T / EI) (-> P L^3 / (3 EI) as T -> 0)
    linear, quad = bars
    ei = E * A ** 4 / 12
    w0 = _tip(linear, 0.0, 1.0)
    # no tension: the solid's cantilever, 0.66 % stiffer than Euler-Bernoulli's on this mesh
    assert w0 == pytest.approx(L ** 3 / (3 * ei), rel=1e-2)
    # no tension and a large tip load (w = L / 34): the quadratic strain changes nothing to 1e-5
    # (the geometrically exact beam: (w / L)^2 effects); the cubic energy alone softens it by
    # 0.26 %, the quartic one without the condensation locks it by 1.1 % at P = 5 (docs)
    assert _tip(quad, 0.0, 50.0) == pytest.approx(50.0 * w0, rel=5e-5)
    for kl, tol in ((1.0, 1.5e-2), (2.0, 3.5e-2)):
        t = kl ** 2 * ei / L ** 2
        want = L / t * (1 - math.tanh(kl) / kl)
        # measured -1.17 % and -2.82 % (the mesh's -0.66 % included; the condensed shape
        # change is first order in T: docs)
        got = _tip(quad, t, 1.0)
        assert got == pytest.approx(want, rel=tol), (kl, got / want - 1)
        # the linear body ignores the tension: 38 % and 151 % too soft
        assert _tip(linear, t, 1.0) > 1.3 * want


def test_undamped_free_body_conserves_energy(bars):
    # a free bar (no joint), spinning and vibrating: the cubic strain energy exercised
    _, quad = bars
    s = ukflex.SpatialScene()
    n = quad.n_modes
    q0 = np.zeros(n)
    q0[0] = 2e-4  # face B's axial stretch (m) and transverse displacement
    q0[2] = 1e-2
    s.flexible_body("bar", quad, angular_velocity=(0.0, 5.0, 20.0), elastic=q0.tolist(), elastic_rates=(0.1,) + (0.0,) * (n - 1))
    system = ukflex.System(s)
    res = ukflex.simulate(system, 0.02, method="DOPRI5", rtol=1e-10, atol=1e-12)
    assert res.status == 0, res.message
    out = ukflex.spatial_outputs(system, res)
    e, ke = out["energy"], np.max(out["kinetic_energy"])
    strain = res.sensors.energies()["strain"]
    lin = np.array([0.5 * x @ quad.k_ff @ x for x in np.asarray(res.q)[7:].T])
    # the cubic part is well above the drift it must not cause
    assert np.max(np.abs(strain - lin)) > 1e-4 * ke
    assert np.max(np.abs(e - e[0])) < 1e-8 * ke, np.max(np.abs(e - e[0])) / ke


def test_quadratic_strain_bad_input(bars):
    with pytest.raises(InvalidArgumentError, match="quadratic_strain"):
        _bar(cells=(4, 1, 1), modes=2, quadratic_strain="yes")
    with pytest.raises(InvalidArgumentError, match="quadratic strain needs a clamped frame"):
        fe3.from_mesh(fe3.bar_mesh(L, A, A, (4, 1, 1)), density=RHO, youngs_modulus=E, poisson_ratio=NU, modes=2,
                      interfaces={"A": lambda x: x[:, 0] < 1e-9}, quadratic_strain=True)
    with pytest.raises(InvalidArgumentError, match="count the inertia loads' stress twice"):
        _bar(cells=(4, 1, 1), modes=2, quadratic_strain=True, stress_stiffening=True)
    d = _bar(cells=(4, 1, 1), modes=2, quadratic_strain=True)
    n = d.n_modes
    assert d.quadratic_strain.shape == (n, n, n)
    body = d.to_dict()

    def scene(**change):
        s = ukflex.SpatialScene()
        s.flexible_body("bar", {**body, **change})
        return ukflex.System(s)

    assert scene().body_info("bar")["quadratic_strain"] is True
    with pytest.raises(InvalidSceneError, match="quadratic_strain must hold one n x n matrix per mode"):
        scene(quadratic_strain=body["quadratic_strain"][:-1])
    with pytest.raises(InvalidSceneError, match="quadratic_strain needs quadratic_strain_quartic"):
        scene(quadratic_strain_quartic=None)
    bad = np.array(body["quadratic_strain"])
    bad[1, 0, 1] += 1.0
    with pytest.raises(InvalidSceneError, match=r"quadratic_strain\[1\] must be symmetric"):
        scene(quadratic_strain=bad.tolist())
    bad[1, 0, 1] = np.nan
    with pytest.raises(InvalidSceneError, match=r"quadratic_strain\[1\]\[0\]\[1\] must be finite"):
        scene(quadratic_strain=bad.tolist())


def test_cubic_terms_agree_with_the_assembled_geometric_stiffness():
    # G_k (scikit-fem's assembly of the geometric stiffness) = int sigma(phi_k) : B_ij with the
    # B_ij the quartic tensor is built from; H without the condensation: 1/2 int E_nl : C : E_nl,
    # and the condensation lowers the energy (K_c^+ is positive)
    from ukflex.model import fe3_stiffening as st
    from ukflex.model.fe3 import _solid

    mesh = fe3.bar_mesh(L, A, A, (6, 1, 1))
    solid = _solid(mesh, density=RHO, youngs_modulus=E, poisson_ratio=NU)
    d = _bar(cells=(6, 1, 1), modes=3)
    basis = d.info["modes"]
    n = basis.shape[1]
    held = np.zeros(3 * solid.nodes.shape[0], dtype=bool)
    for i in np.nonzero(solid.nodes[:, 0] < 1e-9)[0]:
        held[3 * i:3 * i + 3] = True
    g, h = st.quadratic_strain(solid, basis, held)
    grads = np.stack([np.stack([np.stack(solid.basis.interpolate(basis[a::3, i]).grad) for a in range(3)]) for i in range(n)]).reshape(n, 3, 3, -1)
    a_ = np.einsum("iakp,jalp->ijklp", grads, grads)
    b = 0.5 * (a_ + a_.transpose(0, 1, 3, 2, 4))
    eps = 0.5 * (grads + grads.transpose(0, 2, 1, 3))
    sig = 2 * solid.mu * eps + solid.lam * np.einsum("iaap->ip", eps)[:, None, None, :] * np.eye(3)[None, :, :, None]
    dx = np.asarray(solid.basis.dx).reshape(-1)
    assert np.abs(g - np.einsum("kabp,ijabp,p->kij", sig, b, dx)).max() < 1e-10 * np.abs(g).max()
    q = np.random.default_rng(0).normal(size=n) * 1e-3
    enl = 0.5 * np.einsum("i,j,ijabp->abp", q, q, b)
    v4 = np.einsum("p,abp,abp->", dx, solid.mu * enl, enl) + 0.5 * solid.lam * np.einsum("p,p->", dx, np.einsum("aap->p", enl) ** 2)
    v4c = 0.125 * np.einsum("ijkl,i,j,k,l->", h.reshape(n, n, n, n), q, q, q, q)
    assert 0.0 < v4c < v4


def test_condensation_compliance_every_path_against_a_dense_solve():
    """``R^T K^-1 R`` of the condensation (issue 31): the banded Cholesky of a narrow band (a
    chain), SuperLU for a wide band (random couplings) and for an indefinite ``K`` (the Cholesky
    fails), each against the dense solve."""
    import scipy.sparse as sp

    from ukflex.model.fe3_stiffening import _compliance

    rng = np.random.default_rng(3)
    n = 400
    chain = sp.diags([-np.ones(n - 1), 4.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    wide = sp.random(n, n, density=0.02, random_state=4)
    wide = wide + wide.T + 10.0 * sp.eye(n)
    indefinite = chain - 3.0 * sp.eye(n)  # eigenvalues 1 - 2 cos(.) in (-1, 3)
    r = rng.standard_normal((n, 7))
    for k in (chain, wide, indefinite):
        dense = r.T @ np.linalg.solve(k.toarray(), r)
        assert np.allclose(_compliance(k, r), dense, rtol=1e-9, atol=1e-9 * np.abs(dense).max())
