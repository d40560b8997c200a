//! The extension module `motorfactory._core` of the Python package: motors, scans and dataset
//! samples made in-process and handed to Python as numpy arrays (a sample's arrays take over
//! the Rust memory they were made in; a motor's and a scan's, which Python may read again, are
//! one copy of it), the GIL released while Rust works. Bad input raises `ValueError`, a failed
//! read or write `OSError`, with the messages of the command line.

mod generator;
mod motor;
mod station;
mod write;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use glam::Vec3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};

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

/// A configuration table as the dict `config` takes (laid over the default configuration,
/// every key of it given): what pickling a configured object stores.
fn table_dict<'py>(py: Python<'py>, table: &toml::Table) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(table).expect("a TOML table is JSON");
    json(py, &text)
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

/// Bytes a pixel takes in a pickled [`Scan`]: its fields in order, little-endian.
const PIXEL_BYTES: usize = 3 * 12 + 2 + 4 + 4 + 3 + 4 + 4 + 1 + 1;

/// A scan from its pickled bytes (see `Scan.__reduce__`): how a pickled [`Scan`] is made
/// again.
#[pyfunction]
fn _scan(
    size: (u32, u32),
    pose: [f32; 12],
    window: ((usize, usize), (usize, usize)),
    pixels: &[u8],
) -> PyResult<Scan> {
    let ((width, height), ((c0, c1), (r0, r1))) = (size, window);
    if pixels.len() != width as usize * height as usize * PIXEL_BYTES {
        return Err(PyValueError::new_err(
            "a pickled scan: its pixels are cut short",
        ));
    }
    let pixels = pixels
        .chunks_exact(PIXEL_BYTES)
        .map(|b| {
            let mut f = Fields(b);
            sensor::Pixel {
                point: f.vec3(),
                clean: f.vec3(),
                normal: f.vec3(),
                class: u16::from_le_bytes(f.bytes()),
                instance: u32::from_le_bytes(f.bytes()),
                intensity: f.f32(),
                rgb: f.bytes(),
                snr: f.f32(),
                incidence: f.f32(),
                wear: f.bytes::<1>()[0],
                indirect: f.bytes::<1>()[0],
            }
        })
        .collect();
    Ok(Scan {
        scan: sensor::Scan {
            width,
            height,
            pixels,
            pose: glam::Affine3A::from_cols_slice(&pose),
            window: sensor::Window {
                cols: c0..c1,
                rows: r0..r1,
            },
        },
    })
}

/// A pickled pixel's bytes, read field by field in order.
struct Fields<'a>(&'a [u8]);

impl Fields<'_> {
    fn bytes<const N: usize>(&mut self) -> [u8; N] {
        let (head, rest) = self.0.split_at(N);
        self.0 = rest;
        head.try_into().expect("N bytes")
    }

    fn f32(&mut self) -> f32 {
        f32::from_le_bytes(self.bytes())
    }

    fn vec3(&mut self) -> Vec3 {
        let x = self.f32();
        let y = self.f32();
        Vec3::new(x, y, self.f32())
    }
}

/// What pickling a [`Scan`] stores: its size, pose, window and pixels' bytes.
type ScanFields<'py> = (
    (u32, u32),
    [f32; 12],
    ((usize, usize), (usize, usize)),
    Bound<'py, PyBytes>,
);

#[pymethods]
impl Scan {
    /// Pickles as its pixels, every field, to the bit.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, ScanFields<'py>)> {
        let remake = py.import("motorfactory._core")?.getattr("_scan")?;
        let s = &self.scan;
        let mut bytes = Vec::with_capacity(s.pixels.len() * PIXEL_BYTES);
        for p in &s.pixels {
            for v in [p.point, p.clean, p.normal] {
                v.to_array()
                    .iter()
                    .for_each(|x| bytes.extend(x.to_le_bytes()));
            }
            bytes.extend(p.class.to_le_bytes());
            bytes.extend(p.instance.to_le_bytes());
            bytes.extend(p.intensity.to_le_bytes());
            bytes.extend(p.rgb);
            bytes.extend(p.snr.to_le_bytes());
            bytes.extend(p.incidence.to_le_bytes());
            bytes.extend([p.wear, p.indirect]);
        }
        let fields = (
            (s.width, s.height),
            s.pose.to_cols_array(),
            (
                (s.window.cols.start, s.window.cols.end),
                (s.window.rows.start, s.window.rows.end),
            ),
            PyBytes::new(py, &bytes),
        );
        Ok((remake, fields))
    }

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
    m.add_function(wrap_pyfunction!(motor::motor, m)?)?;
    m.add_function(wrap_pyfunction!(motor::_motor_from_params, m)?)?;
    m.add_function(wrap_pyfunction!(motor::_part, m)?)?;
    m.add_function(wrap_pyfunction!(_scan, m)?)?;
    // what unpickling calls, not offered: out of the names `import *` takes
    for name in ["_motor_from_params", "_part", "_scan"] {
        m.index()?.call_method1("remove", (name,))?;
    }
    m.add_function(wrap_pyfunction!(scan, m)?)?;
    m.add_function(wrap_pyfunction!(write::write, m)?)?;
    m.add_class::<motor::Motor>()?;
    m.add_class::<motor::Part>()?;
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
