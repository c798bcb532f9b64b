"""CP must say so when its dependent block is singular, not return garbage (issue 6)."""

import numpy as np
import pytest

from ukflex.reference import ReferenceModel
from ukflex.reference.cp import CPPartition, SingularDependentBlock, reduced_accelerations


def _pendulum():
    # body frame at the centre of mass, pivot at (-1, 0) in the body frame
    return {
        "gravity": [0.0, -9.81],
        "bodies": [{"name": "bob", "kind": "rigid", "mass": 1.0, "inertia": 0.1}],
        "joints": [{"kind": "revolute", "a": {"body": "ground"}, "b": {"body": "bob", "point": [-1.0, 0.0]}}],
    }


def test_singular_dependent_block_is_reported_not_garbage():
    model = ReferenceModel(_pendulum())
    # Phi = -(R + A(theta) (-1, 0)); with (x, theta) dependent, A_D = [[-1, -sin th], [0, cos th]]:
    # singular when the pendulum is horizontal... at theta = pi/2 the x row loses theta
    part = CPPartition(dep=[0, 2], ind=[1], rows=[0, 1], cond=1.0)
    th = np.pi / 2
    q = np.array([np.cos(th), np.sin(th), th])
    qd = np.zeros(3)
    with pytest.raises(SingularDependentBlock, match=r"t=0.5 .*coordinates \[0, 2\]"):
        reduced_accelerations(model, part, 0.5, q, qd)
    # away from the singular angle the same partition works and satisfies the constraints
    th = 0.3
    q = np.array([np.cos(th), np.sin(th), th])
    _, qdd = reduced_accelerations(model, part, 0.0, q, qd)
    A, b = model.A(q), model.gamma(0.0, q, qd)
    np.testing.assert_allclose(A @ qdd, b, atol=1e-12)
