//! The precomputed model: immutable after it is built, validated once. Holds the coordinate
//! layout, the bodies with their constant shape integrals, the resolved markers, the
//! constraint rows and the forces. A scene pays only for what it declares: no gravity field
//! means no gravity term, a rigid-only scene has no elastic blocks, no driver no time terms.
//!
//! `ModelBuilder` is the one place that validates a scene: it adds items one at a time (each
//! kind validates itself in its `from_desc`), names the offending item in every error, and is
//! used both for a whole description (`Model::from_json`) and item by item by the Python scene
//! builder (so Python never re-derives a rule).

pub mod scale;
pub mod spatial;

use std::collections::HashMap;

use serde::de::DeserializeOwned;
use serde::Deserialize;
use serde_json::Value;

use crate::body::Body;
use crate::constraint::{BuildContext, Constraint};
use crate::description::{to_external, to_internal, BodyDesc, Description, DriverDesc, ForceDesc, JointDesc, Vec2};
use crate::error::{check_finite_item, Error, Result};
use crate::force::Force;

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
    pub coordinate_names: Vec<String>,
    pub constraint_row_names: Vec<String>,
    /// The scene's length scale [m] (`scale::length_scale`; 1 m for a model not built from a
    /// description).
    pub length_scale: f64,
    /// Initial guess from the description.
    pub q0: Vec<f64>,
    pub qd0: Vec<f64>,
}

impl Model {
    /// Parse and validate a JSON scene description (`docs/scene-format.md`).
    pub fn from_json(text: &str) -> Result<Model> {
        let mut model = Self::build_json(text)?;
        let desc: Value = serde_json::from_str(text).map_err(|e| Error::Description(e.to_string()))?;
        model.length_scale = scale::length_scale(&desc);
        scale::check_lengths(&desc, model.length_scale)?;
        Ok(model)
    }

    fn build_json(text: &str) -> Result<Model> {
        if let Some(model) = spatial::model_if_spatial(text)? {
            return Ok(model);
        }
        let raw: RawDescription = parse_json("scene", text)?;
        let mut b = ModelBuilder::new(raw.gravity)?;
        for v in raw.bodies {
            b.add_body(&parse_item(Section::Body, b.bodies.len(), v)?)?;
        }
        for v in raw.joints {
            b.add_joint(&parse_item(Section::Joint, b.joints.len(), v)?)?;
        }
        for v in raw.drivers {
            b.add_driver(&parse_item(Section::Driver, b.drivers.len(), v)?)?;
        }
        for v in raw.forces {
            b.add_force(&parse_item(Section::Force, b.forces.len(), v)?)?;
        }
        b.finish()
    }

    /// Validate and build from a parsed description.
    pub fn new(d: &Description) -> Result<Model> {
        let mut b = ModelBuilder::new(d.gravity)?;
        for x in &d.bodies {
            b.add_body(x)?;
        }
        for x in &d.joints {
            b.add_joint(x)?;
        }
        for x in &d.drivers {
            b.add_driver(x)?;
        }
        for x in &d.forces {
            b.add_force(x)?;
        }
        let mut model = b.finish()?;
        let desc = item_to_json(d)?;
        model.length_scale = scale::length_scale(&desc);
        scale::check_lengths(&desc, model.length_scale)?;
        Ok(model)
    }

    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The body-frame points at which joints, drivers and forces attach to rigid body `bi`
    /// (in item order, repeats included): what draws it (`Body::outline`).
    pub fn attachments(&self, bi: usize) -> Vec<[f64; 2]> {
        let markers = self.constraints.iter().flat_map(|c| c.markers()).chain(self.forces.iter().flat_map(|f| f.markers()));
        markers
            .flatten()
            .filter(|m| m.body == Some(bi))
            .filter_map(|m| match m.shape {
                crate::body::marker::MarkerShape::Rigid(p) => Some(p),
                _ => None,
            })
            .collect()
    }

    /// Attach the functions of the loads' callables (`force::value::Callable`): `resolve`
    /// gives the function of a name and its inputs; a name it does not know is an error.
    pub fn attach_callables(&mut self, resolve: &mut dyn FnMut(&str, &[String]) -> Option<std::sync::Arc<dyn crate::force::value::LoadCallback>>) -> Result<()> {
        for f in &mut self.forces {
            let name = f.name.clone();
            for v in f.values_mut() {
                if let crate::force::value::Value::Callable(c) = v {
                    c.f = resolve(&c.name, &c.input_names);
                    if c.f.is_none() {
                        return Err(Error::invalid(format!("force '{name}'"), format!("the callable '{}' was not given to the System", c.name)));
                    }
                }
            }
        }
        Ok(())
    }

    /// The columns of `B^T = F^-1 A^T` that are multiples of unit vectors, as `(row of A,
    /// coordinate)`: the spatial rigid bodies' normalization rows
    /// (`Normalization::unit_coordinate`). The QR of `B^T` skips them
    /// (`QrJacobi::with_unit_columns`): the normalization rows are eliminated in closed form
    /// (docs/spatial-design.md, section 3).
    pub fn unit_columns(&self) -> Vec<(usize, usize)> {
        use crate::constraint::spatial::SpatialConstraint;
        use crate::constraint::ConstraintKind;
        self.constraints
            .iter()
            .filter_map(|c| match &c.kind {
                ConstraintKind::Spatial(SpatialConstraint::Normalization(nr)) => Some((c.row, nr.unit_coordinate(&self.bodies))),
                _ => None,
            })
            .collect()
    }

    /// A model built from a `"dim": 3` description (its bodies are spatial kinds).
    pub fn is_spatial(&self) -> bool {
        self.bodies.iter().any(|b| matches!(b.kind, crate::body::BodyKind::Rigid3(_) | crate::body::BodyKind::Point3(_) | crate::body::BodyKind::Flexible3(_)))
    }

    /// Any body with stiffness-proportional damping (the scene is then truly stiff).
    pub fn has_damping(&self) -> bool {
        self.bodies.iter().any(|b| b.capabilities().damped)
    }
}

/// The top level of a description, items kept raw so that each is parsed with its own context.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDescription {
    /// 2 (planar; also when absent); 3 is built by `model::spatial`.
    #[serde(default)]
    #[allow(dead_code)]
    dim: Option<u32>,
    #[serde(default)]
    gravity: Option<Vec2>,
    bodies: Vec<Value>,
    #[serde(default)]
    joints: Vec<Value>,
    #[serde(default)]
    drivers: Vec<Value>,
    #[serde(default)]
    forces: Vec<Value>,
}

/// The four lists of a description.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Section {
    Body,
    Joint,
    Driver,
    Force,
}

impl Section {
    pub fn from_name(s: &str) -> Option<Section> {
        match s {
            "body" | "bodies" => Some(Section::Body),
            "joint" | "joints" => Some(Section::Joint),
            "driver" | "drivers" => Some(Section::Driver),
            "force" | "forces" => Some(Section::Force),
            _ => None,
        }
    }

    fn word(self) -> &'static str {
        match self {
            Section::Body => "body",
            Section::Joint => "joint",
            Section::Driver => "driver",
            Section::Force => "force",
        }
    }
}

/// How errors name an item: `body 'crank'`, `joint revolute 'pivot'`, `driver angle #0`.
pub fn item_name(section: Section, kind: &str, name: Option<&str>, index: usize) -> String {
    match (section, name) {
        (Section::Body, n) => format!("body '{}'", n.unwrap_or("")),
        (_, Some(n)) => format!("{} {kind} '{n}'", section.word()),
        (_, None) => format!("{} {kind} #{index}", section.word()),
    }
}

pub fn parse_json<T: DeserializeOwned>(item: &str, text: &str) -> Result<T> {
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de).map_err(|e| describe(item, e))
}

fn describe(item: &str, e: serde_path_to_error::Error<serde_json::Error>) -> Error {
    let path = clean_path(&e.path().to_string());
    let inner = e.into_inner().to_string();
    // "unknown field `x`, expected one of ..." / "invalid type: ... at line 1 column 9"
    let msg = match inner.find(" at line ") {
        Some(i) => inner[..i].to_string(),
        None => inner,
    }
    .replace('`', "'");
    let msg = plain_words(&msg);
    // an unknown field names itself: the path of its parent is the context
    let path = if msg.starts_with("unknown field") {
        path.rsplit_once('.').map(|(p, _)| p.to_string()).unwrap_or_default()
    } else {
        path
    };
    if path == "." || path.is_empty() {
        Error::invalid(item, msg)
    } else {
        Error::invalid(item, format!("{path}: {msg}"))
    }
}

/// serde's "invalid type: floating point '1e+30', expected usize" in the user's words:
/// "expected a whole number >= 0, got 1e+30".
fn plain_words(msg: &str) -> String {
    let Some(rest) = msg.strip_prefix("invalid type: ").or_else(|| msg.strip_prefix("invalid value: ")) else {
        return msg.to_string();
    };
    let Some((got, expected)) = rest.rsplit_once(", expected ") else {
        return msg.to_string();
    };
    let got = if let Some(v) = got.strip_prefix("floating point ").or_else(|| got.strip_prefix("integer ")) {
        v.trim_matches('\'').to_string()
    } else if let Some(v) = got.strip_prefix("boolean ") {
        v.trim_matches('\'').to_string()
    } else if got == "sequence" {
        "a list".to_string()
    } else if got == "map" {
        "a table".to_string()
    } else {
        got.to_string()
    };
    let expected = match expected {
        "usize" | "u64" | "u32" | "u16" | "u8" => "a whole number >= 0 (small enough to count with)",
        "f64" | "f32" => "a number",
        "a sequence" => "a list",
        "a boolean" => "true or false",
        other => other,
    };
    format!("expected {expected}, got {got}")
}

/// A field path as the user wrote it: the variant keys that `to_external` introduced (the
/// item's own, and those after `section` and `motion`) are dropped.
fn clean_path(path: &str) -> String {
    if path == "." || path.is_empty() {
        return String::new();
    }
    let segs: Vec<&str> = path.split('.').collect();
    let mut out: Vec<&str> = Vec::new();
    let mut skip_next = false;
    for (i, s) in segs.iter().enumerate() {
        if skip_next {
            skip_next = false;
            continue;
        }
        out.push(s);
        skip_next = i > 0 && (*s == "section" || *s == "motion");
    }
    out.join(".")
}

/// Check the top level of a description (its keys, gravity, that the item lists are lists).
pub fn check_top_level(text: &str) -> Result<()> {
    let raw: RawDescription = parse_json("scene", text)?;
    if let Some(g) = raw.gravity {
        check_finite_item("scene", "gravity", &g)?;
    }
    Ok(())
}

/// Parse one item of a section, errors naming the item (`index` is its position in the list).
pub fn parse_item<T: DeserializeOwned>(section: Section, index: usize, v: Value) -> Result<T> {
    let kind = v.get("kind").and_then(Value::as_str).unwrap_or("?").to_string();
    let name = v.get("name").and_then(Value::as_str).map(str::to_string);
    let item = item_name(section, &kind, name.as_deref(), index);
    if !v.is_object() {
        return Err(Error::invalid(&item, format!("expected a table/dict, got {v}")));
    }
    let what = if section == Section::Body { "kind".to_string() } else { format!("{} kind", section.word()) };
    if v.get("kind").is_none() {
        return Err(Error::invalid(&item, format!("missing {what}")));
    }
    serde_path_to_error::deserialize(to_external(v)).map_err(|e| {
        let inner = e.inner().to_string().replace('`', "'");
        if e.path().to_string() == "." && inner.starts_with("unknown variant") {
            let expected = inner.split("expected ").nth(1).unwrap_or("").to_string();
            return Error::invalid(&item, format!("unknown {what} '{kind}'; expected {expected}"));
        }
        describe(&item, e)
    })
    .map_err(|err| match err {
        // the first path segment is the item's own variant key
        Error::InvalidProperty { item, message } => {
            let message = match message.split_once('.') {
                Some((first, rest)) if first == kind && rest.contains(": ") => rest.to_string(),
                _ => message.strip_prefix(&format!("{kind}: ")).map(str::to_string).unwrap_or(message),
            };
            Error::InvalidProperty { item, message }
        }
        other => other,
    })
}

/// An item as it stands in a description (`{"kind": .., ..}`), from its parsed form.
pub fn item_to_json<T: serde::Serialize>(d: &T) -> Result<Value> {
    let v = serde_json::to_value(d).map_err(|e| Error::Description(e.to_string()))?;
    Ok(to_internal(v, "kind"))
}

/// Parse one item from JSON text (the Python scene builder's entry point).
pub fn parse_item_json<T: DeserializeOwned>(section: Section, index: usize, text: &str) -> Result<T> {
    let v: Value = serde_json::from_str(text).map_err(|e| Error::Description(e.to_string()))?;
    parse_item(section, index, v)
}

/// The name of a joint/driver/force: the given one (unique among `used`, else an error) or a
/// made-up `kind{index}` (made unique with `#k`). Shared by the planar and spatial builders.
pub fn take_name(used: &mut HashMap<String, usize>, item: &str, given: Option<&str>, default: String) -> Result<String> {
    if let Some(n) = given {
        if n.is_empty() {
            return Err(Error::invalid(item, "name must be a non-empty string"));
        }
        if used.contains_key(n) {
            return Err(Error::invalid(item, "duplicate name (joint, driver and force names must be unique)"));
        }
        used.insert(n.to_string(), 1);
        return Ok(n.to_string());
    }
    let k = used.entry(default.clone()).or_insert(0);
    *k += 1;
    Ok(if *k == 1 { default } else { format!("{default}#{k}") })
}

/// Number the constraints' rows consecutively (`Constraint::row`); returns `m` and the row
/// names (`name` or `name.suffix`). Shared by the planar and spatial builders.
pub fn assign_rows(constraints: &mut [Constraint]) -> (usize, Vec<String>) {
    let mut row = 0;
    let mut row_names = Vec::new();
    for c in constraints.iter_mut() {
        c.row = row;
        for s in c.row_suffixes() {
            row_names.push(if s.is_empty() { c.name.clone() } else { format!("{}.{s}", c.name) });
        }
        row += c.rows();
    }
    (row, row_names)
}

/// Builds a `Model` item by item; the only place where a scene is validated.
#[derive(Debug, Clone)]
pub struct ModelBuilder {
    gravity: Option<[f64; 2]>,
    pub bodies: Vec<Body>,
    index: HashMap<String, usize>,
    q0: Vec<f64>,
    qd0: Vec<f64>,
    coordinate_names: Vec<String>,
    pub joints: Vec<Constraint>,
    pub drivers: Vec<Constraint>,
    pub forces: Vec<Force>,
    /// Names of joints, drivers and forces (given or made up), for uniqueness.
    used_names: HashMap<String, usize>,
}

impl ModelBuilder {
    pub fn new(gravity: Option<[f64; 2]>) -> Result<ModelBuilder> {
        if let Some(g) = gravity {
            check_finite_item("scene", "gravity", &g)?;
        }
        Ok(ModelBuilder {
            gravity: gravity.filter(|g| g[0] != 0.0 || g[1] != 0.0),
            bodies: Vec::new(),
            index: HashMap::new(),
            q0: Vec::new(),
            qd0: Vec::new(),
            coordinate_names: Vec::new(),
            joints: Vec::new(),
            drivers: Vec::new(),
            forces: Vec::new(),
            used_names: HashMap::new(),
        })
    }

    pub fn add_body(&mut self, d: &BodyDesc) -> Result<&Body> {
        let name = d.name();
        if self.index.contains_key(name) {
            return Err(Error::invalid(format!("body '{name}'"), "duplicate body name"));
        }
        let (body, init) = Body::from_desc(d, self.q0.len())?;
        self.q0.extend_from_slice(&init.q);
        self.qd0.extend_from_slice(&init.qd);
        self.coordinate_names.extend(init.names.iter().map(|c| format!("{name}.{c}")));
        self.index.insert(name.to_string(), self.bodies.len());
        self.bodies.push(body);
        Ok(self.bodies.last().expect("just pushed"))
    }

    /// The name of a joint/driver/force (see [`take_name`]).
    fn take_name(&mut self, item: &str, given: Option<&str>, default: String) -> Result<String> {
        take_name(&mut self.used_names, item, given, default)
    }

    fn context(&self) -> BuildContext<'_> {
        BuildContext { bodies: &self.bodies, index: &self.index, q0: &self.q0, coordinate_names: &self.coordinate_names, joints: &self.joints }
    }

    pub fn add_joint(&mut self, d: &JointDesc) -> Result<&Constraint> {
        let j = self.joints.len();
        let item = item_name(Section::Joint, d.kind(), d.name(), j);
        let c = Constraint::from_joint(&self.context(), &item, String::new(), d)?;
        let name = self.take_name(&item, d.name(), format!("{}{j}", d.kind()))?;
        self.joints.push(Constraint { name, ..c });
        Ok(self.joints.last().expect("just pushed"))
    }

    pub fn add_driver(&mut self, d: &DriverDesc) -> Result<&Constraint> {
        let j = self.drivers.len();
        let item = item_name(Section::Driver, d.kind(), d.name(), j);
        let c = Constraint::from_driver(&self.context(), &item, String::new(), d)?;
        let name = self.take_name(&item, d.name(), format!("{}_driver{j}", d.kind()))?;
        self.drivers.push(Constraint { name, ..c });
        Ok(self.drivers.last().expect("just pushed"))
    }

    pub fn add_force(&mut self, d: &ForceDesc) -> Result<&Force> {
        let j = self.forces.len();
        let item = item_name(Section::Force, d.kind(), d.name(), j);
        let f = Force::from_desc(&self.context(), &self.joints, &item, String::new(), d)?;
        let name = self.take_name(&item, d.name(), format!("{}{j}", d.kind()))?;
        if let crate::force::ForceKind::Motor(m) = &f.kind {
            if m.rotor_inertia > 0.0 {
                let body = m.a.body.and_then(|b| self.bodies.get_mut(b));
                match body {
                    Some(b) => b.add_rotor_inertia(&item, m.rotor_inertia)?,
                    None => return Err(Error::invalid(&item, "a rotor inertia needs the rotor marker 'a' on a body, not the ground")),
                }
            }
        }
        self.forces.push(Force { name, ..f });
        Ok(self.forces.last().expect("just pushed"))
    }

    /// Number of coordinates so far.
    pub fn n_coords(&self) -> usize {
        self.q0.len()
    }

    pub fn finish(self) -> Result<Model> {
        if self.bodies.is_empty() {
            return Err(Error::Description("a scene needs at least one body".into()));
        }
        let mut constraints = self.joints;
        constraints.extend(self.drivers);
        let (row, row_names) = assign_rows(&mut constraints);
        Ok(Model {
            n: self.q0.len(),
            m: row,
            bodies: self.bodies,
            constraints,
            forces: self.forces,
            gravity: self.gravity,
            coordinate_names: self.coordinate_names,
            constraint_row_names: row_names,
            length_scale: 1.0,
            q0: self.q0,
            qd0: self.qd0,
        })
    }
}
