//! Reverse Cuthill-McKee ordering: the fill-reducing order that makes the sparse Newton
//! matrices (`sparse_newton`) and the Gram matrix of the sparse UK path (`uk::sparse`) banded.

use std::collections::VecDeque;

/// Reverse Cuthill-McKee order of a graph given by its adjacency lists (`perm[v]`: the
/// position of vertex `v`): each connected component from a vertex of least degree, breadth
/// first, neighbours by increasing degree, the whole order reversed.
pub fn rcm(adj: &[Vec<usize>]) -> Vec<usize> {
    let nv = adj.len();
    let deg: Vec<usize> = adj.iter().map(Vec::len).collect();
    let mut order = Vec::with_capacity(nv);
    let mut seen = vec![false; nv];
    let mut by_degree: Vec<usize> = (0..nv).collect();
    by_degree.sort_by_key(|&i| (deg[i], i));
    let mut next = Vec::new();
    for &start in &by_degree {
        if seen[start] {
            continue;
        }
        let mut queue = VecDeque::from([start]);
        seen[start] = true;
        while let Some(v) = queue.pop_front() {
            order.push(v);
            next.clear();
            next.extend(adj[v].iter().copied().filter(|&u| !seen[u]));
            next.sort_by_key(|&u| (deg[u], u));
            for &u in &next {
                seen[u] = true;
                queue.push_back(u);
            }
        }
    }
    order.reverse();
    let mut perm = vec![0; nv];
    for (p, &v) in order.iter().enumerate() {
        perm[v] = p;
    }
    perm
}
