"""Data of a general planar flexible (FFRF) body: its inertia invariants, elastic matrices and
interface points (``docs/flexible-bodies.md``).

:class:`FlexibleData` is what :meth:`ukflex.Scene.flexible_body` takes.  Users rarely write one
by hand: the builders in :mod:`ukflex.fe` compute it from a finite-element model (node
coordinates and nodal mass/stiffness matrices, or a planar mesh) reduced to a few modes.  The
core (``rust/body/flexible.rs``) validates it: sizes, symmetry, a positive definite mass, a
stiffness without rigid-body modes, markers that fit.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

__all__ = ["FlexibleData", "InterfacePoint"]


@dataclass
class InterfacePoint:
    """A point of a flexible body where joints, drivers and forces attach.

    ``point``: undeformed body-frame position; ``displacement``: the (2, n_f) rows of its elastic
    displacement ``u = displacement @ q_f`` (body frame); ``rotation``: the (n_f,) row of its
    elastic rotation ``psi = rotation @ q_f`` (optional; zero if omitted).
    """

    point: Tuple[float, float]
    displacement: np.ndarray
    rotation: Optional[np.ndarray] = None

    def to_dict(self, name: str) -> Dict[str, Any]:
        d: Dict[str, Any] = {
            "name": name,
            "point": [float(self.point[0]), float(self.point[1])],
            "displacement": np.asarray(self.displacement, dtype=float).reshape(2, -1).tolist(),
        }
        if self.rotation is not None:
            d["rotation"] = np.asarray(self.rotation, dtype=float).ravel().tolist()
        return d


@dataclass
class FlexibleData:
    """Invariants of a planar FFRF body with ``n_f`` elastic coordinates (body frame; the
    displacement field is ``u_f(P) = S(P) q_f`` and ``u0`` the undeformed position):

    mass, inertia (about the centre of mass), com
        of the undeformed body;
    s_bar : (2, n_f)
        ``int rho S dV``;
    s_u0, s_ju0 : (n_f,)
        ``int rho S^T u0 dV`` and ``int rho S^T J u0 dV`` (``J`` the +90 degree turn; plus the
        rotary inertia of sections for structural elements);
    s_tilde : (n_f, n_f)
        ``int rho S^T I~ S dV``, entries ``S_x,i S_y,j - S_y,i S_x,j`` (antisymmetric);
    m_ff, k_ff, d_ff : (n_f, n_f)
        elastic mass, stiffness (positive definite: rigid-body modes removed) and damping;
    m_ff_tr : (n_f, n_f), optional
        ``int rho S^T S dV`` where it differs from ``m_ff`` (rotary inertia);
    k3, k4 : optional
        third- and fourth-order stiffness tensors (``n_f**3``, ``n_f**4``) of the strain energy
        ``q K q / 2 + k3 q q q / 6 + k4 q q q q / 24``, used with ``strain="nonlinear"``;
    markers : dict name -> InterfacePoint
        the interface points.
    """

    mass: float
    inertia: float
    com: Tuple[float, float]
    s_bar: np.ndarray
    s_u0: np.ndarray
    s_ju0: np.ndarray
    s_tilde: np.ndarray
    m_ff: np.ndarray
    k_ff: np.ndarray
    markers: Dict[str, InterfacePoint] = field(default_factory=dict)
    d_ff: Optional[np.ndarray] = None
    m_ff_tr: Optional[np.ndarray] = None
    k3: Optional[np.ndarray] = None
    k4: Optional[np.ndarray] = None
    #: Optional extras for inspection (frequencies, mode shapes on the nodes, ...): never sent
    #: to the core.
    info: Dict[str, Any] = field(default_factory=dict)

    @property
    def n_f(self) -> int:
        return int(np.asarray(self.k_ff).shape[0])

    def to_dict(self) -> Dict[str, Any]:
        """The body fields of the scene description (``docs/scene-format.md``)."""
        d: Dict[str, Any] = {
            "mass": float(self.mass),
            "inertia": float(self.inertia),
            "com": [float(self.com[0]), float(self.com[1])],
        }
        for key in ("s_bar", "s_u0", "s_ju0", "s_tilde", "m_ff", "k_ff", "d_ff", "m_ff_tr"):
            v = getattr(self, key)
            if v is not None:
                d[key] = np.asarray(v, dtype=float).tolist()
        for key in ("k3", "k4"):
            v = getattr(self, key)
            if v is not None:
                d[key] = np.asarray(v, dtype=float).ravel().tolist()
        d["markers"] = [p.to_dict(name) for name, p in self.markers.items()]
        return d

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "FlexibleData":
        """Inverse of :meth:`to_dict` (also reads a flexible body entry of a description)."""
        n = len(d["k_ff"])
        arr = lambda k: None if d.get(k) is None else np.asarray(d[k], dtype=float)  # noqa: E731
        markers = {
            m["name"]: InterfacePoint(tuple(m["point"]), np.asarray(m["displacement"], dtype=float), arr_or_none(m.get("rotation")))
            for m in d.get("markers", [])
        }
        k3 = arr("k3")
        k4 = arr("k4")
        return cls(
            mass=float(d["mass"]),
            inertia=float(d["inertia"]),
            com=tuple(d.get("com", (0.0, 0.0))),
            s_bar=arr("s_bar"),
            s_u0=arr("s_u0"),
            s_ju0=arr("s_ju0"),
            s_tilde=arr("s_tilde"),
            m_ff=arr("m_ff"),
            k_ff=arr("k_ff"),
            markers=markers,
            d_ff=arr("d_ff"),
            m_ff_tr=arr("m_ff_tr"),
            k3=None if k3 is None else k3.reshape(n, n, n),
            k4=None if k4 is None else k4.reshape(n, n, n, n),
        )


def arr_or_none(v: Optional[Sequence[float]]) -> Optional[np.ndarray]:
    return None if v is None else np.asarray(v, dtype=float)
