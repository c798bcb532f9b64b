"""The 3D flexible pendulum's beam against Exudyn's ``ObjectBeamGeometricallyExact`` (issue 31,
item 5; ``studies/spatial_beam_pendulum_exudyn.py``, docs/spatial-flexible.md): the default
``simulate()`` on 10 elements against Exudyn on 40 elements at 1000 steps, over the elastic part
of the tip motion (the tip against the rigid bar of the same inertia)."""

from __future__ import annotations

import numpy as np
import pytest

from studies import _exudyn_beam as xb
from studies import spatial_beam_pendulum_exudyn as sbe


def test_rectangle_section_data_as_beam3_derives_them():
    # the square's torsion constant 0.1406 a^4 (Saint-Venant), Cowper's factor at nu = 0.3
    s = xb.rectangle_section(0.02, 0.02, 7850.0, 2.1e9, 0.3)
    g = 2.1e9 / 2.6
    assert abs(s["gj"] / (g * 0.02 ** 4) - 0.1406) < 1e-4
    assert np.isclose(s["ga_y"], 10 * 1.3 / (12 + 3.3) * g * 4e-4, rtol=1e-14)
    assert np.allclose(s["rotary_inertia"], 7850.0 * 0.02 ** 4 / 12 * np.array([2.0, 1.0, 1.0]), rtol=1e-14)
    # the rectangle is symmetric in its two sides for the torsion constant, not for the bending
    r, q = xb.rectangle_section(0.04, 0.01, 1.0, 1.0, 0.3), xb.rectangle_section(0.01, 0.04, 1.0, 1.0, 0.3)
    assert np.isclose(r["gj"], q["gj"], rtol=1e-14) and np.isclose(r["ei_y"], q["ei_z"], rtol=1e-14) and r["ei_y"] < r["ei_z"]


def test_default_run_against_exudyn():
    pytest.importorskip("exudyn")
    t = np.linspace(0.0, sbe.T_END, 31)
    tip, _ = sbe.beam_tip(10, t)
    ex, _ = sbe.exudyn_tip(40, t, 1000)
    elastic = sbe.gap(tip, sbe.rigid_bar_tip(t))
    # the elastic part: 4.15e-4 m here (8.3e-4 L); the two 2.2e-2 of it apart (the study:
    # ukflex's 10 elements 6.6e-3 from its mesh limit, Exudyn's 40 elements 3.8e-2, its lumped
    # point masses carrying the second moment by the trapezoidal rule); a model error (gravity,
    # inertia, the joint) moves the tip by the whole elastic part
    assert 4.0e-4 < elastic < 4.4e-4, elastic
    assert sbe.gap(tip, ex) / elastic < 0.04, sbe.gap(tip, ex) / elastic
