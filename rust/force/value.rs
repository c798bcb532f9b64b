//! The value of a load that is a function: a constant, an expression of `t` and of named state
//! quantities (compiled by `crate::expr` with its gradient), or a table (a cubic spline of one
//! quantity). Shared by the load kinds (`load.rs`, `motor.rs`); docs/loads.md.
//!
//! State quantities are spelled as the output expressions of docs/outputs.md: `t`, a
//! coordinate name (`crank.theta`, `slider.x`, `coupler.qf1`) and its rate (`d:crank.theta`),
//! the world position of a body's point `x(BODY, XI)`, `y(BODY, XI)` (a beam's axis point at
//! `XI`, as the outputs'; the point of a marker at `xi`) and its rate `d:x(BODY, XI)`, a beam's
//! displacement `u/v/psi(BEAM, XI)` and its rate (`value_beam.rs`), plus the
//! element's own quantities (a motor's `angle` and `w`, the relative angle and rate of its two
//! markers). A point quantity is read into the expression as a variable: before parsing, its
//! text is replaced by a placeholder name of the same length (so error positions stay).

use std::sync::Arc;

use super::value3::Spatial;
use super::value_beam::BeamQuantity;
use super::value_joint::JointQuantity;
use crate::body::marker3::{add_jacobian, Marker3};
use crate::body::{Body, Marker};
use crate::constraint::BuildContext;
use crate::description::{CallableDesc, LoadValueDesc, MarkerDesc, TableDesc};
use crate::constraint::motion::Spline;
use crate::error::{check_finite_item, Error, Result};
use crate::expr::{Function, ParseError};

/// Where an input of a load's function comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Input {
    Time,
    /// `q[i]`.
    Coord(usize),
    /// `qd[i]`.
    Rate(usize),
    /// The element's own quantity `k` (`Env::local`).
    Local(usize),
    /// Component `axis` (0: x, 1: y) of the position (`rate`: velocity) of the value's point
    /// `k` (`Expr::points`).
    Point { k: usize, axis: usize, rate: bool },
    /// Component `axis` (0: x, 1: y, 2: z) of the position (`rate`: velocity) of the value's
    /// spatial point `k` (`Expr::points3`, `value3.rs`).
    Point3 { k: usize, axis: usize, rate: bool },
    /// The value's beam quantity `k` (`Expr::beams`, `value_beam.rs`): `u`, `v`, `psi` or a rate.
    Beam(usize),
    /// The value's joint quantity `k` (`Expr::joints`, `value_joint.rs`): `angle`, `s` or a rate.
    Joint(usize),
}

/// The state a value is evaluated at.
pub struct Env<'a> {
    pub bodies: &'a [Body],
    pub t: f64,
    pub q: &'a [f64],
    pub qd: &'a [f64],
    /// The element's own quantities (a motor: relative angle and rate).
    pub local: [f64; 2],
}

impl Env<'_> {
    #[inline]
    fn get(&self, i: Input, points: &[Marker], points3: &[Marker3], beams: &[BeamQuantity], joints: &[JointQuantity]) -> f64 {
        match i {
            Input::Time => self.t,
            Input::Coord(k) => self.q[k],
            Input::Rate(k) => self.qd[k],
            Input::Local(k) => self.local[k],
            Input::Point { k, axis, rate } => {
                let s = points[k].state(self.bodies, self.q, self.qd);
                if rate { s.v[axis] } else { s.r[axis] }
            }
            Input::Point3 { k, axis, rate } => {
                let s = points3[k].state_axes(self.bodies, self.q, self.qd, 0).point;
                if rate { s.vd[axis] } else { s.v[axis] }
            }
            Input::Beam(k) => beams[k].value(self.q, self.qd),
            Input::Joint(k) => joints[k].value(self.bodies, self.q, self.qd),
        }
    }
}

/// The names an element's values may read: the model's coordinates (and their rates) and the
/// element's own quantities.
pub struct Scope<'a> {
    pub coordinate_names: &'a [String],
    pub local: &'a [&'static str],
    /// Where point quantities are resolved (`None`: not available).
    pub ctx: Option<&'a BuildContext<'a>>,
    /// Where the spatial point quantities `x(BODY)`, `z(BODY, [sx, sy, sz])` are resolved
    /// (`value3.rs`; `None`: a planar scene).
    pub spatial: Option<Spatial<'a>>,
}

/// A point quantity `x(BODY, XI)` / `y(...)` (optionally `d:`), parsed from the start of `s`:
/// `(axis, rate, body, xi, length of the text)`.
fn point_quantity(s: &str) -> Option<(usize, bool, String, f64, usize)> {
    let (axis, rate, args, consumed) = super::value3::point_call(s, b"xy")?;
    let (body, xi) = args.split_once(',')?;
    let (body, xi) = (body.trim(), xi.trim().parse::<f64>().ok()?);
    if body.is_empty() || !body.chars().all(|c| c.is_alphanumeric() || "_.:-".contains(c)) {
        return None;
    }
    Some((axis, rate, body.to_string(), xi, consumed))
}

/// An expression's text with its point quantities replaced: the text, the placeholders with
/// their inputs, the planar and the spatial points' markers.
type Substituted = (String, Vec<(String, Input)>, Vec<Marker>, Vec<Marker3>, Vec<BeamQuantity>, Vec<JointQuantity>);

impl Scope<'_> {
    /// `text` with each point quantity replaced by a placeholder variable of the same length
    /// (`_p0_____`), and the points' markers with their inputs, by placeholder.
    fn substitute_points(&self, item: &str, text: &str) -> Result<Substituted> {
        let mut out = String::with_capacity(text.len());
        let (mut found, mut markers): (Vec<(String, Input)>, Vec<Marker>) = (Vec::new(), Vec::new());
        let mut markers3: Vec<Marker3> = Vec::new();
        let mut beams: Vec<BeamQuantity> = Vec::new();
        let mut joints: Vec<JointQuantity> = Vec::new();
        let mut i = 0;
        let bytes = text.as_bytes();
        while i < text.len() {
            // a quantity starts where a name could (not inside one)
            let boundary = i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_' || bytes[i - 1] == b'.' || bytes[i - 1] == b':');
            if let (true, Some(sp)) = (boundary, self.spatial) {
                if let Some((axis, rate, body, point, len)) = super::value3::point_quantity(&text[i..]) {
                    let placeholder = format!("_p{}", found.len());
                    if placeholder.len() <= len {
                        markers3.push(super::value3::marker(item, sp, &body, point)?);
                        found.push((format!("{placeholder:_<len$}"), Input::Point3 { k: markers3.len() - 1, axis, rate }));
                        out.push_str(&found.last().expect("just pushed").0);
                        i += len;
                        continue;
                    }
                }
            } else if boundary {
                if let Some(len) = self.beam_quantity(item, text, i, found.len(), &mut beams)? {
                    found.push((format!("{:_<len$}", format!("_p{}", found.len())), Input::Beam(beams.len() - 1)));
                    out.push_str(&found.last().expect("just pushed").0);
                    i += len;
                    continue;
                }
                if let Some(len) = self.joint_quantity(item, text, i, found.len(), &mut joints)? {
                    found.push((format!("{:_<len$}", format!("_p{}", found.len())), Input::Joint(joints.len() - 1)));
                    out.push_str(&found.last().expect("just pushed").0);
                    i += len;
                    continue;
                }
                if let Some((axis, rate, body, xi, len)) = point_quantity(&text[i..]) {
                    let placeholder = format!("_p{}", found.len());
                    if let (Some(ctx), true) = (self.ctx, placeholder.len() <= len) {
                        let md = MarkerDesc { body: body.clone(), point: None, xi: Some(xi), angle: 0.0 };
                        let md = if ctx.index.get(&body).is_some_and(|&b| ctx.bodies[b].capabilities().beam) { md } else { MarkerDesc { xi: None, point: Some([0.0, 0.0]), ..md } };
                        let m = ctx.marker(item, &md)?;
                        found.push((format!("{placeholder:_<len$}"), Input::Point { k: markers.len(), axis, rate }));
                        markers.push(m);
                        out.push_str(&found.last().expect("just pushed").0);
                        i += len;
                        continue;
                    }
                }
            }
            let c = text[i..].chars().next().expect("in range");
            out.push(c);
            i += c.len_utf8();
        }
        Ok((out, found, markers, markers3, beams, joints))
    }

    /// A joint quantity `angle(J)`, `s(J)` (or its rate) at `text[i..]`, pushed on `joints`:
    /// the length of its text; `None` if there is none (or no room for the placeholder `k`).
    fn joint_quantity(&self, item: &str, text: &str, i: usize, k: usize, joints: &mut Vec<JointQuantity>) -> Result<Option<usize>> {
        let (Some(ctx), Some((what, rate, joint, len))) = (self.ctx, super::value_joint::parse(&text[i..])) else { return Ok(None) };
        if format!("_p{k}").len() > len {
            return Ok(None);
        }
        let err = |message: String| Error::Expression { item: item.to_string(), text: text.to_string(), message, position: i };
        joints.push(JointQuantity::new(ctx, what, rate, joint, &err)?);
        Ok(Some(len))
    }

    /// A beam quantity `u/v/psi(B, XI)` (or its rate) at `text[i..]`, pushed on `beams`: the
    /// length of its text; `None` if there is none (or no room for the placeholder of number
    /// `k`). A sensor that is not an input is refused by name here.
    fn beam_quantity(&self, item: &str, text: &str, i: usize, k: usize, beams: &mut Vec<BeamQuantity>) -> Result<Option<usize>> {
        let err = |message: String| Error::Expression { item: item.to_string(), text: text.to_string(), message, position: i };
        if let Some(m) = super::value_beam::refused_sensor(&text[i..]) {
            return Err(err(m));
        }
        let (Some(ctx), Some((what, rate, body, xi, len))) = (self.ctx, super::value_beam::parse(&text[i..])) else { return Ok(None) };
        if format!("_p{k}").len() > len {
            return Ok(None);
        }
        beams.push(BeamQuantity::new(ctx, item, what, rate, body, xi, &err)?);
        Ok(Some(len))
    }

    fn resolve(&self, name: &str) -> Option<Input> {
        if name == "t" {
            return Some(Input::Time);
        }
        if let Some(k) = self.local.iter().position(|l| *l == name) {
            return Some(Input::Local(k));
        }
        let (rate, coord) = match name.strip_prefix("d:") {
            Some(c) => (true, c),
            None => (false, name),
        };
        let k = self.coordinate_names.iter().position(|c| c == coord)?;
        Some(if rate { Input::Rate(k) } else { Input::Coord(k) })
    }

    /// What the names may be, for messages.
    fn help(&self) -> String {
        let mut s = String::from("t, a coordinate (");
        s += &self.coordinate_names.iter().take(4).cloned().collect::<Vec<_>>().join(", ");
        if self.coordinate_names.len() > 4 {
            s += ", ...";
        }
        s += ") or its rate d:<coordinate>";
        if self.ctx.is_some() {
            s += ", x(BODY, XI), y(BODY, XI) or their rates d:x(...)";
            s += super::value_beam::HELP;
            s += super::value_joint::HELP;
        }
        if self.spatial.is_some() {
            s += super::value3::HELP;
        }
        for l in self.local {
            s += &format!(", {l}");
        }
        s
    }
}

#[derive(Debug, Clone)]
pub struct Expr {
    f: Function,
    inputs: Vec<Input>,
    /// The markers of the point quantities it reads.
    points: Vec<Marker>,
    /// The markers of the spatial point quantities it reads.
    points3: Vec<Marker3>,
    /// The beam quantities it reads.
    beams: Vec<BeamQuantity>,
    /// The joint quantities it reads.
    joints: Vec<JointQuantity>,
}

/// The natural cubic spline of `constraint::motion` (a driver's tabulated motion) through
/// `(x_i, y_i)`, of one input, held at its end values outside `[x_0, x_last]`; with a `period`
/// the input is first wrapped into `[x_0, x_0 + period)`.
#[derive(Debug, Clone)]
pub struct Table {
    input: Input,
    spline: Spline,
    range: [f64; 2],
    period: Option<f64>,
}

impl Table {
    fn new(item: &str, scope: &Scope, d: &TableDesc) -> Result<Table> {
        let input = scope.resolve(&d.of).ok_or_else(|| Error::invalid(item, format!("table: unknown state quantity '{}'; expected {}", d.of, scope.help())))?;
        let spline = Spline::new(item, &d.x, &d.y, None)?;
        let range = [d.x[0], d.x[d.x.len() - 1]];
        if let Some(p) = d.period {
            if !(p.is_finite() && p > 0.0 && p >= range[1] - range[0]) {
                return Err(Error::invalid(item, format!("table: period must be positive and at least the span of x, got {p}")));
            }
        }
        Ok(Table { input, spline, range, period: d.period })
    }

    /// Value and slope at `s`.
    #[inline]
    pub fn eval(&self, s: f64) -> (f64, f64) {
        let [x0, x1] = self.range;
        let s = match self.period {
            Some(p) => x0 + (s - x0).rem_euclid(p),
            None => s,
        };
        if s <= x0 || s >= x1 {
            return (self.spline.eval(s.clamp(x0, x1)).0, 0.0);
        }
        let (v, d, _) = self.spline.eval(s);
        (v, d)
    }
}

/// A function supplied from outside the core (a Python callable, through the bindings, which
/// hold the interpreter only while it runs). It returns NaN when it fails, after recording
/// why (the bindings raise that error when the NaN stops the computation).
pub trait LoadCallback: Send + Sync + std::fmt::Debug {
    /// The value at `t` and the inputs `x` (in the order of the callable's `inputs`).
    fn call(&self, t: f64, x: &[f64]) -> f64;
}

/// A callable value: its name in the description, its inputs, and the function once attached
/// (`Model::attach_callables`).
#[derive(Debug, Clone)]
pub struct Callable {
    pub name: String,
    pub input_names: Vec<String>,
    inputs: Vec<Input>,
    pub f: Option<Arc<dyn LoadCallback>>,
}

impl Callable {
    fn new(item: &str, scope: &Scope, d: &CallableDesc) -> Result<Callable> {
        if d.callable.is_empty() {
            return Err(Error::invalid(item, "callable: the name must be a non-empty string"));
        }
        let inputs = d
            .inputs
            .iter()
            .map(|n| scope.resolve(n).ok_or_else(|| Error::invalid(item, format!("callable '{}': unknown state quantity '{n}'; expected {}", d.callable, scope.help()))))
            .collect::<Result<Vec<_>>>()?;
        Ok(Callable { name: d.callable.clone(), input_names: d.inputs.clone(), inputs, f: None })
    }
}

/// A load's value.
#[derive(Debug, Clone)]
pub enum Value {
    Const(f64),
    Expr(Box<Expr>),
    Table(Box<Table>),
    Callable(Box<Callable>),
}

impl Value {
    /// Build from the description; `what` names the value in errors (`fx`, `torque`).
    pub fn new(item: &str, what: &str, scope: &Scope, d: &LoadValueDesc) -> Result<Value> {
        match d {
            LoadValueDesc::Number(v) => {
                check_finite_item(item, what, &[*v])?;
                Ok(Value::Const(*v))
            }
            LoadValueDesc::Expression(text) => {
                let (parsed, points, markers, markers3, beams, joints) = scope.substitute_points(item, text)?;
                let mut names: Vec<String> = vec!["t".into()];
                names.extend(scope.local.iter().map(|s| s.to_string()));
                names.extend(scope.coordinate_names.iter().cloned());
                names.extend(scope.coordinate_names.iter().map(|c| format!("d:{c}")));
                names.extend(points.iter().map(|(p, _)| p.clone()));
                // a name an expression cannot spell (a beam node's `bar[3].x`) is left to the
                // tables and callables, which name their input as a string
                let refs: Vec<&str> = names.iter().map(String::as_str).filter(|n| crate::expr::is_variable_name(n)).collect();
                let f = Function::parse_used(&parsed, &refs).map_err(|e| expression_error(item, what, text, scope, e))?;
                let inputs = f
                    .vars()
                    .iter()
                    .map(|v| points.iter().find(|(p, _)| p == v).map(|(_, i)| *i).or_else(|| scope.resolve(v)).expect("a candidate name"))
                    .collect();
                Ok(Value::Expr(Box::new(Expr { f, inputs, points: markers, points3: markers3, beams, joints })))
            }
            LoadValueDesc::Table(t) => Ok(Value::Table(Box::new(Table::new(item, scope, t)?))),
            LoadValueDesc::Callable(c) => Ok(Value::Callable(Box::new(Callable::new(item, scope, c)?))),
        }
    }

    /// Scratch this value needs to evaluate (with its gradient: [`Value::add_position_gradient`]).
    pub fn scratch_len(&self) -> usize {
        match self {
            Value::Expr(e) => 2 * e.inputs.len() + e.f.scratch_len(),
            Value::Callable(c) => c.inputs.len(),
            _ => 0,
        }
    }

    /// Whether the value depends on the positions through a known derivative (an expression
    /// or a table; a callable's derivative is unknown: the differences of the Jacobian see it).
    pub fn has_gradient(&self) -> bool {
        matches!(self, Value::Expr(_) | Value::Table(_))
    }

    /// `row += dF/dq` (row spans `q`) through the positions the value reads (coordinates and
    /// points), from the expression's symbolic gradient or the table's slope; returns
    /// `dF/d local` (the element's own quantities: a motor adds `dF/d angle` itself). The rates'
    /// derivatives are not here (the velocity Jacobian differences them exactly), but for a
    /// spatial point's velocity, which changes with the positions as well (`value3::rate_kin`;
    /// a planar point's `d:x(BODY, XI)` does too, and that is left out).
    pub fn add_position_gradient(&self, env: &Env, scratch: &mut [f64], row: &mut [f64]) -> [f64; 2] {
        let mut local = [0.0; 2];
        let mut put = |i: Input, g: f64, points: &[Marker], points3: &[Marker3], beams: &[BeamQuantity], joints: &[JointQuantity], row: &mut [f64]| match i {
            Input::Coord(j) => row[j] += g,
            Input::Point { k, axis, rate: false } => {
                let s = points[k].state(env.bodies, env.q, env.qd);
                let mut w = [0.0; 2];
                w[axis] = g;
                points[k].add_point_jacobian(env.bodies, &s, w, row);
            }
            Input::Point3 { k, axis, rate } => {
                let s = points3[k].state_axes(env.bodies, env.q, env.qd, 0);
                let mut w = [0.0; 3];
                w[axis] = g;
                // a velocity changes with the positions too (`value3::rate_kin`)
                let kin = if rate { super::value3::rate_kin(&points3[k], env.bodies, env.qd, &points3[k].s) } else { s.point };
                add_jacobian(env.bodies, &s, &kin, &w, row, None);
            }
            Input::Local(k) => local[k] += g,
            Input::Beam(k) => beams[k].add_gradient(env.q, env.qd, g, row),
            Input::Joint(k) => joints[k].add_gradient(env.bodies, env.q, env.qd, g, row),
            _ => {}
        };
        match self {
            Value::Expr(e) => {
                let k = e.inputs.len();
                let (x, rest) = scratch.split_at_mut(k);
                let (grad, buf) = rest.split_at_mut(k);
                for (xi, &i) in x.iter_mut().zip(&e.inputs) {
                    *xi = env.get(i, &e.points, &e.points3, &e.beams, &e.joints);
                }
                e.f.eval_gradient(x, buf, grad);
                for (&i, &g) in e.inputs.iter().zip(grad.iter()) {
                    put(i, g, &e.points, &e.points3, &e.beams, &e.joints, row);
                }
            }
            Value::Table(t) => {
                let (_, slope) = t.eval(env.get(t.input, &[], &[], &[], &[]));
                put(t.input, slope, &[], &[], &[], &[], row);
            }
            _ => {}
        }
        local
    }

    /// Whether the value has a gradient and reads coordinates (or their rates) or points: the
    /// spatial loads' `add_stiffness` has something to add (a value of `t` alone adds nothing).
    pub fn reads_positions(&self) -> bool {
        self.has_gradient() && !(self.coords().is_empty() && self.points().is_empty())
    }

    /// The coordinates (positions or rates) the value reads.
    pub fn coords(&self) -> Vec<usize> {
        let of = |i: &Input| match i {
            Input::Coord(k) | Input::Rate(k) => Some(*k),
            _ => None,
        };
        match self {
            Value::Const(_) => Vec::new(),
            Value::Expr(e) => e.inputs.iter().filter_map(of).chain(e.beams.iter().flat_map(BeamQuantity::coords)).collect(),
            Value::Table(t) => of(&t.input).into_iter().collect(),
            Value::Callable(c) => c.inputs.iter().filter_map(of).collect(),
        }
    }

    /// The markers of the point quantities the value reads (a spatial point's: its `base`).
    pub fn points(&self) -> Vec<&Marker> {
        match self {
            Value::Expr(e) => e.points.iter().chain(e.points3.iter().map(|m| &m.base)).chain(e.joints.iter().flat_map(JointQuantity::markers)).collect(),
            _ => Vec::new(),
        }
    }

    /// An expression of `t` alone: the times in `(lo, hi)` of its kinks and jumps
    /// (`Function::time_switches`); none for any other value.
    pub fn time_switches(&self, lo: f64, hi: f64, samples: usize) -> Vec<f64> {
        match self {
            Value::Expr(e) => e.f.time_switches(lo, hi, samples),
            _ => Vec::new(),
        }
    }

    /// Whether the value is a constant.
    pub fn is_const(&self) -> bool {
        matches!(self, Value::Const(_))
    }

    /// The value at `env`; `scratch` at least [`Value::scratch_len`].
    #[inline]
    pub fn eval(&self, env: &Env, scratch: &mut [f64]) -> f64 {
        match self {
            Value::Const(v) => *v,
            Value::Expr(e) => {
                let (x, buf) = scratch.split_at_mut(e.inputs.len());
                for (xi, &i) in x.iter_mut().zip(&e.inputs) {
                    *xi = env.get(i, &e.points, &e.points3, &e.beams, &e.joints);
                }
                e.f.eval(x, buf)
            }
            Value::Table(tb) => tb.eval(env.get(tb.input, &[], &[], &[], &[])).0,
            Value::Callable(c) => {
                let x = &mut scratch[..c.inputs.len()];
                for (xi, &i) in x.iter_mut().zip(&c.inputs) {
                    *xi = env.get(i, &[], &[], &[], &[]);
                }
                c.f.as_ref().map_or(f64::NAN, |f| f.call(env.t, x))
            }
        }
    }
}

/// A parse error of a load's expression as the named `ExpressionError`; an unknown variable
/// is an unknown state quantity.
fn expression_error(item: &str, what: &str, text: &str, scope: &Scope, e: ParseError) -> Error {
    let message = match e.message.strip_prefix("unknown name '").and_then(|r| r.split_once('\'')) {
        Some((name, _)) => format!("unknown state quantity '{name}' in {what}; expected {}, pi, e or a function", scope.help()),
        None => format!("{what}: {}", e.message),
    };
    Error::Expression { item: item.to_string(), text: text.to_string(), message, position: e.position }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_reproduces_cubic_data_and_slopes() {
        // a natural spline through a straight line is that line; through a parabola it is close
        let scope = Scope { coordinate_names: &["a.x".to_string()], local: &[], ctx: None, spatial: None };
        let d = TableDesc { of: "a.x".into(), x: vec![0.0, 1.0, 2.5, 4.0], y: vec![1.0, 3.0, 6.0, 9.0], period: None };
        let t = Table::new("t", &scope, &d).unwrap();
        for s in [0.3, 1.7, 3.9] {
            let (v, dv) = t.eval(s);
            assert!((v - (1.0 + 2.0 * s)).abs() < 1e-14 && (dv - 2.0).abs() < 1e-14, "{v} {dv}");
        }
        assert_eq!(t.eval(-1.0), (1.0, 0.0));
        assert_eq!(t.eval(5.0), (9.0, 0.0));
        let d = TableDesc { of: "t".into(), x: vec![0.0, 1.0, 2.0], y: vec![0.0, 1.0, 0.0], period: Some(2.0) };
        let t = Table::new("t", &scope, &d).unwrap();
        assert!((t.eval(2.5).0 - t.eval(0.5).0).abs() < 1e-15);
        assert!((t.eval(-1.5).0 - t.eval(0.5).0).abs() < 1e-15);
        // the slope against a central difference
        let (h, s) = (1e-6, 0.7);
        assert!(((t.eval(s + h).0 - t.eval(s - h).0) / (2.0 * h) - t.eval(s).1).abs() < 1e-8);
    }

    #[test]
    fn unknown_quantity_is_named() {
        let names = ["crank.theta".to_string()];
        let scope = Scope { coordinate_names: &names, local: &["w"], ctx: None, spatial: None };
        let v = Value::new("force 'f'", "torque", &scope, &LoadValueDesc::Expression("2*w + sin(crank.theta) + d:crank.theta".into())).unwrap();
        let env = Env { bodies: &[], t: 0.0, q: &[0.5], qd: &[3.0], local: [7.0, 0.0] };
        let mut s = vec![0.0; v.scratch_len()];
        assert!((v.eval(&env, &mut s) - (14.0 + 0.5f64.sin() + 3.0)).abs() < 1e-15);
        match Value::new("force 'f'", "torque", &scope, &LoadValueDesc::Expression("2*crank.omega".into())) {
            Err(Error::Expression { message, position, .. }) => {
                assert!(message.contains("unknown state quantity 'crank.omega'"), "{message}");
                assert_eq!(position, 2);
            }
            other => panic!("{other:?}"),
        }
    }
}
