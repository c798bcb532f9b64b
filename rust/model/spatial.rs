//! A spatial model (`"dim": 3`) from its JSON description: every item validated by its kind
//! (`Rigid3::from_desc`, `Marker3::from_desc`, the joint rules below), errors naming the item as
//! in the planar builder (`model::item_name`). The constraint rows are the joints', then the
//! drivers', then one normalization row per rigid3 body; the force elements are gravity (one
//! element, `gravity`, when the scene's gravity is nonzero) and the listed ones.
//!
//! Spatial (3D) rigid multibody systems (issue 30; docs/spatial.md, docs/spatial-design.md) live
//! in the layers of the planar ones: the description `description/spatial.rs`, the
//! Euler-parameter algebra `linalg/rot3.rs`, the bodies `body/rigid3.rs` and `body/point3.rs`,
//! the joints `constraint/spatial/`, the force elements `force/spatial.rs`, this builder (the
//! same `Model` as the planar scenes) and the sensors `sensors/spatial.rs`. The kernels
//! (`dynamics`, `uk`, `correct`, `integrate`) run them unchanged.

use std::collections::HashMap;

use serde::Deserialize;
use serde_json::Value;

use crate::body::marker3::Marker3;
use crate::body::{Body, BodyKind, Flexible3, InitialState, Point3, Rigid3};
use crate::constraint::spatial::{self as sc, Normalization, Pair, RotationDriver, SpatialConstraint, TranslationDriver};
use crate::constraint::{Constraint, ConstraintKind, Motion};
use crate::error::{check_finite_item, non_negative, positive, Error, Result};
use crate::force::{Force, ForceKind};
use crate::model::{assign_rows, item_name, parse_item, parse_json, take_name, Model, Section};
use crate::description::spatial::{Body3Desc, Driver3Desc, Force3Desc, Joint3Desc, Marker3Desc};
use crate::force::spatial::{marker_point, SpatialForce};
use crate::force::motor3::Motor3;
use crate::force::spatial_load::SpatialLoad;
use crate::force::value3::Spatial;
use crate::linalg::rot3::{norm, sub};

/// Planar body kinds (refused in a spatial scene) and spatial ones (refused in a planar one).
const PLANAR_KINDS: [&str; 4] = ["rigid", "point_mass", "beam", "flexible"];
const SPATIAL_KINDS: [&str; 4] = ["rigid3", "point3", "flexible3", "beam3"];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw3 {
    #[allow(dead_code)]
    dim: u32,
    #[serde(default)]
    gravity: Option<[f64; 3]>,
    bodies: Vec<Value>,
    #[serde(default)]
    joints: Vec<Value>,
    #[serde(default)]
    drivers: Vec<Value>,
    #[serde(default)]
    forces: Vec<Value>,
}

/// The model of a spatial description, `None` for a planar one (no `dim` or `dim = 2`; a planar
/// description holding a spatial body kind is refused: dimensions do not mix).
pub fn model_if_spatial(text: &str) -> Result<Option<Model>> {
    let v: Value = parse_json("scene", text)?;
    let dim = match v.get("dim") {
        None => 2,
        Some(d) => match d.as_u64() {
            Some(2) => 2,
            Some(3) => 3,
            _ => return Err(Error::invalid("scene", format!("dim must be 2 (planar) or 3 (spatial), got {d}"))),
        },
    };
    if dim == 2 {
        if let Some(Value::Array(bodies)) = v.get("bodies") {
            for (i, b) in bodies.iter().enumerate() {
                let kind = b.get("kind").and_then(Value::as_str).unwrap_or("");
                if SPATIAL_KINDS.contains(&kind) {
                    let name = b.get("name").and_then(Value::as_str);
                    return Err(Error::invalid(
                        item_name(Section::Body, kind, name, i),
                        format!("body kind '{kind}' is spatial: the scene needs \"dim\": 3 (a scene does not mix dimensions)"),
                    ));
                }
            }
        }
        return Ok(None);
    }
    build(text).map(Some)
}

struct Builder {
    bodies: Vec<Body>,
    index: HashMap<String, usize>,
    q0: Vec<f64>,
    qd0: Vec<f64>,
    names: Vec<String>,
    used: HashMap<String, usize>,
    /// The elements of the beams (`beam3`), named, in the order of their beams.
    beam_elements: Vec<(String, SpatialForce)>,
}

impl Builder {
    fn take_name(&mut self, item: &str, given: Option<&str>, default: String) -> Result<String> {
        take_name(&mut self.used, item, given, default)
    }

    fn marker(&self, item: &str, md: &Marker3Desc) -> Result<Marker3> {
        Marker3::from_desc(item, md, &self.bodies, &self.index)
    }

    fn pair(&self, item: &str, a: &Marker3Desc, b: &Marker3Desc) -> Result<Pair> {
        Pair::new(item, self.marker(item, a)?, self.marker(item, b)?)
    }

    fn add_body(&mut self, item: &str, d: &Body3Desc) -> Result<()> {
        let name = d.name();
        if name.is_empty() || name == "ground" {
            return Err(Error::invalid(item, "body names must be non-empty and not 'ground' (the name 'ground' is reserved)"));
        }
        if self.index.contains_key(name) {
            return Err(Error::invalid(item, "duplicate body name"));
        }
        let (kind, init): (BodyKind, InitialState) = match d {
            Body3Desc::Rigid3(r) => {
                let k = Rigid3::from_desc(r, item)?;
                let init = k.initial_state(r, item)?;
                (BodyKind::Rigid3(k), init)
            }
            Body3Desc::Point3(p) => {
                let k = Point3::from_desc(p, item)?;
                let init = k.initial_state(p, item)?;
                (BodyKind::Point3(k), init)
            }
            Body3Desc::Flexible3(f) => {
                let k = Flexible3::from_desc(f, item)?;
                let init = k.initial_state(f, item)?;
                (BodyKind::Flexible3(k), init)
            }
            Body3Desc::Beam3(bd) => return self.add_beam(item, bd),
        };
        let offset = self.q0.len();
        self.q0.extend_from_slice(&init.q);
        self.qd0.extend_from_slice(&init.qd);
        self.names.extend(init.names.iter().map(|c| format!("{name}.{c}")));
        self.index.insert(name.to_string(), self.bodies.len());
        self.bodies.push(Body { name: name.to_string(), offset, n_coords: init.q.len(), kind });
        Ok(())
    }

    /// A beam: its node bodies `name[i]` (rigid3) and its elements `name[e j]` (`body/beam3.rs`).
    fn add_beam(&mut self, item: &str, d: &crate::description::spatial::Beam3Desc) -> Result<()> {
        let (nodes, elements) = crate::body::beam3::expand(item, d)?;
        let first = self.bodies.len();
        for node in &nodes {
            self.add_body(item, &Body3Desc::Rigid3(node.clone()))?;
        }
        for (j, element) in elements.into_iter().enumerate() {
            let name = self.take_name(item, None, format!("{}[e{j}]", d.name))?;
            let ab = [first + j, first + j + 1];
            let base = ab.map(SpatialForce::torque_marker);
            self.beam_elements.push((name, SpatialForce::Beam3 { nodes: ab, base, element }));
        }
        Ok(())
    }

    fn joint(&self, item: &str, d: &Joint3Desc) -> Result<SpatialConstraint> {
        use SpatialConstraint as S;
        let kind = d.kind();
        Ok(match d {
            Joint3Desc::Distance(dd) => {
                let pair = self.pair(item, &dd.a, &dd.b)?;
                let length = match dd.length {
                    Some(l) => l,
                    None => norm(&sub(&marker_point(&pair.j, &self.bodies, &self.q0), &marker_point(&pair.i, &self.bodies, &self.q0))),
                };
                let length = positive(item, "length (distance between the markers)", length)?;
                S::Distance(sc::distance::Distance3 { pair, length })
            }
            Joint3Desc::Spherical(p) => S::Spherical(sc::spherical::Spherical { pair: self.pair(item, &p.a, &p.b)? }),
            Joint3Desc::Revolute(p) => S::Revolute(sc::revolute::Revolute3 { pair: self.pair(item, &p.a, &p.b)?.oriented(item, kind)? }),
            Joint3Desc::Prismatic(p) => S::Prismatic(sc::prismatic::Prismatic3 { pair: self.pair(item, &p.a, &p.b)?.oriented(item, kind)? }),
            Joint3Desc::Cylindrical(p) => S::Cylindrical(sc::cylindrical::Cylindrical { pair: self.pair(item, &p.a, &p.b)?.oriented(item, kind)? }),
            Joint3Desc::Universal(p) => S::Universal(sc::universal::Universal { pair: self.pair(item, &p.a, &p.b)?.oriented(item, kind)? }),
            Joint3Desc::Fixed(p) => S::Fixed(sc::fixed::Fixed { pair: self.pair(item, &p.a, &p.b)?.oriented(item, kind)? }),
            Joint3Desc::Planar(p) => S::Planar(sc::planar::Planar { pair: self.pair(item, &p.a, &p.b)?.oriented(item, kind)? }),
            Joint3Desc::PointOnLine(p) => {
                let pair = self.pair(item, &p.a, &p.b)?;
                pair.i.check_oriented(item, "the line's marker a")?;
                S::PointOnLine(sc::point_on_line::PointOnLine3 { pair })
            }
            Joint3Desc::PointOnPlane(p) => {
                let pair = self.pair(item, &p.a, &p.b)?;
                pair.i.check_oriented(item, "the plane's marker a")?;
                S::PointOnPlane(sc::point_on_plane::PointOnPlane { pair })
            }
        })
    }

    fn driver(&self, item: &str, d: &Driver3Desc) -> Result<SpatialConstraint> {
        let b = d.body();
        let motion = Motion::from_desc(item, &b.motion)?;
        let pair = self.pair(item, &b.a, &b.b)?;
        Ok(match d {
            Driver3Desc::Rotation(_) => SpatialConstraint::Rotation(RotationDriver { pair: pair.oriented(item, "rotation driver")?, motion }),
            Driver3Desc::Translation(_) => {
                pair.i.check_oriented(item, "translation driver marker a")?;
                SpatialConstraint::Translation(TranslationDriver { pair, motion })
            }
        })
    }

    fn force(&self, item: &str, d: &Force3Desc) -> Result<ForceKind> {
        Ok(ForceKind::Spatial(match d {
            Force3Desc::PointLoad(f) => return Ok(ForceKind::SpatialLoad(Box::new(SpatialLoad::force(item, &self.names, self.spatial(), self.marker(item, &f.point)?, &f.force, f.frame)?))),
            Force3Desc::TorqueLoad(t) => return Ok(ForceKind::SpatialLoad(Box::new(SpatialLoad::torque(item, &self.names, self.spatial(), self.rigid3(item, &t.body, "torque")?, &t.torque, t.frame)?))),
            Force3Desc::PointForce(f) => {
                check_finite_item(item, "force", &f.force)?;
                SpatialForce::PointForce { point: self.marker(item, &f.point)?, force: f.force, frame: f.frame }
            }
            Force3Desc::Torque(t) => {
                check_finite_item(item, "torque", &t.torque)?;
                let bi = self.rigid3(item, &t.body, "torque")?;
                SpatialForce::Torque { body: bi, base: SpatialForce::torque_marker(bi), torque: t.torque, frame: t.frame }
            }
            Force3Desc::SpringDamper(s) => {
                let pair = self.pair(item, &s.a, &s.b)?;
                let rest_length = match s.rest_length {
                    Some(l) => l,
                    None => norm(&sub(&marker_point(&pair.j, &self.bodies, &self.q0), &marker_point(&pair.i, &self.bodies, &self.q0))),
                };
                SpatialForce::SpringDamper {
                    a: pair.i,
                    b: pair.j,
                    stiffness: non_negative(item, "stiffness", s.stiffness)?,
                    damping: non_negative(item, "damping", s.damping)?,
                    rest_length: non_negative(item, "rest_length", rest_length)?,
                }
            }
            Force3Desc::RotationalSpringDamper(s) => {
                let pair = self.pair(item, &s.a, &s.b)?.oriented(item, "rotational spring-damper")?;
                check_finite_item(item, "angle0", &[s.angle0])?;
                SpatialForce::RotationalSpringDamper {
                    a: pair.i,
                    b: pair.j,
                    stiffness: non_negative(item, "stiffness", s.stiffness)?,
                    damping: non_negative(item, "damping", s.damping)?,
                    angle0: s.angle0,
                }
            }
            // built from its joint with the joints (`force::friction3::from_desc`, `Motor3::from_desc`)
            Force3Desc::JointFriction(_) | Force3Desc::Motor(_) => return Err(Error::invalid(item, "joint friction and motors are built from their joint (JointFriction::from_desc3, Motor3::from_desc)")),
        }))
    }

    /// Where the loads' spatial point quantities are resolved (`force/value3.rs`).
    fn spatial(&self) -> Spatial<'_> {
        Spatial { bodies: &self.bodies, index: &self.index }
    }

    /// The rigid3 body `name` a torque acts on (an unknown body, or one without orientation,
    /// named).
    fn rigid3(&self, item: &str, name: &str, what: &str) -> Result<usize> {
        let Some(&bi) = self.index.get(name) else {
            let known: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
            return Err(Error::UnknownBody { item: item.to_string(), body: name.to_string(), known: known.join(", ") });
        };
        if !matches!(self.bodies[bi].kind, BodyKind::Rigid3(_)) {
            return Err(Error::invalid(item, format!("a {what} needs a rigid3 body; '{name}' has no orientation")));
        }
        Ok(bi)
    }
}

/// The kind tag of an item (for the mixed-dimension check).
fn kind_of(v: &Value) -> &str {
    v.get("kind").and_then(Value::as_str).unwrap_or("")
}

/// Build a spatial model from its JSON description.
pub fn build(text: &str) -> Result<Model> {
    let raw: Raw3 = parse_json("scene", text)?;
    let gravity = raw.gravity.unwrap_or([0.0; 3]);
    check_finite_item("scene", "gravity", &gravity)?;
    let mut b = Builder { bodies: Vec::new(), index: HashMap::new(), q0: Vec::new(), qd0: Vec::new(), names: Vec::new(), used: HashMap::new(), beam_elements: Vec::new() };
    for (i, v) in raw.bodies.into_iter().enumerate() {
        let kind = kind_of(&v).to_string();
        let name = v.get("name").and_then(Value::as_str).map(str::to_string);
        let item = item_name(Section::Body, &kind, name.as_deref(), i);
        if PLANAR_KINDS.contains(&kind.as_str()) {
            return Err(Error::invalid(item, format!("body kind '{kind}' is planar: a scene with \"dim\": 3 holds rigid3, point3, flexible3 and beam3 bodies (a scene does not mix dimensions)")));
        }
        let d: Body3Desc = parse_item(Section::Body, i, v)?;
        b.add_body(&item, &d)?;
    }
    if b.bodies.is_empty() {
        return Err(Error::Description("a scene needs at least one body".into()));
    }
    let mut constraints: Vec<Constraint> = Vec::new();
    for (i, v) in raw.joints.into_iter().enumerate() {
        let d: Joint3Desc = parse_item(Section::Joint, i, v)?;
        let item = item_name(Section::Joint, d.kind(), d.name(), i);
        let kind = b.joint(&item, &d)?;
        let name = b.take_name(&item, d.name(), format!("{}{i}", d.kind()))?;
        constraints.push(Constraint { name, row: 0, kind: ConstraintKind::Spatial(kind) });
    }
    for (i, v) in raw.drivers.into_iter().enumerate() {
        let d: Driver3Desc = parse_item(Section::Driver, i, v)?;
        let item = item_name(Section::Driver, d.kind(), d.body().name.as_deref(), i);
        let kind = b.driver(&item, &d)?;
        let name = b.take_name(&item, d.body().name.as_deref(), format!("{}_driver{i}", d.kind()))?;
        constraints.push(Constraint { name, row: 0, kind: ConstraintKind::Spatial(kind) });
    }
    for (bi, body) in b.bodies.iter().enumerate() {
        if matches!(body.kind, BodyKind::Rigid3(_) | BodyKind::Flexible3(_)) {
            let kind = SpatialConstraint::Normalization(Normalization { body: bi, base: SpatialForce::torque_marker(bi) });
            constraints.push(Constraint { name: format!("{}.normalization", body.name), row: 0, kind: ConstraintKind::Spatial(kind) });
        }
    }
    let mut forces: Vec<Force> = Vec::new();
    if gravity != [0.0; 3] {
        b.used.insert("gravity".into(), 1);
        forces.push(Force { name: "gravity".into(), kind: ForceKind::Spatial(SpatialForce::Gravity { g: gravity }) });
    }
    for (name, kind) in std::mem::take(&mut b.beam_elements) {
        forces.push(Force { name, kind: ForceKind::Spatial(kind) });
    }
    for (i, v) in raw.forces.into_iter().enumerate() {
        let d: Force3Desc = parse_item(Section::Force, i, v)?;
        let item = item_name(Section::Force, d.kind(), d.name(), i);
        let kind = match &d {
            Force3Desc::JointFriction(f) => ForceKind::JointFriction(Box::new(crate::force::friction::JointFriction::from_desc3(&item, &constraints, f)?)),
            Force3Desc::Motor(m) => {
                let motor = Motor3::from_desc(&item, &b.names, b.spatial(), &constraints, m)?;
                motor.add_rotor_inertia(&item, &mut b.bodies)?;
                ForceKind::Motor3(Box::new(motor))
            }
            _ => b.force(&item, &d)?,
        };
        let name = b.take_name(&item, d.name(), format!("{}{i}", d.kind()))?;
        forces.push(Force { name, kind });
    }
    let (row, row_names) = assign_rows(&mut constraints);
    Ok(Model {
        n: b.q0.len(),
        m: row,
        bodies: b.bodies,
        constraints,
        forces,
        gravity: None,
        coordinate_names: b.names,
        constraint_row_names: row_names,
        length_scale: 1.0,
        q0: b.q0,
        qd0: b.qd0,
    })
}
