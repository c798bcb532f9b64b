//! Singular passages: where the constraint Jacobian of a run's motion comes close to losing
//! rank (a parallelogram passing flat, a slider-crank with equal crank and coupler at dead
//! centre). The UK acceleration there is the minimum-norm one and the equations of motion are
//! ill-conditioned: an error in the directions that open up is amplified by
//! `1 / sigma_min`, and a method that does not hold the motion on its branch may leave it
//! (docs/integrators.md, singular configurations).
//!
//! **Measure.** `kappa = sigma_min / sigma_max` of the mass-weighted Jacobian `B = A M^-1/2`
//! at every accepted step, from the factorization the step already made
//! (`SecondOrderSystem::conditioning`), and `kappa_ref`, the largest `kappa` of the run so far:
//! a scale-free reference (the conditioning away from singular configurations depends on the
//! mechanism's size and masses: 0.25 for one four-bar, 0.04 for ten in a row).
//!
//! **Detection.** A step whose `kappa` is a local minimum below `DIP x kappa_ref` is a dip. The
//! configuration where the rank drops lies between steps, so the dip is refined: `kappa` along
//! the cubic Hermite interpolant of `(q, qd)` through the neighbouring steps, by secants on the
//! signed `sigma_min` (a transversal rank drop makes `sigma_min` vanish linearly, `|s (t - t*)|`,
//! so a secant through two points on one side lands on `t*`), at most `REFINE_EVALS` evaluations.
//! A dip whose refined `kappa` falls below `SINGULAR x kappa_ref` is a singular passage,
//! reported with its time, that ratio, and the rank before, at and after it. A change of rank
//! between two steps is a passage too.

use super::{Conditioning, SecondOrderSystem};
use crate::error::Result;

/// A step is a dip when its conditioning is a local minimum below this fraction of the run's
/// best conditioning (a loose test: the steps may pass far from the singular configuration
/// itself; the refinement decides).
pub const DIP: f64 = 0.5;
/// A refined dip below this fraction of the run's best conditioning is a singular passage.
pub const SINGULAR: f64 = 1e-2;
/// `sigma_min / sigma_max` below which a factorization of `B B^T` cannot tell `sigma_min` from 0
/// (`sigma_min^2` at the rounding of the Gram matrix's entries).
pub const ROUNDING_RATIO: f64 = 1e-8;
/// Conditioning evaluations spent refining one dip, at most.
pub const REFINE_EVALS: usize = 8;

/// One singular passage of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Passage {
    /// Time of the closest approach (refined between the steps).
    pub t: f64,
    /// `sigma_min / sigma_max` there, and the run's best ratio up to then.
    pub ratio: f64,
    pub ratio_ref: f64,
    /// Numerical rank of `A` at the steps before and after the passage, and at its refined
    /// closest approach, where the singular values that vanish there (those below the
    /// geometric mean of `ratio` and `ratio_ref`, relative to the largest) count as lost: the
    /// mobility gained at the singular configuration (`rank_before - rank_at`; without the
    /// dense SVD, beyond `uk::EXACT_RANK_MAX_ROWS` rows, the rank of the factorization).
    pub rank_before: usize,
    pub rank_after: usize,
    pub rank_at: usize,
}

/// The state of the monitor over a run: the last three accepted steps.
#[derive(Debug, Clone)]
pub struct SingularMonitor {
    n: usize,
    /// `(t, y, conditioning)` of the last three accepted steps, oldest first (`len` valid).
    t: [f64; 3],
    y: [Vec<f64>; 3],
    c: [Conditioning; 3],
    len: usize,
    ratio_ref: f64,
    /// After a passage the monitor waits until the conditioning recovers above the dip level
    /// (one passage per visit to a singular configuration, however many steps it lingers).
    armed: bool,
    qbuf: Vec<f64>,
    pub passages: Vec<Passage>,
}

impl SingularMonitor {
    pub fn new(n: usize) -> Self {
        let z = || vec![0.0; 2 * n];
        SingularMonitor { n, t: [0.0; 3], y: [z(), z(), z()], c: [Conditioning::default(); 3], len: 0, ratio_ref: 0.0, armed: true, qbuf: vec![0.0; n], passages: Vec::new() }
    }

    /// Record the accepted state `(t, y)` (the initial state too) and look for a passage.
    pub fn push<S: SecondOrderSystem + ?Sized>(&mut self, sys: &mut S, t: f64, y: &[f64]) -> Result<()> {
        let Some(c) = sys.conditioning(t, &y[..self.n])? else { return Ok(()) };
        // shift the window
        if self.len == 3 {
            self.t.rotate_left(1);
            self.y.rotate_left(1);
            self.c.rotate_left(1);
            self.len = 2;
        }
        let k = self.len;
        self.t[k] = t;
        self.y[k].copy_from_slice(y);
        self.c[k] = c;
        self.len += 1;
        self.ratio_ref = self.ratio_ref.max(c.ratio());
        if c.ratio() >= DIP * self.ratio_ref {
            self.armed = true;
        }
        if self.len < 2 || !self.armed {
            return Ok(());
        }
        let (prev, cur) = (self.c[self.len - 2], self.c[self.len - 1]);
        if self.len == 3 {
            let (a, b) = (self.c[0].ratio(), self.c[1].ratio());
            if b < a && b <= cur.ratio() && b < DIP * self.ratio_ref {
                let (ts, ratio, rank_at) = self.refine(sys)?;
                if ratio < SINGULAR * self.ratio_ref {
                    let i = if ts <= self.t[1] { 0 } else { 1 };
                    self.interpolate(i, ts);
                    // vanishing: below the geometric mean of the closest approach (at least the
                    // rounding level of sigma_min^2, where a factorization calls it 0) and the
                    // reference
                    let lost = match sys.small_singular_values(ts, &self.qbuf, (ratio.max(ROUNDING_RATIO) * self.ratio_ref).sqrt()) {
                        Ok(Some(k)) => k,
                        _ => 0,
                    };
                    let rank_before = self.c[0].rank;
                    let rank_at = rank_at.min(self.c[1].rank).min(rank_before.saturating_sub(lost));
                    self.passages.push(Passage { t: ts, ratio, ratio_ref: self.ratio_ref, rank_before, rank_after: cur.rank, rank_at });
                    self.armed = false;
                    return Ok(());
                }
            }
        }
        if prev.rank != cur.rank {
            let t0 = self.t[self.len - 2];
            self.passages.push(Passage { t: 0.5 * (t0 + t), ratio: prev.ratio().min(cur.ratio()), ratio_ref: self.ratio_ref, rank_before: prev.rank, rank_after: cur.rank, rank_at: prev.rank.min(cur.rank) });
        }
        Ok(())
    }

    /// Positions at `t` on the cubic Hermite interpolant of `(q, qd)` between window entries
    /// `i` and `i + 1`, into `qbuf`.
    fn interpolate(&mut self, i: usize, t: f64) {
        let n = self.n;
        let (t0, t1) = (self.t[i], self.t[i + 1]);
        let h = t1 - t0;
        let s = if h > 0.0 { (t - t0) / h } else { 0.0 };
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) = (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, -2.0 * s3 + 3.0 * s2, s3 - s2);
        let (y0, y1) = (&self.y[i], &self.y[i + 1]);
        for k in 0..n {
            self.qbuf[k] = h00 * y0[k] + h10 * h * y0[n + k] + h01 * y1[k] + h11 * h * y1[n + k];
        }
    }

    fn ratio_at<S: SecondOrderSystem + ?Sized>(&mut self, sys: &mut S, t: f64) -> Result<(f64, usize)> {
        let i = if t <= self.t[1] { 0 } else { 1 };
        self.interpolate(i, t);
        // an interpolated state the kernels refuse (e.g. a singular mass block) ends the search
        match sys.conditioning(t, &self.qbuf) {
            Ok(Some(c)) => Ok((c.ratio(), c.rank)),
            _ => Ok((f64::INFINITY, 0)),
        }
    }

    /// The closest approach between the window's first and last step: secants on the signed
    /// ratio (positive left of the current best point, negative right of it).
    fn refine<S: SecondOrderSystem + ?Sized>(&mut self, sys: &mut S) -> Result<(f64, f64, usize)> {
        // bracket points (t, ratio), the best in the middle
        let (mut ta, mut ra) = (self.t[0], self.c[0].ratio());
        let (mut tm, mut rm) = (self.t[1], self.c[1].ratio());
        let (mut tb, mut rb) = (self.t[2], self.c[2].ratio());
        let mut rank_at = self.c[1].rank;
        let mut evals = 0;
        while evals + 2 <= REFINE_EVALS && rm > 0.0 {
            // left secant through (ta, ra), (tm, rm) extrapolated to zero (zero right of tm), and
            // right secant through (tm, -rm), (tb, -rb) mirrored (zero left of tm)
            let mut cands = [f64::NAN; 2];
            if ra > rm {
                cands[0] = tm + rm * (tm - ta) / (ra - rm);
            }
            if rb > rm {
                cands[1] = tm - rm * (tb - tm) / (rb - rm);
            }
            let mut improved = false;
            for tc in cands {
                if !(tc > ta && tc < tb) || tc == tm {
                    continue;
                }
                let (rc, kc) = self.ratio_at(sys, tc)?;
                evals += 1;
                if rc < rm {
                    // the old best becomes the bracket end on its side
                    if tc > tm {
                        ta = tm;
                        ra = rm;
                    } else {
                        tb = tm;
                        rb = rm;
                    }
                    tm = tc;
                    rm = rc;
                    rank_at = kc;
                    improved = true;
                } else if tc > tm {
                    tb = tc;
                    rb = rc;
                } else {
                    ta = tc;
                    ra = rc;
                }
            }
            if !improved || rm < 1e-3 * SINGULAR * self.ratio_ref {
                break;
            }
        }
        Ok((tm, rm, rank_at))
    }
}
