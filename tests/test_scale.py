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
