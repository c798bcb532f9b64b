"""Simo and Vu-Quoc's right-angle cantilever (issue 31, item 4; ``studies/right_angle_cantilever.py``,
docs/spatial-flexible.md): the two welded ``beam3`` members struck at the elbow by the triangular
pulse (a ``point_load`` expression of ``t``), over the first 3 s on a coarse mesh (5 elements per
member), against a finer, tighter ukflex run and against Exudyn's ``ObjectBeamGeometricallyExact``
on the same mesh (an independent implementation of the same discretized physics)."""

from __future__ import annotations

import numpy as np
import pytest

import ukflex

from studies import right_angle_cantilever as rac

T = np.linspace(0.0, 3.0, 31)


@pytest.fixture(scope="module")
def coarse():
    return rac.ukflex_run(5, T)


def test_coarse_default_run_against_a_finer_tighter_ukflex_run(coarse):
    fine = rac.ukflex_run(10, T, method="RADAU5", rtol=1e-8, atol=1e-10)
    g = rac.gap(coarse[:2], fine[:2])
    assert g < 0.012, g
    # the elbow is pushed out of the plane along the force; at 3 s it is past 5 (both runs)
    for elbow in (coarse[0], fine[0]):
        assert np.all(np.diff(elbow[:, 2]) > 0)
        assert 5.0 < elbow[-1, 2] < 6.0


def test_coarse_run_against_exudyn_on_the_same_mesh(coarse):
    pytest.importorskip("exudyn")
    ex = rac.exudyn_run(5, T, 1200)
    g = rac.gap(coarse[:2], ex[:2])
    assert g < 0.012, g


def test_the_default_runs_the_beam_as_an_elastic_scene():
    """The beam's elements store strain energy between rigid node bodies: ``method="auto"`` sees
    an elastic scene (its lowest mode, 0.33 rad/s, far below the axial 1,000 rad/s) and takes
    RADAU5M at a fixed step, where it once took DOPRI5 as for rigid bodies (10x slower at 5
    elements per member, 90x at 20)."""
    from ukflex.run.choice import choose_method

    c = choose_method(ukflex.System(rac.scene(5)), 0.0, rac.T_END, 1e-6)
    assert c.method == "RADAU5M" and c.step is not None, c
    assert 0.2 < c.omega_elastic < 0.5 and c.omega_max > 500.0, c
