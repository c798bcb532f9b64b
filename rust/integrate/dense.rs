//! Dense output: what defines one step's interpolant (`DenseParts`), a run's record
//! (`DenseRecord`) and its evaluation (`DenseView`).

use super::*;

/// What defines one step's dense output (`Stepper::dense_parts`).
pub struct DenseParts<'a> {
    /// `[t_old, t, aux]` (`aux`: a method's extra scalar, e.g. RADAU5's step size).
    pub meta: [f64; 3],
    pub parts: [&'a [f64]; 5],
    pub count: usize,
}

/// The dense output of a whole run, one segment per accepted step (`integrate` with
/// `dense = true`): `meta` (3 per segment, `[t_old, t, aux]`) and the parts' data, concatenated
/// (`width` values per segment, split by `part_len`). Grown by amortized doubling, no per-step
/// allocation in the steady state.
#[derive(Debug, Clone, Default)]
pub struct DenseRecord {
    pub meta: Vec<f64>,
    pub data: Vec<f64>,
    pub part_len: Vec<usize>,
}

impl DenseRecord {
    pub(super) fn push(&mut self, d: &DenseParts<'_>) {
        if self.part_len.is_empty() {
            self.part_len = d.parts[..d.count].iter().map(|p| p.len()).collect();
        }
        self.meta.extend_from_slice(&d.meta);
        for p in &d.parts[..d.count] {
            self.data.extend_from_slice(p);
        }
    }

    /// Values per segment.
    pub fn width(&self) -> usize {
        self.part_len.iter().sum()
    }

    pub fn view(&self) -> DenseView<'_> {
        DenseView { meta: &self.meta, data: &self.data, part_len: &self.part_len }
    }
}

/// A dense record to evaluate (a run's own, or arrays handed back by Python: `dense_eval`),
/// checked against its method's layout before any evaluation.
#[derive(Debug, Clone, Copy)]
pub struct DenseView<'a> {
    pub meta: &'a [f64],
    pub data: &'a [f64],
    pub part_len: &'a [usize],
}

impl DenseView<'_> {
    /// Check the record as a run of `method` writes it: at least one segment, `meta` 3 per
    /// segment, the parts of the method's layout (`Stepper::dense_dim`), `data` the width per
    /// segment, every value finite, each segment forward in time and the segments in order (the
    /// search in `eval` relies on it). Returns the dimension of an evaluated state.
    pub fn check(&self, method: &Method) -> Result<usize> {
        let bad = |m: String| Err(Error::argument("dense output", m));
        let dim = match method {
            Method::Dopri5 => Dopri5::dense_dim(self.part_len),
            Method::Radau5 => Radau5::dense_dim(self.part_len),
            Method::GenAlpha(_) => GenAlpha::dense_dim(self.part_len),
            Method::RadauM(_) => RadauM::dense_dim(self.part_len),
        };
        let Some(dim) = dim else {
            return bad(format!("part lengths {:?} are not the layout of a {} record", self.part_len, method.name()));
        };
        let nseg = self.meta.len() / 3;
        if nseg == 0 || self.meta.len() % 3 != 0 {
            return bad(format!("meta must hold 3 values per segment (at least one), got {}", self.meta.len()));
        }
        let width = self.part_len.iter().try_fold(0usize, |a, &b| a.checked_add(b));
        if width.filter(|w| nseg.checked_mul(*w) == Some(self.data.len())).is_none() {
            return bad(format!("data must hold {nseg} segments of {:?} values, got {} values", self.part_len, self.data.len()));
        }
        check_finite("dense output meta", self.meta)?;
        check_finite("dense output data", self.data)?;
        for k in 0..nseg {
            let (t_old, t) = (self.meta[3 * k], self.meta[3 * k + 1]);
            let next = if k + 1 < nseg { self.meta[3 * k + 3] } else { t };
            if !(t_old <= t) || !(next >= t) {
                return bad(format!("segment {k} [{t_old}, {t}] runs backwards or out of order"));
            }
        }
        Ok(dim)
    }

    /// Evaluate at `t` into `out` (`check`ed record, `out` of its dimension): the segment whose
    /// interval holds `t`; before the first or after the last segment, that segment's polynomial
    /// extrapolated.
    pub fn eval(&self, method: &Method, t: f64, out: &mut [f64]) {
        let nseg = self.meta.len() / 3;
        if nseg == 0 {
            out.fill(f64::NAN);
            return;
        }
        // first segment whose end is >= t
        let (mut lo, mut hi) = (0usize, nseg - 1);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.meta[3 * mid + 1] < t {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let w: usize = self.part_len.iter().sum();
        let seg = &self.data[lo * w..(lo + 1) * w];
        let mut parts: [&[f64]; 5] = [&[]; 5];
        let mut at = 0;
        for (k, len) in self.part_len.iter().enumerate().take(5) {
            parts[k] = &seg[at..at + len];
            at += len;
        }
        let meta = [self.meta[3 * lo], self.meta[3 * lo + 1], self.meta[3 * lo + 2]];
        let parts = &parts[..self.part_len.len().min(5)];
        match method {
            Method::Dopri5 => Dopri5::dense_eval(meta, parts, t, out),
            Method::Radau5 => Radau5::dense_eval(meta, parts, t, out),
            Method::GenAlpha(_) => GenAlpha::dense_eval(meta, parts, t, out),
            Method::RadauM(_) => RadauM::dense_eval(meta, parts, t, out),
        }
    }
}

