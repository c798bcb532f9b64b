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
