//! The expression language: functions of named variables written as text
//! (`"0.3 * sin(2*pi*t) + t^2"`), their symbolic partial derivatives, and fast evaluation.
//!
//! * [`parse`] reads the text with an iterative operator-precedence parser (no recursion: the
//!   nesting depth cannot overflow the stack) into a [`Graph`];
//! * [`Graph`] is a DAG of hash-consed nodes (equal subexpressions are one node), with constant
//!   folding; [`Graph::derivative`] forms `d(node)/d(variable)` once per node (memoized), so a
//!   derivative costs a bounded number of new nodes per node of its argument: linear in the
//!   expression's size, for any order and any variable;
//! * [`Tape`] lists the nodes the wanted outputs need, children first; evaluation is one pass
//!   over it into a buffer the caller sizes once ([`Tape::len`]): no allocation, no recursion.
//!
//! Two front ends: [`TimeFunction`] (a driver's motion `f(t)` with `f'` and `f''`) and
//! [`Function`] (a function of several variables with its gradient).
//!
//! Grammar (precedence low to high; `^` is right associative and binds tighter than a unary
//! minus, so `-t^2 = -(t^2)`; `**` is accepted for `^`):
//!
//! ```text
//! expr  := term (("+" | "-") term)*
//! term  := unary (("*" | "/") unary)*
//! unary := ("-" | "+") unary | power
//! power := atom (("^" | "**") unary)?
//! atom  := number | variable | "pi" | "e" | function "(" expr ")" | "(" expr ")"
//! ```
//!
//! Functions: `sin cos tan exp log sqrt abs tanh sinh cosh atan sign`. A variable name starts
//! with a letter or `_` and continues with letters, digits, `_`, `.` and `:` (so that state
//! quantities such as `crank.theta` or `d:crank.theta` can be variables).
//!
//! Limits ([`MAX_LENGTH`], [`MAX_DEPTH`]): beyond them a parse error says which was passed.

mod graph;
mod parse;
mod tape;

pub use graph::{Func, Graph, Node, NodeId, TooLarge, MAX_NODES};
pub use parse::{is_variable_name, parse, ParseError, MAX_DEPTH, MAX_LENGTH};
pub use tape::Tape;

use crate::error::{Error, Result};

/// A driver's motion `f(t)` with its first and second time derivatives, compiled into one tape.
#[derive(Debug, Clone)]
pub struct TimeFunction {
    pub text: String,
    tape: Tape,
}

impl TimeFunction {
    /// Parse `text` (the variable is `t`) and differentiate it twice; `item` names the scene
    /// item in errors.
    pub fn parse(item: &str, text: &str) -> Result<TimeFunction> {
        let err = |e: ParseError| Error::Expression { item: item.to_string(), text: text.to_string(), message: e.message, position: e.position };
        let mut g = Graph::new(1);
        let f = parse(&mut g, text, &["t"]).map_err(err)?;
        let too_large = |e: TooLarge| err(ParseError { message: e.to_string(), position: 0 });
        let d1 = g.derivative(f, 0).map_err(too_large)?;
        let d2 = g.derivative(d1, 0).map_err(too_large)?;
        Ok(TimeFunction { text: text.to_string(), tape: Tape::new(&g, &[f, d1, d2]) })
    }

    /// Length of the buffer [`TimeFunction::eval`] needs.
    pub fn scratch_len(&self) -> usize {
        self.tape.len()
    }

    /// `(f, f', f'')` at time `t`, evaluated in `buf` (at least [`TimeFunction::scratch_len`]
    /// long; overwritten).
    #[inline]
    pub fn eval(&self, t: f64, buf: &mut [f64]) -> (f64, f64, f64) {
        self.tape.eval(&[t], buf);
        (self.tape.output(0, buf), self.tape.output(1, buf), self.tape.output(2, buf))
    }

    /// Nodes of the compiled tape (its evaluation cost).
    pub fn tape_len(&self) -> usize {
        self.tape.len()
    }
}

/// A function of several named variables with its gradient, compiled into one tape
/// (`[f, df/dx_0, ..., df/dx_{k-1}]`).
#[derive(Debug, Clone)]
pub struct Function {
    vars: Vec<String>,
    tape: Tape,
    /// `f` alone (the value without the gradient: [`Function::eval`]).
    value: Tape,
}

impl Function {
    /// Parse `text` over the variables `vars` (slot `k` is `vars[k]`) and form every first
    /// partial derivative.
    pub fn parse(text: &str, vars: &[&str]) -> std::result::Result<Function, ParseError> {
        let mut g = Graph::new(vars.len());
        let f = parse(&mut g, text, vars)?;
        let mut roots = vec![f];
        for k in 0..vars.len() {
            roots.push(g.derivative(f, k).map_err(|e| ParseError { message: e.to_string(), position: 0 })?);
        }
        Ok(Function { vars: vars.iter().map(|v| v.to_string()).collect(), tape: Tape::new(&g, &roots), value: Tape::new(&g, &[f]) })
    }

    /// Parse `text` over those of `candidates` it uses (in the order of `candidates`): a load
    /// may read any coordinate of the model, but its tape and gradient hold only what it reads.
    pub fn parse_used(text: &str, candidates: &[&str]) -> std::result::Result<Function, ParseError> {
        let mut g = Graph::new(candidates.len());
        let f = parse(&mut g, text, candidates)?;
        let reach = g.reachable(&[f]);
        let mut used = vec![false; candidates.len()];
        for (i, r) in reach.iter().enumerate() {
            if let (true, Node::Var(k)) = (*r, g.node(i as NodeId)) {
                used[k as usize] = true;
            }
        }
        let vars: Vec<&str> = candidates.iter().zip(&used).filter(|(_, u)| **u).map(|(c, _)| *c).collect();
        Function::parse(text, &vars)
    }

    /// `f(x)` alone; `buf` at least [`Function::scratch_len`] (overwritten).
    #[inline]
    pub fn eval(&self, x: &[f64], buf: &mut [f64]) -> f64 {
        self.value.eval(x, buf);
        self.value.output(0, buf)
    }

    /// A function of `t` alone: the times in `(lo, hi)` at which it has a kink or a jump (an
    /// `abs` or `sign` of an argument that changes sign there; [`Tape::switches`]); none for a
    /// function of anything else.
    pub fn time_switches(&self, lo: f64, hi: f64, samples: usize) -> Vec<f64> {
        if self.vars.len() != 1 || self.vars[0] != "t" {
            return Vec::new();
        }
        self.value.switches(lo, hi, samples)
    }

    /// The variables, in slot order.
    pub fn vars(&self) -> &[String] {
        &self.vars
    }

    /// Length of the buffer [`Function::eval_gradient`] and [`Function::eval`] need.
    pub fn scratch_len(&self) -> usize {
        self.tape.len().max(self.value.len())
    }

    /// `f(x)`, with `grad[k] = df/dx_k`; `x` and `grad` hold one entry per variable, `buf` at
    /// least [`Function::scratch_len`] (overwritten).
    pub fn eval_gradient(&self, x: &[f64], buf: &mut [f64], grad: &mut [f64]) -> f64 {
        self.tape.eval(x, buf);
        for (k, g) in grad.iter_mut().enumerate().take(self.vars.len()) {
            *g = self.tape.output(k + 1, buf);
        }
        self.tape.output(0, buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_switches_of_a_function_of_t_are_its_kinks_and_jumps() {
        // the right-angle cantilever's pulse: kinks at 0, 1 and 2 (0 is the interval's end)
        let f = Function::parse_used("25 * (1 - abs(t - 1) + abs(1 - abs(t - 1)))", &["t", "x"]).unwrap();
        let s = f.time_switches(0.0, 30.0, 4096);
        assert_eq!(s.len(), 2, "{s:?}");
        assert!((s[0] - 1.0).abs() < 1e-12 && (s[1] - 2.0).abs() < 1e-12, "{s:?}");
        // a jump (sign), a kink on a sample, none in a smooth function or one of the state
        let j = Function::parse("3 * sign(t - 0.3) + abs(t - 0.5)", &["t"]).unwrap().time_switches(0.0, 1.0, 8);
        assert!(j.len() == 2 && (j[0] - 0.3).abs() < 1e-12 && j[1] == 0.5, "{j:?}");
        assert!(Function::parse("sin(t) + t^2", &["t"]).unwrap().time_switches(0.0, 10.0, 64).is_empty());
        assert!(Function::parse("abs(x - 1)", &["x"]).unwrap().time_switches(0.0, 10.0, 64).is_empty());
    }

    fn ev(s: &str, t: f64) -> (f64, f64, f64) {
        let f = TimeFunction::parse("test", s).unwrap();
        let mut buf = vec![0.0; f.scratch_len()];
        f.eval(t, &mut buf)
    }

    #[test]
    fn precedence_and_derivatives() {
        assert_eq!(ev("-t^2", 3.0).0, -9.0);
        assert_eq!(ev("2^3^2", 0.0).0, 512.0);
        assert_eq!(ev("2^-1^2", 0.0).0, 0.5); // 2^(-(1^2))
        assert_eq!(ev("2^-3*4", 0.0).0, 0.5); // (2^-3) * 4
        assert_eq!(ev("1 - 2 - 3", 0.0).0, -4.0);
        assert_eq!(ev("8 / 2 / 2", 0.0).0, 2.0);
        assert_eq!(ev("2 ** 3", 0.0).0, 8.0);
        assert_eq!(ev("-2 * -3", 0.0).0, 6.0);
        assert_eq!(ev("+-+t", 2.0).0, -2.0);
        assert!(ev("0/0", 0.0).0.is_nan());
        assert_eq!(ev("1.5e1 + .5", 0.0).0, 15.5);
        let (f, d1, d2) = ev("3*t^2 + sin(2*t)", 0.7);
        assert!((f - (3.0 * 0.49 + 1.4f64.sin())).abs() < 1e-15);
        assert!((d1 - (6.0 * 0.7 + 2.0 * 1.4f64.cos())).abs() < 1e-14);
        assert!((d2 - (6.0 - 4.0 * 1.4f64.sin())).abs() < 1e-14);
        // t^t: the general power rule
        let (_, d1, _) = ev("t^t", 2.0);
        assert!((d1 - 4.0 * (2f64.ln() + 1.0)).abs() < 1e-13);
    }

    #[test]
    fn errors_carry_positions() {
        let pos = |s: &str| match TimeFunction::parse("d", s) {
            Err(Error::Expression { position, .. }) => position,
            other => panic!("{other:?}"),
        };
        assert_eq!(pos("sin(t"), 5);
        assert_eq!(pos("2 * foo(t)"), 4);
        assert_eq!(pos("t +"), 3);
        assert_eq!(pos("t t"), 2);
        assert_eq!(pos(""), 0);
        assert_eq!(pos("(t))"), 3);
        assert_eq!(pos("1e+"), 1);
        assert_eq!(pos("()"), 1);
        assert_eq!(pos("sin t"), 4);
    }

    #[test]
    fn sign_of_nan_is_nan() {
        // was 0: sign(log(t - 1)) ran as a motion x = 0
        assert!(ev("sign(log(t - 1))", 0.0).0.is_nan());
        assert_eq!(ev("sign(t - 1)", 3.0), (1.0, 0.0, 0.0));
        assert_eq!(ev("sign(0*t)", 3.0).0, 0.0);
    }

    #[test]
    fn quotient_rule_keeps_scaled_operands_in_range() {
        // was f' = f'' = 0: (a'b - ab')/b^2 underflowed (b^2 = 1e-340)
        let (f, d1, d2) = ev("1e-170/(1e-170*(t+1))", 0.0);
        assert_eq!((f, d1, d2), (1.0, -1.0, 2.0));
        let (f, d1, d2) = ev("1e170*t/(1e170*(t+1))", 1.0);
        assert!((f - 0.5).abs() < 1e-15 && (d1 - 0.25).abs() < 1e-15 && (d2 + 0.25).abs() < 1e-15, "{f} {d1} {d2}");
        let (_, d1, d2) = ev("log(1e-300*t)", 2.0);
        assert!((d1 - 0.5).abs() < 1e-15 && (d2 + 0.25).abs() < 1e-15, "{d1} {d2}");
    }

    #[test]
    fn constant_parts_have_zero_derivatives() {
        // pi/0 is infinite and tanh(0.5)/inf is 0: f = 2, a constant, whose derivatives are 0
        // (the quotient rule on the constant pi/0 gave 0/0 = NaN)
        assert_eq!(ev("tanh(0.5) / (pi / 0) + 2 + t - t", 0.5), (2.0, 0.0, 0.0));
        assert!(ev("t * log(-1)", 0.3).1.is_nan()); // a NaN constant still multiplies
        let f = Function::parse("x * exp(2) + y^2", &["x", "y"]).unwrap();
        let (mut buf, mut g) = (vec![0.0; f.scratch_len()], [0.0; 2]);
        f.eval_gradient(&[1.0, 3.0], &mut buf, &mut g);
        assert_eq!(g, [2f64.exp(), 6.0]);
    }

    #[test]
    fn products_and_quotients_as_written_keep_ieee_values() {
        // 0 * x and 0 / x are not folded where x can be infinite or NaN: 0 * (t/0) is NaN, not 0
        assert!(ev("t/0*(1*0)", 1.0).0.is_nan());
        assert!(ev("0/(t - t)", 1.0).0.is_nan());
        assert_eq!(ev("1/(0*sin(t))", -2.0).0, f64::NEG_INFINITY); // 0 * sin(-2) = -0, as IEEE has it
        // in derivatives the zeros are structural: d/dt (0 * t) = 0
        assert_eq!(ev("0*t + t", 2.0), (2.0, 1.0, 0.0));
        // pow within an ulp: tan of 1.7e12 amplifies every ulp of the argument
        let x = 2f64.tan().powf(3.0).powf(3.0).powf(4.0);
        assert_eq!(ev("tan(((tan(2)^3)^3)^4)", 0.0).0, x.tan());
    }

    #[test]
    fn shared_subexpressions_are_one_node() {
        let mut g = Graph::new(1);
        let a = parse(&mut g, "sin(t)*sin(t) + sin(t)", &["t"]).unwrap();
        // t, sin(t), sin(t)^2 (as a product), the sum
        assert_eq!(g.len(), 4, "{:?}", g);
        let b = parse(&mut g, "sin(t) + sin(t)*sin(t)", &["t"]).unwrap();
        assert_eq!(a, b, "+ and * are commutative: one node");
    }

    /// Nodes of `f`, `f'` and `f''` of `text`.
    fn tape_len(text: &str) -> usize {
        TimeFunction::parse("test", text).unwrap().tape_len()
    }

    #[test]
    fn derivatives_grow_linearly() {
        // each family at n and 2n levels: the tape at most doubles (plus a constant); the trees of
        // the old differentiator grew exponentially (towers) or quadratically (nested calls)
        let families: [(&str, fn(usize) -> String); 5] = [
            ("tower", |n| "t^".repeat(n) + "t"),
            ("nested sin", |n| "sin(".repeat(n) + "t" + &")".repeat(n)),
            ("product", |n| vec!["(t+1)"; n].join("*")),
            ("quotients", |n| vec!["(t+2)"; n].join("/")),
            ("sum of products", |n| (0..n).map(|k| format!("{}*t^{}", k + 1, k % 7)).collect::<Vec<_>>().join("+")),
        ];
        for (name, make) in families {
            let (a, b) = (tape_len(&make(200)), tape_len(&make(400)));
            assert!(b <= 2 * a + 16, "{name}: {a} nodes at 200 levels, {b} at 400");
            assert!(a <= 40 * 200, "{name}: {a} nodes for 200 levels");
        }
        // the reproducers of issue 28: built at once
        let tic = std::time::Instant::now();
        let f = TimeFunction::parse("d", &("t^".repeat(9000) + "t")).unwrap();
        let g = TimeFunction::parse("d", &("sin(".repeat(1000) + "t" + &")".repeat(1000))).unwrap();
        assert!(tic.elapsed().as_secs_f64() < 2.0, "{:?}", tic.elapsed());
        let mut buf = vec![0.0; f.scratch_len().max(g.scratch_len())];
        let (v, d1, _) = f.eval(1.0, &mut buf);
        assert_eq!((v, d1), (1.0, 1.0)); // 1^1^...^1, d/dt t^(...) at 1: 1 + ln 1 * ... = 1
        let (v, d1, _) = g.eval(0.0, &mut buf);
        assert_eq!((v, d1), (0.0, 1.0));
    }

    #[test]
    fn limits_are_named_errors() {
        let msg = |s: &str| match TimeFunction::parse("d", s) {
            Err(Error::Expression { message, .. }) => message,
            other => panic!("{other:?}"),
        };
        for s in ["(".repeat(30000) + "t" + &")".repeat(30000), "-".repeat(30000) + "t", "(".repeat(30000), "t^".repeat(MAX_DEPTH + 1) + "t"] {
            assert!(msg(&s).contains("nested deeper"), "{}", msg(&s));
        }
        assert!(msg(&("t+".repeat(100000) + "t")).contains("characters"));
        // at the limits: accepted
        TimeFunction::parse("d", &("(".repeat(MAX_DEPTH) + "t" + &")".repeat(MAX_DEPTH))).unwrap();
        let flat = "t+".repeat((MAX_LENGTH - 1) / 2) + "t";
        assert!(flat.len() <= MAX_LENGTH);
        let f = TimeFunction::parse("d", &flat).unwrap();
        let mut buf = vec![0.0; f.scratch_len()];
        assert_eq!(f.eval(2.0, &mut buf), (2.0 * (MAX_LENGTH / 2) as f64, (MAX_LENGTH / 2) as f64, 0.0));
        // the excerpt of a long expression in the message stays short
        let e = TimeFunction::parse("d", &("(".repeat(30000) + "t")).unwrap_err().to_string();
        assert!(e.len() < 400, "{e}");
    }

    #[test]
    fn several_variables_and_their_gradient() {
        let f = Function::parse("sin(crank.theta) * d:crank.theta^2 + 3*t*crank.theta", &["t", "crank.theta", "d:crank.theta"]).unwrap();
        let mut buf = vec![0.0; f.scratch_len()];
        let mut grad = [0.0; 3];
        let x = [0.5, 1.2, -0.7];
        let v = f.eval_gradient(&x, &mut buf, &mut grad);
        let (t, th, w) = (x[0], x[1], x[2]);
        assert!((v - (th.sin() * w * w + 3.0 * t * th)).abs() < 1e-15);
        let exact = [3.0 * th, th.cos() * w * w + 3.0 * t, 2.0 * th.sin() * w];
        for k in 0..3 {
            assert!((grad[k] - exact[k]).abs() < 1e-14, "d/d{}: {} vs {}", f.vars()[k], grad[k], exact[k]);
        }
        // against central differences, on a function using every operation
        let text = "x^y / (1 + atan(x*y)) - log(sqrt(x^2 + y^2)) * tanh(y) + abs(x - y) * exp(-x) + cosh(x/3) - sinh(y/4) + tan(x/5)";
        let f = Function::parse(text, &["x", "y"]).unwrap();
        let mut buf = vec![0.0; f.scratch_len()];
        let mut grad = [0.0; 2];
        let x = [1.3, 0.8];
        f.eval_gradient(&x, &mut buf, &mut grad);
        let mut g2 = [0.0; 2];
        for k in 0..2 {
            let h = 1e-6;
            let (mut xp, mut xm) = (x, x);
            xp[k] += h;
            xm[k] -= h;
            let fd = (f.eval_gradient(&xp, &mut buf, &mut g2) - f.eval_gradient(&xm, &mut buf, &mut g2)) / (2.0 * h);
            assert!((grad[k] - fd).abs() < 1e-8, "d/d{}: {} vs {}", f.vars()[k], grad[k], fd);
        }
        // second partial derivatives through the graph
        let mut g = Graph::new(2);
        let h = parse(&mut g, "x^2*y^3", &["x", "y"]).unwrap();
        let hx = g.derivative(h, 0).unwrap();
        let hxy = g.derivative(hx, 1).unwrap();
        let hy = g.derivative(h, 1).unwrap();
        let hyx = g.derivative(hy, 0).unwrap();
        let tape = Tape::new(&g, &[hxy, hyx]);
        let mut buf = vec![0.0; tape.len()];
        tape.eval(&[2.0, 3.0], &mut buf);
        assert_eq!((tape.output(0, &buf), tape.output(1, &buf)), (108.0, 108.0)); // 6 x y^2
        // unknown and reserved names
        let e = Function::parse("x + z", &["x", "y"]).unwrap_err();
        assert!(e.message.contains("unknown name 'z'") && e.message.contains("x, y"), "{}", e.message);
        assert!(Function::parse("sin + 1", &["sin"]).is_err());
    }
}
