//! Driver motions written as an expression of `t` (`"0.3 * sin(2*pi*t) + t^2"`): a small
//! recursive-descent parser, an AST in one arena, and its first and second time derivatives by
//! symbolic differentiation (with constant folding), all built once at model build. Evaluation
//! walks the three trees: no allocation, no Python.
//!
//! Grammar (precedence low to high; `^` is right associative and binds tighter than a unary
//! minus, so `-t^2 = -(t^2)`; `**` is accepted for `^`):
//!
//! ```text
//! expr  := term (("+" | "-") term)*
//! term  := unary (("*" | "/") unary)*
//! unary := ("-" | "+") unary | power
//! power := atom (("^" | "**") unary)?
//! atom  := number | "t" | "pi" | "e" | name "(" expr ")" | "(" expr ")"
//! ```
//!
//! Functions: `sin cos tan exp log sqrt abs tanh sinh cosh atan sign`.

use crate::error::{Error, Result};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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

    fn apply(self, x: f64) -> f64 {
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
            Func::Sign => {
                if x > 0.0 {
                    1.0
                } else if x < 0.0 {
                    -1.0
                } else {
                    0.0
                }
            }
        }
    }
}

/// One node of the arena; children are indices into the same arena.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Node {
    Num(f64),
    T,
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Pow(usize, usize),
    Neg(usize),
    Call(Func, usize),
}

/// A parsed expression with its first and second derivatives (three roots in one arena).
#[derive(Debug, Clone)]
pub struct Expr {
    pub text: String,
    nodes: Vec<Node>,
    roots: [usize; 3],
}

/// A parse error: the message and the 0-based character position where it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    pub message: String,
    pub position: usize,
}

impl Expr {
    /// Parse `text` and differentiate it twice. `item` names the scene item in errors.
    pub fn parse(item: &str, text: &str) -> Result<Expr> {
        let mut p = Parser { chars: text.chars().collect(), pos: 0, nodes: Vec::new() };
        let root = p.parse_all().map_err(|e| Error::Expression {
            item: item.to_string(),
            text: text.to_string(),
            message: e.message,
            position: e.position,
        })?;
        let mut nodes = p.nodes;
        let d1 = derive(&mut nodes, root);
        let d2 = derive(&mut nodes, d1);
        Ok(Expr { text: text.to_string(), nodes, roots: [root, d1, d2] })
    }

    /// `(f, f', f'')` at time `t`.
    #[inline]
    pub fn eval(&self, t: f64) -> (f64, f64, f64) {
        (self.value(self.roots[0], t), self.value(self.roots[1], t), self.value(self.roots[2], t))
    }

    /// The derivative of order `k` (0, 1, 2) written back as text (inspection, docs, tests).
    pub fn derivative_text(&self, k: usize) -> String {
        self.show(self.roots[k.min(2)])
    }

    fn value(&self, i: usize, t: f64) -> f64 {
        match self.nodes[i] {
            Node::Num(v) => v,
            Node::T => t,
            Node::Add(a, b) => self.value(a, t) + self.value(b, t),
            Node::Sub(a, b) => self.value(a, t) - self.value(b, t),
            Node::Mul(a, b) => self.value(a, t) * self.value(b, t),
            Node::Div(a, b) => self.value(a, t) / self.value(b, t),
            Node::Pow(a, b) => pow(self.value(a, t), self.value(b, t)),
            Node::Neg(a) => -self.value(a, t),
            Node::Call(f, a) => f.apply(self.value(a, t)),
        }
    }

    fn show(&self, i: usize) -> String {
        match self.nodes[i] {
            Node::Num(v) => {
                if v < 0.0 {
                    format!("({v})")
                } else {
                    format!("{v}")
                }
            }
            Node::T => "t".into(),
            Node::Add(a, b) => format!("({} + {})", self.show(a), self.show(b)),
            Node::Sub(a, b) => format!("({} - {})", self.show(a), self.show(b)),
            Node::Mul(a, b) => format!("{} * {}", self.show(a), self.show(b)),
            Node::Div(a, b) => format!("{} / ({})", self.show(a), self.show(b)),
            Node::Pow(a, b) => format!("({})^({})", self.show(a), self.show(b)),
            Node::Neg(a) => format!("(-{})", self.show(a)),
            Node::Call(f, a) => {
                let name = Func::ALL.iter().find(|(_, g)| *g == f).map(|(n, _)| *n).unwrap_or("?");
                format!("{name}({})", self.show(a))
            }
        }
    }
}

/// `x^y`, with integer exponents by `powi` (exact for negative bases).
#[inline]
fn pow(x: f64, y: f64) -> f64 {
    if y == y.trunc() && y.abs() <= 64.0 {
        x.powi(y as i32)
    } else {
        x.powf(y)
    }
}

// ------------------------------------------------------------------------------------------
// construction with constant folding (keeps the derivative trees small)
// ------------------------------------------------------------------------------------------

fn push(nodes: &mut Vec<Node>, n: Node) -> usize {
    nodes.push(n);
    nodes.len() - 1
}

fn num_of(nodes: &[Node], i: usize) -> Option<f64> {
    match nodes[i] {
        Node::Num(v) => Some(v),
        _ => None,
    }
}

fn num(nodes: &mut Vec<Node>, v: f64) -> usize {
    push(nodes, Node::Num(v))
}

fn add(nodes: &mut Vec<Node>, a: usize, b: usize) -> usize {
    match (num_of(nodes, a), num_of(nodes, b)) {
        (Some(x), Some(y)) => num(nodes, x + y),
        (Some(0.0), _) => b,
        (_, Some(0.0)) => a,
        _ => push(nodes, Node::Add(a, b)),
    }
}

fn sub(nodes: &mut Vec<Node>, a: usize, b: usize) -> usize {
    match (num_of(nodes, a), num_of(nodes, b)) {
        (Some(x), Some(y)) => num(nodes, x - y),
        (Some(0.0), _) => neg(nodes, b),
        (_, Some(0.0)) => a,
        _ => push(nodes, Node::Sub(a, b)),
    }
}

fn mul(nodes: &mut Vec<Node>, a: usize, b: usize) -> usize {
    match (num_of(nodes, a), num_of(nodes, b)) {
        (Some(x), Some(y)) => num(nodes, x * y),
        (Some(0.0), _) | (_, Some(0.0)) => num(nodes, 0.0),
        (Some(1.0), _) => b,
        (_, Some(1.0)) => a,
        _ => push(nodes, Node::Mul(a, b)),
    }
}

fn div(nodes: &mut Vec<Node>, a: usize, b: usize) -> usize {
    match (num_of(nodes, a), num_of(nodes, b)) {
        (Some(x), Some(y)) if y != 0.0 => num(nodes, x / y),
        (Some(0.0), None) => num(nodes, 0.0),
        (_, Some(1.0)) => a,
        _ => push(nodes, Node::Div(a, b)),
    }
}

fn neg(nodes: &mut Vec<Node>, a: usize) -> usize {
    match nodes[a] {
        Node::Num(x) => num(nodes, -x),
        Node::Neg(inner) => inner,
        _ => push(nodes, Node::Neg(a)),
    }
}

fn powr(nodes: &mut Vec<Node>, a: usize, b: usize) -> usize {
    match (num_of(nodes, a), num_of(nodes, b)) {
        (Some(x), Some(y)) => num(nodes, pow(x, y)),
        (_, Some(0.0)) => num(nodes, 1.0),
        (_, Some(1.0)) => a,
        _ => push(nodes, Node::Pow(a, b)),
    }
}

fn call(nodes: &mut Vec<Node>, f: Func, a: usize) -> usize {
    match num_of(nodes, a) {
        Some(x) => num(nodes, f.apply(x)),
        None => push(nodes, Node::Call(f, a)),
    }
}

/// The node of `d(node i)/dt`, appended to the arena.
fn derive(nodes: &mut Vec<Node>, i: usize) -> usize {
    match nodes[i] {
        Node::Num(_) => num(nodes, 0.0),
        Node::T => num(nodes, 1.0),
        Node::Add(a, b) => {
            let (da, db) = (derive(nodes, a), derive(nodes, b));
            add(nodes, da, db)
        }
        Node::Sub(a, b) => {
            let (da, db) = (derive(nodes, a), derive(nodes, b));
            sub(nodes, da, db)
        }
        Node::Mul(a, b) => {
            // a' b + a b'
            let (da, db) = (derive(nodes, a), derive(nodes, b));
            let l = mul(nodes, da, b);
            let r = mul(nodes, a, db);
            add(nodes, l, r)
        }
        Node::Div(a, b) => {
            // (a' b - a b') / b^2
            let (da, db) = (derive(nodes, a), derive(nodes, b));
            let l = mul(nodes, da, b);
            let r = mul(nodes, a, db);
            let top = sub(nodes, l, r);
            let two = num(nodes, 2.0);
            let b2 = powr(nodes, b, two);
            div(nodes, top, b2)
        }
        Node::Pow(a, b) => {
            let da = derive(nodes, a);
            match num_of(nodes, b) {
                // c a^(c-1) a'
                Some(c) => {
                    let cm1 = num(nodes, c - 1.0);
                    let p = powr(nodes, a, cm1);
                    let cn = num(nodes, c);
                    let cp = mul(nodes, cn, p);
                    mul(nodes, cp, da)
                }
                // a^b (b' ln a + b a'/a)
                None => {
                    let db = derive(nodes, b);
                    let ln = call(nodes, Func::Log, a);
                    let l = mul(nodes, db, ln);
                    let ba = mul(nodes, b, da);
                    let r = div(nodes, ba, a);
                    let s = add(nodes, l, r);
                    mul(nodes, i, s)
                }
            }
        }
        Node::Neg(a) => {
            let da = derive(nodes, a);
            neg(nodes, da)
        }
        Node::Call(f, a) => {
            let da = derive(nodes, a);
            let outer = match f {
                Func::Sin => call(nodes, Func::Cos, a),
                Func::Cos => {
                    let s = call(nodes, Func::Sin, a);
                    neg(nodes, s)
                }
                Func::Tan | Func::Tanh => {
                    // 1 + tan^2, 1 - tanh^2
                    let two = num(nodes, 2.0);
                    let sq = powr(nodes, i, two);
                    let one = num(nodes, 1.0);
                    if f == Func::Tan { add(nodes, one, sq) } else { sub(nodes, one, sq) }
                }
                Func::Exp => i,
                Func::Log => {
                    let one = num(nodes, 1.0);
                    div(nodes, one, a)
                }
                Func::Sqrt => {
                    let half = num(nodes, 0.5);
                    div(nodes, half, i)
                }
                Func::Abs => call(nodes, Func::Sign, a),
                Func::Sinh => call(nodes, Func::Cosh, a),
                Func::Cosh => call(nodes, Func::Sinh, a),
                Func::Atan => {
                    let two = num(nodes, 2.0);
                    let sq = powr(nodes, a, two);
                    let one = num(nodes, 1.0);
                    let den = add(nodes, one, sq);
                    let one = num(nodes, 1.0);
                    div(nodes, one, den)
                }
                Func::Sign => num(nodes, 0.0),
            };
            mul(nodes, outer, da)
        }
    }
}

// ------------------------------------------------------------------------------------------
// parser
// ------------------------------------------------------------------------------------------

struct Parser {
    chars: Vec<char>,
    pos: usize,
    nodes: Vec<Node>,
}

type PResult<T> = std::result::Result<T, ParseError>;

impl Parser {
    fn err<T>(&self, position: usize, message: impl Into<String>) -> PResult<T> {
        Err(ParseError { message: message.into(), position })
    }

    fn skip_ws(&mut self) {
        while self.pos < self.chars.len() && self.chars[self.pos].is_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip_ws();
        self.chars.get(self.pos).copied()
    }

    fn parse_all(&mut self) -> PResult<usize> {
        if self.peek().is_none() {
            return self.err(self.pos, "empty expression");
        }
        let e = self.expr()?;
        match self.peek() {
            None => Ok(e),
            Some(')') => self.err(self.pos, "unmatched ')'"),
            Some(c) => self.err(self.pos, format!("unexpected '{c}' (expected an operator)")),
        }
    }

    fn expr(&mut self) -> PResult<usize> {
        let mut a = self.term()?;
        while let Some(c @ ('+' | '-')) = self.peek() {
            self.pos += 1;
            let b = self.term()?;
            a = if c == '+' { add(&mut self.nodes, a, b) } else { sub(&mut self.nodes, a, b) };
        }
        Ok(a)
    }

    fn term(&mut self) -> PResult<usize> {
        let mut a = self.unary()?;
        loop {
            match self.peek() {
                Some('*') if self.chars.get(self.pos + 1) != Some(&'*') => {
                    self.pos += 1;
                    let b = self.unary()?;
                    a = mul(&mut self.nodes, a, b);
                }
                Some('/') => {
                    self.pos += 1;
                    let b = self.unary()?;
                    a = div(&mut self.nodes, a, b);
                }
                _ => return Ok(a),
            }
        }
    }

    fn unary(&mut self) -> PResult<usize> {
        match self.peek() {
            Some('-') => {
                self.pos += 1;
                let a = self.unary()?;
                Ok(neg(&mut self.nodes, a))
            }
            Some('+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> PResult<usize> {
        let a = self.atom()?;
        match self.peek() {
            Some('^') => self.pos += 1,
            Some('*') if self.chars.get(self.pos + 1) == Some(&'*') => self.pos += 2,
            _ => return Ok(a),
        }
        let b = self.unary()?;
        Ok(powr(&mut self.nodes, a, b))
    }

    fn atom(&mut self) -> PResult<usize> {
        let start = match self.peek() {
            None => return self.err(self.pos, "unexpected end of expression (expected a number, t, a function or '(')"),
            Some(_) => self.pos,
        };
        let c = self.chars[start];
        if c == '(' {
            self.pos += 1;
            let e = self.expr()?;
            if self.peek() != Some(')') {
                return self.err(self.pos, format!("expected ')' to close the '(' at position {start}"));
            }
            self.pos += 1;
            return Ok(e);
        }
        if c.is_ascii_digit() || c == '.' {
            return self.number(start);
        }
        if c.is_ascii_alphabetic() || c == '_' {
            while self.pos < self.chars.len() && (self.chars[self.pos].is_ascii_alphanumeric() || self.chars[self.pos] == '_') {
                self.pos += 1;
            }
            let name: String = self.chars[start..self.pos].iter().collect();
            match name.as_str() {
                "t" => return Ok(push(&mut self.nodes, Node::T)),
                "pi" => return Ok(num(&mut self.nodes, std::f64::consts::PI)),
                "e" => return Ok(num(&mut self.nodes, std::f64::consts::E)),
                _ => {}
            }
            let Some(&(_, f)) = Func::ALL.iter().find(|(n, _)| *n == name) else {
                let known: Vec<&str> = Func::ALL.iter().map(|(n, _)| *n).collect();
                return self.err(start, format!("unknown name '{name}' (the variable is t; constants pi, e; functions {})", known.join(", ")));
            };
            if self.peek() != Some('(') {
                return self.err(self.pos, format!("expected '(' after the function '{name}'"));
            }
            let open = self.pos;
            self.pos += 1;
            let a = self.expr()?;
            if self.peek() != Some(')') {
                return self.err(self.pos, format!("expected ')' to close the '(' at position {open}"));
            }
            self.pos += 1;
            return Ok(call(&mut self.nodes, f, a));
        }
        self.err(start, format!("unexpected '{c}' (expected a number, t, a function or '(')"))
    }

    fn number(&mut self, start: usize) -> PResult<usize> {
        let n = self.chars.len();
        let digits = |p: &mut usize, chars: &[char]| {
            let s = *p;
            while *p < n && chars[*p].is_ascii_digit() {
                *p += 1;
            }
            *p > s
        };
        let mut p = start;
        let mut any = digits(&mut p, &self.chars);
        if p < n && self.chars[p] == '.' {
            p += 1;
            any |= digits(&mut p, &self.chars);
        }
        if !any {
            return self.err(start, "malformed number");
        }
        if p < n && (self.chars[p] == 'e' || self.chars[p] == 'E') {
            let mut q = p + 1;
            if q < n && (self.chars[q] == '+' || self.chars[q] == '-') {
                q += 1;
            }
            if digits(&mut q, &self.chars) {
                p = q;
            } else if q >= n || !self.chars[q].is_ascii_alphabetic() {
                return self.err(p, "malformed exponent of a number");
            }
        }
        let s: String = self.chars[start..p].iter().collect();
        let v: f64 = match s.parse() {
            Ok(v) => v,
            Err(_) => return self.err(start, format!("malformed number '{s}'")),
        };
        self.pos = p;
        Ok(num(&mut self.nodes, v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(s: &str, t: f64) -> (f64, f64, f64) {
        Expr::parse("test", s).unwrap().eval(t)
    }

    #[test]
    fn precedence_and_derivatives() {
        assert_eq!(ev("-t^2", 3.0).0, -9.0);
        assert_eq!(ev("2^3^2", 0.0).0, 512.0);
        assert_eq!(ev("1 - 2 - 3", 0.0).0, -4.0);
        assert_eq!(ev("8 / 2 / 2", 0.0).0, 2.0);
        assert_eq!(ev("2 ** 3", 0.0).0, 8.0);
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
        let pos = |s: &str| match Expr::parse("d", s) {
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
    }
}
