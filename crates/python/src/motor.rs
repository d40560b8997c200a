//! `motorfactory.motor` and the `Motor` and `Part` it gives: the add-on's parametric gear
//! motors built from Python, pickled as their parameters.

use std::path::PathBuf;

use glam::Vec3;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use motorgen::export::{earlier_output, write_motor};
use motorgen::{Detail, Dist, Format, MotorParams, ParamSpace, Scheme, build};

use crate::{json, motor_error, to_toml, vectors, work};

/// One part of a motor: a closed mesh with its labels (motor frame, metres).
#[pyclass(frozen, module = "motorfactory")]
pub(crate) struct Part {
    /// Unique name within the motor, e.g. `cover_bolt_2`.
    #[pyo3(get)]
    name: String,
    /// What it is, e.g. `cover`, `side_bolt`.
    #[pyo3(get)]
    kind: String,
    /// Its class id in the SynMotor labels (`synmotor7`: 1 cover, 2 gear container, 3 charger,
    /// 4 bottom, 5 side bolt, 6 cover bolt; 0 for parts that scheme does not label).
    #[pyo3(get)]
    class_id: u8,
    /// Instance id, unique within the motor, from 1.
    #[pyo3(get)]
    instance: u32,
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

/// A part of the given fields: how a pickled [`Part`] is made again.
#[pyfunction]
pub(crate) fn _part(
    name: String,
    kind: String,
    class_id: u8,
    instance: u32,
    vertices: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
) -> Part {
    Part {
        name,
        kind,
        class_id,
        instance,
        vertices: vertices.into_iter().map(Vec3::from).collect(),
        triangles,
    }
}

/// What pickling a [`Part`] stores: its fields.
type PartFields = (String, String, u8, u32, Vec<[f32; 3]>, Vec<[u32; 3]>);

#[pymethods]
impl Part {
    /// Pickles as its fields.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, PartFields)> {
        let remake = py.import("motorfactory._core")?.getattr("_part")?;
        let fields = (
            self.name.clone(),
            self.kind.clone(),
            self.class_id,
            self.instance,
            self.vertices.iter().map(|v| v.to_array()).collect(),
            self.triangles.clone(),
        );
        Ok((remake, fields))
    }

    /// Vertex positions, N×3 float32, metres.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        vectors(py, self.vertices.clone())
    }

    /// Vertex indices of each triangle, M×3 uint32, counter-clockwise seen from outside.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<u32> = self.triangles.iter().flatten().copied().collect();
        Ok(PyArray1::from_vec(py, flat)
            .reshape([self.triangles.len(), 3])?
            .into_any())
    }

    fn __repr__(&self) -> String {
        format!(
            "Part({}, {} vertices, {} triangles)",
            self.name,
            self.vertices.len(),
            self.triangles.len()
        )
    }
}

/// A built motor: its parts, parameters and ground truth.
#[pyclass(frozen, module = "motorfactory")]
pub(crate) struct Motor {
    motor: motorgen::Motor,
    detail: Detail,
}

/// A motor built from `params` (a `MotorParams` as JSON) at `detail` (as JSON): how a pickled
/// [`Motor`] is made again.
#[pyfunction]
pub(crate) fn _motor_from_params(py: Python<'_>, params: &str, detail: &str) -> PyResult<Motor> {
    let bad = |e: serde_json::Error| PyValueError::new_err(format!("a pickled motor: {e}"));
    let params: MotorParams = serde_json::from_str(params).map_err(bad)?;
    let detail: Detail = serde_json::from_str(detail).map_err(bad)?;
    let motor = work(py, || build(&params, detail));
    Ok(Motor { motor, detail })
}

#[pymethods]
impl Motor {
    /// Pickles as its parameters and detail: a copy in another process is built again from
    /// them, the same motor.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String, String))> {
        let remake = py
            .import("motorfactory._core")?
            .getattr("_motor_from_params")?;
        let params = serde_json::to_string(&self.motor.params).expect("parameters are JSON");
        let detail = serde_json::to_string(&self.detail).expect("a detail is JSON");
        Ok((remake, (params, detail)))
    }

    /// The parts, in the order `attributes["attributes"]["parts"]` lists them.
    #[getter]
    fn parts(&self) -> Vec<Part> {
        self.motor
            .parts
            .iter()
            .map(|p| Part {
                name: p.name.clone(),
                kind: serde_json::to_value(p.kind)
                    .ok()
                    .and_then(|v| v.as_str().map(String::from))
                    .unwrap_or_default(),
                class_id: Scheme::SynMotor.id(p.kind),
                instance: p.instance,
                vertices: p.mesh.positions.clone(),
                triangles: p.mesh.triangles.clone(),
            })
            .collect()
    }

    /// The motor's ground truth as `attributes.json` holds it: parameters and derived
    /// attributes (dimensions, parts with bounds, volumes, bolt positions).
    #[getter]
    fn attributes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json(py, &motorgen::export::motor_json(&self.motor).to_string())
    }

    /// The parameters the motor was built from, as `attributes.json` holds them.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let doc = motorgen::export::motor_json(&self.motor);
        json(py, &doc["params"].to_string())
    }

    /// Writes the motor to `folder` as `motorfactory motor` does: the whole motor and, with
    /// `per_part`, each part in every format of `formats` (`obj`, `stl`, `ply`, `glb`), and
    /// `attributes.json`. A folder holding an earlier motor is refused unless `replace`, which
    /// removes that motor's files first. Returns the paths written.
    #[pyo3(signature = (folder, formats = vec!["obj".to_string()], per_part = true, replace = false))]
    fn save(
        &self,
        py: Python<'_>,
        folder: PathBuf,
        formats: Vec<String>,
        per_part: bool,
        replace: bool,
    ) -> PyResult<Vec<PathBuf>> {
        let formats = formats
            .iter()
            .map(|f| Format::parse(f.trim()))
            .collect::<motorgen::Result<Vec<_>>>()
            .map_err(motor_error)?;
        work(py, || {
            let earlier = earlier_output(&folder, false).map_err(motor_error)?;
            if !earlier.is_empty() && !replace {
                return Err(PyValueError::new_err(format!(
                    "folder {} already holds a motor; pass replace=True to replace it, or \
                     choose another folder",
                    folder.display()
                )));
            }
            for path in earlier {
                std::fs::remove_file(&path)
                    .map_err(|e| PyOSError::new_err(format!("{}: {e}", path.display())))?;
            }
            write_motor(&self.motor, &folder, &formats, per_part).map_err(motor_error)
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Motor({}, {} parts)",
            self.motor.attributes.variant,
            self.motor.parts.len()
        )
    }
}

/// The default batch configuration of `motorfactory motor` and `motors`, whose `[params]` the
/// commands lay over their parameter space.
const MOTORS_CONFIG: &str = include_str!("../../../configs/motors.toml");

/// Builds a motor as `motorfactory motor` does (its defaults included). `params` fixes parameters (`{"type": "B", "gear_radius": 0.03}`) or gives
/// them distributions (`{"gear_radius": {"uniform": [0.025, 0.035]}}`), as `motorfactory motor
/// --set` does; the others keep their defaults, or with `random` are drawn from the add-on's
/// generator. `seed` draws what is random; `detail` is `coarse`, `normal` or `fine`. See
/// `motorfactory params` for every parameter.
#[pyfunction]
#[pyo3(signature = (params = None, seed = 0, random = false, detail = "normal"))]
pub(crate) fn motor(
    py: Python<'_>,
    params: Option<&Bound<'_, PyDict>>,
    seed: u64,
    random: bool,
    detail: &str,
) -> PyResult<Motor> {
    let mut space = if random {
        ParamSpace::addon()
    } else {
        ParamSpace::defaults()
    };
    // the command's defaults first (configs/motors.toml's `[params]`: Torx bolts)
    let batch: toml::Table = toml::from_str(MOTORS_CONFIG).expect("configs/motors.toml is TOML");
    if let Some(toml::Value::Table(defaults)) = batch.get("params") {
        for (key, value) in defaults {
            let dist = Dist::from_toml(key, value.clone()).map_err(motor_error)?;
            space.set(key, dist).map_err(motor_error)?;
        }
    }
    for (key, value) in params.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        let value = match to_toml(&key, &value)? {
            toml::Value::String(s) => Dist::from_cli(&key, &s),
            other => Dist::from_toml(&key, other),
        }
        .map_err(motor_error)?;
        space.set(&key, value).map_err(motor_error)?;
    }
    space.check().map_err(motor_error)?;
    let detail: Detail =
        serde_json::from_value(serde_json::Value::String(detail.into())).map_err(|_| {
            PyValueError::new_err(format!(
                "detail = \"{}\" is not allowed: expected coarse, normal or fine",
                motorgen::shown(detail)
            ))
        })?;
    let params = space.sample(seed).map_err(motor_error)?;
    let motor = work(py, || build(&params, detail));
    Ok(Motor { motor, detail })
}
