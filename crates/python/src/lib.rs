//! The extension module `motorfactory._core` of the Python package: motors, scans and dataset
//! samples made in-process and handed to Python as numpy arrays (a sample's arrays take over
//! the Rust memory they were made in; a motor's and a scan's, which Python may read again, are
//! one copy of it), the GIL released while Rust works. Bad input raises `ValueError`, a failed
//! read or write `OSError`, with the messages of the command line.

mod generator;
mod station;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use glam::Vec3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use motorgen::export::{earlier_output, write_motor};
use motorgen::{Detail, Dist, Format, ParamSpace, Scheme, build};
use sensor::{Material, PointCloud, Target, World, look_at};

/// The extension's own allocator: a sample's buffers (tens of MB, made and freed on the thread
/// pool's threads) are reused from sample to sample, where the host's malloc maps and faults them
/// in anew each time.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Runs `f` with the GIL released, its parallel work on this process's own thread pool. A
/// DataLoader's workers are forked from the process that made samples before, and a forked
/// child has none of its parent's threads: a pool made before the fork would wait for them
/// forever, so each process (by id) makes its own when it first needs one.
fn work<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> T {
    static POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);
    let pool = {
        let mut held = POOL.lock().unwrap_or_else(|e| e.into_inner());
        match &*held {
            Some((pid, pool)) if *pid == std::process::id() => pool.clone(),
            _ => {
                let pool = Arc::new(
                    rayon::ThreadPoolBuilder::new()
                        .build()
                        .expect("a thread pool"),
                );
                // the parent's pool, in a forked child: its threads are not there to stop
                if let Some(stale) = held.replace((std::process::id(), pool.clone())) {
                    std::mem::forget(stale);
                }
                pool
            }
        }
    };
    py.detach(|| pool.install(f))
}

/// A motorgen error as the Python exception a user expects: `OSError` for a file, else
/// `ValueError`.
fn motor_error(e: motorgen::Error) -> PyErr {
    match e {
        motorgen::Error::Io { .. } => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// A scene error as a Python exception: `ValueError` for a configuration or output location,
/// `OSError` for a failed read or write.
fn scene_error(e: scene::Error) -> PyErr {
    if e.is_usage() {
        PyValueError::new_err(e.to_string())
    } else {
        PyOSError::new_err(e.to_string())
    }
}

/// `text` parsed by Python's `json` module: the values a JSON file holds, as Python sees them.
fn json<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// A Python value as a TOML value (bool, int, float, str, list, dict), for parameters and
/// configuration overrides; `key` names it in the error.
fn to_toml(key: &str, value: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    let bad = || {
        PyValueError::new_err(format!(
            "{key}: a {} is not allowed: expected a bool, int, float, str, list or dict",
            value
                .get_type()
                .name()
                .map_or("value".into(), |n| n.to_string())
        ))
    };
    Ok(if let Ok(b) = value.extract::<bool>() {
        toml::Value::Boolean(b)
    } else if let Ok(i) = value.extract::<i64>() {
        toml::Value::Integer(i)
    } else if let Ok(f) = value.extract::<f64>() {
        toml::Value::Float(f)
    } else if let Ok(s) = value.extract::<String>() {
        toml::Value::String(s)
    } else if let Ok(d) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in d.iter() {
            let k: String = k.extract().map_err(|_| bad())?;
            let v = to_toml(&format!("{key}.{k}"), &v)?;
            table.insert(k, v);
        }
        toml::Value::Table(table)
    } else if let Ok(items) = value.try_iter() {
        toml::Value::Array(
            items
                .map(|v| to_toml(key, &v?))
                .collect::<PyResult<Vec<_>>>()?,
        )
    } else {
        return Err(bad());
    })
}

/// Row-major N×3 float32 array of `v`, in `v`'s memory (no copy).
fn vectors<'py>(py: Python<'py>, v: Vec<Vec3>) -> PyResult<Bound<'py, PyAny>> {
    let n = v.len();
    let flat: Vec<f32> = bytemuck::allocation::cast_vec(v);
    Ok(PyArray1::from_vec(py, flat).reshape([n, 3])?.into_any())
}

/// A cloud's arrays as a dict: `xyz`, `normal` (N×3 float32), `intensity`, `snr` (float32),
/// `rgb` (N×3 uint8), `label` (uint16), `instance` (uint32), as the `.npz` files hold them.
/// The arrays take over the cloud's memory.
fn cloud_dict(py: Python<'_>, c: PointCloud) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    let n = c.len();
    d.set_item("xyz", vectors(py, c.xyz)?)?;
    d.set_item("normal", vectors(py, c.normal)?)?;
    d.set_item("intensity", PyArray1::from_vec(py, c.intensity))?;
    d.set_item("snr", PyArray1::from_vec(py, c.snr))?;
    let rgb: Vec<u8> = bytemuck::allocation::cast_vec(c.rgb);
    d.set_item("rgb", PyArray1::from_vec(py, rgb).reshape([n, 3])?)?;
    d.set_item("label", PyArray1::from_vec(py, c.class))?;
    d.set_item("instance", PyArray1::from_vec(py, c.instance))?;
    d.set_item("wear", PyArray1::from_vec(py, c.wear))?;
    Ok(d)
}

/// A scan's images into `d`, as `rgb.png`, `labels.png` and `instances.png` hold them:
/// `image` (H×W×3 uint8 sRGB), `image_label` (H×W uint16) and `image_instance` (H×W uint32),
/// each pixel's surface under its centre.
fn image_arrays(d: &Bound<'_, PyDict>, scan: &sensor::Scan) -> PyResult<()> {
    let py = d.py();
    let (w, h) = (scan.width as usize, scan.height as usize);
    let rgb: Vec<u8> = scan.pixels.iter().flat_map(|p| p.rgb).collect();
    d.set_item("image", PyArray1::from_vec(py, rgb).reshape([h, w, 3])?)?;
    let class: Vec<u16> = scan.pixels.iter().map(|p| p.class).collect();
    d.set_item(
        "image_label",
        PyArray1::from_vec(py, class).reshape([h, w])?,
    )?;
    let instance: Vec<u32> = scan.pixels.iter().map(|p| p.instance).collect();
    d.set_item(
        "image_instance",
        PyArray1::from_vec(py, instance).reshape([h, w])?,
    )?;
    Ok(())
}

/// One part of a motor: a closed mesh with its labels (motor frame, metres).
#[pyclass(frozen, module = "motorfactory")]
struct Part {
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

#[pymethods]
impl Part {
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
struct Motor {
    motor: motorgen::Motor,
}

#[pymethods]
impl Motor {
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
fn motor(
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
    Ok(Motor { motor })
}

/// A scan: the sensor's organized image, pixel by pixel (rows × columns).
#[pyclass(frozen, module = "motorfactory")]
struct Scan {
    scan: sensor::Scan,
}

impl Scan {
    /// `f` of every pixel as a rows × columns (× 3 for vectors) array.
    fn image<'py, T: numpy::Element>(
        &self,
        py: Python<'py>,
        f: impl Fn(&sensor::Pixel) -> T,
    ) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<T> = self.scan.pixels.iter().map(f).collect();
        let shape = [self.scan.height as usize, self.scan.width as usize];
        Ok(PyArray1::from_vec(py, v).reshape(shape)?.into_any())
    }

    /// `f` of every pixel as a rows × columns × 3 float32 array.
    fn vector_image<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&sensor::Pixel) -> Vec3,
    ) -> PyResult<Bound<'py, PyAny>> {
        let v: Vec<f32> = self
            .scan
            .pixels
            .iter()
            .flat_map(|p| f(p).to_array())
            .collect();
        let shape = [self.scan.height as usize, self.scan.width as usize, 3];
        Ok(PyArray1::from_vec(py, v).reshape(shape)?.into_any())
    }
}

#[pymethods]
impl Scan {
    /// Measured points, camera frame, metres; NaN where a pixel has none.
    #[getter]
    fn xyz<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.vector_image(py, |p| p.point)
    }

    /// Surface normals, camera frame (NaN where no surface).
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.vector_image(py, |p| p.normal)
    }

    /// Depth (camera z) of the measured points, metres; NaN where a pixel has none.
    #[getter]
    fn depth<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.image(py, |p| p.point.z)
    }

    /// Class of the surface each pixel sees (0 where none), uint16.
    #[getter]
    fn label<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.image(py, |p| p.class)
    }

    /// Instance of the surface each pixel sees (0 where none), uint32.
    #[getter]
    fn instance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.image(py, |p| p.instance)
    }

    /// Signal each pixel receives, float32.
    #[getter]
    fn intensity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.image(py, |p| p.intensity)
    }

    /// Camera-to-world pose, a 4×4 float32 matrix.
    #[getter]
    fn pose<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = glam::Mat4::from(self.scan.pose).transpose().to_cols_array();
        Ok(PyArray1::from_vec(py, m.to_vec())
            .reshape([4, 4])?
            .into_any())
    }

    /// The valid points as a dict of arrays (`xyz`, `normal`, `intensity`, `snr`, `rgb`,
    /// `label`, `instance`), camera frame, metres, in pixel order.
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let cloud = work(py, || {
            self.scan
                .cloud(false, sensor::Frame::Camera, sensor::Units::Metres)
        });
        cloud_dict(py, cloud)
    }

    fn __repr__(&self) -> String {
        format!(
            "Scan({}x{}, {} points)",
            self.scan.width,
            self.scan.height,
            self.scan.valid_count()
        )
    }
}

/// The targets of one mesh given to [`scan`]: a file (OBJ, STL, PLY), or a tuple (vertices N×3,
/// triangles M×3, class, instance); instances are numbered on from the meshes before.
fn targets(mesh: &Bound<'_, PyAny>, material: Material, offset: u32) -> PyResult<Vec<Target>> {
    let mut out = if let Ok(tuple) = mesh.cast::<PyTuple>() {
        let (vertices, triangles, class, instance): (
            PyReadonlyArray2<'_, f32>,
            PyReadonlyArray2<'_, u32>,
            u16,
            u32,
        ) = tuple.extract().map_err(|_| {
            PyValueError::new_err(
                "a mesh tuple is (vertices: N×3 float32, triangles: M×3 uint32, class, \
                 instance)",
            )
        })?;
        let (v, t) = (vertices.as_array(), triangles.as_array());
        if v.ncols() != 3 || t.ncols() != 3 {
            return Err(PyValueError::new_err(
                "a mesh's vertices and triangles must have 3 columns",
            ));
        }
        let positions: Vec<Vec3> = v
            .rows()
            .into_iter()
            .map(|r| Vec3::new(r[0], r[1], r[2]))
            .collect();
        let mut tris = Vec::with_capacity(t.nrows());
        for r in t.rows() {
            let corner = |i: u32| {
                positions.get(i as usize).copied().ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "a mesh's triangle uses vertex {i}: it has {}",
                        positions.len()
                    ))
                })
            };
            tris.push([corner(r[0])?, corner(r[1])?, corner(r[2])?]);
        }
        vec![Target::from_triangles(&tris, class, instance, material)]
    } else {
        let path: PathBuf = mesh.extract().map_err(|_| {
            PyValueError::new_err(
                "a mesh is a file path or a (vertices, triangles, class, instance) tuple",
            )
        })?;
        let mut read = sensor::mesh::read(&path).map_err(|e| PyOSError::new_err(e.to_string()))?;
        for t in &mut read {
            t.material = material;
            t.instance += offset;
        }
        read
    };
    for t in &mut out {
        t.material = material;
    }
    Ok(out)
}

/// Scans `meshes` (file paths, or (vertices, triangles, class, instance) tuples, in metres)
/// with `sensor` (a preset or a sensor TOML file) from a camera at `eye` looking at `target`,
/// `up` up, as `motorfactory scan` does; `sampling` one of Zivid's names the sensor offers (`all`;
/// `blueSubsample2x2`, `blueSubsample4x4`, … on the Zivid 2+ M and L; `by2x2`, `by4x4` on the R
/// line), `material` a name from the material library.
#[pyfunction]
#[pyo3(signature = (meshes, sensor = "zivid-2plus-m130", eye = (0.0, -0.6, 0.6), target = (0.0, 0.0, 0.0), up = (0.0, 0.0, 1.0), seed = 0, sampling = "all", material = "grey-plastic"))]
#[allow(clippy::too_many_arguments)]
fn scan(
    py: Python<'_>,
    meshes: &Bound<'_, PyList>,
    sensor: &str,
    eye: (f32, f32, f32),
    target: (f32, f32, f32),
    up: (f32, f32, f32),
    seed: u64,
    sampling: &str,
    material: &str,
) -> PyResult<Scan> {
    let spec = scene::config::read_sensor(sensor).map_err(|e| match e {
        scene::Error::Io { .. } => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(format!("sensor {e}")),
    })?;
    let sampling: sensor::Sampling = sampling
        .parse()
        .map_err(|e| PyValueError::new_err(format!("{e}")))?;
    let spec = spec
        .sampled(sampling)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    spec.validate()
        .map_err(|e| PyValueError::new_err(format!("sensor {sensor}: {e}")))?;
    let material = Material::named(material).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let pose = look_at(Vec3::from(eye), Vec3::from(target), Vec3::from(up))
        .ok_or_else(|| PyValueError::new_err("eye and target must differ"))?;
    let mut all = Vec::new();
    for mesh in meshes.iter() {
        let offset = all.iter().map(|t: &Target| t.instance).max().unwrap_or(0);
        all.extend(targets(&mesh, material, offset)?);
    }
    let scan = work(py, || sensor::scan(&World::new(&all), &spec, &pose, seed));
    Ok(Scan { scan })
}

/// The package's extension module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(motor, m)?)?;
    m.add_function(wrap_pyfunction!(scan, m)?)?;
    m.add_class::<Motor>()?;
    m.add_class::<Part>()?;
    m.add_class::<Scan>()?;
    m.add_class::<generator::Generator>()?;
    m.add_class::<station::Station>()?;
    m.add("PRESETS", sensor::PRESETS.to_vec())?;
    m.add(
        "CONFIGS",
        scene::config::BUILTIN
            .iter()
            .map(|(n, _)| *n)
            .collect::<Vec<_>>(),
    )?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
