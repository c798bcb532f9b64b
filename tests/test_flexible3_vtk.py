"""VTK export of the FE fields of a spatial modal body (``flexible3``; docs/outputs.md, "Export to
ParaView (VTK)"): the files read back by meshio against the modal reconstruction
``r + R(p) (u0 + S q_f)`` written here from the coordinates alone."""

import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import ukflex
from ukflex import fe3
from ukflex.errors import InvalidArgumentError

meshio = pytest.importorskip("meshio")


def _rotation(p):
    """``R = A(p) / |p|^2`` of Euler parameters ``p = [e0, e1, e2, e3]``."""
    e0, e = p[0], np.asarray(p[1:])
    sk = np.array([[0, -e[2], e[1]], [e[2], 0, -e[0]], [-e[1], e[0], 0]])
    return ((e0 * e0 - e @ e) * np.eye(3) + 2 * np.outer(e, e) + 2 * e0 * sk) / (p @ p)


def test_export_vtk_of_a_spatial_modal_body(tmp_path):
    mesh = fe3.bar_mesh(0.5, 0.02, 0.02, (6, 1, 1))
    data = fe3.from_mesh(mesh, density=7850.0, youngs_modulus=2.1e9, poisson_ratio=0.3,
                         interfaces={"A": lambda x: x[:, 0] < 1e-9}, modes=3, frame=("clamped", "A"))
    s = ukflex.SpatialScene(gravity=(0, 0, -9.81))
    bar = s.flexible_body("bar", data, angular_velocity=(0, 2.0, 3.0))
    s.spherical(s.ground.marker(data.interfaces["A"].point), bar.interface("A"))
    system = ukflex.System(s)
    res = ukflex.simulate(system, 0.05, t_eval=np.linspace(0, 0.05, 6))
    path = ukflex.export_vtk(system, res, str(tmp_path / "run.pvd"), flexible={"bar": data})
    sets = [d for d in ET.parse(path).getroot().iter("DataSet") if d.get("name") == "bar"]
    np.testing.assert_allclose([float(d.get("timestep")) for d in sets], res.t, rtol=0, atol=1e-15)
    nodes, modes = data.info["nodes"], data.info["modes"]
    sl, el = system.body_slice("bar"), system.elastic_slice("bar")
    q0 = np.asarray(system.q0)
    ref0 = q0[sl][:3] + nodes @ _rotation(q0[sl][3:7]).T
    k = 4
    got = meshio.read(os.path.join(tmp_path, sets[k].get("file")))
    q = res.q[:, k]
    rot = _rotation(q[sl][3:7])
    u = nodes + (modes @ q[el]).reshape(-1, 3)
    want = q[sl][:3] + u @ rot.T
    assert np.abs(q[el]).max() > 1e-7  # the bar deforms
    np.testing.assert_allclose(got.points, want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.point_data["displacement"], want - ref0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.point_data["elastic_displacement"], (modes @ q[el]).reshape(-1, 3) @ rot.T,
                               rtol=0, atol=1e-12)
    # the stress: the modes' nodal stress shapes times q_f, and its von Mises value
    sig = np.einsum("nkf,f->nk", data.info["stress_modes"], q[el])
    np.testing.assert_allclose(got.point_data["stress"], sig, rtol=1e-12, atol=1e-9)
    s_ = sig
    vm = np.sqrt(0.5 * ((s_[:, 0] - s_[:, 1]) ** 2 + (s_[:, 1] - s_[:, 2]) ** 2 + (s_[:, 2] - s_[:, 0]) ** 2)
                 + 3 * (s_[:, 3] ** 2 + s_[:, 4] ** 2 + s_[:, 5] ** 2))
    np.testing.assert_allclose(got.point_data["von_mises"], vm, rtol=1e-12, atol=1e-9)
    assert vm.max() > 1e3  # Pa: the bar is stressed
    # the cells: the mesh's tetrahedra on its vertices (the first nodes of the P2 space)
    tets = got.cells_dict["tetra"]
    assert tets.shape == (mesh.t.shape[1], 4)
    np.testing.assert_allclose(nodes[: mesh.p.shape[1]], mesh.p.T, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(np.sort(tets, axis=1), np.sort(mesh.t.T, axis=1))


def test_export_vtk_of_a_hexahedral_body_and_bad_data(tmp_path):
    mesh = fe3.bar_mesh(0.5, 0.02, 0.02, (4, 1, 1), kind="hex")
    data = fe3.from_mesh(mesh, density=7850.0, youngs_modulus=2.1e9, poisson_ratio=0.3,
                         interfaces={"A": lambda x: x[:, 0] < 1e-9}, modes=2, frame=("clamped", "A"))
    s = ukflex.SpatialScene()
    bar = s.flexible_body("bar", data, angular_velocity=(0, 0, 3.0))
    s.spherical(s.ground.marker(data.interfaces["A"].point), bar.interface("A"))
    system = ukflex.System(s)
    res = ukflex.simulate(system, 0.01, t_eval=[0.0, 0.01])
    ukflex.export_vtk(system, res, str(tmp_path / "hex.pvd"), flexible={"bar": data})
    got = meshio.read(str(tmp_path / "hex" / "bar_00001.vtu"))
    hexes = got.cells_dict["hexahedron"]
    # VTK's vertex order: every cell has a positive volume by the VTK rule
    x = got.points[hexes]
    vol = np.einsum("ij,ij->i", x[:, 1] - x[:, 0], np.cross(x[:, 3] - x[:, 0], x[:, 4] - x[:, 0]))
    assert np.all(vol > 0)
    # data of another body (its k_ff differs) is refused by name
    other = fe3.from_mesh(mesh, density=7850.0, youngs_modulus=2.1e10, poisson_ratio=0.3,
                          interfaces={"A": lambda x: x[:, 0] < 1e-9}, modes=2, frame=("clamped", "A"))
    with pytest.raises(InvalidArgumentError, match="not the one the body was built from"):
        ukflex.export_vtk(system, res, str(tmp_path / "bad.pvd"), flexible={"bar": other})


def test_stress_of_a_cantilever_under_gravity_against_beam_theory():
    # the clamped 0.5 m x 20 mm x 20 mm bar sagging under gravity (System.equilibrium): the axial
    # stress at the top surface, sum_k q_k sigma_k from the modes' nodal stress shapes, against
    # M c / I with M = rho g A (L - x)^2 / 2; measured +0.42 % at L/4 and +0.66 % at L/2 (40 x 2 x 2
    # P2 tets, 16 modes; 20 x 2 x 2: +1.3 %, +2.0 %: the surface stress converges with the mesh)
    from ukflex.results.fields import modal_fields

    length, b, h, rho = 0.5, 0.02, 0.02, 7850.0
    mesh = fe3.bar_mesh(length, b, h, (40, 2, 2))
    d = fe3.from_mesh(mesh, density=rho, youngs_modulus=2.1e9, poisson_ratio=0.3,
                      interfaces={"A": lambda x: x[:, 0] < 1e-9}, modes=16, frame=("clamped", "A"))
    s = ukflex.SpatialScene(gravity=(0, 0, -9.81))
    bar = s.flexible_body("bar", d)
    s.fixed(s.ground.marker(d.interfaces["A"].point), bar.interface("A"))
    system = ukflex.System(s)
    f = modal_fields(system, np.asarray(system.equilibrium().q), "bar", d)
    nodes = d.info["nodes"]
    for x in (0.125, 0.25):
        top = np.nonzero((np.abs(nodes[:, 0] - x) < 1e-9) & (np.abs(nodes[:, 2] - h / 2) < 1e-9))[0]
        bottom = np.nonzero((np.abs(nodes[:, 0] - x) < 1e-9) & (np.abs(nodes[:, 2] + h / 2) < 1e-9))[0]
        ref = rho * 9.81 * b * h * (length - x) ** 2 / 2 * (h / 2) / (b * h ** 3 / 12)
        assert f["stress"][0, top, 0].mean() == pytest.approx(ref, rel=1e-2)  # tension on top
        assert f["stress"][0, bottom, 0].mean() == pytest.approx(-ref, rel=1e-2)
        assert f["von_mises"][0, top].mean() == pytest.approx(ref, rel=1e-2)
