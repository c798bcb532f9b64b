//! The velocity terms of the Newton matrices by differences, one pair of evaluations per colour
//! of the coordinates' pattern: shared by the sparse form (`fill_velocity_terms`) and the dense
//! one (`integrate::uk_system`), so both read the same values.

use super::{Pattern, Structure};
use crate::data::Data;
use crate::dynamics::{constraints, mass_and_forces};
use crate::model::Model;

/// Central differences in `qd` by the colours of `p` (columns that share no row), with
/// `dynamics::velocity_jacobians_into`'s steps: for each colour and sign (`+1` first), the
/// forces and constraint terms at the perturbed velocities are in `data` when
/// `store(j, sign, 2 step_j, data)` is called for each column `j` of the colour. `v` is an
/// n-long scratch. Leaves `data` at a perturbed state.
pub fn velocity_differences(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], p: &Pattern, v: &mut [f64], store: &mut dyn FnMut(usize, f64, f64, &Data)) {
    v.copy_from_slice(qd);
    let step = |x: f64| 1e-3 * x.abs().max(1.0);
    for col in 0..p.colors() {
        let cols = &p.color_cols[p.color_ptr[col]..p.color_ptr[col + 1]];
        for sign in [1.0, -1.0] {
            for &j in cols {
                v[j] = qd[j] + sign * step(qd[j]);
            }
            mass_and_forces(model, data, t, q, v);
            crate::dynamics::add_friction_at_last_multipliers(model, data);
            constraints(model, data, t, q, v, false);
            for &j in cols {
                store(j, sign, 2.0 * step(qd[j]), data);
            }
        }
        for &j in cols {
            v[j] = qd[j];
        }
    }
}

/// `C = -dQ/dqd` and `db/dqd` at `(t, q, qd)` by central differences in `qd`, one pair of
/// evaluations per colour (`velocity_differences`; as `dynamics::velocity_jacobians_into` does
/// per column, with the same steps and the same arithmetic: the same values). Leaves `data` at
/// a perturbed state.
pub fn fill_velocity_terms(model: &Model, data: &mut Data, t: f64, q: &[f64], qd: &[f64], s: &mut Structure) {
    let Structure { pattern: p, c, bv, v, .. } = s;
    velocity_differences(model, data, t, q, qd, p, v, &mut |j, sign, s2, data| {
        for e in p.col_ptr[j]..p.col_ptr[j + 1] {
            let f = data.force[p.row[e]];
            c[e] = if sign > 0.0 { -f } else { (c[e] + f) / s2 };
        }
        for e in p.acol_ptr[j]..p.acol_ptr[j + 1] {
            let g = data.gamma[p.arow[e]];
            bv[e] = if sign > 0.0 { g } else { (bv[e] - g) / s2 };
        }
    });
}
