"""Independent NumPy reference for spatial (3D) rigid multibody systems.

Written apart from the Rust core, as the cross-check for its spatial kinds (docs/spatial-design.md):

* :mod:`.rotations` -- Euler parameters: ``A(p)``, ``G``, ``E``, ``B(p, a) = d(A a)/dp``;
* :mod:`.bodies` -- rigid body ``[r (3), p (4)]`` (centre of mass, Euler parameters) and point mass;
* :mod:`.joints` -- markers (frames on bodies), the ten joint kinds, rotation/translation drivers;
* :mod:`.forces` -- point forces, torques, translational and rotational spring-dampers;
* :mod:`.model` -- :class:`SpatialModel`: ``M``, ``Q``, ``Phi``, ``A``, ``b``, energies, rank report;
* :mod:`.uk` -- UK accelerations for the singular Euler-parameter mass matrix (three routes),
  multipliers, joint reactions and their uniqueness, initial-state correction, solve_ivp driver;
* :mod:`.cp` -- coordinate partitioning (complete-pivoting LU, Newton recovery);
* :mod:`.scenes` -- heavy top, spatial double pendulum, MBS benchmarks A04 and A05, spatial
  slider-crank.

Pure NumPy/SciPy; it imports nothing else from ukflex.
"""
from .rotations import (skew, rot_A, rot_G, rot_E, rot_B, p_from_matrix, p_from_axis_angle,
                        matrix_from_axis_angle, omega_world, omega_body)
from .bodies import RigidBody, PointMass, box_inertia, check_inertia, InvalidBody
from .joints import (Marker, Joint, Driver, JOINT_ROWS, ConstantSpeed, Polynomial, Harmonic,
                     MotionFunctions, InvalidJoint, frame_from_z)
from .model import SpatialModel
from .uk import (qdd_block, qdd_augmented, qdd_singular, accelerations, multipliers, joint_reactions,
                 reaction_uniqueness, correct_initial_state, consistent_velocities, simulate, project,
                 SpatialResult, uk_rank)
from .cp import partition, cp_accelerations, simulate_cp
from . import scenes

__all__ = [
    "skew", "rot_A", "rot_G", "rot_E", "rot_B", "p_from_matrix", "p_from_axis_angle",
    "matrix_from_axis_angle", "omega_world", "omega_body",
    "RigidBody", "PointMass", "box_inertia", "check_inertia", "InvalidBody",
    "Marker", "Joint", "Driver", "JOINT_ROWS", "ConstantSpeed", "Polynomial", "Harmonic",
    "MotionFunctions", "InvalidJoint", "frame_from_z",
    "SpatialModel",
    "qdd_block", "qdd_augmented", "qdd_singular", "accelerations", "multipliers", "joint_reactions",
    "reaction_uniqueness", "correct_initial_state", "consistent_velocities", "simulate", "project",
    "SpatialResult", "uk_rank",
    "partition", "cp_accelerations", "simulate_cp", "scenes",
]
