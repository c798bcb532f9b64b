"""Scale (docs/scale.md): the sparse UK path through the public API, the uk_solver and
memory_limit build options, and the chain / rope scenes."""

import numpy as np
import pytest

import ukflex
from ukflex import scenes


def test_chain_and_rope_are_registered_scenes():
    assert scenes.SCENES["chain"] is scenes.chain
    assert scenes.SCENES["rope"] is scenes.rope
    s = scenes.chain(links=5).build()
    assert (s.n_coords, s.n_constraints) == (15, 10)
    r = scenes.rope(links=8).build()
    assert (r.n_coords, r.n_constraints) == (24, 18)
    # the V layout is consistent: the initial correction has nothing to do
    assert np.max(np.abs(r.phi(0.0, r.q_guess))) < 1e-12
    with pytest.raises(ValueError):
        scenes.rope(links=7)
    with pytest.raises(ValueError):
        scenes.chain(links=0)


@pytest.mark.parametrize("links", [8, 40])
def test_sparse_and_dense_paths_agree(links):
    scene = scenes.chain(links=links, angle=-0.4)
    sp = scene.build(uk_solver="sparse")
    de = scene.build(uk_solver="dense")
    rng = np.random.default_rng(1)
    q, qd = sp.q0.copy(), rng.normal(size=sp.n_coords)
    a, b = sp.qdd(0.0, q, qd), de.qdd(0.0, q, qd)
    assert sp.core.uk_solver == ("sparse", "sparse")
    assert de.core.uk_solver == ("dense", "dense")
    info = de.rank_info()
    cond = info["sigma_max"] / info["sigma_min_kept"]
    assert np.max(np.abs(a - b)) <= 20 * cond * np.finfo(float).eps * np.max(np.abs(b))
    assert np.allclose(sp.multipliers(0.0, q, qd), de.multipliers(0.0, q, qd), rtol=1e-12, atol=1e-12 * np.max(np.abs(b)))
    ri = sp.rank_info()
    assert ri["uk_path"] == "sparse" and ri["rank"] == sp.n_constraints


def test_auto_choice_and_validation():
    assert scenes.chain(links=4).build().core.uk_solver[0] == "auto"
    small = scenes.chain(links=2).build()
    small.qdd(0.0, small.q0, small.qd0)
    assert small.core.uk_solver[1] == "dense"
    big = scenes.chain(links=64).build()
    big.qdd(0.0, big.q0, big.qd0)
    assert big.core.uk_solver[1] == "sparse"
    with pytest.raises(ValueError, match="uk_solver"):
        scenes.chain(links=4).build(uk_solver="banded")
    with pytest.raises(ValueError, match="memory_limit"):
        scenes.chain(links=4).build(memory_limit=-1)


def test_memory_limit_refuses_dense_buffers_with_a_named_error():
    scene = scenes.cantilever(elements=64)  # n = 195
    s = scene.build(memory_limit=1.5e6)  # enough for the UK workspace, not for n x n Jacobians
    with pytest.raises(ukflex.MemoryLimitError, match="DOPRI5"):
        s.jac(0.0, s.y0)
    with pytest.raises(ukflex.MemoryLimitError, match="DOPRI5"):
        s.integrate(0.0, s.y0, 1e-3, method="RADAU5")
    res = s.integrate(0.0, s.y0, 1e-4, method="DOPRI5")
    assert res["status"] == 0
    assert issubclass(ukflex.MemoryLimitError, ukflex.UkflexError)
    ok = scene.build()
    assert ok.jac(0.0, ok.y0).shape == (2 * ok.n_coords, 2 * ok.n_coords)


def test_lattice_scene_layout_and_errors():
    assert scenes.SCENES["lattice"] is scenes.lattice
    w, h = 3, 2
    links = scenes.lattice(columns=w, rows=h).build()
    # per level: w + 1 hangers and w bars; 3w + 1 revolutes
    assert (links.n_coords, links.n_constraints) == (3 * h * (2 * w + 1), h * (6 * w + 2))
    cont = scenes.lattice(columns=w, rows=h, beams="continuous").build()
    # per level: w + 1 hangers and one beam; 2 (w + 1) revolutes
    assert (cont.n_coords, cont.n_constraints) == (3 * h * (w + 2), h * 4 * (w + 1))
    for s in (links, cont):  # the sheared layout is consistent
        assert np.max(np.abs(s.phi(0.0, s.q_guess))) < 1e-12
    for bad in (dict(columns=0), dict(rows=0), dict(beams="truss"), dict(cell=-1.0), dict(shear=2.0)):
        with pytest.raises(ValueError):
            scenes.lattice(**bad)
    with pytest.raises(TypeError):
        scenes.lattice(columns=2.5)


@pytest.mark.parametrize("beams", ["links", "continuous"])
def test_lattice_rank_handling_on_the_sparse_path(beams):
    """Closed loops: independent rows (beams="links") are certified on the sparse path;
    redundant ones (a continuous beam per level: a parallel-crank linkage, columns - 1 redundant
    rows per level) fail the certificate and fall back to the dense rank-revealing path, which
    reports the rank. Both give the dense path's answer."""
    w, h = 4, 3
    scene = scenes.lattice(columns=w, rows=h, beams=beams)
    sp = scene.build(uk_solver="sparse")
    de = scene.build(uk_solver="dense")
    m = sp.n_constraints
    redundant = h * (w - 1) if beams == "continuous" else 0
    run = sp.integrate(0.0, sp.y0, 0.15, method="DOPRI5", rtol=1e-10, t_eval=[0.0, 0.05, 0.15])
    n = sp.n_coords
    for k in range(3):  # states along the motion (consistent, moving)
        y = np.asarray(run["y"])[:, k]
        q, qd = y[:n], y[n:]
        a, b = sp.qdd(0.0, q, qd), de.qdd(0.0, q, qd)
        ri, rd = sp.rank_info(), de.rank_info()
        assert rd["rank"] == m - redundant and rd["exact"]
        assert ri["rank"] == m - redundant
        assert ri["uk_path"] == ("dense" if redundant else "sparse")
        cond = rd["sigma_max"] / rd["sigma_min_kept"]
        assert np.max(np.abs(a - b)) <= 20 * cond * np.finfo(float).eps * np.max(np.abs(b))
        # the constrained acceleration satisfies A qdd = b on the (consistent) rows
        _, _, acc = sp.residuals(0.0, q, qd)
        assert np.max(np.abs(acc)) <= 1e-9 * max(1.0, np.max(np.abs(b)))


def test_rank_info_after_a_large_sparse_solve_reports_the_certificate():
    s = scenes.chain(links=200, angle=-0.3).build(uk_solver="sparse")  # m = 400 > 256
    s.qdd(0.0, s.q0, s.qd0)
    info = s.rank_info()
    assert info["uk_path"] == "sparse" and info["rank"] == s.n_constraints
    assert info["exact"] is False and info["sigma_min_kept"] > info["tolerance"] > 0.0
    small = scenes.chain(links=100, angle=-0.3).build(uk_solver="sparse")  # m = 200: exact on demand
    small.qdd(0.0, small.q0, small.qd0)
    exact = small.rank_info()
    assert exact["exact"] is True and exact["rank"] == small.n_constraints


def test_lattice_example_is_the_builtin_scene():
    from pathlib import Path

    from ukflex.model import scenefile

    sf = scenefile.load(Path(__file__).resolve().parents[1] / "examples" / "lattice.toml")
    assert sf.scene.to_dict() == scenes.lattice(columns=6, rows=4).to_dict()
    s = sf.build()
    s.qdd(0.0, s.q0, s.qd0)
    assert s.rank_info()["uk_path"] == "sparse" and s.rank_info()["rank"] == s.n_constraints == 152
