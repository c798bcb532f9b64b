//! The planar kinematics and mass of a floating frame `(x, y, theta)`: the reference frame of
//! rigid bodies, FFRF beams and modal bodies (`ffrf.rs`). A point moving in the frame, its
//! Jacobian row, the frame's mass block from the mass and first moment, gravity, and the
//! memoized `sin_cos` of the frame angle.

use super::MarkerState;

/// `(sin, cos)` of a floating frame's angle `theta`, memoized per thread. One evaluation of a
/// scene reads the same body angle many times -- the body's own mass and forces, and every
/// marker a constraint or force evaluates on it (the paper's slider-crank: ~9 reads of 3 angles
/// per evaluation) -- and `sin_cos` is among the most expensive operations of the kernel. The
/// cache is keyed by the exact bits of `theta` (a hit returns exactly what `sin_cos` returns),
/// holds 8 angles, direct-mapped, and is per thread, so concurrent runs do not share it.
#[inline]
pub(crate) fn frame_sin_cos(theta: f64) -> (f64, f64) {
    use std::cell::Cell;
    thread_local! {
        static CACHE: [Cell<(u64, f64, f64)>; 8] = const { [const { Cell::new((u64::MAX, 0.0, 0.0)) }; 8] };
    }
    let bits = theta.to_bits();
    let slot = ((bits ^ (bits >> 17) ^ (bits >> 37)) & 7) as usize;
    CACHE.with(|c| {
        let (k, s, co) = c[slot].get();
        if k == bits {
            return (s, co);
        }
        let (s, co) = theta.sin_cos();
        c[slot].set((bits, s, co));
        (s, co)
    })
}

/// The planar kinematics shared by the kinds with a floating frame `(x, y, theta)` (rigid
/// bodies, FFRF beams): a body-frame point `pl` moving with body-frame velocity `vl`, on a
/// frame at `(q[0], q[1])` with angle `q[2]`.
#[inline]
pub(crate) fn frame_point_state(pl: [f64; 2], vl: [f64; 2], phi_local: f64, omega_local: f64, q: &[f64], qd: &[f64]) -> MarkerState {
    let (th, thd) = (q[2], qd[2]);
    let (s, c) = frame_sin_cos(th);
    let pw = [c * pl[0] - s * pl[1], s * pl[0] + c * pl[1]];
    let vw = [c * vl[0] - s * vl[1], s * vl[0] + c * vl[1]];
    let r_theta = [-pw[1], pw[0]];
    MarkerState {
        r: [q[0] + pw[0], q[1] + pw[1]],
        phi: th + phi_local,
        v: [qd[0] + thd * r_theta[0] + vw[0], qd[1] + thd * r_theta[1] + vw[1]],
        omega: thd + omega_local,
        // -theta_dot^2 A u + 2 theta_dot A J S qd_f
        h: [-thd * thd * pw[0] - 2.0 * thd * vw[1], -thd * thd * pw[1] + 2.0 * thd * vw[0]],
        h_phi: 0.0,
        r_theta,
        cs: [c, s],
        dphi_dslope: [0.0; 2],
    }
}

/// `row[0..3] += w . d r / d (x, y, theta)` for a frame point.
#[inline]
pub(crate) fn add_frame_point_jacobian(ms: &MarkerState, w: [f64; 2], row: &mut [f64]) {
    row[0] += w[0];
    row[1] += w[1];
    row[2] += w[0] * ms.r_theta[0] + w[1] * ms.r_theta[1];
}

/// The floating-frame mass block of a body with total mass `mass` and first moment `sig`
/// (body frame) about the frame origin, rotated by `(c, s)`: `[[m I, A J sig], [., j]]`.
#[inline]
pub(crate) fn frame_mass_block(mass: f64, sig: [f64; 2], j: f64, c: f64, s: f64) -> [[f64; 3]; 3] {
    let asig = [c * sig[0] - s * sig[1], s * sig[0] + c * sig[1]];
    let ajsig = [-asig[1], asig[0]];
    [[mass, 0.0, ajsig[0]], [0.0, mass, ajsig[1]], [ajsig[0], ajsig[1], j]]
}

/// Gravity on a floating frame: `Q_R += m g`, `Q_theta += g . A J sig`.
#[inline]
pub(crate) fn add_frame_gravity(mass: f64, m_rr: &[[f64; 3]; 3], g: [f64; 2], f: &mut [f64]) {
    f[0] += mass * g[0];
    f[1] += mass * g[1];
    f[2] += g[0] * m_rr[0][2] + g[1] * m_rr[1][2];
}

/// `m R + A sig` (world first moment of a floating-frame body).
#[inline]
pub(crate) fn frame_mass_moment(mass: f64, sig: [f64; 2], q: &[f64]) -> [f64; 2] {
    let (s, c) = frame_sin_cos(q[2]);
    [mass * q[0] + c * sig[0] - s * sig[1], mass * q[1] + s * sig[0] + c * sig[1]]
}

#[cfg(test)]
mod tests {
    use super::frame_sin_cos;

    #[test]
    fn memoized_frame_sin_cos_is_exactly_sin_cos() {
        // many angles through the 8 slots (collisions evict), each asked twice, and revisited
        let angles: Vec<f64> = (0..200).map(|k| -7.0 + 0.0713 * k as f64).chain([0.0, -0.0, 1e-300, 3.0e5]).collect();
        for _ in 0..2 {
            for &a in &angles {
                for _ in 0..2 {
                    let (s, c) = frame_sin_cos(a);
                    let (s0, c0) = a.sin_cos();
                    assert_eq!((s.to_bits(), c.to_bits()), (s0.to_bits(), c0.to_bits()), "angle {a}");
                }
            }
        }
        // a non-finite angle is not cached as a finite one
        assert!(frame_sin_cos(f64::NAN).0.is_nan());
    }
}
