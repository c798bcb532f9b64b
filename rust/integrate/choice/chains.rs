//! The geometrically exact beams (`beam3`) as the floor ([`super::floor`]) sees them: a beam is
//! a chain of `rigid3` node bodies joined by `beam3_element` forces, and its rigid motion is the
//! chain's as one body, not each node's alone (moving each node on its own rigidifies nothing:
//! every node coordinate is a rigid motion of its node). Its displacements are read at the
//! nodes' positions (a node body's `r`, the centre of its segment).

use crate::body::Body;
use crate::force::spatial::SpatialForce;
use crate::force::ForceKind;
use crate::linalg::rot3::{cross, rot_e, V3};
use crate::model::Model;

/// The chains of node bodies of the model's beams (body indices, first node first), each with
/// two nodes or more; a body in no chain is in none of them.
pub fn beam_chains(model: &Model) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..model.bodies.len()).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let mut linked = vec![false; model.bodies.len()];
    for f in &model.forces {
        if let ForceKind::Spatial(SpatialForce::Beam3 { nodes, .. }) = &f.kind {
            let (a, b) = (root(&mut parent, nodes[0]), root(&mut parent, nodes[1]));
            parent[a.max(b)] = a.min(b);
            linked[nodes[0]] = true;
            linked[nodes[1]] = true;
        }
    }
    let mut chains: Vec<Vec<usize>> = Vec::new();
    let mut chain_of = vec![usize::MAX; model.bodies.len()];
    for i in (0..model.bodies.len()).filter(|&i| linked[i]) {
        let r = root(&mut parent, i);
        if chain_of[r] == usize::MAX {
            chain_of[r] = chains.len();
            chains.push(Vec::new());
        }
        chains[chain_of[r]].push(i);
    }
    chains
}

/// The angular velocity (world axes) of a `rigid3` body's coordinates `q`, `qd`: `2 E(p) p' / |p|^2`.
fn angular_velocity(q: &[f64], qd: &[f64]) -> V3 {
    let e = rot_e(&q[3..7]);
    let p2: f64 = q[3..7].iter().map(|x| x * x).sum();
    std::array::from_fn(|k| 2.0 * (0..4).map(|l| e[k][l] * qd[3 + l]).sum::<f64>() / p2)
}

/// The rigid motions of a chain of node bodies as one body (columns `col0..col0 + 6`: the first
/// node's translation, then the rotation about it, world axes) and their centripetal part at the
/// nodes' mean angular velocity (the nodes' own for their parameters' rows); returns 6.
pub fn chain_motions(bodies: &[Body], chain: &[usize], q: &[f64], qd: &[f64], col0: usize, put: &mut impl FnMut(usize, usize, f64), cen: &mut [f64]) -> usize {
    let o0 = bodies[chain[0]].offset;
    let mut w: V3 = [0.0; 3];
    for &b in chain {
        let o = bodies[b].offset;
        let wi = angular_velocity(&q[o..o + 7], &qd[o..o + 7]);
        for k in 0..3 {
            w[k] += wi[k] / chain.len() as f64;
        }
    }
    for &b in chain {
        let o = bodies[b].offset;
        let d: V3 = std::array::from_fn(|k| q[o + k] - q[o0 + k]);
        for k in 0..3 {
            put(o + k, col0 + k, 1.0);
            let mut ek = [0.0; 3];
            ek[k] = 1.0;
            let c = cross(&ek, &d); // alpha_k e_k x d
            for j in 0..3 {
                put(o + j, col0 + 3 + k, c[j]);
            }
        }
        let wwd = cross(&w, &cross(&w, &d));
        cen[o..o + 3].copy_from_slice(&wwd);
        let e = rot_e(&q[o + 3..o + 7]);
        for k in 0..3 {
            for l in 0..4 {
                put(o + 3 + l, col0 + 3 + k, 0.5 * e[k][l]);
            }
        }
        let wi = angular_velocity(&q[o..o + 7], &qd[o..o + 7]);
        let ed = rot_e(&qd[o + 3..o + 7]);
        for l in 0..4 {
            cen[o + 3 + l] = 0.5 * (ed[0][l] * wi[0] + ed[1][l] * wi[1] + ed[2][l] * wi[2]);
        }
    }
    6
}

/// The largest displacement of a chain's node per unit of the coordinates' change `s`.
pub fn node_displacement(bodies: &[Body], chain: &[usize], s: &[f64]) -> f64 {
    chain.iter().map(|&b| {
        let o = bodies[b].offset;
        (s[o] * s[o] + s[o + 1] * s[o + 1] + s[o + 2] * s[o + 2]).sqrt()
    }).fold(0.0, f64::max)
}
