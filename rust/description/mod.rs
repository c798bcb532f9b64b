//! Scene description: plain data, parsed from the JSON-compatible dict documented in
//! `docs/scene-format.md`. Validation happens in `model::ModelBuilder` (each kind's
//! `from_desc`), not here.
//!
//! In the description a tagged object carries its variant inside: `{"kind": "revolute", "a":
//! ..}`, `{"shape": "circular", "diameter": ..}`. The Rust types use serde's external tagging
//! (`{"revolute": {"a": ..}}`), into which `to_external` turns the description before parsing:
//! that keeps the path of every field in error messages (serde loses it inside internally
//! tagged enums). `to_internal` turns it back.

pub mod spatial;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

/// Keys that name the variant of a tagged object.
const TAGS: [&str; 2] = ["kind", "shape"];

/// `{"kind": k, rest..}` -> `{k: {rest..}}`, recursively (see the module docs).
pub fn to_external(v: Value) -> Value {
    match v {
        Value::Object(map) => {
            let mut map: Map<String, Value> = map.into_iter().map(|(k, v)| (k, to_external(v))).collect();
            for tag in TAGS {
                if let Some(Value::String(variant)) = map.get(tag).cloned() {
                    map.remove(tag);
                    let mut outer = Map::new();
                    outer.insert(variant, Value::Object(map));
                    return Value::Object(outer);
                }
            }
            Value::Object(map)
        }
        Value::Array(a) => Value::Array(a.into_iter().map(to_external).collect()),
        other => other,
    }
}

/// The inverse of `to_external` for serialized descriptions: a one-key object whose value is
/// an object, at a place where `is_tagged` says an enum stands, becomes `{tag: key, ..}`.
pub fn to_internal(v: Value, tag: &str) -> Value {
    match v {
        Value::Object(map) if map.len() == 1 => {
            let (variant, inner) = map.into_iter().next().expect("one entry");
            match inner {
                Value::Object(fields) => {
                    let mut out = Map::new();
                    out.insert(tag.to_string(), Value::String(variant));
                    for (k, v) in fields {
                        out.insert(k.clone(), internal_field(&k, v));
                    }
                    Value::Object(out)
                }
                // unit variants serialize as plain strings; other shapes do not occur
                other => {
                    let mut out = Map::new();
                    out.insert(variant, other);
                    Value::Object(out)
                }
            }
        }
        other => other,
    }
}

/// Fields that hold tagged enums inside an item: `section` (by `shape`), `motion` (by `kind`).
fn internal_field(key: &str, v: Value) -> Value {
    match key {
        "section" => to_internal(v, "shape"),
        "motion" => to_internal(v, "kind"),
        _ => v,
    }
}

pub type Vec2 = [f64; 2];

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Description {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<Vec2>,
    pub bodies: Vec<BodyDesc>,
    #[serde(default)]
    pub joints: Vec<JointDesc>,
    #[serde(default)]
    pub drivers: Vec<DriverDesc>,
    #[serde(default)]
    pub forces: Vec<ForceDesc>,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyDesc {
    Rigid(RigidDesc),
    Beam(BeamDesc),
    PointMass(PointMassDesc),
    Flexible(FlexibleDesc),
    Cable(CableDesc),
}

impl BodyDesc {
    pub fn name(&self) -> &str {
        match self {
            BodyDesc::Rigid(r) => &r.name,
            BodyDesc::Beam(b) => &b.name,
            BodyDesc::PointMass(p) => &p.name,
            BodyDesc::Flexible(f) => &f.name,
            BodyDesc::Cable(c) => &c.name,
        }
    }

    /// The `kind` tag as written in the description.
    pub fn kind(&self) -> &'static str {
        match self {
            BodyDesc::Rigid(_) => "rigid",
            BodyDesc::Beam(_) => "beam",
            BodyDesc::PointMass(_) => "point_mass",
            BodyDesc::Flexible(_) => "flexible",
            BodyDesc::Cable(_) => "cable",
        }
    }
}

/// A general planar FFRF body given by its inertia invariants and elastic matrices (body frame,
/// `n_f` elastic coordinates; `rust/body/flexible.rs`, docs/flexible-bodies.md). Matrices are lists
/// of rows.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FlexibleDesc {
    pub name: String,
    pub mass: f64,
    /// Moment of inertia of the undeformed body about its centre of mass.
    pub inertia: f64,
    /// Centre of mass of the undeformed body in the body frame.
    #[serde(default)]
    pub com: Vec2,
    /// `S_bar = int rho S dV` (2 x n_f).
    pub s_bar: Vec<Vec<f64>>,
    /// `int rho S^T u0 dV` (n_f).
    pub s_u0: Vec<f64>,
    /// `int rho S^T J u0 dV` (n_f), `J` the +90 deg turn (plus any rotary part).
    pub s_ju0: Vec<f64>,
    /// `S_tilde = int rho S^T I~ S dV` (n_f x n_f, antisymmetric): `S_u,i S_v,j - S_v,i S_u,j`.
    pub s_tilde: Vec<Vec<f64>>,
    /// Elastic mass block `M_ff` (n_f x n_f, symmetric positive definite).
    pub m_ff: Vec<Vec<f64>>,
    /// `int rho S^T S dV`, the part of `M_ff` in `m_thetatheta` and the centrifugal forces
    /// (default `M_ff`; differs from it by rotary inertia).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub m_ff_tr: Option<Vec<Vec<f64>>>,
    /// Stiffness `K_ff` (n_f x n_f, symmetric positive definite: no rigid-body modes).
    pub k_ff: Vec<Vec<f64>>,
    /// Damping `D_ff` (n_f x n_f, symmetric positive semi-definite).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d_ff: Option<Vec<Vec<f64>>>,
    /// Default linear; `nonlinear` adds the strain energy `k3 q q q / 6 (+ k4 q q q q / 24)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strain: Option<Strain>,
    /// Third-order stiffness tensor (n_f^3, row-major, symmetric), with `strain = nonlinear`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k3: Option<Vec<f64>>,
    /// Fourth-order stiffness tensor (n_f^4, row-major, symmetric), optional.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k4: Option<Vec<f64>>,
    /// Interface points: markers on this body are given by one of these points.
    pub markers: Vec<FlexibleMarkerDesc>,
    #[serde(default)]
    pub position: Vec2,
    #[serde(default)]
    pub angle: f64,
    #[serde(default)]
    pub velocity: Vec2,
    #[serde(default)]
    pub angular_velocity: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic_rates: Option<Vec<f64>>,
}

/// An interface point of a flexible body: undeformed position, the rows of its displacement
/// `u = D q_f` (2 x n_f) and, optionally, of its rotation `psi = r . q_f` (n_f).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FlexibleMarkerDesc {
    pub name: String,
    pub point: Vec2,
    pub displacement: Vec<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<Vec<f64>>,
}

/// A particle: coordinates `(x, y)`, no orientation.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PointMassDesc {
    pub name: String,
    pub mass: f64,
    #[serde(default)]
    pub position: Vec2,
    #[serde(default)]
    pub velocity: Vec2,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RigidDesc {
    pub name: String,
    pub mass: f64,
    /// Moment of inertia about the centre of mass.
    pub inertia: f64,
    /// Centre of mass in the body frame.
    #[serde(default)]
    pub com: Vec2,
    #[serde(default)]
    pub position: Vec2,
    #[serde(default)]
    pub angle: f64,
    #[serde(default)]
    pub velocity: Vec2,
    #[serde(default)]
    pub angular_velocity: f64,
}

/// Beam theory of an FFRF beam. Default: Timoshenko (shear deformation and rotary inertia: the
/// paper's coupler).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BeamTheory {
    #[default]
    Timoshenko,
    EulerBernoulli,
}

/// Strain measure of a beam's elastic forces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strain {
    /// Linear strain (the paper): no coupling of axial force and bending.
    Linear,
    /// Second-order axial strain `u' + v'^2 / 2` averaged over each element (a constant axial
    /// force per element): geometric stiffening/softening and foreshortening.
    #[default]
    Nonlinear,
}

/// The floating frame of an FFRF body: which elastic motions the frame takes out (reference
/// conditions, not a boundary condition). One vocabulary for every FFRF kind: a beam takes
/// `pinned-pinned` (default) or `clamped`; a modal body from FE data (`ukflex.fe`) takes these
/// two on its first interfaces, `mean-axis`, or three explicit reference conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReferenceConditions {
    /// The chord frame: the first point fixed in x and y, the second's displacement across the
    /// chord zero (a beam: u_1 = v_1 = 0, v_{N+1} = 0; the paper's choice).
    #[default]
    PinnedPinned,
    /// The first point fixed in x, y and rotation (a beam: u_1 = v_1 = psi_1 = 0).
    Clamped,
    /// Free-free modes without the rigid-body modes (Buckens' mean axes, linearized).
    MeanAxis,
}

impl ReferenceConditions {
    /// Every option, in the order the documentation lists them.
    pub const ALL: [ReferenceConditions; 3] = [Self::PinnedPinned, Self::Clamped, Self::MeanAxis];

    /// The option's word in scene descriptions (its serde name).
    pub fn word(self) -> String {
        match serde_json::to_value(self) {
            Ok(serde_json::Value::String(s)) => s,
            _ => String::new(),
        }
    }
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum SectionDesc {
    Circular { diameter: f64 },
    /// `height` lies in the bending plane.
    Rectangular { width: f64, height: f64 },
    Custom { area: f64, second_moment: f64 },
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BeamDesc {
    pub name: String,
    pub length: f64,
    #[serde(default = "one")]
    pub elements: usize,
    #[serde(default)]
    pub theory: BeamTheory,
    /// Default: nonlinear (the physically right answer at speed).
    #[serde(default)]
    pub strain: Strain,
    pub density: f64,
    pub youngs_modulus: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_modulus: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_factor: Option<f64>,
    pub section: SectionDesc,
    #[serde(default)]
    pub frame: ReferenceConditions,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotary_inertia: Option<bool>,
    #[serde(default)]
    pub damping: f64,
    #[serde(default)]
    pub position: Vec2,
    #[serde(default)]
    pub angle: f64,
    #[serde(default)]
    pub velocity: Vec2,
    #[serde(default)]
    pub angular_velocity: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic_rates: Option<Vec<f64>>,
}

/// A geometrically exact planar cable: ANCF elements (absolute positions and slopes of its
/// nodes; `rust/body/ancf_cable.rs`), Euler-Bernoulli, no floating frame, exact strain. It
/// starts straight and undeformed at `position` (its `xi = 0` end) and `angle`, moving rigidly
/// with `velocity` (of that end) and `angular_velocity`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CableDesc {
    pub name: String,
    pub length: f64,
    #[serde(default = "one")]
    pub elements: usize,
    pub density: f64,
    pub youngs_modulus: f64,
    pub section: SectionDesc,
    /// Stiffness-proportional (Kelvin-Voigt) damping time constant [s].
    #[serde(default)]
    pub damping: f64,
    #[serde(default)]
    pub position: Vec2,
    #[serde(default)]
    pub angle: f64,
    #[serde(default)]
    pub velocity: Vec2,
    #[serde(default)]
    pub angular_velocity: f64,
}

fn one() -> usize {
    1
}

/// A point and a frame on a body (or on the ground).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerDesc {
    pub body: String,
    /// Point in the body frame (rigid bodies and ground).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<Vec2>,
    /// Abscissa along a beam, in [0, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub xi: Option<f64>,
    /// Orientation of the marker frame relative to the body frame.
    #[serde(default)]
    pub angle: f64,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum JointDesc {
    Revolute { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, a: MarkerDesc, b: MarkerDesc },
    PointOnLine { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, point: MarkerDesc, line: MarkerDesc },
    Prismatic { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, a: MarkerDesc, b: MarkerDesc },
    Weld { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, a: MarkerDesc, b: MarkerDesc },
    /// `|r_a - r_b| = length` (a massless rod); `length` defaults to the distance at the
    /// initial guess.
    Distance { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, a: MarkerDesc, b: MarkerDesc, #[serde(default, skip_serializing_if = "Option::is_none")] length: Option<f64> },
}

impl JointDesc {
    pub fn kind(&self) -> &'static str {
        match self {
            JointDesc::Revolute { .. } => "revolute",
            JointDesc::PointOnLine { .. } => "point_on_line",
            JointDesc::Prismatic { .. } => "prismatic",
            JointDesc::Weld { .. } => "weld",
            JointDesc::Distance { .. } => "distance",
        }
    }

    pub fn name(&self) -> Option<&str> {
        match self {
            JointDesc::Revolute { name, .. }
            | JointDesc::PointOnLine { name, .. }
            | JointDesc::Prismatic { name, .. }
            | JointDesc::Weld { name, .. }
            | JointDesc::Distance { name, .. } => name.as_deref(),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum MotionDesc {
    ConstantSpeed { #[serde(default)] initial: f64, speed: f64 },
    Polynomial { coefficients: Vec<f64> },
    Harmonic { #[serde(default)] offset: f64, amplitude: f64, frequency: f64, #[serde(default)] phase: f64 },
    /// `f(t)` written as an expression of `t` (`rust/constraint/expr.rs`).
    Expression { expression: String },
    /// A C2 cubic spline through `(times, values)`; natural ends unless `slopes = [f'(t0), f'(tn)]`.
    Spline { times: Vec<f64>, values: Vec<f64>, #[serde(default, skip_serializing_if = "Option::is_none")] slopes: Option<[f64; 2]> },
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum DriverDesc {
    Angle { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, a: MarkerDesc, #[serde(default, skip_serializing_if = "Option::is_none")] b: Option<MarkerDesc>, motion: MotionDesc },
    Coordinate { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, point: MarkerDesc, axis: Axis, motion: MotionDesc },
}

impl DriverDesc {
    pub fn kind(&self) -> &'static str {
        match self {
            DriverDesc::Angle { .. } => "angle",
            DriverDesc::Coordinate { .. } => "coordinate",
        }
    }

    pub fn name(&self) -> Option<&str> {
        match self {
            DriverDesc::Angle { name, .. } | DriverDesc::Coordinate { name, .. } => name.as_deref(),
        }
    }
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ForceDesc {
    PointForce { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, point: MarkerDesc, force: Vec2 },
    Torque { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, frame: MarkerDesc, torque: f64 },
    SpringDamper {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        a: MarkerDesc,
        b: MarkerDesc,
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        /// Default: the distance between the markers at the initial guess (unloaded start).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rest_length: Option<f64>,
    },
    /// A force at a marker whose world components are functions (docs/loads.md).
    PointLoad {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        point: MarkerDesc,
        #[serde(default)]
        fx: LoadValueDesc,
        #[serde(default)]
        fy: LoadValueDesc,
    },
    /// A torque on a marker frame that is a function.
    TorqueLoad { #[serde(default, skip_serializing_if = "Option::is_none")] name: Option<String>, frame: MarkerDesc, torque: LoadValueDesc },
    /// A torque `tau` between two marker frames (`+tau` on `a`, `-tau` on `b`, the ground
    /// when absent), a function of their relative angle `angle` and rate `w`; the rotor's
    /// inertia is added to `a`'s body.
    Motor {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        a: MarkerDesc,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        b: Option<MarkerDesc>,
        torque: LoadValueDesc,
        #[serde(default)]
        rotor_inertia: f64,
    },
    /// `tau = -k (angle - rest_angle) - c w` between two marker frames (`b`: the ground when
    /// absent); with `k = 0` the viscous friction of a hinge.
    RotationalSpringDamper {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        a: MarkerDesc,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        b: Option<MarkerDesc>,
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        /// Default: the relative angle at the initial guess.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rest_angle: Option<f64>,
    },
    /// Regularized Coulomb and viscous friction in a planar revolute or prismatic joint,
    /// from the joint's reaction (`force/friction.rs`, docs/loads.md).
    JointFriction {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        /// The name of the revolute or prismatic joint.
        joint: String,
        /// Coulomb friction coefficient.
        mu: f64,
        /// Pin radius of a revolute joint (the friction torque's lever).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        radius: Option<f64>,
        /// Slider length of a prismatic joint (its reaction moment adds normal force); absent:
        /// the moment is left out.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        length: Option<f64>,
        /// Viscous coefficient (N s/m or N m s/rad).
        #[serde(default)]
        damping: f64,
        /// Regularization speed (m/s or rad/s); default `force::friction::DEFAULT_V_EPS`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        v_eps: Option<f64>,
    },
    /// Linear stiffness and damping in x, y (in `b`'s frame) and the angle between two markers.
    Bushing {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        a: MarkerDesc,
        b: MarkerDesc,
        stiffness: [f64; 3],
        #[serde(default)]
        damping: [f64; 3],
    },
    /// A revolute joint with clearance: a journal inside a bearing, contact by a dissipative
    /// Hertz law with Coulomb friction, no constraint rows (docs/loads.md).
    RevoluteClearance {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        journal: MarkerDesc,
        bearing: MarkerDesc,
        /// Radial clearance `R_B - R_J` [m].
        clearance: f64,
        journal_radius: f64,
        /// `K` of `K delta^exponent` [N/m^exponent].
        stiffness: f64,
        #[serde(default = "hertz_exponent")]
        exponent: f64,
        restitution: f64,
        /// The impact velocity at which the law's restitution is `restitution` [m/s].
        impact_velocity: f64,
        #[serde(default)]
        law: ClearanceLaw,
        #[serde(default)]
        friction: f64,
        /// `[v1, v2]` of the modified Coulomb law: no friction below `v1`, full above `v2`.
        #[serde(default = "clearance_friction_velocities")]
        friction_velocities: [f64; 2],
    },
}

/// The hysteresis factor of a clearance joint's normal law (docs/loads.md).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ClearanceLaw {
    /// `D = 3 (1 - c_e^2) / (4 v_0)`.
    #[default]
    LankaraniNikravesh,
    /// `D = 8 (1 - c_e) / (5 c_e v_0)`.
    Flores,
}

fn hertz_exponent() -> f64 {
    1.5
}

/// Ambrosio's transition velocities of the modified Coulomb law (as used by Flores et al.).
fn clearance_friction_velocities() -> [f64; 2] {
    [1e-4, 1e-3]
}

/// A load's value: a number, an expression of `t` and state quantities, a table, or a
/// callable's reference (read by its shape, with messages that say which was meant).
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum LoadValueDesc {
    Number(f64),
    Expression(String),
    Table(TableDesc),
    Callable(CallableDesc),
}

impl<'de> Deserialize<'de> for LoadValueDesc {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error as _;
        let v = Value::deserialize(d)?;
        let msg = |e: serde_json::Error| e.to_string().replace('`', "'");
        match v {
            Value::Number(n) => n.as_f64().map(LoadValueDesc::Number).ok_or_else(|| D::Error::custom("expected a finite number")),
            Value::String(s) => Ok(LoadValueDesc::Expression(s)),
            Value::Object(ref m) if m.contains_key("callable") => {
                serde_json::from_value(v).map(LoadValueDesc::Callable).map_err(|e| D::Error::custom(format!("callable: {}", msg(e))))
            }
            Value::Object(_) => serde_json::from_value(v).map(LoadValueDesc::Table).map_err(|e| D::Error::custom(format!("table {{of, x, y, period}}: {}", msg(e)))),
            other => Err(D::Error::custom(format!("expected a number, an expression string, a table {{of, x, y, period}} or a callable, got {other}"))),
        }
    }
}

/// A Python callable `f(t, state)` given to `System` under the name `callable`; `state` is a
/// dict of the quantities `inputs` (docs/loads.md).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CallableDesc {
    pub callable: String,
    #[serde(default)]
    pub inputs: Vec<String>,
}

impl Default for LoadValueDesc {
    fn default() -> Self {
        LoadValueDesc::Number(0.0)
    }
}

/// A cubic spline of one state quantity `of` through `(x, y)`; `period` wraps `of`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TableDesc {
    pub of: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
}

impl ForceDesc {
    pub fn kind(&self) -> &'static str {
        match self {
            ForceDesc::PointForce { .. } => "point_force",
            ForceDesc::Torque { .. } => "torque",
            ForceDesc::SpringDamper { .. } => "spring_damper",
            ForceDesc::PointLoad { .. } => "point_load",
            ForceDesc::TorqueLoad { .. } => "torque_load",
            ForceDesc::Motor { .. } => "motor",
            ForceDesc::RotationalSpringDamper { .. } => "rotational_spring_damper",
            ForceDesc::Bushing { .. } => "bushing",
            ForceDesc::RevoluteClearance { .. } => "revolute_clearance",
            ForceDesc::JointFriction { .. } => "joint_friction",
        }
    }

    pub fn name(&self) -> Option<&str> {
        match self {
            ForceDesc::PointForce { name, .. }
            | ForceDesc::Torque { name, .. }
            | ForceDesc::SpringDamper { name, .. }
            | ForceDesc::PointLoad { name, .. }
            | ForceDesc::TorqueLoad { name, .. }
            | ForceDesc::Motor { name, .. }
            | ForceDesc::RotationalSpringDamper { name, .. }
            | ForceDesc::Bushing { name, .. }
            | ForceDesc::RevoluteClearance { name, .. }
            | ForceDesc::JointFriction { name, .. } => name.as_deref(),
        }
    }
}

impl Description {
    pub fn from_json(text: &str) -> crate::error::Result<Self> {
        let v: Value = serde_json::from_str(text).map_err(|e| crate::error::Error::Description(e.to_string()))?;
        serde_json::from_value(to_external(v)).map_err(|e| crate::error::Error::Description(e.to_string()))
    }
}
