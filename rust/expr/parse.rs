//! The parser: operator precedence with two explicit stacks (operands and pending operators),
//! so nesting costs heap, not call stack. The grammar is in `mod.rs`.

use super::graph::{Func, Graph, NodeId};

/// Longest expression text, in characters.
pub const MAX_LENGTH: usize = 100_000;

/// Deepest nesting: constructs open at once (parentheses and function calls, unary signs and
/// operators waiting for their right operand). 10,000 keeps any hand-written or generated
/// expression with 1,000 levels of parentheses (with a sign and an operator at each level).
pub const MAX_DEPTH: usize = 10_000;

/// A parse error: the message and the 0-based character position where it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct ParseError {
    pub message: String,
    pub position: usize,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Neg,
    /// An open parenthesis (at `pos`), of a function call when `Some`.
    Open(usize, Option<Func>),
}

impl Op {
    /// Binding strength; `Open` holds everything above it.
    fn prec(self) -> u8 {
        match self {
            Op::Open(..) => 0,
            Op::Add | Op::Sub => 1,
            Op::Mul | Op::Div => 2,
            Op::Neg => 3,
            Op::Pow => 4,
        }
    }
}

const RESERVED: [&str; 2] = ["pi", "e"];

fn is_name_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == ':'
}

/// Whether `v` can name a variable of an expression: letters, digits, `_ . :`, starting with a
/// letter or `_`, not a constant or a function.
pub fn is_variable_name(v: &str) -> bool {
    v.chars().next().is_some_and(is_name_start) && v.chars().all(is_name_char) && !RESERVED.contains(&v) && Func::by_name(v).is_none()
}

/// Parse `text` into `g` over the variables `vars` (slot `k` is `vars[k]`); returns the root.
pub fn parse(g: &mut Graph, text: &str, vars: &[&str]) -> Result<NodeId, ParseError> {
    debug_assert_eq!(vars.len(), g.n_vars());
    for v in vars {
        if !is_variable_name(v) {
            return Err(ParseError { message: format!("'{v}' cannot name a variable (a name of letters, digits, _ . :, not a constant or a function)"), position: 0 });
        }
    }
    if text.len() > MAX_LENGTH {
        let n = text.chars().count();
        if n > MAX_LENGTH {
            return Err(ParseError { message: format!("the expression is {n} characters long, beyond the limit of {MAX_LENGTH}"), position: MAX_LENGTH });
        }
    }
    Parser { chars: text.chars().collect(), pos: 0, vars, operands: Vec::new(), ops: Vec::new(), g }.run()
}

struct Parser<'a> {
    chars: Vec<char>,
    pos: usize,
    vars: &'a [&'a str],
    operands: Vec<NodeId>,
    ops: Vec<Op>,
    g: &'a mut Graph,
}

type PResult<T> = Result<T, ParseError>;

fn err<T>(position: usize, message: impl Into<String>) -> PResult<T> {
    Err(ParseError { message: message.into(), position })
}

const OPERAND: &str = "(expected a number, a variable, a function or '(')";

impl Parser<'_> {
    fn peek(&mut self) -> Option<char> {
        while self.pos < self.chars.len() && self.chars[self.pos].is_whitespace() {
            self.pos += 1;
        }
        self.chars.get(self.pos).copied()
    }

    fn push_op(&mut self, op: Op) -> PResult<()> {
        if self.ops.len() >= MAX_DEPTH {
            return err(self.pos, format!("nested deeper than {MAX_DEPTH} levels (parentheses, function calls, signs and pending operators)"));
        }
        self.ops.push(op);
        Ok(())
    }

    /// Apply the operator on top of the stack to its operands.
    fn reduce(&mut self) {
        let Some(op) = self.ops.pop() else { return };
        // the shunting discipline keeps the operands there: an operator is pushed only after
        // its left operand, and reduced only after its right one
        let Some(b) = self.operands.pop() else { return };
        let node = match op {
            Op::Neg => self.g.neg(b),
            Op::Open(_, Some(f)) => self.g.call(f, b),
            Op::Open(_, None) => b,
            _ => {
                let Some(a) = self.operands.pop() else { return };
                match op {
                    Op::Add => self.g.add(a, b),
                    Op::Sub => self.g.sub(a, b),
                    Op::Mul => self.g.product(a, b),
                    Op::Div => self.g.quotient(a, b),
                    _ => self.g.pow(a, b),
                }
            }
        };
        self.operands.push(node);
    }

    /// A binary operator: reduce what binds at least as tightly (`^`: right associative, only
    /// tighter), then push it.
    fn binary(&mut self, op: Op) -> PResult<()> {
        let p = op.prec();
        while let Some(&top) = self.ops.last() {
            let reduce = if op == Op::Pow { top.prec() > p } else { top.prec() >= p };
            if !reduce || matches!(top, Op::Open(..)) {
                break;
            }
            self.reduce();
        }
        self.push_op(op)
    }

    fn run(mut self) -> PResult<NodeId> {
        if self.peek().is_none() {
            return err(self.pos, "empty expression");
        }
        let mut want_operand = true;
        loop {
            let Some(c) = self.peek() else { break };
            if want_operand {
                match c {
                    '(' => {
                        self.push_op(Op::Open(self.pos, None))?;
                        self.pos += 1;
                    }
                    '-' => {
                        self.push_op(Op::Neg)?;
                        self.pos += 1;
                    }
                    '+' => self.pos += 1,
                    _ if c.is_ascii_digit() || c == '.' => {
                        let v = self.number()?;
                        let id = self.g.num(v);
                        self.operands.push(id);
                        want_operand = false;
                    }
                    _ if is_name_start(c) => want_operand = self.name()?,
                    _ => return err(self.pos, format!("unexpected '{c}' {OPERAND}")),
                }
            } else {
                match c {
                    '+' => self.binary(Op::Add)?,
                    '-' => self.binary(Op::Sub)?,
                    '*' if self.chars.get(self.pos + 1) == Some(&'*') => {
                        self.pos += 1;
                        self.binary(Op::Pow)?
                    }
                    '*' => self.binary(Op::Mul)?,
                    '/' => self.binary(Op::Div)?,
                    '^' => self.binary(Op::Pow)?,
                    ')' => {
                        loop {
                            match self.ops.last() {
                                None => return err(self.pos, "unmatched ')'"),
                                Some(Op::Open(..)) => break,
                                Some(_) => self.reduce(),
                            }
                        }
                        self.reduce(); // the parenthesis itself (a call applies its function)
                        self.pos += 1;
                        continue;
                    }
                    _ => return err(self.pos, format!("unexpected '{c}' (expected an operator)")),
                }
                self.pos += 1;
                want_operand = true;
            }
        }
        if want_operand {
            return err(self.pos, format!("unexpected end of expression {OPERAND}"));
        }
        while let Some(&top) = self.ops.last() {
            if let Op::Open(open, _) = top {
                return err(self.pos, format!("expected ')' to close the '(' at position {open}"));
            }
            self.reduce();
        }
        match (self.operands.pop(), self.operands.is_empty()) {
            (Some(root), true) => Ok(root),
            _ => err(self.pos, "malformed expression"),
        }
    }

    /// A variable, a constant or a function call's name and its '('. Returns whether an operand
    /// is still wanted (after a function's '(').
    fn name(&mut self) -> PResult<bool> {
        let start = self.pos;
        while self.pos < self.chars.len() && is_name_char(self.chars[self.pos]) {
            self.pos += 1;
        }
        let name: String = self.chars[start..self.pos].iter().collect();
        if let Some(k) = self.vars.iter().position(|v| *v == name) {
            let id = self.g.var(k);
            self.operands.push(id);
            return Ok(false);
        }
        let constant = match name.as_str() {
            "pi" => Some(std::f64::consts::PI),
            "e" => Some(std::f64::consts::E),
            _ => None,
        };
        if let Some(v) = constant {
            let id = self.g.num(v);
            self.operands.push(id);
            return Ok(false);
        }
        let Some(f) = Func::by_name(&name) else {
            let known: Vec<&str> = Func::ALL.iter().map(|(n, _)| *n).collect();
            let vars = if self.vars.len() == 1 { format!("the variable is {}", self.vars[0]) } else { format!("variables {}", self.vars.join(", ")) };
            return err(start, format!("unknown name '{name}' ({vars}; constants pi, e; functions {})", known.join(", ")));
        };
        if self.peek() != Some('(') {
            return err(self.pos, format!("expected '(' after the function '{name}'"));
        }
        self.push_op(Op::Open(self.pos, Some(f)))?;
        self.pos += 1;
        Ok(true)
    }

    fn number(&mut self) -> PResult<f64> {
        let start = self.pos;
        let chars = &self.chars;
        let n = chars.len();
        let digits = |p: &mut usize| {
            let s = *p;
            while *p < n && chars[*p].is_ascii_digit() {
                *p += 1;
            }
            *p > s
        };
        let mut p = start;
        let mut any = digits(&mut p);
        if p < n && chars[p] == '.' {
            p += 1;
            any |= digits(&mut p);
        }
        if !any {
            return err(start, "malformed number");
        }
        if p < n && (chars[p] == 'e' || chars[p] == 'E') {
            let mut q = p + 1;
            if q < n && (chars[q] == '+' || chars[q] == '-') {
                q += 1;
            }
            if digits(&mut q) {
                p = q;
            } else if q >= n || !chars[q].is_ascii_alphabetic() {
                return err(p, "malformed exponent of a number");
            }
        }
        let s: String = chars[start..p].iter().collect();
        let v: f64 = match s.parse() {
            Ok(v) => v,
            Err(_) => return err(start, format!("malformed number '{s}'")),
        };
        self.pos = p;
        Ok(v)
    }
}
