"""The general flexible body (rust/body/flexible.rs): a beam given by its invariants computed in
NumPy by quadrature (ukflex.reference.fe_invariants) reproduces the built-in beam's mass matrix,
forces and constraint Jacobian; the FE builders (ukflex.fe) against an independent quadrature;
named errors for bad input."""

import numpy as np
import pytest

import ukflex
from ukflex import FlexibleData, InterfacePoint, Rectangular, Scene
from ukflex.reference import fe_invariants as fi

L, N, RHO, E, B, H, NU = 0.3048, 3, 2770.0, 7.1e10, 0.0127, 0.0127 / 4, 0.33
AREA, I2 = B * H, B * H**3 / 12
KG = 10 * (1 + NU) / (12 + 11 * NU) * E / (2 * (1 + NU))


def beam_data(nonlinear=False):
    inv = fi.beam_invariants(L, N, RHO, E, AREA, I2, shear_stiffness=KG, rotary_inertia=True, nonlinear=nonlinear)
    markers = {name: InterfacePoint(m["point"], m["displacement"], m["rotation"]) for name, m in inv.pop("markers").items()}
    return FlexibleData(markers=markers, **inv)


def pair(strain):
    """The same pinned beam (pin at xi = 0 to the ground, point force at the tip) as a built-in
    beam and as a flexible body."""
    out = []
    for kind in ("beam", "flexible"):
        s = Scene(gravity=(0.0, -9.81))
        if kind == "beam":
            b = s.beam("b", length=L, elements=N, section=ukflex.Rectangular(B, H), density=RHO, youngs_modulus=E,
                       poisson_ratio=NU, shear_factor=10 * (1 + NU) / (12 + 11 * NU), strain=strain)
            a0, a1 = b.at(0.0), b.at(1.0)
        else:
            b = s.flexible_body("b", beam_data(strain == "nonlinear"), strain=strain)
            a0, a1 = b.marker("xi=0"), b.marker("xi=1")
        s.revolute(s.ground.point(0.0, 0.0), a0)
        s.angle_driver(a1, ukflex.ConstantSpeed(1.0))
        out.append(s.build(correct=False))
    return out


@pytest.mark.parametrize("strain", ["linear", "nonlinear"])
def test_flexible_beam_reproduces_the_builtin_beam(strain):
    beam, flex = pair(strain)
    rng = np.random.default_rng(3)
    n = beam.core.n_coords
    assert flex.core.n_coords == n
    for _ in range(3):
        q = np.concatenate([rng.normal(size=3), 1e-3 * rng.normal(size=n - 3)])
        qd = np.concatenate([rng.normal(size=3), 0.3 * rng.normal(size=n - 3)])
        mb, mf = beam.core.M(q), flex.core.M(q)
        assert np.max(np.abs(mb - mf)) <= 1e-12 * np.max(np.abs(mb))
        fb, ff = beam.core.Q(0.0, q, qd), flex.core.Q(0.0, q, qd)
        assert np.max(np.abs(fb - ff)) <= 1e-12 * np.max(np.abs(fb)), np.max(np.abs(fb - ff)) / np.max(np.abs(fb))
        ab, af = beam.core.A(q), flex.core.A(q)
        assert np.max(np.abs(ab - af)) <= 1e-12 * np.max(np.abs(ab))
        assert abs(beam.core.potential_energy(q) - flex.core.potential_energy(q)) <= 1e-12 * abs(beam.core.potential_energy(q))
        ab, af = beam.core.qdd(0.0, q, qd), flex.core.qdd(0.0, q, qd)
        assert np.max(np.abs(ab - af)) <= 1e-10 * np.max(np.abs(ab))


def test_numpy_quadrature_matches_the_rust_beam_integrals():
    beam, _ = pair("linear")
    m_ff, k_ff = beam.beam_matrices("b")
    d = beam_data()
    assert np.max(np.abs(m_ff - d.m_ff)) <= 1e-12 * np.max(np.abs(m_ff))
    assert np.max(np.abs(k_ff - d.k_ff)) <= 1e-12 * np.max(np.abs(k_ff))


def test_flexible_tangent_stiffness_matches_finite_differences():
    _, flex = pair("nonlinear")
    n = flex.core.n_coords
    rng = np.random.default_rng(5)
    q = np.concatenate([np.zeros(3), 1e-3 * rng.normal(size=n - 3)])
    kt = flex.core.tangent_stiffness("b", q)
    h = 1e-7
    kfd = np.zeros((n - 3, n - 3))
    for j in range(n - 3):
        qp, qm = q.copy(), q.copy()
        qp[3 + j] += h
        qm[3 + j] -= h
        kfd[:, j] = -(flex.core.Q(0.0, qp, np.zeros(n)) - flex.core.Q(0.0, qm, np.zeros(n)))[3:] / (2 * h)
    assert np.allclose(kt[3:, 3:] if kt.shape[0] == n else kt, kfd, rtol=1e-5, atol=1e-6 * np.max(np.abs(kfd)))


# -------------------------------------------------------------------------------- named errors
def _data(**change):
    d = beam_data()
    for k, v in change.items():
        setattr(d, k, v)
    return d


@pytest.mark.parametrize(
    "change, exc, match",
    [
        (dict(m_ff="unsym"), ukflex.InvalidSceneError, "m_ff must be symmetric"),
        (dict(m_ff="indef"), ukflex.SingularMassError, "m_ff is not positive definite"),
        (dict(s_bar="huge"), ukflex.SingularMassError, "do not belong to one mass distribution"),
        (dict(k_ff="rigid"), ukflex.InvalidSceneError, "rigid-body modes"),
        (dict(k_ff="size"), ukflex.InvalidSceneError, "must be 8 x 8|n_f"),
        (dict(s_tilde="sym"), ukflex.InvalidSceneError, "antisymmetric"),
        (dict(markers="size"), ukflex.InvalidSceneError, "displacement must be 2 x n_f"),
    ],
)
def test_bad_flexible_bodies_raise_named_errors(change, exc, match):
    d = beam_data()
    (key, how), = change.items()
    if key == "m_ff":
        m = d.m_ff.copy()
        if how == "unsym":
            m[0, 1] += 0.1 * np.max(np.abs(m))
        else:
            m[0, 0] = -m[0, 0]
        d.m_ff = m
    elif key == "s_bar":
        d.s_bar = d.s_bar * 1e3
    elif key == "k_ff":
        if how == "rigid":
            # add back a rigid-body mode: a null vector of K
            v = np.zeros(d.n_f)
            v[0] = 1.0
            k = d.k_ff.copy()
            k[0, :] = 0.0
            k[:, 0] = 0.0
            d.k_ff = k
        else:
            d.k_ff = d.k_ff[:-1, :-1]
    elif key == "s_tilde":
        d.s_tilde = np.abs(d.s_tilde) + np.abs(d.s_tilde).T + np.eye(d.n_f) * 1e-9
    elif key == "markers":
        d.markers["xi=1"] = InterfacePoint((L, 0.0), np.zeros((2, d.n_f + 1)))
    with pytest.raises(exc, match=match):
        Scene().flexible_body("b", d)


def test_markers_that_do_not_fit_are_refused():
    s = Scene()
    b = s.flexible_body("b", beam_data())
    with pytest.raises(ukflex.InvalidSceneError, match="no interface point"):
        s.revolute(s.ground.point(0, 0), ukflex.Marker("b", point=(0.1, 0.0)))
    with pytest.raises(ukflex.InvalidSceneError, match="not by xi"):
        s.revolute(s.ground.point(0, 0), ukflex.Marker("b", xi=0.5))
    with pytest.raises(ukflex.InvalidSceneError, match="no interface point 'tip'"):
        b.marker("tip")


# -------------------------------------------------------------------------------- FE builders
def _plate_mesh(nx=12, ny=3, length=0.3, height=0.02):
    xs, ys = np.linspace(0, length, nx + 1), np.linspace(-height / 2, height / 2, ny + 1)
    pts = np.array([(x, y) for y in ys for x in xs])
    tris = []
    for j in range(ny):
        for i in range(nx):
            a = j * (nx + 1) + i
            b, c, d = a + 1, a + nx + 1, a + nx + 2
            tris += [(a, b, d), (a, d, c)]
    return pts, np.array(tris)


@pytest.mark.parametrize("frame,reduction", [("mean-axis", "modes"), ("pinned-pinned", "modes"),
                                             ([("A", "x"), ("A", "y"), ("B", "y")], "modes"),
                                             ("pinned-pinned", "craig-bampton")])
def test_mesh_invariants_match_an_independent_quadrature(frame, reduction):
    fe = pytest.importorskip("ukflex.model.fe")
    pytest.importorskip("skfem")
    pts, tris = _plate_mesh()
    left = [i for i, p in enumerate(pts) if p[0] == 0.0]
    right = [i for i, p in enumerate(pts) if abs(p[0] - 0.3) < 1e-12]
    data = fe.from_mesh(pts, cells=tris, thickness=0.01, density=7800.0, youngs_modulus=2e11, poisson_ratio=0.3,
                        interfaces={"A": left, "B": right}, modes=4, frame=frame, reduction=reduction)
    ref = fi.triangle_invariants(pts, tris, 0.01, 7800.0, data.info["modes"])
    for key in ("mass", "inertia", "s_bar", "s_u0", "s_ju0", "s_tilde", "m_ff"):
        a, b = np.asarray(getattr(data, key), dtype=float), np.asarray(ref[key], dtype=float)
        scale = max(np.max(np.abs(b)), 1e-300)
        assert np.max(np.abs(a - b)) <= 1e-12 * max(scale, np.max(np.abs(np.asarray(ref["m_ff"])))), key
    assert np.allclose(data.com, ref["com"], atol=1e-14)
    if frame == "mean-axis":
        # free-free modes: mean-axis conditions S_bar q = 0, s_ju0 . q = 0
        assert np.max(np.abs(data.s_bar)) < 1e-10 * np.sqrt(data.mass)
        assert np.max(np.abs(data.s_ju0)) < 1e-10 * np.sqrt(data.mass) * 0.3
    else:
        # the reference conditions hold: A does not move, B moves only along x
        assert np.max(np.abs(data.markers["A"].displacement)) < 1e-12
        assert np.max(np.abs(data.markers["B"].displacement[1])) < 1e-12
    # the body builds (validation passes); its lowest frequency is the first bending mode, above
    # the slender-beam value (a conforming mesh is stiffer; linear triangles lock in bending)
    s = Scene()
    s.flexible_body("plate", data)
    f0 = data.info["frequencies"][0]
    ei, rho_a = 2e11 * 0.01 * 0.02**3 / 12, 7800.0 * 0.01 * 0.02
    w_pinned, w_free = (np.pi / 0.3) ** 2 * np.sqrt(ei / rho_a), (4.730 / 0.3) ** 2 * np.sqrt(ei / rho_a)
    expect = w_free if frame == "mean-axis" else w_pinned
    assert 0.98 * expect < f0 < 2.0 * expect, (f0, expect)


def test_flexible_body_round_trips_through_a_toml_scene_file():
    from ukflex.model import scenefile
    from ukflex.reference import testset_crank as ts
    from studies import simeon_crank as sc

    scene = sc.crank_scene(nonlinear=True)
    again = scenefile.loads(scenefile.dumps(scene)).scene
    a, b = scene.build(correct=False), again.build(correct=False)
    q0, qd0 = sc.crank_state(a, ts.Y0[:14])
    assert np.array_equal(a.core.qdd(0.0, q0, qd0), b.core.qdd(0.0, q0, qd0))


def test_holed_link_example_loads_runs_and_draws(tmp_path):
    import os

    from ukflex.model import scenefile
    from ukflex import simulate
    from ukflex.results.animate import MechanismDrawer

    path = os.path.join(os.path.dirname(__file__), os.pardir, "examples", "slider_crank_holed_link.toml")
    system = scenefile.load(path).build()
    res = simulate(system, 0.005, method="DOPRI5", rtol=1e-6)
    assert res.success and res.max_residual("position") < 1e-8
    drawer = MechanismDrawer(system, deform_scale=10.0)
    q = np.asarray(system.q0, dtype=float)
    outline = drawer.body_polyline(q, "link")
    assert outline.shape == (7, 2)  # six interface points, closed
    assert np.allclose(drawer.joint_positions(q)[1], outline[0])  # crank pin at interface A


# -------------------------------------------------------------------------------- modal derivatives
def _static_midpoint_deflection(data, force):
    """Nonlinear static equilibrium ``K q + k3 q q / 2 + k4 q q q / 6 = f`` (Newton) under a
    transverse force at marker "M"; returns its deflection."""
    k3, k4 = np.asarray(data.k3), np.asarray(data.k4)
    row = np.asarray(data.markers["M"].displacement)[1]
    q = np.zeros(data.n_f)
    for _ in range(60):
        r = data.k_ff @ q + np.einsum("ijk,j,k->i", k3, q, q) / 2 + np.einsum("ijkl,j,k,l->i", k4, q, q, q) / 6 - force * row
        kt = data.k_ff + np.einsum("ijk,k->ij", k3, q) + np.einsum("ijkl,k,l->ij", k4, q, q) / 2
        dq = np.linalg.solve(kt, -r)
        q += dq
        if np.linalg.norm(dq) <= 1e-14 * np.linalg.norm(q):
            break
    linear = force * row @ np.linalg.solve(data.k_ff, row)
    return row @ q, linear


def test_modal_derivatives_let_the_reduced_coupler_shorten():
    """The paper's coupler (pinned-pinned, free axial end) under a transverse midpoint load of a
    deflection of 1 % of its length: the nodal model with nonlinear strain relaxes its membrane
    strain by axial shortening (nonlinear = linear deflection); two bending modes alone cannot
    shorten and lock (> 30 % stiffer); with their modal derivatives they shorten exactly."""
    from ukflex import fe
    from studies import flexible_coupler as fc

    nodal = fc.coupler_data(8, None, "nonlinear")
    v, lin = _static_midpoint_deflection(nodal, 85.0)
    assert abs(v - lin) <= 1e-9 * abs(lin)
    locked, lin2 = _static_midpoint_deflection(fe.reduce(nodal, 2), 85.0)
    assert locked < 0.7 * lin2
    enriched = fe.reduce(nodal, 2, modal_derivatives=True)
    assert enriched.n_f == 5  # two bending modes and the three (axial) derivatives
    v_md, lin_md = _static_midpoint_deflection(enriched, 85.0)
    assert abs(v_md - lin_md) <= 1e-8 * abs(lin_md)
    # the enriched basis's linear answer is the two modes' (the derivatives are axial)
    assert abs(lin_md - lin2) <= 1e-10 * abs(lin2)
    with pytest.raises(ukflex.InvalidArgumentError, match="k3"):
        fe.reduce(fc.coupler_data(8, None, "linear"), 2, modal_derivatives=True)
    with pytest.raises(ValueError, match="number of modes differentiated"):
        fe.reduce(nodal, 2, modal_derivatives=3)


def test_reduced_tensors_are_the_projection_of_the_nodal_ones():
    from ukflex import fe
    from studies import flexible_coupler as fc

    nodal = fc.coupler_data(4, None, "nonlinear")
    red = fe.reduce(nodal, 3, modal_derivatives=2)
    p = red.info["modes"]
    assert np.allclose(p.T @ nodal.m_ff @ p, np.eye(red.n_f), atol=1e-10)
    k4 = np.einsum("ijkl,ia,jb,kc,ld->abcd", nodal.k4, p, p, p, p)
    k3 = np.einsum("ijk,ia,jb,kc->abc", nodal.k3, p, p, p)
    assert np.max(np.abs(red.k4 - k4)) <= 1e-12 * np.max(np.abs(k4))
    assert np.max(np.abs(red.k3 - k3)) <= 1e-12 * np.max(np.abs(k3))
    # and the body builds with its nonlinear strain
    Scene().flexible_body("c", red, strain="nonlinear")


# -------------------------------------------------------------------------------- quadratic meshes
def test_quadratic_mesh_of_the_coupler_converges_to_the_timoshenko_beam():
    """Q2 quads do not lock: the coupler's plane-stress rectangle approaches the Timoshenko beam
    (shear factor of the rectangle, Cowper) under refinement; Q1 quads of the same mesh are far
    off (locking)."""
    pytest.importorskip("skfem")
    from studies import flexible_coupler as fc

    nu = fc.P["poisson_ratio"]
    beam = fc.beam_frequencies(32, 10 * (1 + nu) / (12 + 11 * nu), count=4)
    errs = []
    for nx in (8, 16):
        f = fc.mesh_coupler_data(nx, 1, order=2, modes=4).info["frequencies"] / (2 * np.pi)
        errs.append(np.abs(f[[0, 1, 2, 3]] - beam) / beam)
    assert np.all(errs[1] < errs[0] / 3)  # quadratic elements: error ~ h^2 or faster
    assert errs[1][0] < 1e-3 and errs[1][1] < 5e-3
    q1 = fc.mesh_coupler_data(16, 1, order=1, modes=1).info["frequencies"][0] / (2 * np.pi)
    assert q1 > 1.5 * beam[0]


def test_quadratic_mesh_invariants_of_a_rectangle():
    """P2 triangles: mass, centre of mass and inertia of the rectangle exactly; the chord-frame
    reference conditions hold; interfaces by a node predicate take the mid-edge nodes too."""
    fe = pytest.importorskip("ukflex.model.fe")
    pytest.importorskip("skfem")
    pts, tris = _plate_mesh(nx=6, ny=2)
    length, height, t, rho = 0.3, 0.02, 0.01, 7800.0
    ifs = {"A": lambda p: np.isclose(p[:, 0], 0.0), "B": lambda p: np.isclose(p[:, 0], length)}
    data = fe.from_mesh(pts, cells=tris, thickness=t, density=rho, youngs_modulus=2e11, poisson_ratio=0.3,
                        interfaces=ifs, modes=3, frame="pinned-pinned", order=2)
    m = rho * t * length * height
    assert abs(data.mass - m) <= 1e-12 * m
    assert np.allclose(data.com, (length / 2, 0.0), atol=1e-15)
    inertia = m * (length**2 + height**2) / 12
    assert abs(data.inertia - inertia) <= 1e-12 * inertia
    nodes = data.info["nodes"]
    assert nodes.shape[0] == 7 * 3 + (6 * 2 * 3 + 6 + 2)  # vertices + edges
    assert np.max(np.abs(data.markers["A"].displacement)) < 1e-12
    assert np.max(np.abs(data.markers["B"].displacement[1])) < 1e-12
    with pytest.raises(ukflex.InvalidArgumentError, match="matches no node"):
        fe.from_mesh(pts, cells=tris, thickness=t, density=rho, youngs_modulus=2e11, poisson_ratio=0.3,
                     interfaces={"A": lambda p: p[:, 0] < -1.0}, order=2)
    with pytest.raises(ukflex.InvalidArgumentError, match="order"):
        fe.from_mesh(pts, cells=tris, thickness=t, density=rho, youngs_modulus=2e11, poisson_ratio=0.3,
                     interfaces=ifs, order=3)


# -------------------------------------------------------------------------------- bad FE input
def _nodal_plate():
    fe = pytest.importorskip("ukflex.model.fe")
    pytest.importorskip("skfem")
    pts, tris = _plate_mesh(nx=4, ny=1)
    mm, kk, nodes = fe.plane_stress_mesh_matrices(pts, tris, thickness=0.01, density=7800.0, youngs_modulus=2e11,
                                                  poisson_ratio=0.3)
    left = [i for i, p in enumerate(nodes) if p[0] == 0.0]
    right = [i for i, p in enumerate(nodes) if abs(p[0] - 0.3) < 1e-12]
    return fe, nodes, mm, kk, {"A": left, "B": right}


def test_one_frame_vocabulary_for_beams_and_fe_bodies():
    """``frame`` has one vocabulary (the core's): a pinned-pinned FE body takes the chord of its
    first two interfaces, also when the chord is not the body's x axis; clamped fixes the first
    interface's rotation; a beam refuses 'mean-axis' by name."""
    fe, nodes, mm, kk, ifs = _nodal_plate()
    assert fe.FRAMES == ("pinned-pinned", "clamped", "mean-axis")
    # the chord frame of the ends equals the explicit conditions when AB is the x axis
    a = fe.from_nodal(nodes, mm, kk, interfaces=ifs, modes=3, frame="pinned-pinned")
    b = fe.from_nodal(nodes, mm, kk, interfaces=ifs, modes=3, frame=[("A", "x"), ("A", "y"), ("B", "y")])
    assert np.allclose(a.info["frequencies"], b.info["frequencies"], rtol=1e-12)
    # a slanted chord (A = the left edge, B = the upper right corner, named): B moves along AB only
    corner = [i for i, p in enumerate(nodes) if abs(p[0] - 0.3) < 1e-12 and p[1] == nodes[:, 1].max()]
    c = fe.from_nodal(nodes, mm, kk, interfaces={"M": [2], "B": corner, "A": ifs["A"]}, modes=3,
                      frame=("pinned-pinned", "A", "B"))
    chord = np.subtract(c.markers["B"].point, c.markers["A"].point)
    across = np.array([-chord[1], chord[0]]) / np.hypot(*chord)
    assert np.max(np.abs(c.markers["A"].displacement)) < 1e-12
    assert np.max(np.abs(across @ np.asarray(c.markers["B"].displacement))) < 1e-12
    assert np.max(np.abs(np.asarray(c.markers["B"].displacement))) > 1e-3
    # clamped: the first interface neither moves nor turns
    d = fe.from_nodal(nodes, mm, kk, interfaces=ifs, modes=3, frame="clamped")
    assert np.max(np.abs(d.markers["A"].displacement)) < 1e-12
    assert np.max(np.abs(d.markers["A"].rotation)) < 1e-12
    assert d.info["frequencies"][0] < a.info["frequencies"][0]  # cantilever below pinned-pinned
    for frame, match in (("fixed", "unknown frame"), ([("A", "x")], "three"), (("pinned-pinned", "A"), "2 interface"), ([("A", "q"), ("A", "y"), ("B", "y")], "rotation")):
        with pytest.raises(ukflex.InvalidArgumentError, match=match):
            fe.from_nodal(nodes, mm, kk, interfaces=ifs, modes=3, frame=frame)
    with pytest.raises(ukflex.InvalidArgumentError, match="single node"):
        fe.from_nodal(nodes, mm, kk, interfaces={"A": [0], "B": ifs["B"]}, modes=3, frame="clamped")
    with pytest.raises(ukflex.InvalidArgumentError, match="reduction"):
        fe.from_nodal(nodes, mm, kk, interfaces=ifs, modes=3, frame="mean-axis", reduction="craig-bampton")
    with pytest.raises(ukflex.InvalidSceneError, match="modal bodies from FE data"):
        s = Scene()
        s.beam("b", length=1.0, elements=2, density=7800.0, youngs_modulus=2e11, theory="euler-bernoulli",
               section=Rectangular(0.01, 0.02), frame="mean-axis")
        s.build()


@pytest.mark.parametrize("case, match", [
    ("mass unsymmetric", "mass_matrix: must be symmetric"),
    ("mass indefinite", "mass_matrix: is not positive definite"),
    ("stiffness unsymmetric", "stiffness_matrix: must be symmetric"),
    ("stiffness supported", "three rigid-body modes"),
    ("fixed frame leaves a rigid motion", "not independent"),
    ("fixed frame on a disconnected stiffness", "not positive definite"),
    ("marker outside the mesh", "not nodes of the mesh"),
    ("too many modes", "do not fit"),
])
def test_bad_fe_input_raises_named_errors(case, match):
    fe, nodes, mm, kk, ifs = _nodal_plate()
    kw = dict(interfaces=ifs, modes=3, frame="mean-axis")
    n = mm.shape[0]
    if case == "mass unsymmetric":
        mm = mm.copy()
        mm[0, 2] += 0.1 * mm[0, 0]
    elif case == "mass indefinite":
        mm = mm.copy()
        mm[0, 0] = mm[1, 1] = -mm[0, 0]
    elif case == "stiffness unsymmetric":
        kk = kk.copy()
        kk[0, 3] += 0.1 * kk[0, 0]
    elif case == "stiffness supported":
        kk = kk + np.diag(np.r_[1e-3 * kk[0, 0], 1e-3 * kk[0, 0], np.zeros(n - 2)])
    elif case == "fixed frame leaves a rigid motion":
        kw.update(frame=[("A", "x"), ("A", "x"), ("B", "y")])
    elif case == "fixed frame on a disconnected stiffness":
        kk = kk.copy()
        kk[:, :2] = kk[:2, :] = 0.0  # node 0 connected to nothing
        kk = kk + np.diag(np.r_[0.0, 0.0, np.zeros(n - 2)])
        kw.update(frame=[("B", "x"), ("B", "y"), ("M", "y")], interfaces={"B": ifs["B"], "M": [2]})
    elif case == "marker outside the mesh":
        kw.update(interfaces={"A": [0], "B": [len(nodes) + 3]})
    elif case == "too many modes":
        kw.update(modes=n)
    with pytest.raises(ukflex.InvalidArgumentError, match=match):
        fe.from_nodal(nodes, mm, kk, **kw)


# -------------------------------------------------------------------------------- Green-Lagrange
def test_green_lagrange_tensors_of_a_mesh_match_direct_quadrature():
    """k3/k4 of a P2 mesh on a (random) basis are the cubic and quartic parts of the plane-stress
    Green-Lagrange energy integrated directly; the modal-derivative loads are k3's contraction."""
    fe = pytest.importorskip("ukflex.model.fe")
    pytest.importorskip("skfem")
    pts, tris = _plate_mesh(nx=4, ny=1)
    basis, perm, nodes = fe._mesh_basis(pts, tris, 2)
    lam, mu = fe._plane_stress_lame(2e11, 0.3)
    rng = np.random.default_rng(7)
    phi = 1e-3 * rng.normal(size=(2 * nodes.shape[0], 3))
    k3, k4 = fe._green_lagrange_tensors(basis, perm, phi, 0.01, lam, mu)
    g, dx = fe._mode_gradients(basis, perm, phi)
    w = 0.01 * dx
    for _ in range(3):
        q = rng.normal(size=3)
        gq = np.einsum("aijeq,a->ijeq", g, q)
        e_l = 0.5 * (gq + np.swapaxes(gq, 0, 1))
        e_n = 0.5 * np.einsum("kieq,kjeq->ijeq", gq, gq)
        u3 = np.einsum("ijeq,ijeq,eq->", fe._stress(e_l, lam, mu), e_n, w)
        u4 = 0.5 * np.einsum("ijeq,ijeq,eq->", fe._stress(e_n, lam, mu), e_n, w)
        assert abs(np.einsum("abc,a,b,c->", k3, q, q, q) / 6 - u3) <= 1e-12 * abs(u3)
        assert abs(np.einsum("abcd,a,b,c,d->", k4, q, q, q, q) / 24 - u4) <= 1e-12 * abs(u4)
    import itertools

    for perm3 in itertools.permutations(range(3)):
        assert np.allclose(k3, np.transpose(k3, perm3), rtol=0, atol=1e-12 * np.max(np.abs(k3)))
    for perm4 in itertools.permutations(range(4)):
        assert np.allclose(k4, np.transpose(k4, perm4), rtol=0, atol=1e-12 * np.max(np.abs(k4)))
    loads = fe._green_lagrange_md_loads(basis, perm, phi[:, :2], 0.01, lam, mu)
    for j, (a, b) in enumerate([(0, 0), (0, 1), (1, 1)]):
        assert np.allclose(phi.T @ loads[:, j], k3[:, a, b], rtol=1e-10, atol=1e-12 * np.max(np.abs(k3)))


def test_mesh_coupler_with_modal_derivatives_does_not_lock():
    """The coupler meshed with Q2 quads, Green-Lagrange strain, two modes: under a transverse
    midpoint load (deflection 1 % of the length) the two bending modes alone are far too stiff;
    with their modal derivatives the nonlinear deflection is within 0.5 % of the linear one
    (a pinned-sliding beam shortens freely)."""
    pytest.importorskip("skfem")
    from studies import flexible_coupler as fc

    locked = fc.mesh_coupler_data(16, 1, 2, 2, strain="nonlinear")
    v, lin = _static_midpoint_deflection(locked, 85.0)
    assert v < 0.7 * lin
    md = fc.mesh_coupler_data(16, 1, 2, 2, strain="nonlinear", modal_derivatives=True)
    assert md.n_f == 5
    v, lin = _static_midpoint_deflection(md, 85.0)
    assert abs(v - lin) <= 5e-3 * abs(lin)
    with pytest.raises(ukflex.InvalidArgumentError, match="reference conditions"):
        fe = pytest.importorskip("ukflex.model.fe")
        pts, tris = _plate_mesh(nx=4, ny=1)
        fe.from_mesh(pts, cells=tris, thickness=0.01, density=7800.0, youngs_modulus=2e11, poisson_ratio=0.3,
                     interfaces={"A": [0]}, modes=2, strain="nonlinear", modal_derivatives=True)
