//! Scene description: plain data, parsed from the JSON-compatible dict documented in
//! `docs/scene-format.md`. Validation happens in `Model::new`, not here.

use serde::Deserialize;

pub type Vec2 = [f64; 2];

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Description {
    #[serde(default)]
    pub gravity: Option<Vec2>,
    pub bodies: Vec<BodyDesc>,
    #[serde(default)]
    pub joints: Vec<JointDesc>,
    #[serde(default)]
    pub drivers: Vec<DriverDesc>,
    #[serde(default)]
    pub forces: Vec<ForceDesc>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum BodyDesc {
    Rigid(RigidDesc),
    Beam(BeamDesc),
}

impl BodyDesc {
    pub fn name(&self) -> &str {
        match self {
            BodyDesc::Rigid(r) => &r.name,
            BodyDesc::Beam(b) => &b.name,
        }
    }
}

#[derive(Debug, Clone, Deserialize)]
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

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BeamTheory {
    Timoshenko,
    EulerBernoulli,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReferenceConditions {
    /// u_1 = v_1 = 0, v_{N+1} = 0 (the paper's choice).
    PinnedPinned,
    /// u_1 = v_1 = psi_1 = 0 (cantilever frame).
    Clamped,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum SectionDesc {
    Circular { diameter: f64 },
    /// `height` lies in the bending plane.
    Rectangular { width: f64, height: f64 },
    Custom { area: f64, second_moment: f64 },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeamDesc {
    pub name: String,
    pub length: f64,
    #[serde(default = "one")]
    pub elements: usize,
    pub theory: BeamTheory,
    pub density: f64,
    pub youngs_modulus: f64,
    #[serde(default)]
    pub poisson_ratio: Option<f64>,
    #[serde(default)]
    pub shear_modulus: Option<f64>,
    #[serde(default)]
    pub shear_factor: Option<f64>,
    pub section: SectionDesc,
    pub frame: ReferenceConditions,
    #[serde(default)]
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
    #[serde(default)]
    pub elastic: Option<Vec<f64>>,
    #[serde(default)]
    pub elastic_rates: Option<Vec<f64>>,
}

fn one() -> usize {
    1
}

/// A point and a frame on a body (or on the ground).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerDesc {
    pub body: String,
    /// Point in the body frame (rigid bodies and ground).
    #[serde(default)]
    pub point: Option<Vec2>,
    /// Abscissa along a beam, in [0, 1].
    #[serde(default)]
    pub xi: Option<f64>,
    /// Orientation of the marker frame relative to the body frame.
    #[serde(default)]
    pub angle: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum JointDesc {
    Revolute { #[serde(default)] name: Option<String>, a: MarkerDesc, b: MarkerDesc },
    PointOnLine { #[serde(default)] name: Option<String>, point: MarkerDesc, line: MarkerDesc },
    Prismatic { #[serde(default)] name: Option<String>, a: MarkerDesc, b: MarkerDesc },
    Weld { #[serde(default)] name: Option<String>, a: MarkerDesc, b: MarkerDesc },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum MotionDesc {
    ConstantSpeed { #[serde(default)] initial: f64, speed: f64 },
    Polynomial { coefficients: Vec<f64> },
    Harmonic { #[serde(default)] offset: f64, amplitude: f64, frequency: f64, #[serde(default)] phase: f64 },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum DriverDesc {
    Angle { #[serde(default)] name: Option<String>, a: MarkerDesc, #[serde(default)] b: Option<MarkerDesc>, motion: MotionDesc },
    Coordinate { #[serde(default)] name: Option<String>, point: MarkerDesc, axis: Axis, motion: MotionDesc },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ForceDesc {
    PointForce { #[serde(default)] name: Option<String>, point: MarkerDesc, force: Vec2 },
    Torque { #[serde(default)] name: Option<String>, frame: MarkerDesc, torque: f64 },
    SpringDamper {
        #[serde(default)]
        name: Option<String>,
        a: MarkerDesc,
        b: MarkerDesc,
        stiffness: f64,
        #[serde(default)]
        damping: f64,
        rest_length: f64,
    },
}

impl Description {
    pub fn from_json(text: &str) -> crate::error::Result<Self> {
        serde_json::from_str(text).map_err(|e| crate::error::Error::Description(e.to_string()))
    }
}
