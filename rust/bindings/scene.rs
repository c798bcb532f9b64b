//! `ukflex._core.SceneChecker` and the small module functions the Python scene builder uses.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{arg_err, to_py, InvalidSceneError};
use crate::description::{BodyDesc, DriverDesc, ForceDesc, JointDesc};
use crate::model::{parse_item_json, ModelBuilder, Section};

/// Validates a scene item by item with the core's own rules (the Python `Scene` builder calls
/// it for every item it adds, so no rule is written twice). Each `add_*` takes one item as
/// JSON text and returns what the core derived from it, or raises `InvalidSceneError` naming
/// the item.
#[pyclass(name = "SceneChecker", module = "ukflex._core")]
pub struct PySceneChecker {
    builder: ModelBuilder,
}

#[pymethods]
impl PySceneChecker {
    /// `gravity_json`: the scene's gravity vector as JSON text, or None.
    #[new]
    #[pyo3(signature = (gravity_json=None))]
    fn new(gravity_json: Option<&str>) -> PyResult<Self> {
        let gravity = match gravity_json {
            Some(text) => Some(crate::model::parse_json::<[f64; 2]>("scene: gravity", text).map_err(to_py)?),
            None => None,
        };
        Ok(PySceneChecker { builder: ModelBuilder::new(gravity).map_err(to_py)? })
    }

    /// Check the top level of a description (keys and types; item lists may be empty).
    #[staticmethod]
    fn check_top_level(description_json: &str) -> PyResult<()> {
        crate::model::check_top_level(description_json).map_err(to_py)
    }

    /// Add a body: returns {kind, n_coords, n_f, coordinate_names}.
    fn add_body<'py>(&mut self, py: Python<'py>, item_json: &str) -> PyResult<Bound<'py, PyDict>> {
        let index = self.builder.bodies.len();
        let d: BodyDesc = parse_item_json(Section::Body, index, item_json).map_err(to_py)?;
        let before = self.builder.n_coords();
        let body = self.builder.add_body(&d).map_err(to_py)?;
        let out = PyDict::new(py);
        out.set_item("item", to_json(&d)?)?;
        out.set_item("kind", body.kind_name())?;
        out.set_item("n_coords", body.n_coords)?;
        out.set_item("n_f", body.n_f())?;
        out.set_item("first_coordinate", before)?;
        Ok(out)
    }

    /// Add a joint: returns {name, rows, row_names, length (distance joints)}.
    fn add_joint<'py>(&mut self, py: Python<'py>, item_json: &str) -> PyResult<Bound<'py, PyDict>> {
        let index = self.builder.joints.len();
        let mut d: JointDesc = parse_item_json(Section::Joint, index, item_json).map_err(to_py)?;
        let c = self.builder.add_joint(&d).map_err(to_py)?;
        let out = constraint_info(py, c)?;
        c.fill_defaults(&mut d);
        out.set_item("item", to_json(&d)?)?;
        Ok(out)
    }

    /// Add a driver: returns {name, rows, row_names}.
    fn add_driver<'py>(&mut self, py: Python<'py>, item_json: &str) -> PyResult<Bound<'py, PyDict>> {
        let index = self.builder.drivers.len();
        let d: DriverDesc = parse_item_json(Section::Driver, index, item_json).map_err(to_py)?;
        let c = self.builder.add_driver(&d).map_err(to_py)?;
        let out = constraint_info(py, c)?;
        out.set_item("item", to_json(&d)?)?;
        Ok(out)
    }

    /// Add a force element: returns {name, rest_length (spring-dampers)}.
    fn add_force<'py>(&mut self, py: Python<'py>, item_json: &str) -> PyResult<Bound<'py, PyDict>> {
        let index = self.builder.forces.len();
        let mut d: ForceDesc = parse_item_json(Section::Force, index, item_json).map_err(to_py)?;
        let f = self.builder.add_force(&d).map_err(to_py)?;
        let out = PyDict::new(py);
        out.set_item("name", &f.name)?;
        f.fill_defaults(&mut d);
        out.set_item("item", to_json(&d)?)?;
        Ok(out)
    }

    /// Whole-scene checks (at least one body).
    fn finish(&self) -> PyResult<()> {
        self.builder.clone().finish().map(|_| ()).map_err(to_py)
    }
}

/// The normalized item (defaults filled in) as JSON text, in the description's form.
fn to_json<T: serde::Serialize>(d: &T) -> PyResult<String> {
    let v = crate::model::item_to_json(d).map_err(to_py)?;
    Ok(v.to_string())
}

/// How errors name a scene item (`body 'crank'`, `joint revolute 'pivot'`, `driver angle #0`).
#[pyfunction]
#[pyo3(signature = (section, kind, name, index))]
pub fn item_name(section: &str, kind: &str, name: Option<&str>, index: usize) -> PyResult<String> {
    let s = Section::from_name(section).ok_or_else(|| arg_err("section", format!("unknown section '{section}'")))?;
    Ok(crate::model::item_name(s, kind, name, index))
}

/// Number of elements of a 3D beam whose description gives none (`body::beam3`).
#[pyfunction]
pub fn beam3_default_elements() -> usize {
    crate::body::beam3::DEFAULT_ELEMENTS
}

/// The node of a 3D beam (`elements`, `length`) whose rigid segment holds the material point at
/// arc length `s`, and the point's offset from it along the axis (`body::beam3::material_point`).
#[pyfunction]
pub fn beam3_material_point(elements: usize, length: f64, s: f64) -> PyResult<(usize, f64)> {
    crate::body::beam3::material_point(elements, length, s).map_err(super::to_py)
}

/// Number of elastic coordinates of a beam with `elements` elements and reference `frame`.
#[pyfunction]
pub fn beam_elastic_dofs(elements: usize, frame: &str) -> PyResult<usize> {
    use crate::description::ReferenceConditions;
    let f: ReferenceConditions = serde_json::from_value(serde_json::Value::String(frame.to_string())).map_err(|_| {
        let words: Vec<String> = ReferenceConditions::ALL.iter().map(|w| format!("'{}'", w.word())).collect();
        InvalidSceneError::new_err(format!("unknown frame '{frame}'; expected one of {}", words.join(", ")))
    })?;
    crate::body::ffrf_beam::elastic_dofs(elements, f, "beam").map_err(super::to_py)
}

/// The words of the floating-frame option (`ReferenceConditions`), in order.
#[pyfunction]
pub fn frame_options() -> Vec<String> {
    crate::description::ReferenceConditions::ALL.iter().map(|f| f.word()).collect()
}

fn constraint_info<'py>(py: Python<'py>, c: &crate::constraint::Constraint) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("name", &c.name)?;
    out.set_item("rows", c.rows())?;
    let names: Vec<String> = c.row_suffixes().iter().map(|s| if s.is_empty() { c.name.clone() } else { format!("{}.{s}", c.name) }).collect();
    out.set_item("row_names", names)?;
    Ok(out)
}

