//! The two factorizations behind `BandNewton`: the band LU (a narrow band after RCM) and the
//! sparse LU with a minimum degree order and kept pivots (`static_lu`), one interface; the
//! band layout (RCM) both read.

use super::Pattern;
use crate::linalg::rcm::rcm;
use crate::linalg::band_lu::{BandLu, Scalar};
use crate::linalg::static_lu::{Factored, Ordering, StaticLu};
use super::Structure;

/// How `BandNewton` factors: the band LU (a narrow band after RCM) or the sparse LU with a
/// fill-reducing order and kept pivots (`static_lu`: a wide band whose elimination stays sparse).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factorization {
    Band,
    Static,
}

/// The sparse form's analysis of a structure for one method (`NewtonMatrices::for_system`): its
/// band layout (RCM) and, where the static LU is taken, its minimum degree order, which the
/// real and the complex factorization then share (the order is found once).
#[derive(Debug, Clone)]
pub struct SparsePlan {
    pub structure: Structure,
    pub layout: BandLayout,
    /// `Some`: the static LU on this order; `None`: the band LU.
    pub order: Option<Ordering>,
    /// With Radau IIA's complex matrix.
    pub complex: bool,
}

impl SparsePlan {
    pub fn kind(&self) -> Factorization {
        if self.order.is_some() { Factorization::Static } else { Factorization::Band }
    }
}

/// One of the two factorizations, behind the band LU's interface.
#[derive(Debug, Clone)]
pub(super) enum Lu<T: Scalar> {
    Band(BandLu<T>),
    Static(StaticLu<T>),
}

impl<T: Scalar> Lu<T> {
    /// The static LU on `order`, the band LU in `layout` without one.
    pub(super) fn new(layout: &BandLayout, order: Option<Ordering>) -> Self {
        match order {
            Some(o) => Lu::Static(StaticLu::with_ordering(o)),
            None => Lu::Band(BandLu::new(layout.size, layout.hb, layout.hb)),
        }
    }
    pub(super) fn clear(&mut self) {
        match self {
            Lu::Band(b) => b.clear(),
            Lu::Static(s) => s.clear(),
        }
    }
    pub(super) fn index(&self, i: usize, j: usize) -> usize {
        match self {
            Lu::Band(b) => b.index(i, j),
            Lu::Static(s) => s.index(i, j),
        }
    }
    pub(super) fn values_mut(&mut self) -> &mut [T] {
        match self {
            Lu::Band(b) => b.values_mut(),
            Lu::Static(s) => s.values_mut(),
        }
    }
    pub(super) fn factor(&mut self) -> Factored {
        match self {
            Lu::Band(b) => {
                if b.factor() {
                    Factored::Ok
                } else {
                    Factored::Singular
                }
            }
            Lu::Static(s) => s.factor(),
        }
    }
    pub(super) fn solve(&mut self, x: &mut [T]) {
        match self {
            Lu::Band(b) => b.solve(x),
            Lu::Static(s) => s.solve(x),
        }
    }
}

/// The positions (in band order) of every entry `BandNewton` writes: the coordinate block, `A`
/// and its transpose, the multipliers' diagonal.
pub fn newton_entries(p: &Pattern, layout: &BandLayout) -> Vec<(usize, usize)> {
    let (n, perm) = (p.n, &layout.perm);
    let mut e: Vec<(usize, usize)> = p.entries().map(|(i, j)| (perm[i], perm[j])).collect();
    for (r, j) in p.a_entries() {
        e.push((perm[n + r], perm[j]));
        e.push((perm[j], perm[n + r]));
    }
    e.extend((0..p.m).map(|r| (perm[n + r], perm[n + r])));
    e
}

/// The ordering and band positions of `H = [M + g_c C + g_k K, A^T; A - g_c db/dqd, reg I]`
/// (size `n + m`) for a `Pattern`: symmetric half-bandwidth `hb` after RCM.
#[derive(Debug, Clone)]
pub struct BandLayout {
    pub size: usize,
    pub hb: usize,
    /// `perm[i]`: band position of unknown `i` (coordinates, then multipliers).
    pub perm: Vec<usize>,
}

impl BandLayout {
    pub fn new(p: &Pattern) -> BandLayout {
        let (n, m) = (p.n, p.m);
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n + m];
        for (i, j) in p.entries() {
            if i != j {
                adj[i].push(j);
                adj[j].push(i);
            }
        }
        for (r, j) in p.a_entries() {
            adj[n + r].push(j);
            adj[j].push(n + r);
        }
        for a in adj.iter_mut() {
            a.sort_unstable();
            a.dedup();
        }
        let perm = rcm(&adj);
        let mut hb = 0;
        for (v, a) in adj.iter().enumerate() {
            for &u in a {
                hb = hb.max(perm[v].abs_diff(perm[u]));
            }
        }
        BandLayout { size: n + m, hb, perm }
    }

    /// Multiply-adds of one real band factorization (at most).
    pub fn factor_flops(&self) -> f64 {
        BandLu::<f64>::factor_flops(self.size, self.hb, self.hb)
    }
}
