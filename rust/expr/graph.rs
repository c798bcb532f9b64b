//! The expression DAG: nodes in one arena, hash-consed (building a node equal to an existing
//! one returns the existing id), folded where their operands are constants, children always
//! before their parents (ids increase along every path to the root). Derivatives are nodes of
//! the same graph, formed once per node and variable.

use std::collections::HashMap;

/// Index of a node in its [`Graph`].
pub type NodeId = u32;

/// At most this many nodes in one graph (the text limits keep real expressions far below:
/// 100,000 characters make at most a few million nodes with both derivatives).
pub const MAX_NODES: usize = 1 << 26;

/// A derivative would pass [`MAX_NODES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TooLarge {
    pub nodes: usize,
}

impl std::fmt::Display for TooLarge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the expression and its derivatives would need more than {} nodes ({} already)", MAX_NODES, self.nodes)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Exp,
    Log,
    Sqrt,
    Abs,
    Tanh,
    Sinh,
    Cosh,
    Atan,
    Sign,
}

impl Func {
    pub const ALL: [(&'static str, Func); 12] = [
        ("sin", Func::Sin),
        ("cos", Func::Cos),
        ("tan", Func::Tan),
        ("exp", Func::Exp),
        ("log", Func::Log),
        ("sqrt", Func::Sqrt),
        ("abs", Func::Abs),
        ("tanh", Func::Tanh),
        ("sinh", Func::Sinh),
        ("cosh", Func::Cosh),
        ("atan", Func::Atan),
        ("sign", Func::Sign),
    ];

    pub fn by_name(name: &str) -> Option<Func> {
        Func::ALL.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
    }

    #[inline]
    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Exp => x.exp(),
            Func::Log => x.ln(),
            Func::Sqrt => x.sqrt(),
            Func::Abs => x.abs(),
            Func::Tanh => x.tanh(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Atan => x.atan(),
            // NaN stays NaN: an undefined argument must not become a defined motion
            Func::Sign => {
                if x > 0.0 {
                    1.0
                } else if x < 0.0 {
                    -1.0
                } else if x == 0.0 {
                    0.0
                } else {
                    f64::NAN
                }
            }
        }
    }
}

/// One node; operands are ids of earlier nodes. `Const` holds the bits of an `f64` (so that
/// nodes hash and compare exactly).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Node {
    Const(u64),
    Var(u32),
    Neg(NodeId),
    Add(NodeId, NodeId),
    Sub(NodeId, NodeId),
    Mul(NodeId, NodeId),
    Div(NodeId, NodeId),
    Pow(NodeId, NodeId),
    Call(Func, NodeId),
}

impl Node {
    /// Operands (up to two).
    #[inline]
    pub fn children(self) -> [Option<NodeId>; 2] {
        match self {
            Node::Const(_) | Node::Var(_) => [None, None],
            Node::Neg(a) | Node::Call(_, a) => [Some(a), None],
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) | Node::Pow(a, b) => [Some(a), Some(b)],
        }
    }
}

/// `x^y` by the C library's `pow`: within an ulp, also for negative bases with integer
/// exponents (`powi`, repeated multiplication, drifted by several ulps: `tan(tan(2)^36)`, an
/// argument of 1.7e12, came out 5e-4 off).
#[inline]
pub fn pow(x: f64, y: f64) -> f64 {
    x.powf(y)
}

const NONE: NodeId = NodeId::MAX;

/// Nodes of the rule of one node's derivative, at most (the size check of `derivative`).
const RULE_NODES: usize = 10;

/// The variables a node depends on, one bit per slot (slots from 64 on share the last bits:
/// conservatively "depends on all of them").
fn var_bit(k: usize) -> u64 {
    if k < 63 { 1 << k } else { !((1u64 << 63) - 1) }
}

#[derive(Debug, Clone)]
pub struct Graph {
    nodes: Vec<Node>,
    /// `deps[i]`: the variables node `i` depends on (`var_bit`s).
    deps: Vec<u64>,
    index: HashMap<Node, NodeId>,
    n_vars: usize,
    /// `memo[v][i]`: the node of `d(node i)/d(variable v)` (`NONE`: not formed yet).
    memo: Vec<Vec<NodeId>>,
}

impl Graph {
    /// An empty graph over `n_vars` variables (slots `0..n_vars`).
    pub fn new(n_vars: usize) -> Graph {
        Graph { nodes: Vec::new(), deps: Vec::new(), index: HashMap::new(), n_vars, memo: vec![Vec::new(); n_vars] }
    }

    pub fn n_vars(&self) -> usize {
        self.n_vars
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    pub fn node(&self, id: NodeId) -> Node {
        self.nodes[id as usize]
    }

    /// The value of a constant node.
    pub fn constant(&self, id: NodeId) -> Option<f64> {
        match self.nodes[id as usize] {
            Node::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    fn intern(&mut self, n: Node) -> NodeId {
        if let Some(&id) = self.index.get(&n) {
            return id;
        }
        let id = self.nodes.len() as NodeId;
        let deps = match n {
            Node::Const(_) => 0,
            Node::Var(k) => var_bit(k as usize),
            _ => n.children().into_iter().flatten().fold(0, |d, c| d | self.deps[c as usize]),
        };
        self.nodes.push(n);
        self.deps.push(deps);
        self.index.insert(n, id);
        id
    }

    pub fn num(&mut self, v: f64) -> NodeId {
        self.intern(Node::Const(v.to_bits()))
    }

    /// Variable slot `k` (`k < n_vars`).
    pub fn var(&mut self, k: usize) -> NodeId {
        debug_assert!(k < self.n_vars);
        self.intern(Node::Var(k as u32))
    }


    pub fn neg(&mut self, a: NodeId) -> NodeId {
        match self.nodes[a as usize] {
            Node::Const(x) => self.num(-f64::from_bits(x)),
            Node::Neg(inner) => inner,
            _ => self.intern(Node::Neg(a)),
        }
    }

    pub fn add(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.constant(a), self.constant(b)) {
            (Some(x), Some(y)) => self.num(x + y),
            (Some(x), _) if x == 0.0 => b,
            (_, Some(y)) if y == 0.0 => a,
            // exactly commutative in IEEE arithmetic: one node for a + b and b + a
            _ => self.intern(Node::Add(a.min(b), a.max(b))),
        }
    }

    pub fn sub(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.constant(a), self.constant(b)) {
            (Some(x), Some(y)) => self.num(x - y),
            (Some(x), _) if x == 0.0 => self.neg(b),
            (_, Some(y)) if y == 0.0 => a,
            _ => self.intern(Node::Sub(a, b)),
        }
    }

    /// `a * b` as written (the parser's): folded only where IEEE arithmetic gives the same
    /// value for every value of the other operand, so `0 * (t/0)` stays NaN and `0 * sin(t)`
    /// keeps its sign of zero. The derivative rules use `mul`, whose zeros are structural.
    pub fn product(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.constant(a), self.constant(b)) {
            (Some(x), Some(y)) => self.num(x * y),
            (Some(x), _) if x == 1.0 => b,
            (_, Some(y)) if y == 1.0 => a,
            (Some(x), _) if x == -1.0 => self.neg(b),
            (_, Some(y)) if y == -1.0 => self.neg(a),
            _ => self.intern(Node::Mul(a.min(b), a.max(b))),
        }
    }

    /// `a / b` as written (the parser's): `0 / x` is not folded (`0 / (t - t)` is NaN).
    pub fn quotient(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.constant(a), self.constant(b)) {
            (Some(x), Some(y)) if y != 0.0 => self.num(x / y),
            (_, Some(y)) if y == 1.0 => a,
            _ => self.intern(Node::Div(a, b)),
        }
    }

    pub fn mul(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.constant(a), self.constant(b)) {
            (Some(x), Some(y)) => self.num(x * y),
            (Some(x), _) | (_, Some(x)) if x == 0.0 => self.num(0.0),
            (Some(x), _) if x == 1.0 => b,
            (_, Some(y)) if y == 1.0 => a,
            (Some(x), _) if x == -1.0 => self.neg(b),
            (_, Some(y)) if y == -1.0 => self.neg(a),
            _ => self.intern(Node::Mul(a.min(b), a.max(b))),
        }
    }

    pub fn div(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.constant(a), self.constant(b)) {
            (Some(x), Some(y)) if y != 0.0 => self.num(x / y),
            (Some(x), None) if x == 0.0 => self.num(0.0),
            (_, Some(y)) if y == 1.0 => a,
            _ => self.intern(Node::Div(a, b)),
        }
    }

    pub fn pow(&mut self, a: NodeId, b: NodeId) -> NodeId {
        match (self.constant(a), self.constant(b)) {
            (Some(x), Some(y)) => self.num(pow(x, y)),
            (_, Some(y)) if y == 0.0 => self.num(1.0),
            (_, Some(y)) if y == 1.0 => a,
            _ => self.intern(Node::Pow(a, b)),
        }
    }

    pub fn call(&mut self, f: Func, a: NodeId) -> NodeId {
        match self.constant(a) {
            Some(x) => self.num(f.apply(x)),
            None => self.intern(Node::Call(f, a)),
        }
    }

    /// Mark the nodes `roots` depend on (children have smaller ids, so one backward sweep).
    pub(crate) fn reachable(&self, roots: &[NodeId]) -> Vec<bool> {
        let top = roots.iter().map(|&r| r as usize + 1).max().unwrap_or(0);
        let mut reach = vec![false; top];
        for &r in roots {
            reach[r as usize] = true;
        }
        for i in (0..top).rev() {
            if reach[i] {
                for c in self.nodes[i].children().into_iter().flatten() {
                    reach[c as usize] = true;
                }
            }
        }
        reach
    }

    /// The node of `d(f)/d(variable var)`. Each node's derivative is formed once (memoized),
    /// children first, with a bounded number of new nodes per node: the cost is linear in the
    /// size of `f`'s DAG, for derivatives of derivatives too. No recursion.
    pub fn derivative(&mut self, f: NodeId, var: usize) -> Result<NodeId, TooLarge> {
        assert!(var < self.n_vars, "variable slot {var} of a graph over {} variables", self.n_vars);
        let reach = self.reachable(&[f]);
        let todo: Vec<usize> = (0..reach.len()).filter(|&i| reach[i] && self.memo_get(var, i) == NONE).collect();
        if self.nodes.len() + RULE_NODES * todo.len() > MAX_NODES {
            return Err(TooLarge { nodes: self.nodes.len() });
        }
        for i in todo {
            let d = self.rule(i, var);
            let memo = &mut self.memo[var];
            if memo.len() <= i {
                memo.resize(i + 1, NONE);
            }
            memo[i] = d;
        }
        Ok(self.memo_get(var, f as usize))
    }

    fn memo_get(&self, var: usize, i: usize) -> NodeId {
        self.memo[var].get(i).copied().unwrap_or(NONE)
    }

    /// The derivative of node `i` from its operands' (already formed) derivatives. Quotients
    /// and logarithms are differentiated as ratios of commensurate quantities
    /// (`(a/b)' = a'/b - (a/b)(b'/b)`, `(log a)' = a'/a`), so operands scaled by 1e-170 do not
    /// underflow in between (`(a'b - ab')/b^2` did).
    fn rule(&mut self, i: usize, var: usize) -> NodeId {
        // a part that does not depend on the variable has derivative 0, whatever its value
        // (`pi/0` is infinite, its derivative is still 0, not the NaN the quotient rule gives)
        if self.deps[i] & var_bit(var) == 0 {
            return self.num(0.0);
        }
        let me = i as NodeId;
        let d = |g: &Graph, a: NodeId| g.memo_get(var, a as usize);
        match self.nodes[i] {
            Node::Const(_) => self.num(0.0),
            Node::Var(k) => self.num(if k as usize == var { 1.0 } else { 0.0 }),
            Node::Neg(a) => {
                let da = d(self, a);
                self.neg(da)
            }
            Node::Add(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                self.add(da, db)
            }
            Node::Sub(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                self.sub(da, db)
            }
            Node::Mul(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                let l = self.mul(da, b);
                let r = self.mul(a, db);
                self.add(l, r)
            }
            Node::Div(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                let l = self.div(da, b);
                let rb = self.div(db, b);
                let r = self.mul(me, rb);
                self.sub(l, r)
            }
            Node::Pow(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                match self.constant(b) {
                    // c a^(c-1) a'
                    Some(c) => {
                        let cm1 = self.num(c - 1.0);
                        let p = self.pow(a, cm1);
                        let cn = self.num(c);
                        let cp = self.mul(cn, p);
                        self.mul(cp, da)
                    }
                    // a^b (b' ln a + b a'/a)
                    None => {
                        let ln = self.call(Func::Log, a);
                        let l = self.mul(db, ln);
                        let ra = self.div(da, a);
                        let r = self.mul(b, ra);
                        let s = self.add(l, r);
                        self.mul(me, s)
                    }
                }
            }
            Node::Call(f, a) => {
                let da = d(self, a);
                match f {
                    Func::Log => return self.div(da, a),
                    Func::Sqrt => {
                        // a' / (2 sqrt a)
                        let two = self.num(2.0);
                        let den = self.mul(two, me);
                        return self.div(da, den);
                    }
                    Func::Atan => {
                        // a' / (1 + a^2)
                        let two = self.num(2.0);
                        let sq = self.pow(a, two);
                        let one = self.num(1.0);
                        let den = self.add(one, sq);
                        return self.div(da, den);
                    }
                    _ => {}
                }
                let outer = match f {
                    Func::Sin => self.call(Func::Cos, a),
                    Func::Cos => {
                        let s = self.call(Func::Sin, a);
                        self.neg(s)
                    }
                    Func::Tan | Func::Tanh => {
                        // 1 + tan^2, 1 - tanh^2
                        let two = self.num(2.0);
                        let sq = self.pow(me, two);
                        let one = self.num(1.0);
                        if f == Func::Tan { self.add(one, sq) } else { self.sub(one, sq) }
                    }
                    Func::Exp => me,
                    Func::Abs => self.call(Func::Sign, a),
                    Func::Sinh => self.call(Func::Cosh, a),
                    Func::Cosh => self.call(Func::Sinh, a),
                    Func::Sign => self.num(0.0),
                    Func::Log | Func::Sqrt | Func::Atan => unreachable!("handled above"),
                };
                self.mul(outer, da)
            }
        }
    }
}
