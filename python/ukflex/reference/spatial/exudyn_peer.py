"""The same spherical-joint scenes in Exudyn (the peer): ``NodeRigidBodyEP`` + ``ObjectRigidBody``
+ ``ObjectJointSpherical``, gravity by ``LoadMassProportional``, generalized-alpha with spectral
radius 1 (second order, no numerical damping), dense linear solver, Newton to 1e-12.

Exudyn is imported inside :func:`run` only; the reference does not need it.
"""
from __future__ import annotations

import warnings

import numpy as np


def run(model, q0, qd0, t_end, h):
    """Positions and rotation matrices of every body at ``t_end`` (dicts by body name)."""
    import exudyn as exu
    from exudyn.itemInterface import (LoadMassProportional, MarkerBodyMass, MarkerBodyPosition,
                                      NodeRigidBodyEP, ObjectGround, ObjectJointSpherical, ObjectRigidBody)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    obj, nodes = {}, {}
    for b in model.bodies:
        if b.kind != "rigid":
            raise NotImplementedError("rigid bodies only")
        o = b.offset
        n = mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=list(q0[o:o + 7]),
                                        initialVelocities=list(qd0[o:o + 7])))
        J = b.inertia
        obj[b.name] = mbs.AddObject(ObjectRigidBody(
            physicsMass=b.mass, physicsInertia=[J[0, 0], J[1, 1], J[2, 2], J[1, 2], J[0, 2], J[0, 1]],
            nodeNumber=n))
        nodes[b.name] = n
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=obj[b.name])),
                                         loadVector=list(model.gravity)))
    for j in model.joints:
        if j.kind != "spherical":
            raise NotImplementedError("spherical joints only")
        mk = [mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground if mm.body is None else obj[mm.body.name],
                                               localPosition=list(mm.s))) for mm in (j.mi, j.mj)]
        mbs.AddObject(ObjectJointSpherical(markerNumbers=mk))
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.timeIntegration.numberOfSteps = int(round(t_end / h))
    s.timeIntegration.endTime = t_end
    s.timeIntegration.verboseMode = 0
    s.timeIntegration.newton.relativeTolerance = 1e-12
    s.timeIntegration.newton.absoluteTolerance = 1e-14
    s.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    s.timeIntegration.generalizedAlpha.computeInitialAccelerations = True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        s.solutionSettings.writeSolutionToFile = False
    exu.SolveDynamic(mbs, s, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    pos = {k: np.array(mbs.GetNodeOutput(n, exu.OutputVariableType.Position)) for k, n in nodes.items()}
    rot = {k: np.array(mbs.GetNodeOutput(n, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
           for k, n in nodes.items()}
    return pos, rot


def compare(model, t_end=0.5, steps=(2.5e-4, 1.25e-4), ref=None):
    """Max position error of Exudyn at each step against the reference run (rtol 1e-12), and of
    Richardson's extrapolation of the last two (positions; rotation matrices scaled by 0.1 m)."""
    from .rotations import rot_A
    from .uk import simulate
    q0, qd0 = model.initial_guess()
    if ref is None:
        ref = simulate(model, t_end, q0, qd0, rtol=1e-12, atol=1e-14, t_eval=[t_end])
    qe = ref.q[:, -1]
    runs = [run(model, q0, qd0, t_end, h) for h in steps]
    errs = [max(np.abs(pos[b.name] - b.r(qe)).max() for b in model.bodies) for pos, _ in runs]
    rerr = [max(np.abs(rot[b.name] - rot_A(b.p(qe))).max() for b in model.bodies) for _, rot in runs]
    rich = max(max(np.abs((4 * runs[-1][0][b.name] - runs[-2][0][b.name]) / 3 - b.r(qe)).max(),
                   0.1 * np.abs((4 * runs[-1][1][b.name] - runs[-2][1][b.name]) / 3 - rot_A(b.p(qe))).max())
               for b in model.bodies)
    return {"steps": list(steps), "position_error": errs, "rotation_error": rerr, "richardson": rich}
