"""Outputs for users (issue 33, item 5): FE meshes from scikit-fem and meshio objects, missing
optional dependencies, the warning of a driven coordinate moved by the initial correction, the
nodal displacement and stress fields of modal bodies, and the VTK export (docs/outputs.md)."""

import ast
import math
import pathlib
import sys
import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import ukflex
from ukflex import scenes

skfem = pytest.importorskip("skfem")
meshio = pytest.importorskip("meshio")

from ukflex import fe  # noqa: E402
from ukflex.results.fields import modal_fields, von_mises  # noqa: E402

STEEL = dict(density=7800.0, youngs_modulus=2.0e11, poisson_ratio=0.3)


def _rect(nx, ny, L=1.0, h=0.1):
    return skfem.MeshQuad.init_tensor(np.linspace(0.0, L, nx + 1), np.linspace(-h / 2, h / 2, ny + 1))


def _ends(L=1.0):
    return {"A": lambda p: np.isclose(p[:, 0], 0.0), "B": lambda p: np.isclose(p[:, 0], L)}


# ------------------------------------------------------------------------------ mesh objects
def test_from_mesh_takes_scikit_fem_and_meshio_meshes():
    m = _rect(6, 1)
    kw = dict(thickness=0.01, interfaces=_ends(), modes=3, **STEEL)
    ref = fe.from_mesh(m.p.T, cells=m.t.T, **kw)
    from_skfem = fe.from_mesh(m, **kw)
    # a meshio mesh whose quads come in two blocks (as gmsh writes physical groups)
    q = m.t.T
    mio = meshio.Mesh(np.column_stack([m.p.T, np.zeros(m.p.shape[1])]), [("quad", q[:3]), ("line", q[:2, :2]), ("quad", q[3:])])
    from_meshio = fe.from_mesh(mio, **kw)
    for d in (from_skfem, from_meshio):
        assert np.array_equal(d.info["cells"], ref.info["cells"])
        assert np.allclose(d.info["frequencies"], ref.info["frequencies"], rtol=1e-12)
        assert d.mass == pytest.approx(ref.mass, rel=1e-14)
    # triangles, and a quadratic-geometry MeshTri2 taken by its vertices (straight edges)
    tri = skfem.MeshTri.init_tensor(np.linspace(0.0, 1.0, 7), np.linspace(-0.05, 0.05, 2))
    t_ref = fe.from_mesh(tri.p.T, cells=tri.t.T, **kw)
    t_obj = fe.from_mesh(skfem.MeshTri2.init_circle(1), thickness=0.01, interfaces={"A": [0, 1]}, modes=2, **STEEL)
    assert np.allclose(fe.from_mesh(tri, **kw).info["frequencies"], t_ref.info["frequencies"], rtol=1e-12)
    assert t_obj.info["nodes"].shape[0] == skfem.MeshTri2.init_circle(1).nvertices
    with pytest.raises(ukflex.InvalidArgumentError, match="planar scikit-fem mesh"):
        fe.from_mesh(skfem.MeshTet(), **kw)
    mixed = meshio.Mesh(mio.points, [("quad", q[:3]), ("triangle", np.array([[0, 1, 8]]))])
    with pytest.raises(ukflex.InvalidArgumentError, match="mixes triangles and quads"):
        fe.from_mesh(mixed, **kw)


def test_a_missing_optional_dependency_names_its_extra(monkeypatch, tmp_path):
    m = _rect(2, 1)
    kw = dict(thickness=0.01, interfaces=_ends(), modes=2, **STEEL)
    monkeypatch.setitem(sys.modules, "skfem", None)  # import skfem -> ImportError
    with pytest.raises(ukflex.MissingDependencyError, match=r"scikit-fem.*extra \[fe\]"):
        fe.from_mesh(m.p.T, cells=m.t.T, **kw)
    monkeypatch.setitem(sys.modules, "meshio", None)
    with pytest.raises(ukflex.MissingDependencyError, match=r"'meshio'.*extra \[fe\]"):
        fe.from_mesh(str(tmp_path / "part.msh"), **kw)
    system = scenes.pendulum().build()
    res = ukflex.simulate(system, 0.01, method="DOPRI5", t_eval=[0.0, 0.01])
    with pytest.raises(ukflex.MissingDependencyError, match="meshio"):
        ukflex.export_vtk(system, res, str(tmp_path / "run.pvd"))


#: optional packages: importing them must go through ``ukflex.errors.require`` (a named
#: MissingDependencyError), except where a missing one only turns a feature off (a ``try``
#: with ``except ImportError`` around the import)
OPTIONAL = {"skfem", "meshio", "matplotlib", "dask", "distributed", "pandas", "PIL", "exudyn", "tqdm", "cloudpickle",
            "threadpoolctl"}


def test_optional_imports_go_through_one_helper():
    root = pathlib.Path(ukflex.__file__).parent
    direct = []
    for f in sorted(root.rglob("*.py")):
        if f.relative_to(root).parts[0] == "reference":  # independent of the rest of ukflex (test_layout)
            continue
        tree = ast.parse(f.read_text())
        guarded = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.Try) and any(
                    h.type is not None and "ImportError" in ast.dump(h.type) for h in node.handlers):
                guarded |= {id(n) for stmt in node.body for n in ast.walk(stmt)}
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module else [])
            if any(n.split(".")[0] in OPTIONAL for n in names) and id(node) not in guarded:
                direct.append(f"{f.relative_to(root)}:{node.lineno} {names}")
    assert not direct, direct


# ------------------------------------------------------------------------ initial correction
def test_initial_correction_warns_when_it_moves_a_driven_coordinate():
    scene = scenes.four_bar()  # crank at 90 degrees, driver ConstantSpeed(10, initial=pi/2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ukflex.System(scene)  # consistent: no warning
    d = scene.to_dict()
    d["drivers"][0]["motion"]["initial"] = 0.0  # initial= left out
    with pytest.warns(ukflex.InitialCorrectionWarning, match=r"crank_speed' by -1.571 rad \(-90 degrees\)") as rec:
        system = ukflex.System(d)
    assert len(rec) == 1
    assert rec[0].message.moves["crank_speed"] == pytest.approx(-math.pi / 2, abs=1e-12)
    assert system.q0[system.coordinate_index("crank.theta")] == pytest.approx(0.0, abs=1e-12)
    # an unnamed driver is named as the core names it
    s = ukflex.Scene()
    crank = s.rigid_body("crank", mass=1.0, inertia=0.1, com=(0.05, 0.0), angle=0.3)
    s.revolute(s.ground.point(0, 0), crank.point(0, 0))
    s.angle_driver(crank.frame(), ukflex.ConstantSpeed(1.0))
    with pytest.warns(ukflex.InitialCorrectionWarning, match="angle_driver0' by -0.3 rad"):
        s.build()
    # below the tolerance: no warning
    d["drivers"][0]["motion"]["initial"] = math.pi / 2 - 0.5 * ukflex.System.DRIVEN_MOVE_TOL
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ukflex.System(d)


def test_initial_correction_warns_for_a_spatial_rotation_driver():
    def scene(angle):
        s = ukflex.SpatialScene()
        c, h = math.cos(angle / 2), math.sin(angle / 2)
        disk = s.rigid_body("disk", mass=1.0, inertia=[1.0, 1.0, 2.0], orientation=[c, 0.0, 0.0, h])
        s.revolute(s.ground.marker((0, 0, 0)), disk.marker((0, 0, 0)), name="axle")
        s.rotation_driver(s.ground.marker((0, 0, 0)), disk.marker((0, 0, 0)), ukflex.ConstantSpeed(2.0), name="spin")
        return s

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ukflex.System(scene(0.0))
    # 1 rad off: the move is the angle itself
    with pytest.warns(ukflex.InitialCorrectionWarning, match="spin") as rec:
        ukflex.System(scene(1.0))
    assert rec[0].message.moves["spin"] == pytest.approx(-1.0, abs=1e-9)
    # 2 rad off (more than a quarter turn): corrected onto the driver's angle, not onto the
    # opposite branch theta = f + pi where the former row sin(theta - f) also vanished
    with pytest.warns(ukflex.InitialCorrectionWarning, match="spin") as rec:
        ukflex.System(scene(2.0))
    assert rec[0].message.moves["spin"] == pytest.approx(-2.0, abs=1e-9)


# ------------------------------------------------------------------------- modal body fields
def _cantilever(nx=10, ny=1, L=1.0, h=0.1, t=0.01, P=-100.0):
    """A Q2 plane-stress cantilever with all its modes (the static answer of the mesh), clamped
    at its left edge (a weld of the edge's rigid average) and loaded at the right edge."""
    n_dofs = 2 * (2 * nx + 1) * (2 * ny + 1)
    data = fe.from_mesh(_rect(nx, ny, L, h), thickness=t, order=2, interfaces=_ends(L), frame="pinned-pinned",
                        modes=n_dofs - 3, **STEEL)
    return _clamped(data, P), data


def _clamped(data, P):
    s = ukflex.Scene(gravity=(0.0, 0.0))
    bar = s.flexible_body("bar", data)
    s.weld(s.ground.point(0, 0), bar.marker("A"), name="clamp")
    s.point_force(bar.marker("B"), (0.0, P), name="tip")
    return s.build()


def test_modal_stress_of_a_cantilever_is_the_beam_formula():
    L, h, t, P = 1.0, 0.1, 0.01, -100.0
    system, data = _cantilever(L=L, h=h, t=t, P=P)
    eq = system.equilibrium()
    f = modal_fields(system, eq.q, "bar", data)
    nodes, stress = f["nodes"], f["stress"][0]
    second_moment = t * h ** 3 / 12
    for x, tol in ((0.5, 5e-5), (0.25, 5e-5), (0.75, 5e-5)):  # away from the clamp and the load (St Venant)
        top = np.flatnonzero(np.isclose(nodes[:, 0], x) & np.isclose(nodes[:, 1], h / 2))
        bottom = np.flatnonzero(np.isclose(nodes[:, 0], x) & np.isclose(nodes[:, 1], -h / 2))
        sigma = -P * (L - x) * (h / 2) / second_moment  # M c / I, tension on top under a downward load
        assert stress[top, 0] == pytest.approx(sigma, rel=tol)
        assert stress[bottom, 0] == pytest.approx(-sigma, rel=tol)
        assert f["von_mises"][0][top] == pytest.approx(von_mises(stress[top]), rel=1e-14)
        # the shear stress over the section carries the load (one element through the height:
        # the recovered shear is its mean V / A at every node)
        section = np.flatnonzero(np.isclose(nodes[:, 0], x))
        order = np.argsort(nodes[section, 1])
        y, sxy = nodes[section[order], 1], stress[section[order], 2]
        resultant = t * np.sum(np.diff(y) * (sxy[1:] + sxy[:-1]) / 2)
        assert resultant == pytest.approx(P, rel=1e-6)
    # the tip's displacement (rigid + elastic: the frame turns with the chord) is Timoshenko's
    # to the clamp's flexibility (a weld of the edge's rigid average leaves the section free to warp)
    shear = 1.0 / (5.0 / 6.0 * STEEL["youngs_modulus"] / 2.6 * h * t)
    tip = f["displacement"][0][np.isclose(nodes[:, 0], L), 1].mean()
    assert tip == pytest.approx(P * L ** 3 / (3 * STEEL["youngs_modulus"] * second_moment) + P * L * shear, rel=5e-3)
    # fe.reduce keeps the nodal fields on its basis: 20 of the 123 modes give the stress within
    # their truncation error (4.7e-3 measured; 5 modes: 13 %)
    reduced = fe.reduce(data, 20)
    small = _clamped(reduced, P)
    fr = modal_fields(small, small.equilibrium().q, "bar", reduced)
    top = np.flatnonzero(np.isclose(nodes[:, 0], 0.5) & np.isclose(nodes[:, 1], h / 2))
    assert fr["stress"][0][top, 0] == pytest.approx(-P * 0.5 * (h / 2) / second_moment, rel=1e-2)
    assert von_mises(np.array([1.0, 0.0, 0.0])) == 1.0 and von_mises(np.array([0.0, 0.0, 1.0])) == pytest.approx(math.sqrt(3))
    with pytest.raises(ukflex.InvalidArgumentError, match="not the one the body was built from"):
        other = fe.from_mesh(_rect(4, 1), thickness=t, order=1, interfaces=_ends(), modes=3, **STEEL)
        modal_fields(system, eq.q, "bar", other)


# -------------------------------------------------------------------------------- VTK export
def _pvd(path):
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("name"), pathlib.Path(path).parent / d.get("file")) for d in root.iter("DataSet")]


def test_export_vtk_reads_back_as_the_run(tmp_path):
    # a pendulum of a meshed plate hung from a crank-like rigid body by a pin, beside a beam
    data = fe.from_mesh(_rect(4, 1, L=0.3, h=0.05), thickness=0.005, order=1, interfaces=_ends(0.3), modes=3, **STEEL)
    s = ukflex.Scene(gravity=(0.0, -9.81))
    rod = s.rigid_body("rod", mass=1.0, inertia=0.01, com=(0.1, 0.0))
    plate = s.flexible_body("plate", data, position=(0.2, 0.0))
    s.revolute(s.ground.point(0, 0), rod.point(0, 0), name="pivot")
    s.revolute(rod.point(0.2, 0), plate.marker("A"), name="pin")
    beam = s.beam("beam", length=0.5, elements=2, section=ukflex.Rectangular(0.01, 0.01), density=7800.0,
                  youngs_modulus=2e11, theory="euler-bernoulli", frame="clamped", position=(0.0, -1.0))
    s.weld(s.ground.point(0.0, -1.0), beam.at(0.0), name="clamp")
    system = s.build()
    res = ukflex.simulate(system, 0.02, method="DOPRI5", rtol=1e-8, t_eval=np.linspace(0, 0.02, 5))
    path = ukflex.export_vtk(system, res, str(tmp_path / "run.pvd"), flexible={"plate": data})
    entries = _pvd(path)
    assert sorted({e[1] for e in entries}) == ["beam", "plate", "rod"]
    assert sorted({e[0] for e in entries}) == pytest.approx(res.t.tolist())
    fields = modal_fields(system, res, "plate", data)
    for tk, name, file in entries:
        k = int(np.flatnonzero(res.t == tk)[0])
        m = meshio.read(file)
        if name == "plate":
            assert m.cells[0].type == "quad" and np.array_equal(m.cells[0].data, data.info["cells"])
            assert np.allclose(m.points[:, :2], fields["position"][k], rtol=0, atol=1e-14)
            assert np.allclose(m.point_data["von_mises"], fields["von_mises"][k], rtol=1e-14)
            assert np.allclose(m.point_data["displacement"][:, :2], fields["displacement"][k], rtol=0, atol=1e-14)
        elif name == "beam":
            tip = np.asarray(system.beam_point("beam", 1.0, res.q[:, k]))
            assert m.cells[0].type == "line" and np.allclose(m.points[-1, :2], tip[:2], atol=1e-14)
            assert np.allclose(m.point_data["deflection"][-1, :2], tip[2:4], atol=1e-15)
        else:  # the rod: its pivot and pin points
            th = res.q[system.coordinate_index("rod.theta"), k]
            pin = res.q[system.body_slice("rod"), k][:2] + 0.2 * np.array([math.cos(th), math.sin(th)])
            assert np.min(np.linalg.norm(m.points[:, :2] - pin, axis=1)) < 1e-14
    # the beam's deflection under its weight is in the files: the last time is not the first
    last = meshio.read([e for e in entries if e[1] == "beam"][-1][2])
    assert abs(last.point_data["deflection"][-1, 1]) > 1e-6


def test_export_vtk_of_a_spatial_scene(tmp_path):
    s = ukflex.SpatialScene(gravity=(0, 0, -9.81))
    top = s.rigid_body("top", mass=1.0, inertia=[2.5e-3, 2.5e-3, 5e-3], position=(0, 0, 0.1),
                       angular_velocity=(0.5, 0, 50))
    s.spherical(s.ground.marker((0, 0, 0)), top.marker((0, 0, -0.1)), name="pivot")
    system = ukflex.System(s)
    res = ukflex.simulate(system, 0.1, method="DOPRI5", rtol=1e-10, t_eval=np.linspace(0, 0.1, 5))
    out = ukflex.spatial_outputs(system, res)["bodies"]["top"]
    entries = _pvd(ukflex.export_vtk(system, res, str(tmp_path / "top.pvd"), frames=3))
    assert [e[0] for e in entries] == pytest.approx([0.0, 0.05, 0.1], abs=1e-15)
    for tk, _, file in entries:
        k = int(np.argmin(np.abs(res.t - tk)))
        m = meshio.read(file)
        assert np.allclose(m.points[0], out["position"][k], atol=1e-14)  # the centre of mass
        assert np.allclose(m.points[1], 0.0, atol=1e-9)  # the pivot, on the ground's point
        assert np.allclose(m.point_data["z_axis"][0], out["rotation"][k][:, 2], atol=1e-14)


def test_from_mesh_reports_progress_by_stage():
    seen = []
    fe.from_mesh(_rect(4, 1), thickness=0.01, interfaces=_ends(), modes=2, progress=seen.append, **STEEL)
    assert seen == [fe.FE_STAGES["assembled"], fe.FE_STAGES["reduced"], 1.0]
    seen.clear()
    fe.from_mesh(_rect(4, 1), thickness=0.01, interfaces=_ends(), modes=2, strain="nonlinear", progress=seen.append,
                 **STEEL)
    assert seen == sorted(seen) and seen[-2:] == [fe.FE_STAGES["nonlinear"], 1.0] and len(seen) == 4
    with pytest.raises(ukflex.InvalidArgumentError, match="progress"):
        fe.from_mesh(_rect(2, 1), thickness=0.01, interfaces=_ends(), modes=2, progress=True, **STEEL)


def test_cli_export_vtk_runs_the_scene_and_writes_the_collection(tmp_path, capsys):
    from ukflex.cli import main

    path = tmp_path / "fb.pvd"
    assert main(["export", "four_bar", "--vtk", str(path), "--t-end", "0.02", "--samples", "3", "--method", "DOPRI5"]) == 0
    assert "3 output times" in capsys.readouterr().out
    entries = _pvd(path)
    assert sorted({e[1] for e in entries}) == ["coupler", "crank", "rocker"]
    assert sorted({e[0] for e in entries}) == pytest.approx([0.0, 0.01, 0.02])
    # the crank turns at the driver's 10 rad/s: its tip at t = 0.02 s is at 90 + 11.46 degrees
    crank = meshio.read([e[2] for e in entries if e[1] == "crank" and e[0] == pytest.approx(0.02)][0])
    tip = crank.points[np.argmax(np.linalg.norm(crank.points, axis=1))]
    assert math.atan2(tip[1], tip[0]) == pytest.approx(math.pi / 2 + 0.2, abs=1e-6)
