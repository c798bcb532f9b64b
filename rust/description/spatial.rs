//! The description of a spatial scene (`"dim": 3`, docs/spatial.md): plain data parsed from the
//! JSON dict, as `description/mod.rs` is for planar scenes. Validation happens when the model is
//! built (`model::spatial`, each kind's `from_desc`), not here.

use serde::{Deserialize, Serialize};

use crate::description::{LoadValueDesc, MotionDesc};

pub type Vec3 = [f64; 3];

/// Orientation of a rigid body: a unit quaternion `[e0, e1, e2, e3]` (scalar first) or a
/// rotation matrix (rows; body -> world).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(untagged)]
pub enum OrientationDesc {
    Quaternion([f64; 4]),
    Matrix([[f64; 3]; 3]),
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Body3Desc {
    Rigid3(Rigid3Desc),
    Point3(Point3Desc),
    Flexible3(Flexible3Desc),
    Beam3(Beam3Desc),
}

impl Body3Desc {
    pub fn name(&self) -> &str {
        match self {
            Body3Desc::Rigid3(r) => &r.name,
            Body3Desc::Point3(p) => &p.name,
            Body3Desc::Flexible3(f) => &f.name,
            Body3Desc::Beam3(b) => &b.name,
        }
    }
}

/// A rigid body: coordinates `[r (3), p (4)]`, `r` its centre of mass (world), `p` the Euler
/// parameters of its body frame.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Rigid3Desc {
    pub name: String,
    pub mass: f64,
    /// Inertia tensor about the centre of mass in body axes (3x3 rows, symmetric), or its three
    /// principal moments `[Ixx, Iyy, Izz]` (a diagonal tensor: the short form of scene files).
    #[serde(deserialize_with = "inertia_matrix")]
    pub inertia: [[f64; 3]; 3],
    /// Centre of mass in the body frame.
    #[serde(default)]
    pub com: Vec3,
    /// Origin of the body frame (world).
    #[serde(default)]
    pub position: Vec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientationDesc>,
    /// Velocity of the body frame origin (world).
    #[serde(default)]
    pub velocity: Vec3,
    /// Angular velocity (world components).
    #[serde(default)]
    pub angular_velocity: Vec3,
}

/// An inertia given as a 3x3 matrix or as its three principal moments (a diagonal matrix).
fn inertia_matrix<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[[f64; 3]; 3], D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Inertia {
        Matrix([[f64; 3]; 3]),
        Principal([f64; 3]),
    }
    match Inertia::deserialize(d) {
        Ok(Inertia::Matrix(m)) => Ok(m),
        Ok(Inertia::Principal([a, b, c])) => Ok([[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]]),
        Err(_) => Err(serde::de::Error::custom("inertia must be a 3x3 matrix (rows) or its 3 principal moments [Ixx, Iyy, Izz]")),
    }
}

/// A 3D floating-frame modal body (`body/flexible3.rs`, docs/spatial-flexible.md): coordinates
/// `[r (3), p (4), q_f (n)]`, `r` the origin of the floating frame (world), `p` its Euler
/// parameters, `q_f` the elastic (modal) coordinates; the displacement field
/// `u(P) = u0(P) + sum_j S_j(P) q_f,j` in the frame. With the extended shapes `S_0 = u0` and
/// `xi = [1, q_f]` the body is given by its inertia invariants: `first_moment[a] = int rho S_a dV`
/// (n + 1 vectors) and `second_moment[a (n + 1) + b] = int rho S_a S_b^T dV` (3x3 each).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Flexible3Desc {
    pub name: String,
    pub mass: f64,
    pub first_moment: Vec<Vec3>,
    pub second_moment: Vec<[[f64; 3]; 3]>,
    pub k_ff: Vec<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d_ff: Option<Vec<Vec<f64>>>,
    /// Stress stiffening (docs/spatial-flexible.md): the modal geometric stiffness (n x n) of
    /// each unit load case, in the order of `body::flexible3::LOAD_CASES` (12 matrices).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometric_stiffness: Option<Vec<Vec<Vec<f64>>>>,
    /// The quadratic (Green-Lagrange) strain (docs/spatial-flexible.md, "Quadratic strain"):
    /// the modal geometric stiffness `G_k` (n x n) of each mode's linear stress (n matrices),
    /// the cubic strain energy `1/2 sum_k q_k q^T G_k q`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadratic_strain: Option<Vec<Vec<Vec<f64>>>>,
    /// With `quadratic_strain`: the quartic energy's `H_ijkl = int B_ij : C : B_kl` (n^2 x n^2,
    /// row `i n + j`, column `k n + l`), `V4 = 1/8 H_ijkl q_i q_j q_k q_l`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadratic_strain_quartic: Option<Vec<Vec<f64>>>,
    /// Interface nodes (the only places markers may sit): undeformed point, per-mode nodal
    /// displacement `phi` (n x 3) and rotation `psi` (n x 3, default zero).
    #[serde(default)]
    pub interfaces: Vec<Interface3Desc>,
    /// Origin of the floating frame (world).
    #[serde(default)]
    pub position: Vec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientationDesc>,
    #[serde(default)]
    pub velocity: Vec3,
    /// Angular velocity of the frame (world components).
    #[serde(default)]
    pub angular_velocity: Vec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elastic_rates: Option<Vec<f64>>,
}

/// A geometrically exact 3D beam (`body/beam3.rs`, docs/spatial-flexible.md): a straight
/// reference axis from `start` to `end` cut into `elements` two-node Simo-Reissner elements.
/// The model builder turns it into `elements + 1` node bodies `name[i]` (kind `rigid3`,
/// coordinates `[r, p]`) and `elements` elastic elements `name[e j]` (force kind
/// `beam3_element`). Sections `circular` and `rectangular` take the material (`density`,
/// `youngs_modulus`, one of `shear_modulus` / `poisson_ratio`, optional `shear_factor`);
/// `custom3` carries its own stiffnesses and inertia and takes none.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Beam3Desc {
    pub name: String,
    pub start: Vec3,
    pub end: Vec3,
    pub section: Section3Desc,
    /// Default `beam3::DEFAULT_ELEMENTS`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_modulus: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_modulus: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    /// Default: Cowper's (`6 (1 + nu) / (7 + 6 nu)` circular, `10 (1 + nu) / (12 + 11 nu)`
    /// rectangular).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_factor: Option<f64>,
    /// Hint for the section's `y` axis (world; its part normal to the axis). Default: the
    /// section's `z` axis as close to world `z` as the axis allows (`beam3::section_frame`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_axis: Option<Vec3>,
    /// Velocity of `start` and angular velocity (world): a rigid motion of the whole beam.
    #[serde(default)]
    pub velocity: Vec3,
    #[serde(default)]
    pub angular_velocity: Vec3,
}

/// Section of a 3D beam. `rectangular`: `width` along the section's `y`, `height` along its `z`
/// (`I_y = width height^3 / 12`). `custom3`: axial and shear stiffnesses `ea`, `ga_y`, `ga_z`
/// (`k G A`), torsional and bending stiffnesses `gj`, `ei_y`, `ei_z`, the mass per length and
/// the rotary inertia per length about the section axes `[x, y, z]` (kg m).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Section3Desc {
    Circular { diameter: f64 },
    Rectangular { width: f64, height: f64 },
    Custom3 { ea: f64, ga_y: f64, ga_z: f64, gj: f64, ei_y: f64, ei_z: f64, mass_per_length: f64, rotary_inertia: Vec3 },
}

/// One interface node of a `flexible3` body.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Interface3Desc {
    pub point: Vec3,
    pub phi: Vec<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub psi: Option<Vec<Vec3>>,
}

/// A particle: coordinates `r` (3), no orientation.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Point3Desc {
    pub name: String,
    pub mass: f64,
    #[serde(default)]
    pub position: Vec3,
    #[serde(default)]
    pub velocity: Vec3,
}

/// A frame on a body (or the ground): a point in the body frame and axes `z` (default the
/// body's `z`) and an optional hint for `x` (its part normal to `z`).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Marker3Desc {
    pub body: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<Vec3>,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PairDesc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub a: Marker3Desc,
    pub b: Marker3Desc,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Joint3Desc {
    Spherical(PairDesc),
    Revolute(PairDesc),
    Prismatic(PairDesc),
    Cylindrical(PairDesc),
    Universal(PairDesc),
    Fixed(PairDesc),
    Planar(PairDesc),
    Distance(DistanceDesc),
    PointOnLine(PairDesc),
    PointOnPlane(PairDesc),
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DistanceDesc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub a: Marker3Desc,
    pub b: Marker3Desc,
    /// Default: the distance at the initial guess.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
}

impl Joint3Desc {
    pub fn kind(&self) -> &'static str {
        match self {
            Joint3Desc::Spherical(_) => "spherical",
            Joint3Desc::Revolute(_) => "revolute",
            Joint3Desc::Prismatic(_) => "prismatic",
            Joint3Desc::Cylindrical(_) => "cylindrical",
            Joint3Desc::Universal(_) => "universal",
            Joint3Desc::Fixed(_) => "fixed",
            Joint3Desc::Planar(_) => "planar",
            Joint3Desc::Distance(_) => "distance",
            Joint3Desc::PointOnLine(_) => "point_on_line",
            Joint3Desc::PointOnPlane(_) => "point_on_plane",
        }
    }

    pub fn name(&self) -> Option<&str> {
        match self {
            Joint3Desc::Distance(d) => d.name.as_deref(),
            Joint3Desc::Spherical(p)
            | Joint3Desc::Revolute(p)
            | Joint3Desc::Prismatic(p)
            | Joint3Desc::Cylindrical(p)
            | Joint3Desc::Universal(p)
            | Joint3Desc::Fixed(p)
            | Joint3Desc::Planar(p)
            | Joint3Desc::PointOnLine(p)
            | Joint3Desc::PointOnPlane(p) => p.name.as_deref(),
        }
    }
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Driver3Body {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub a: Marker3Desc,
    pub b: Marker3Desc,
    pub motion: MotionDesc,
}

/// Drivers (one row each) between two markers whose `z` axes a joint keeps parallel:
/// `rotation` of `x_b` about `z_a` from `x_a`, `translation` of `P_b` along `z_a`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Driver3Desc {
    Rotation(Driver3Body),
    Translation(Driver3Body),
}

impl Driver3Desc {
    pub fn kind(&self) -> &'static str {
        match self {
            Driver3Desc::Rotation(_) => "rotation",
            Driver3Desc::Translation(_) => "translation",
        }
    }
    pub fn body(&self) -> &Driver3Body {
        match self {
            Driver3Desc::Rotation(d) | Driver3Desc::Translation(d) => d,
        }
    }
}

/// Components of a force or torque vector: world axes, or the marker's (body's) axes, which
/// turn with the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FrameDesc {
    #[default]
    World,
    Body,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Force3Desc {
    PointForce(PointForce3Desc),
    Torque(Torque3Desc),
    PointLoad(PointLoad3Desc),
    TorqueLoad(TorqueLoad3Desc),
    SpringDamper(SpringDamper3Desc),
    RotationalSpringDamper(RotSpring3Desc),
    JointFriction(JointFriction3Desc),
    Motor(Motor3Desc),
}

/// A motor on the spatial joint named `joint` (`force/motor3.rs`, docs/loads.md, "Motors in
/// 3D"): on a revolute or cylindrical joint a torque about its axis, on a prismatic joint a
/// force along it; `torque` a load value that may read `angle`, `w` (rotation) or `s`, `v`
/// (slide); `rotor_inertia` about the axis, on the body of the joint's marker `a`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Motor3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub joint: String,
    pub torque: LoadValueDesc,
    #[serde(default)]
    pub rotor_inertia: f64,
}

/// Regularized Coulomb and viscous friction in the spatial revolute, prismatic or spherical
/// joint named `joint` (docs/loads.md, "Joint friction"): `radius` the pin (revolute) or ball
/// (spherical) radius, `collar_radius` the effective radius of a thrust collar that carries a
/// revolute's axial reaction (none: the axial reaction makes no friction).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct JointFriction3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub joint: String,
    pub mu: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub collar_radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    #[serde(default)]
    pub damping: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v_eps: Option<f64>,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PointForce3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub point: Marker3Desc,
    pub force: Vec3,
    #[serde(default)]
    pub frame: FrameDesc,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Torque3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub body: String,
    pub torque: Vec3,
    #[serde(default)]
    pub frame: FrameDesc,
}

/// A force at a marker whose three components are functions (`force/spatial_load.rs`,
/// docs/loads.md): each a number, an expression of `t` and coordinates, a table or a callable.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoad3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub point: Marker3Desc,
    pub force: Vec<LoadValueDesc>,
    #[serde(default)]
    pub frame: FrameDesc,
}

/// A torque on a rigid3 body whose three components are functions (as [`PointLoad3Desc`]).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueLoad3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub body: String,
    pub torque: Vec<LoadValueDesc>,
    #[serde(default)]
    pub frame: FrameDesc,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SpringDamper3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub a: Marker3Desc,
    pub b: Marker3Desc,
    pub stiffness: f64,
    #[serde(default)]
    pub damping: f64,
    /// Default: the distance at the initial guess.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rest_length: Option<f64>,
}

/// A rotational spring-damper about `z_a` (the axis a revolute or cylindrical joint keeps):
/// the angle of `x_b` from `x_a`, read within half a turn of `angle0` (`theta - angle0` in
/// `(-pi, pi]`; no turn counter yet).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RotSpring3Desc {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    pub a: Marker3Desc,
    pub b: Marker3Desc,
    pub stiffness: f64,
    #[serde(default)]
    pub damping: f64,
    #[serde(default)]
    pub angle0: f64,
}

impl Force3Desc {
    pub fn kind(&self) -> &'static str {
        match self {
            Force3Desc::PointForce(_) => "point_force",
            Force3Desc::Torque(_) => "torque",
            Force3Desc::PointLoad(_) => "point_load",
            Force3Desc::TorqueLoad(_) => "torque_load",
            Force3Desc::SpringDamper(_) => "spring_damper",
            Force3Desc::RotationalSpringDamper(_) => "rotational_spring_damper",
            Force3Desc::JointFriction(_) => "joint_friction",
            Force3Desc::Motor(_) => "motor",
        }
    }
    pub fn name(&self) -> Option<&str> {
        match self {
            Force3Desc::PointForce(d) => d.name.as_deref(),
            Force3Desc::Torque(d) => d.name.as_deref(),
            Force3Desc::PointLoad(d) => d.name.as_deref(),
            Force3Desc::TorqueLoad(d) => d.name.as_deref(),
            Force3Desc::SpringDamper(d) => d.name.as_deref(),
            Force3Desc::RotationalSpringDamper(d) => d.name.as_deref(),
            Force3Desc::JointFriction(d) => d.name.as_deref(),
            Force3Desc::Motor(d) => d.name.as_deref(),
        }
    }
}
