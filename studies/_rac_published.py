"""Simo and Vu-Quoc's published out-of-plane displacement histories of the right-angle cantilever
(J. C. Simo and L. Vu-Quoc 1988, "On the dynamics in space of rods undergoing large motions - a
geometrically exact approach", Computer Methods in Applied Mechanics and Engineering 66, 125-161:
the figure of the elbow's and the tip's out-of-plane displacement over 0-30 s of their
right-angle cantilever example). The histories are published as curves (no table of them was
found): the points below were read from that figure by others (digitized), not tabulated by the
authors.

``ELBOW`` and ``TIP``: one reading of both curves, the reference data of the AeroBeams.jl test
suite (its right-angled "elbow frame" case, labelled there Simo and Vu-Quoc). ``TIP_SECOND_READING``:
an independent reading of the tip curve, in the FinEtoolsFlexStructures.jl examples (P. Krysl).
The two readings of the tip agree on its first maximum (8.30 / 8.32), less on its minimum
(-9.67 / -9.21), and not on their times (7.67 s / 6.58 s, 15.99 s / 14.7 s): the second one's time
axis is off by up to a second, so it only shows the spread of the readings.

Pairs ``(t [s], u_z)``; the force ``F_z`` at the elbow is positive (``+z``), and both curves start
upwards.
"""

from __future__ import annotations

from typing import List, Tuple

import numpy as np

ELBOW = (
    (0, 0), (0.60269, 0.29475), (0.95993, 1.0267), (1.322, 2.013), (1.5256, 2.8603), (1.7359, 3.6047),
    (1.9227, 4.1674), (2.2075, 4.7058), (2.5052, 5.1291), (2.7182, 5.3467), (3.0479, 5.5035),
    (3.305, 5.4849), (3.6, 5.2421), (3.8227, 4.7816), (4.0211, 4.2726), (4.3358, 3.7755), (4.6317, 3.3572),
    (4.9271, 3.0237), (5.2406, 2.7627), (5.7128, 2.5742), (6.1294, 2.4765), (6.484, 2.5304), (6.9054, 2.687),
    (7.2484, 2.6259), (7.6169, 2.383), (7.9006, 1.9587), (8.148, 1.4557), (8.427, 0.75279),
    (8.6938, 0.043891), (8.9362, -0.68918), (9.203, -1.3799), (9.6057, -2.3373), (9.9766, -3.0585),
    (10.31, -3.6585), (10.819, -3.8714), (11.124, -3.66), (11.476, -3.1642), (11.809, -2.4261),
    (12.105, -1.6092), (12.364, -0.77413), (12.629, -0.09042), (12.944, 0.52054), (13.23, 0.91359),
    (13.694, 1.161), (14.208, 1.039), (14.718, 0.68685), (15.136, 0.29858), (15.444, -0.1016),
    (15.869, -0.59281), (16.189, -0.96274), (16.625, -1.2481), (17.109, -1.3761), (17.61, -1.2681),
    (18.215, -1.033), (18.637, -1.0096), (19.086, -1.3676), (19.431, -1.8103), (19.837, -2.2348),
    (20.371, -2.6354), (20.831, -2.7331), (21.294, -2.4918), (21.69, -1.99), (21.98, -1.27),
    (22.239, -0.51963), (22.547, 0.30932), (22.817, 1.2231), (23.143, 2.1852), (23.468, 3.214),
    (23.787, 4.2003), (24.18, 5.126), (24.714, 5.9545), (25.16, 6.1051), (25.706, 5.7892), (26.162, 5.2374),
    (26.587, 4.7038), (27.097, 4.2367), (27.736, 3.8117), (28.543, 2.8657), (28.944, 2.1626),
    (29.365, 1.2657), (29.631, 0.59312), (29.892, -0.02495),
)
TIP = (
    (0, 0), (0.8088, 0.034833), (1.6053, 0.033384), (2.1373, 0.13034), (2.5778, 0.61917), (2.9179, 1.3693),
    (3.2859, 2.2033), (3.902, 3.368), (4.6579, 4.8262), (5.1996, 5.7765), (5.8638, 6.7498), (6.2941, 7.3832),
    (6.5982, 7.8164), (7.1945, 8.2303), (7.6655, 8.2947), (8.2129, 8.1585), (8.7673, 7.5699),
    (9.2538, 6.4686), (9.6302, 5.6705), (9.907, 5.0125), (10.181, 4.0234), (10.534, 3.2347), (10.88, 1.8584),
    (11.225, 0.76198), (11.463, -0.49749), (11.73, -2.1301), (12.15, -4.066), (12.525, -5.4936),
    (12.809, -6.5014), (13.304, -7.4582), (13.867, -8.0141), (14.643, -8.6171), (15.236, -9.271),
    (15.987, -9.6734), (16.542, -9.3993), (17.164, -8.5098), (17.607, -7.4847), (18.114, -6.2359),
    (18.56, -5.001), (19.047, -3.4444), (19.515, -2.0043), (19.927, -0.47092), (20.268, 0.95537),
    (20.586, 2.3584), (20.974, 3.7659), (21.518, 5.1919), (22.582, 6.435), (23.066, 6.5926),
    (23.732, 6.2977), (24.351, 6.0167), (25.169, 6.4722), (26.076, 6.9835), (26.78, 6.6325), (27.52, 5.5866),
    (27.985, 4.2148), (28.269, 3.0812), (28.891, 2.0542), (29.673, 1.2693), (29.906, 0.84457),
)
TIP_SECOND_READING = (
    (0, 0), (0.94612, 0.025692), (1.5375, 0.92688), (2.3259, 2.3913), (3.0355, 3.668), (3.8633, 5.0949),
    (4.5729, 6.3715), (5.1643, 7.2352), (5.8739, 8.0237), (6.5834, 8.3241), (7.4507, 8.0237),
    (8.2786, 6.7846), (8.8305, 5.6957), (9.2641, 4.419), (9.8949, 2.6917), (10.329, 1.1522),
    (10.723, -0.53755), (11.275, -3.4664), (11.787, -5.5692), (12.26, -7.0711), (12.97, -7.9723),
    (13.758, -8.5356), (14.428, -9.2115), (15.059, -9.2115), (15.966, -8.4229), (16.873, -6.6581),
    (17.74, -4.33), (18.568, -1.8893), (18.962, -0.086957), (19.632, 2.5791), (20.302, 4.4565),
    (20.894, 5.5079), (21.879, 6.5217), (22.746, 6.7846), (23.693, 6.2964), (24.481, 6.1462),
    (25.191, 6.6719), (25.821, 7.498), (26.413, 6.9348), (26.965, 5.4704), (27.438, 4.1561),
    (27.792, 2.8419), (28.423, 1.2648), (29.409, 0.81423), (29.961, 0.73913),
)

#: The extrema (``|u_z| > 0.5``; t [s], u_z, +1 at a maximum / -1 at a minimum) of a third code's
#: computed histories, not a reading: AeroBeams.jl's own solution of the same frame (its test's stored output,
#: ``test/newTestDataGenerators/elbowFrame/u3_elbow.txt`` and ``u3_tip.txt``, commit 04634043b917;
#: 20 elements per member, time step 0.05 s, the data above; sampled every 0.05 s, so its
#: times are good to 0.025 s). A geometrically exact beam of another formulation (Hodges'
#: mixed one), against which its own figure plots the readings above.
AEROBEAMS_ELBOW = ((3.10, 5.5099, 1), (6.60, 2.4627, -1), (6.90, 2.4685, 1), (10.85, -4.0609, -1), (13.80, 0.9297, 1),
                   (17.40, -1.8773, -1), (18.55, -1.7137, 1), (20.95, -3.2896, -1), (25.25, 6.1061, 1))
AEROBEAMS_TIP = ((7.45, 8.2513, 1), (15.85, -9.7340, -1), (22.65, 6.5650, 1), (23.55, 6.4002, -1), (26.15, 7.2092, 1))

#: how far apart in time [s] a published extremum and ukflex's are still matched
WINDOW = 1.5


def extrema(t: np.ndarray, u: np.ndarray) -> List[Tuple[float, float, int]]:
    """The local extrema ``(t, u, +1 at a maximum / -1 at a minimum)`` of a sampled curve: interior sign changes of its slope, a
    plateau of equal samples (a reading may give two) counted once at its middle."""
    out = []
    d = np.diff(u)
    i = 1
    while i < len(u) - 1:
        j = i
        while j < len(d) - 1 and d[j] == 0:
            j += 1
        if d[i - 1] * d[j] < 0:
            out.append((float(0.5 * (t[i] + t[j])), float(u[i]), 1 if d[j] < 0 else -1))
        i = j + 1
    return out


def compare_computed(t: np.ndarray, elbow: np.ndarray, tip: np.ndarray, scale: float) -> List[str]:
    """Markdown rows: each extremum of AeroBeams' computed histories (``AEROBEAMS_ELBOW``,
    ``AEROBEAMS_TIP``) against the extremum of the same kind nearest in time of the sampled
    histories ``elbow``, ``tip``, and against the published (read) extremum of the same kind
    within ``WINDOW`` (the elbow and the first reading of the tip): the differences in ``u_z``
    over ``scale``."""
    rows = ["| point | AeroBeams (computed): t [s], u_z | ukflex - AeroBeams: u_z (/ max abs u_z), t [s] | "
            "published (read) - AeroBeams: u_z (/ max abs u_z) |", "|---|---|---|---|"]
    for name, theirs, pub, u in (("elbow", AEROBEAMS_ELBOW, ELBOW, elbow), ("tip", AEROBEAMS_TIP, TIP, tip)):
        mine = extrema(t, u)
        p = np.asarray(pub, dtype=float).T
        read = extrema(p[0], p[1])
        for ta, ua, kind in theirs:
            tm, um, _ = min((m for m in mine if m[2] == kind), key=lambda m: abs(m[0] - ta))
            near = [r for r in read if r[2] == kind and abs(r[0] - ta) <= WINDOW]
            pr = min(near, key=lambda r: abs(r[0] - ta)) if near else None
            cell = f"{pr[1] - ua:+.3f} ({(pr[1] - ua) / scale:+.1%})" if pr else "none"
            rows.append(f"| {name} | {ta:.2f}, {ua:+.3f} | {um - ua:+.3f} ({(um - ua) / scale:+.2%}), {tm - ta:+.2f} | {cell} |")
    return rows


def compare(t: np.ndarray, elbow: np.ndarray, tip: np.ndarray, scale: float) -> List[str]:
    """Markdown rows: each published (read) extremum of the elbow's and the tip's ``u_z`` with
    ``|u_z| > 0.5`` against the extremum of the same kind (maximum or minimum) of the sampled
    histories ``elbow``, ``tip`` (``u_z`` at ``t``) nearest in time and within ``WINDOW`` (else
    the history's value at the published time); the difference in value, also over ``scale`` (the
    largest ``|u_z|``), and in time."""
    rows = ["| point | published (read): t [s], u_z | ukflex: t [s], u_z | difference in u_z (/ max abs u_z) | in t [s] |",
            "|---|---|---|---|---:|"]
    for name, pub, u in (("elbow", ELBOW, elbow), ("tip", TIP, tip), ("tip, second reading", TIP_SECOND_READING, tip)):
        p = np.asarray(pub, dtype=float).T
        mine = extrema(t, u)
        for tp, up, kind in extrema(p[0], p[1]):
            if abs(up) <= 0.5:
                continue
            near = [m for m in mine if m[2] == kind and abs(m[0] - tp) <= WINDOW]
            tm, um, _ = min(near, key=lambda m: abs(m[0] - tp)) if near else (tp, float(np.interp(tp, t, u)), kind)
            dt = f"{tm - tp:+.2f}" if near else "no extremum (u_z at t)"
            rows.append(f"| {name} | {tp:.2f}, {up:+.3f} | {tm:.2f}, {um:+.3f} | {um - up:+.3f} ({(um - up) / scale:+.1%}) | {dt} |")
    return rows

