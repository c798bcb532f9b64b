"""Sensors of a simulation result: joint reactions, driver power and work, energies per body and
per kind, an energy balance, and beam internal forces (docs/outputs.md).

Everything per state is computed in Rust from the stored states (``System.sensors``,
``System.beam_internal_forces``: one call for the whole history, no Python per state); this
module names the numbers, integrates powers over time and closes the balance::

    >>> s = res.sensors                                   # doctest: +SKIP
    >>> s.reaction("crank_pin")["fx"]                     # doctest: +SKIP
    >>> s.energy_balance()["relative_error"]              # doctest: +SKIP
    >>> s.internal_forces("coupler", [0.0, 0.5, 1.0])["M"]  # doctest: +SKIP

Sign conventions
----------------
* ``M qdd + A^T lambda = Q``. A joint's reaction is what it exerts on the body of its *first*
  marker (``a``; ``point`` of a point-on-line joint or a coordinate driver), at that marker: a
  force (world frame ``fx, fy``; joint frame ``fx_local, fy_local``) and a torque. The other
  body receives the opposite force at the same point.
* The power of a constraint item is ``-lambda^T A qd`` (its constraint forces on the whole
  system): zero for joints, the input power for drivers.
* Beam internal forces act from the part beyond ``xi`` on the part before it, in the beam frame:
  ``N`` tension positive, ``V`` along +y, ``M`` counterclockwise (``M = E I kappa``,
  ``V = -dM/dx``): a cantilever with an upward tip load ``P`` has ``M(x) = P (L - x)``,
  ``V = P``.
"""

from __future__ import annotations

import re
from functools import cached_property
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..errors import UnknownNameError

def parse_xi(expr: str, xi_text: str) -> float:
    """The axis coordinate XI of an output expression such as ``v(coupler, 0.5)``: a number in [0, 1]."""
    try:
        xi = float(xi_text)
    except ValueError:
        raise ValueError(f"output {expr!r}: XI must be a number in [0, 1], got {xi_text!r}") from None
    if not 0.0 <= xi <= 1.0:
        raise ValueError(f"output {expr!r}: XI must lie in [0, 1], got {xi}")
    return xi


__all__ = ["Sensors", "cumulative_integral", "energy_line", "SENSOR_HELP"]

#: Columns of a reaction (``System.sensors``).
REACTION_COLUMNS = ("fx", "fy", "torque", "fx_local", "fy_local", "power")
#: Columns of beam internal forces.
INTERNAL_COLUMNS = ("N", "V", "M", "eps", "kappa")

SENSOR_HELP = (
    "reaction(JOINT).fx|fy|torque|fx_local|fy_local|power, work(DRIVER), "
    "energy.kinetic|strain|gravity|springs|loads|total, energy(BODY).kinetic|strain|gravity, "
    "clearance(JOINT).eccentricity|penetration|normal_force|tangential_force|force, "
    "work.drivers|external, dissipated, balance, N|V|M|eps|kappa(BEAM, XI)"
)


#: :meth:`Sensors.energy_line`: the balance closes when its largest residual is at most this
#: fraction of its largest term ...
BALANCE_CLOSES = 1e-5
#: ... and judges the integrator only when that residual exceeds this many times the quadrature
#: error of the powers over the output samples (``energy_balance()["quadrature_error"]``)
BALANCE_OVER_QUADRATURE = 10.0


def cumulative_integral(t: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``int_{t_0}^{t_k} p dt`` at every sample, by the integral of the C2 cubic spline through
    the samples (error O(h^4) for a smooth ``p``; trapezoid below four samples)."""
    t = np.asarray(t, dtype=float)
    p = np.asarray(p, dtype=float)
    if t.size < 2:
        return np.zeros_like(t)
    if t.size < 4 or np.any(np.diff(t) <= 0):
        return np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))])
    from scipy.interpolate import CubicSpline

    return CubicSpline(t, p, bc_type="not-a-knot").antiderivative()(t)


def _states(res) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(t, q, qd)`` of a result with q, qd of shape (nt, n) (orientation-free: named
    accessors only)."""
    names = res.system.coordinate_names
    q = np.stack([np.asarray(res.coordinate(nm), dtype=float) for nm in names], axis=1)
    qd = np.stack([np.asarray(res.velocity(nm), dtype=float) for nm in names], axis=1)
    return np.asarray(res.t, dtype=float), q, qd


#: Force kinds whose potential is stored elastic energy (``springs``), not a load's.
_SPRING_KINDS = ("spring_damper", "rotational_spring_damper", "bushing", "revolute_clearance")


class Sensors:
    """Sensors of one :class:`ukflex.SimulationResult` (``res.sensors``), computed once on first
    use and cached."""

    #: Columns of :meth:`reaction` (the spatial sensors have their own).
    reaction_columns = REACTION_COLUMNS

    def __init__(self, res):
        self.result = res
        self.system = res.system

    @cached_property
    def _raw(self) -> Dict[str, Any]:
        t, q, qd = _states(self.result)
        self._t = t
        return dict(self.system.core.sensors(t, q, qd))

    @property
    def t(self) -> np.ndarray:
        return np.asarray(self.result.t, dtype=float)

    # ----------------------------------------------------------------------- reactions
    @property
    def joint_names(self) -> List[str]:
        """Names of the joints and drivers, in order (``reaction`` takes these)."""
        return list(self._raw["reaction_names"])

    @cached_property
    def driver_names(self) -> List[str]:
        """Names of the drivers."""
        # the core orders constraint items joints first, then drivers
        nd = len(self.system.description.get("drivers") or [])
        return self.joint_names[len(self.joint_names) - nd:]

    def reaction(self, joint: str) -> Dict[str, Any]:
        """Reaction of ``joint`` (or driver) on its first marker's body: ``fx, fy, torque``
        (world), ``fx_local, fy_local`` (joint frame), ``power``, each (nt,), and ``body``."""
        names = self.joint_names
        if joint not in names:
            raise UnknownNameError.of("joint or driver", joint, names)
        k = names.index(joint)
        r = np.asarray(self._raw["reactions"])[:, k, :]
        out: Dict[str, Any] = {c: r[:, i].copy() for i, c in enumerate(REACTION_COLUMNS)}
        out["body"] = self._raw["reaction_bodies"][k]
        return out

    def driver_work(self, driver: Optional[str] = None) -> np.ndarray:
        """Work done by one driver (or all drivers), accumulated from ``t_0``, shape (nt,)."""
        if driver is not None and driver not in self.driver_names:
            raise UnknownNameError.of("driver", driver, self.driver_names)
        names = [driver] if driver is not None else self.driver_names
        p = sum((self.reaction(d)["power"] for d in names), np.zeros_like(self.t))
        return cumulative_integral(self.t, p)

    # ----------------------------------------------------------------------- energies
    def body_energies(self, body: str) -> Dict[str, np.ndarray]:
        """``kinetic``, ``strain``, ``gravity`` energy of one body, each (nt,)."""
        names = list(self._raw["body_names"])
        if body not in names:
            raise UnknownNameError.of("body", body, names)
        e = np.asarray(self._raw["body_energies"])[:, names.index(body), :]
        return {"kinetic": e[:, 0].copy(), "strain": e[:, 1].copy(), "gravity": e[:, 2].copy()}

    @cached_property
    def _force_kinds(self) -> List[str]:
        return [f["kind"] for f in (self.system.description.get("forces") or [])]

    def energies(self) -> Dict[str, np.ndarray]:
        """Energies by kind, each (nt,): ``kinetic``, ``strain`` (elastic), ``gravity``,
        ``springs`` (spring-dampers), ``loads`` (potential ``-F . r``, ``-tau phi`` of the
        constant loads) and ``total = kinetic + strain + gravity + springs`` (the loads appear
        as external work instead)."""
        e = np.asarray(self._raw["body_energies"])
        fp = np.asarray(self._raw["force_potentials"])
        kinds = np.array(self._force_kinds, dtype=object)
        spring = np.isin(kinds, _SPRING_KINDS)
        springs = fp[:, spring].sum(axis=1) if fp.size else np.zeros(e.shape[0])
        loads = fp[:, ~spring].sum(axis=1) if fp.size else np.zeros(e.shape[0])
        out = {"kinetic": e[:, :, 0].sum(axis=1), "strain": e[:, :, 1].sum(axis=1),
               "gravity": e[:, :, 2].sum(axis=1), "springs": springs, "loads": loads}
        out["total"] = out["kinetic"] + out["strain"] + out["gravity"] + out["springs"]
        return out

    def clearance(self, name: str) -> Dict[str, np.ndarray]:
        """The contact of the revolute joint with clearance ``name``, each (nt,):
        ``eccentricity``, ``penetration`` (negative in free flight), ``normal_force``,
        ``tangential_force`` and ``force`` (the contact force's magnitude)."""
        names = list(self._raw.get("clearance_names", []))
        if name not in names:
            raise UnknownNameError.of("revolute joint with clearance", name, names)
        c = np.asarray(self._raw["clearance"])[:, names.index(name), :]
        return {col: c[:, i].copy() for i, col in enumerate(self._raw["clearance_columns"])}

    def external_work(self) -> np.ndarray:
        """Work of the external loads from ``t_0``, shape (nt,): the constant ones (point
        forces, torques) exactly minus the change of their potential; the loads that are
        functions of time and state and the motors (docs/loads.md) by the integral of their
        power (``System.sensors``' ``load_power``)."""
        loads = self.energies()["loads"]
        w = -(loads - loads[0])
        power = self._raw.get("load_power")
        if power is not None and np.any(power):
            w = w + cumulative_integral(self.t, np.asarray(power))
        return w

    def dissipated(self) -> np.ndarray:
        """Energy dissipated by damping (spring-dampers, beam strain-rate damping) from ``t_0``,
        the integral of ``System.sensors``' ``dissipation_power``, shape (nt,)."""
        return cumulative_integral(self.t, np.asarray(self._raw["dissipation_power"]))

    def energy_balance(self) -> Dict[str, Any]:
        """``E(t) - E(0) = W_drivers + W_external - dissipated`` term by term, each (nt,), with
        ``residual`` (left minus right side), ``scale`` (the largest term) and
        ``relative_error = max |residual| / scale``. The residual is what the integrator (and
        the quadrature of the powers over the output samples) lost or gained: at a tight
        tolerance with a non-dissipative method it is small; a dissipative method
        (generalized-alpha) shows its numerical dissipation here."""
        e = self.energies()["total"]
        de = e - e[0]
        wd = self.driver_work() if self.driver_names else np.zeros_like(de)
        we = self.external_work()
        d = self.dissipated()
        res = de - wd - we + d
        scale = max(float(np.max(np.abs(x))) for x in (de, wd, we, d, e))
        return {"t": self.t, "energy": e, "change": de, "driver_work": wd, "external_work": we, "dissipated": d,
                "residual": res, "scale": scale,
                "relative_error": float(np.max(np.abs(res)) / scale) if scale > 0 else 0.0,
                "quadrature_error": self._quadrature_error()}

    def _quadrature_error(self) -> float:
        """How much the output sampling limits the balance: the largest change of the integrated
        powers (drivers' work minus dissipation) when every other sample is left out. Zero
        without drivers and damping (the energies and the loads' work are exact at each sample);
        of the order of the work itself when the samples do not resolve the powers (a fast
        oscillation between them)."""
        t = self.t
        p = np.asarray(self._raw["dissipation_power"], dtype=float) * -1.0
        for name in self.driver_names:
            p = p + self.reaction(name)["power"]
        if not np.any(p) or t.size < 3:
            return 0.0
        w = cumulative_integral(t, p)
        return float(np.max(np.abs(w[::2] - cumulative_integral(t[::2], p[::2]))))

    def energy_line(self) -> str:
        """One line: ``T + V`` at both ends, the drivers' and external work, the dissipated
        energy and whether the balance closes (its residual relative to the largest term)."""
        bal = self.energy_balance()
        e, r = bal["energy"], bal["residual"][-1]
        parts = [f"energy T + V: {e[0]:.9g} -> {e[-1]:.9g} (change {e[-1] - e[0]:+.3e})"]
        if np.any(bal["driver_work"]):
            parts.append(f"driver work {bal['driver_work'][-1]:+.3e}")
        if np.any(bal["external_work"]):
            parts.append(f"external work {bal['external_work'][-1]:+.3e}")
        if np.any(bal["dissipated"]):
            parts.append(f"damping {bal['dissipated'][-1]:.3e}")
        closes = bal["relative_error"] <= BALANCE_CLOSES
        worst = float(np.max(np.abs(bal["residual"])))
        if closes:
            verdict = "closes"
        elif worst <= BALANCE_OVER_QUADRATURE * bal["quadrature_error"]:
            # the residual is within what the sampling of the powers can explain: no verdict on the integrator
            parts.append(f"balance not judged: the {self.t.size} output samples do not resolve the driver and "
                         f"damping power (leaving out every other sample changes their work by "
                         f"{bal['quadrature_error']:.1e}; residual {r:+.3e}); more samples tell")
            return ", ".join(parts)
        else:
            verdict = "open: the integrator lost energy" if r < 0 else "open: the integrator gained energy"
        parts.append(f"balance {verdict} (residual {r:+.3e}, {bal['relative_error']:.1e} of the largest term)")
        return ", ".join(parts)

    # ----------------------------------------------------------------------- beams
    def internal_forces(self, body: str, xi: Sequence[float]) -> Dict[str, np.ndarray]:
        """Internal forces and strains of beam ``body`` at the axis points ``xi`` in [0, 1]:
        ``N, V, M, eps, kappa``, each (nt, len(xi)), in the beam frame (module docs)."""
        xi = np.atleast_1d(np.asarray(xi, dtype=float))
        _, q, _ = _states(self.result)
        a = np.asarray(self.system.core.beam_internal_forces(body, xi, q))
        return {c: a[:, :, i] for i, c in enumerate(INTERNAL_COLUMNS)}

    # ----------------------------------------------------------------------- export
    def columns(self) -> Dict[str, np.ndarray]:
        """Every sensor as a named column (nt,): reactions, energies, work, balance."""
        out: Dict[str, np.ndarray] = {}
        for j in self.joint_names:
            r = self.reaction(j)
            for c in self.reaction_columns:
                out[f"reaction({j}).{c}"] = r[c]
        for d in self.driver_names:
            out[f"work({d})"] = self.driver_work(d)
        for b in self._raw["body_names"]:
            for k, v in self.body_energies(b).items():
                out[f"energy({b}).{k}"] = v
        for k, v in self.energies().items():
            out[f"energy.{k}"] = v
        for j in self._raw.get("clearance_names", []):
            for k, v in self.clearance(j).items():
                out[f"clearance({j}).{k}"] = v
        bal = self.energy_balance()
        out["work.drivers"] = bal["driver_work"]
        out["work.external"] = bal["external_work"]
        out["dissipated"] = bal["dissipated"]
        out["balance"] = bal["residual"]
        return out

    def save_npz(self, path: str) -> None:
        """Write ``t`` and :meth:`columns` to a NumPy .npz file."""
        np.savez(path, t=self.t, **self.columns())

    # ----------------------------------------------------------------------- expressions
    _INTERNAL = re.compile(r"^(N|V|M|eps|kappa)\(\s*([^,()\s]+)\s*,\s*([^()\s]+)\s*\)$")
    _REACTION = re.compile(r"^reaction\(\s*([^()\s]+)\s*\)\.(\w+)$")
    _WORK = re.compile(r"^work\(\s*([^()\s]+)\s*\)$")
    _BODY_ENERGY = re.compile(r"^energy\(\s*([^()\s]+)\s*\)\.(\w+)$")
    _CLEARANCE = re.compile(r"^clearance\(\s*([^()\s]+)\s*\)\.(\w+)$")

    @classmethod
    def parse(cls, system, expr: str) -> Optional[Tuple[Any, ...]]:
        """A parsed sensor expression (see ``SENSOR_HELP``), ``None`` if ``expr`` is not one;
        ``ValueError`` naming the problem if it is one with a wrong argument."""
        e = expr.strip()
        m = cls._REACTION.match(e)
        if m:
            if m.group(2) not in REACTION_COLUMNS:
                raise ValueError(f"output {expr!r}: reaction columns are {REACTION_COLUMNS}")
            items = list(system.core.constraint_items)
            if m.group(1) not in items:
                raise ValueError(f"output {expr!r}: unknown joint or driver {m.group(1)!r}; joints and drivers are {items}")
            return ("reaction", m.group(1), m.group(2))
        m = cls._CLEARANCE.match(e)
        if m:
            raw = system.core.sensors(np.array([system.t0]), system.q0[None, :], system.qd0[None, :], reactions=False)
            names, columns = list(raw["clearance_names"]), list(raw["clearance_columns"])
            if m.group(1) not in names:
                raise ValueError(f"output {expr!r}: unknown revolute joint with clearance {m.group(1)!r}; they are {names}")
            if m.group(2) not in columns:
                raise ValueError(f"output {expr!r}: clearance columns are {tuple(columns)}")
            return ("clearance", m.group(1), m.group(2))
        m = cls._INTERNAL.match(e)
        if m:
            what, body, xi_text = m.groups()
            if body not in system.body_names or not system.capabilities(body)["beam"]:
                raise ValueError(f"output {expr!r}: {body!r} is not a beam")
            return ("internal", what, body, parse_xi(expr, xi_text))
        return cls._parse_common(system, e, expr)

    @classmethod
    def _parse_common(cls, system, e: str, expr: str) -> Optional[Tuple[Any, ...]]:
        """The expressions planar and spatial sensors share: energies, work, balance."""
        if e in ("work.drivers", "work.external", "dissipated", "balance"):
            return ("scalar", e)
        if e.startswith("energy.") and e[7:] in ("kinetic", "strain", "gravity", "springs", "loads", "total"):
            return ("energy", e[7:])
        m = cls._WORK.match(e)
        if m:
            drivers = list(system.core.driver_names)
            if m.group(1) not in drivers:
                raise ValueError(f"output {expr!r}: {m.group(1)!r} is not a driver; drivers are {drivers}")
            return ("work", m.group(1))
        m = cls._BODY_ENERGY.match(e)
        if m:
            if m.group(1) not in system.body_names:
                raise ValueError(f"output {expr!r}: unknown body {m.group(1)!r}; bodies are {system.body_names}")
            if m.group(2) not in ("kinetic", "strain", "gravity"):
                raise ValueError(f"output {expr!r}: body energies are kinetic, strain, gravity")
            return ("body_energy", m.group(1), m.group(2))
        return None

    def evaluate(self, p: Tuple[Any, ...]) -> Tuple[str, np.ndarray]:
        """``(label, values (nt,))`` of a parsed expression (:meth:`parse`)."""
        kind = p[0]
        if kind == "scalar":
            bal = self.energy_balance()
            key = {"work.drivers": "driver_work", "work.external": "external_work", "dissipated": "dissipated",
                   "balance": "residual"}[p[1]]
            return f"{p[1]} [J]", bal[key]
        if kind == "energy":
            return f"energy.{p[1]} [J]", self.energies()[p[1]]
        if kind == "reaction":
            unit = {"torque": "N m", "power": "W"}.get(p[2], "N")
            return f"reaction({p[1]}).{p[2]} [{unit}]", self.reaction(p[1])[p[2]]
        if kind == "work":
            if p[1] not in self.driver_names:
                raise ValueError(f"work({p[1]}): not a driver; drivers are {self.driver_names}")
            return f"work({p[1]}) [J]", self.driver_work(p[1])
        if kind == "clearance":
            unit = {"eccentricity": "m", "penetration": "m"}.get(p[2], "N")
            return f"clearance({p[1]}).{p[2]} [{unit}]", self.clearance(p[1])[p[2]]
        if kind == "body_energy":
            return f"energy({p[1]}).{p[2]} [J]", self.body_energies(p[1])[p[2]]
        _, what, body, xi = p
        unit = {"N": "N", "V": "N", "M": "N m", "eps": "-", "kappa": "1/m"}[what]
        return f"{what}({body}, {xi:g}) [{unit}]", self.internal_forces(body, [xi])[what][:, 0]


def energy_line(res) -> str:
    """The CLI's energy summary of a result (:meth:`Sensors.energy_line`)."""
    return Sensors(res).energy_line()
