//! A compiled list of the nodes some outputs need, children first: evaluation is one forward
//! pass writing each node's value into a caller's buffer (sized once: [`Tape::len`]).

use super::graph::{pow, Func, Graph, Node, NodeId};

#[derive(Debug, Clone, Copy, PartialEq)]
enum Instr {
    Const(f64),
    Var(u32),
    Neg(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Pow(u32, u32),
    Call(Func, u32),
}

#[derive(Debug, Clone)]
pub struct Tape {
    code: Vec<Instr>,
    outputs: Vec<u32>,
    n_vars: usize,
}

impl Tape {
    /// The nodes `roots` depend on, renumbered in order; output `k` is `roots[k]`.
    pub fn new(graph: &Graph, roots: &[NodeId]) -> Tape {
        let reach = graph.reachable(roots);
        let mut slot = vec![u32::MAX; reach.len()];
        let mut code = Vec::new();
        for (i, _) in reach.iter().enumerate().filter(|(_, r)| **r) {
            let s = |c: NodeId| slot[c as usize];
            let ins = match graph.node(i as NodeId) {
                Node::Const(bits) => Instr::Const(f64::from_bits(bits)),
                Node::Var(k) => Instr::Var(k),
                Node::Neg(a) => Instr::Neg(s(a)),
                Node::Add(a, b) => Instr::Add(s(a), s(b)),
                Node::Sub(a, b) => Instr::Sub(s(a), s(b)),
                Node::Mul(a, b) => Instr::Mul(s(a), s(b)),
                Node::Div(a, b) => Instr::Div(s(a), s(b)),
                Node::Pow(a, b) => Instr::Pow(s(a), s(b)),
                Node::Call(f, a) => Instr::Call(f, s(a)),
            };
            slot[i] = code.len() as u32;
            code.push(ins);
        }
        let outputs = roots.iter().map(|&r| slot[r as usize]).collect();
        Tape { code, outputs, n_vars: graph.n_vars() }
    }

    /// Instructions, and the length of the evaluation buffer.
    pub fn len(&self) -> usize {
        self.code.len()
    }

    pub fn is_empty(&self) -> bool {
        self.code.is_empty()
    }

    pub fn n_vars(&self) -> usize {
        self.n_vars
    }

    /// Evaluate every instruction at the variables `vars` (slot order, at least `n_vars`) into
    /// `buf` (at least [`Tape::len`]); read outputs with [`Tape::output`].
    #[inline]
    pub fn eval(&self, vars: &[f64], buf: &mut [f64]) {
        let buf = &mut buf[..self.code.len()];
        for k in 0..self.code.len() {
            buf[k] = match self.code[k] {
                Instr::Const(c) => c,
                Instr::Var(j) => vars[j as usize],
                Instr::Neg(a) => -buf[a as usize],
                Instr::Add(a, b) => buf[a as usize] + buf[b as usize],
                Instr::Sub(a, b) => buf[a as usize] - buf[b as usize],
                Instr::Mul(a, b) => buf[a as usize] * buf[b as usize],
                Instr::Div(a, b) => buf[a as usize] / buf[b as usize],
                Instr::Pow(a, b) => pow(buf[a as usize], buf[b as usize]),
                Instr::Call(f, a) => f.apply(buf[a as usize]),
            };
        }
    }

    /// Output `k` of the last [`Tape::eval`] into `buf`.
    #[inline]
    pub fn output(&self, k: usize, buf: &[f64]) -> f64 {
        buf[self.outputs[k] as usize]
    }

    /// The values of the variable in `(lo, hi)` at which the argument of an `abs` or `sign`
    /// changes sign (a kink or a jump of a function of one variable): found on `samples`
    /// equal intervals (two changes of one argument within an interval are not seen), each
    /// bisected to the rounding of the variable; sorted, each once.
    pub fn switches(&self, lo: f64, hi: f64, samples: usize) -> Vec<f64> {
        let args: Vec<usize> = self.code.iter().filter_map(|c| match c {
            Instr::Call(Func::Abs | Func::Sign, a) => Some(*a as usize),
            _ => None,
        }).collect();
        let mut out = Vec::new();
        if args.is_empty() || self.n_vars != 1 || !(hi > lo) || samples == 0 {
            return out;
        }
        let mut buf = vec![0.0; self.code.len()];
        let at = |x: f64, buf: &mut [f64]| -> Vec<f64> {
            self.eval(&[x], buf);
            args.iter().map(|&a| buf[a]).collect()
        };
        let (mut x_prev, mut prev) = (lo, at(lo, &mut buf));
        for i in 1..=samples {
            let x = if i == samples { hi } else { lo + (hi - lo) * i as f64 / samples as f64 };
            let cur = at(x, &mut buf);
            for (k, &a) in args.iter().enumerate() {
                let (p, c) = (prev[k], cur[k]);
                if !(p.is_finite() && c.is_finite()) || p == 0.0 || (p > 0.0) == (c > 0.0) && c != 0.0 {
                    continue;
                }
                // p != 0 and c has the other sign or is 0: the change is in (x_prev, x]
                let (mut x0, mut x1) = (x_prev, x);
                loop {
                    let xm = 0.5 * (x0 + x1);
                    if xm <= x0 || xm >= x1 {
                        break;
                    }
                    self.eval(&[xm], &mut buf);
                    let v = buf[a];
                    if v != 0.0 && (v > 0.0) == (p > 0.0) { x0 = xm } else { x1 = xm }
                }
                if x1 < hi {
                    out.push(x1);
                }
            }
            (x_prev, prev) = (x, cur);
        }
        out.sort_by(f64::total_cmp);
        out.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * (hi - lo));
        out
    }
}
