//! The precomputed model: immutable after `Model::new`, validated once. Holds the coordinate
//! layout, the bodies with their constant shape integrals, the resolved markers, the
//! constraint rows and the forces. A scene pays only for what it declares: no gravity field
//! means no gravity term, a rigid-only scene has no elastic blocks, no driver no time terms.

use std::collections::HashMap;

use crate::body::{Beam, Body, BodyKind, Marker, MarkerShape, Rigid};
use crate::constraint::{Constraint, ConstraintKind, Motion};
use crate::description::{BodyDesc, Description, DriverDesc, ForceDesc, JointDesc, MarkerDesc};
use crate::error::{check_finite, Error, Result};
use crate::force::{Force, ForceKind};

#[derive(Debug, Clone)]
pub struct Model {
    pub bodies: Vec<Body>,
    pub constraints: Vec<Constraint>,
    pub forces: Vec<Force>,
    pub gravity: Option<[f64; 2]>,
    /// Number of coordinates `n`.
    pub n: usize,
    /// Number of constraint rows `m`.
    pub m: usize,
    /// Any beam with stiffness-proportional damping.
    pub has_beam_damping: bool,
    pub coordinate_names: Vec<String>,
    pub constraint_row_names: Vec<String>,
    /// Initial guess from the description.
    pub q0: Vec<f64>,
    pub qd0: Vec<f64>,
}

fn check_finite_item(item: &str, what: &str, v: &[f64]) -> Result<()> {
    check_finite(what, v).map_err(|_| Error::invalid(item, format!("{what} must be finite, got {v:?}")))
}

impl Model {
    pub fn from_json(text: &str) -> Result<Model> {
        Model::new(&Description::from_json(text)?)
    }

    pub fn new(d: &Description) -> Result<Model> {
        if d.bodies.is_empty() {
            return Err(Error::Description("a scene needs at least one body".into()));
        }
        if let Some(g) = d.gravity {
            check_finite_item("gravity", "gravity", &g)?;
        }
        let mut bodies = Vec::with_capacity(d.bodies.len());
        let mut index: HashMap<String, usize> = HashMap::new();
        let mut offset = 0;
        let (mut q0, mut qd0) = (Vec::new(), Vec::new());
        let mut coordinate_names = Vec::new();
        for bd in &d.bodies {
            let name = bd.name().to_string();
            if name.is_empty() || name == "ground" {
                return Err(Error::invalid(format!("body '{name}'"), "body names must be non-empty and not 'ground'"));
            }
            if index.insert(name.clone(), bodies.len()).is_some() {
                return Err(Error::invalid(format!("body '{name}'"), "duplicate body name"));
            }
            let item = format!("body '{name}'");
            let (kind, pos, ang, vel, angvel) = match bd {
                BodyDesc::Rigid(r) => (BodyKind::Rigid(Rigid::new(r)?), r.position, r.angle, r.velocity, r.angular_velocity),
                BodyDesc::Beam(b) => (BodyKind::Beam(Beam::new(b)?), b.position, b.angle, b.velocity, b.angular_velocity),
            };
            check_finite_item(&item, "position", &pos)?;
            check_finite_item(&item, "angle", &[ang])?;
            check_finite_item(&item, "velocity", &vel)?;
            check_finite_item(&item, "angular_velocity", &[angvel])?;
            q0.extend_from_slice(&[pos[0], pos[1], ang]);
            qd0.extend_from_slice(&[vel[0], vel[1], angvel]);
            for c in ["x", "y", "theta"] {
                coordinate_names.push(format!("{name}.{c}"));
            }
            let n_f = match &kind {
                BodyKind::Rigid(_) => 0,
                BodyKind::Beam(beam) => {
                    let BodyDesc::Beam(b) = bd else { unreachable!() };
                    for (what, v) in [("elastic", &b.elastic), ("elastic_rates", &b.elastic_rates)] {
                        match v {
                            Some(v) if v.len() != beam.n_f => {
                                return Err(Error::invalid(&item, format!("{what} must have {} entries, got {}", beam.n_f, v.len())))
                            }
                            Some(v) => check_finite_item(&item, what, v)?,
                            None => {}
                        }
                    }
                    q0.extend(b.elastic.clone().unwrap_or_else(|| vec![0.0; beam.n_f]));
                    qd0.extend(b.elastic_rates.clone().unwrap_or_else(|| vec![0.0; beam.n_f]));
                    for i in 0..beam.n_f {
                        coordinate_names.push(format!("{name}.qf{i}"));
                    }
                    beam.n_f
                }
            };
            bodies.push(Body { name, offset, n_coords: 3 + n_f, kind });
            offset += 3 + n_f;
        }
        let n = offset;

        let marker = |item: &str, md: &MarkerDesc| -> Result<Marker> { resolve_marker(&bodies, &index, item, md) };
        let zeros = vec![0.0; n];
        let mut constraints = Vec::new();
        let mut row = 0;
        let mut row_names = Vec::new();
        let mut used_names: HashMap<String, usize> = HashMap::new();
        let mut unique = |given: &Option<String>, default: String| -> String {
            let base = given.clone().unwrap_or(default);
            let k = used_names.entry(base.clone()).or_insert(0);
            *k += 1;
            if *k == 1 { base } else { format!("{base}#{k}") }
        };
        for (j, jd) in d.joints.iter().enumerate() {
            let (name, kind) = match jd {
                JointDesc::Revolute { name, a, b } => {
                    let nm = unique(name, format!("revolute{j}"));
                    let item = format!("joint '{nm}'");
                    (nm, ConstraintKind::Revolute { a: marker(&item, a)?, b: marker(&item, b)? })
                }
                JointDesc::PointOnLine { name, point, line } => {
                    let nm = unique(name, format!("point_on_line{j}"));
                    let item = format!("joint '{nm}'");
                    (nm, ConstraintKind::PointOnLine { point: marker(&item, point)?, line: marker(&item, line)? })
                }
                JointDesc::Prismatic { name, a, b } => {
                    let nm = unique(name, format!("prismatic{j}"));
                    let item = format!("joint '{nm}'");
                    let (a, b) = (marker(&item, a)?, marker(&item, b)?);
                    let phi0 = a.state(&bodies, &q0, &zeros).phi - b.state(&bodies, &q0, &zeros).phi;
                    (nm, ConstraintKind::Prismatic { a, b, phi0 })
                }
                JointDesc::Weld { name, a, b } => {
                    let nm = unique(name, format!("weld{j}"));
                    let item = format!("joint '{nm}'");
                    let (a, b) = (marker(&item, a)?, marker(&item, b)?);
                    let phi0 = a.state(&bodies, &q0, &zeros).phi - b.state(&bodies, &q0, &zeros).phi;
                    (nm, ConstraintKind::Weld { a, b, phi0 })
                }
            };
            constraints.push(Constraint { name, row, kind });
        }
        for (j, dd) in d.drivers.iter().enumerate() {
            let (name, kind) = match dd {
                DriverDesc::Angle { name, a, b, motion } => {
                    let nm = unique(name, format!("angle_driver{j}"));
                    let item = format!("driver '{nm}'");
                    let b = match b {
                        Some(b) => marker(&item, b)?,
                        None => Marker { body: None, angle: 0.0, shape: MarkerShape::Point([0.0, 0.0]) },
                    };
                    let motion = Motion::from_desc(motion);
                    check_finite_item(&item, "motion", &motion.parameters())?;
                    (nm, ConstraintKind::AngleDriver { a: marker(&item, a)?, b, motion })
                }
                DriverDesc::Coordinate { name, point, axis, motion } => {
                    let nm = unique(name, format!("coordinate_driver{j}"));
                    let item = format!("driver '{nm}'");
                    let motion = Motion::from_desc(motion);
                    check_finite_item(&item, "motion", &motion.parameters())?;
                    (nm, ConstraintKind::CoordinateDriver { point: marker(&item, point)?, axis: *axis, motion })
                }
            };
            constraints.push(Constraint { name, row, kind });
        }
        for c in constraints.iter_mut() {
            c.row = row;
            let suffixes: &[&str] = match &c.kind {
                ConstraintKind::Revolute { .. } => &["x", "y"],
                ConstraintKind::Weld { .. } => &["x", "y", "angle"],
                ConstraintKind::Prismatic { .. } => &["line", "angle"],
                _ => &[""],
            };
            for s in suffixes {
                row_names.push(if s.is_empty() { c.name.clone() } else { format!("{}.{s}", c.name) });
            }
            row += c.kind.rows();
        }
        let m = row;

        let mut forces = Vec::new();
        for (j, fd) in d.forces.iter().enumerate() {
            let (name, kind) = match fd {
                ForceDesc::PointForce { name, point, force } => {
                    let nm = name.clone().unwrap_or(format!("point_force{j}"));
                    let item = format!("force '{nm}'");
                    check_finite_item(&item, "force", force)?;
                    (nm, ForceKind::PointForce { point: marker(&item, point)?, force: *force })
                }
                ForceDesc::Torque { name, frame, torque } => {
                    let nm = name.clone().unwrap_or(format!("torque{j}"));
                    let item = format!("force '{nm}'");
                    check_finite_item(&item, "torque", &[*torque])?;
                    (nm, ForceKind::Torque { frame: marker(&item, frame)?, torque: *torque })
                }
                ForceDesc::SpringDamper { name, a, b, stiffness, damping, rest_length } => {
                    let nm = name.clone().unwrap_or(format!("spring_damper{j}"));
                    let item = format!("force '{nm}'");
                    for (what, v) in [("stiffness", stiffness), ("damping", damping), ("rest_length", rest_length)] {
                        if !v.is_finite() || *v < 0.0 {
                            return Err(Error::invalid(&item, format!("{what} must be >= 0 and finite, got {v}")));
                        }
                    }
                    let kind = ForceKind::SpringDamper {
                        a: marker(&item, a)?,
                        b: marker(&item, b)?,
                        stiffness: *stiffness,
                        damping: *damping,
                        rest_length: *rest_length,
                    };
                    (nm, kind)
                }
            };
            forces.push(Force { name, kind });
        }
        let has_beam_damping = bodies.iter().any(|b| matches!(&b.kind, BodyKind::Beam(beam) if beam.damping > 0.0));
        Ok(Model {
            bodies,
            constraints,
            forces,
            gravity: d.gravity.filter(|g| g[0] != 0.0 || g[1] != 0.0),
            n,
            m,
            has_beam_damping,
            coordinate_names,
            constraint_row_names: row_names,
            q0,
            qd0,
        })
    }

    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }
}

fn resolve_marker(bodies: &[Body], index: &HashMap<String, usize>, item: &str, md: &MarkerDesc) -> Result<Marker> {
    if !md.angle.is_finite() {
        return Err(Error::invalid(item, format!("marker angle must be finite, got {}", md.angle)));
    }
    if md.body == "ground" {
        let p = md.point.unwrap_or([0.0, 0.0]);
        if md.xi.is_some() {
            return Err(Error::invalid(item, "a ground marker takes 'point', not 'xi'"));
        }
        check_finite_item(item, "marker point", &p)?;
        return Ok(Marker { body: None, angle: md.angle, shape: MarkerShape::Point(p) });
    }
    let Some(&bi) = index.get(&md.body) else {
        return Err(Error::UnknownBody { item: item.to_string(), body: md.body.clone() });
    };
    let shape = match &bodies[bi].kind {
        BodyKind::Rigid(_) => {
            if md.xi.is_some() {
                return Err(Error::invalid(item, format!("marker on rigid body '{}' takes 'point', not 'xi'", md.body)));
            }
            let p = md.point.unwrap_or([0.0, 0.0]);
            check_finite_item(item, "marker point", &p)?;
            MarkerShape::Point(p)
        }
        BodyKind::Beam(beam) => {
            if md.point.is_some() {
                return Err(Error::invalid(item, format!("marker on beam '{}' takes 'xi' in [0, 1], not 'point'", md.body)));
            }
            let xi = md.xi.unwrap_or(0.0);
            if !xi.is_finite() || !(0.0..=1.0).contains(&xi) {
                return Err(Error::invalid(item, format!("marker xi on beam '{}' must be in [0, 1], got {xi}", md.body)));
            }
            MarkerShape::Beam(beam.point_shape(xi))
        }
    };
    Ok(Marker { body: Some(bi), angle: md.angle, shape })
}
