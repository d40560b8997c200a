//! `motorfactory.Generator`: a dataset configuration's samples made in memory, and the
//! configuration a user names (a built-in name, a TOML file or a dict, with overrides).

use std::borrow::Cow;
use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::exceptions::{PyIndexError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

use scene::{Dataset, Shard, make, parse_value, sample_json, set_key};
use sensor::PointCloud;

use crate::{cloud_dict, image_arrays, json, scene_error, table_dict, to_toml, work};

/// The configuration a user names: `config` a built-in configuration's name, a TOML file or a
/// dict laid over the default configuration (the default one for `None`), with `overrides`
/// setting dotted keys as `generate --set` does.
pub(crate) fn config_table(
    config: Option<&Bound<'_, PyAny>>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<toml::Table> {
    let mut table = match config {
        None => scene::config::default_table(),
        Some(c) if c.is_instance_of::<PyDict>() => {
            let toml::Value::Table(top) = to_toml("config", c)? else {
                unreachable!("a dict is a table")
            };
            let mut table = scene::config::default_table();
            scene::overlay(&mut table, top);
            table
        }
        Some(c) => {
            let name: PathBuf = c.extract().map_err(|_| {
                PyValueError::new_err("config is a configuration's name, a TOML file or a dict")
            })?;
            scene::config::named_table(&name.to_string_lossy())
                .map_err(|e| PyValueError::new_err(format!("config {e}")))?
        }
    };
    for (key, value) in overrides.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        let value = if value.is_instance_of::<PyString>() {
            parse_value(&value.extract::<String>()?)
        } else {
            to_toml(&key, &value)?
        };
        set_key(&mut table, &key, value).map_err(scene_error)?;
    }
    Ok(table)
}

/// Dataset samples made in memory: `Generator(config)[i]` is sample `i` of the configuration,
/// the values `motorfactory generate` writes for it.
#[pyclass(frozen, module = "motorfactory")]
pub(crate) struct Generator {
    dataset: Dataset,
}

impl Generator {
    fn sample<'py>(&self, py: Python<'py>, index: u64) -> PyResult<Bound<'py, PyDict>> {
        if self.dataset.lidar().is_some() {
            return self.pass(py, index);
        }
        let made = work(py, || {
            let recipe = self.dataset.recipe(index)?;
            let sample = make(&recipe, index)?;
            let json = sample_json(&recipe, &sample).to_text();
            // the views' clouds themselves, recoloured only where the configuration asks for
            // the class palette, and their scans when images are asked for
            let views: Vec<(PointCloud, Option<sensor::Scan>)> = sample
                .views
                .into_iter()
                .map(|v| {
                    let recoloured = match recipe.coloured(&v.cloud) {
                        Cow::Owned(c) => Some(c),
                        Cow::Borrowed(_) => None,
                    };
                    (recoloured.unwrap_or(v.cloud), v.scan)
                })
                .collect();
            Ok::<_, scene::Error>((views, json))
        });
        let (clouds, text) = made.map_err(scene_error)?;
        let views = PyList::empty(py);
        for (c, scan) in clouds {
            let d = cloud_dict(py, c)?;
            if let Some(scan) = scan {
                image_arrays(&d, &scan)?;
            }
            views.append(d)?;
        }
        // the first view's arrays at the top level too (the same arrays)
        let out = views.get_item(0)?.cast::<PyDict>()?.copy()?;
        out.set_item("views", views)?;
        out.set_item("json", json(py, &text)?)?;
        Ok(out)
    }

    /// Pass `index` of the hall: its measured points as a sample's arrays (in `lidar.frame`),
    /// with each return's `ring`, `time` (seconds from the pass's start) and `echo`, and `json`.
    fn pass<'py>(&self, py: Python<'py>, index: u64) -> PyResult<Bound<'py, PyDict>> {
        let made = work(py, || {
            let recipe = self.dataset.recipe(index)?;
            let (pass, doc) = self.dataset.pass(index)?;
            let cloud = pass.scan.cloud(doc.frame, doc.units.scale());
            let cloud = recipe.coloured(&cloud).into_owned();
            let r = &pass.scan.returns;
            let ring: Vec<u16> = r.iter().map(|x| x.laser).collect();
            let time: Vec<f32> = r.iter().map(|x| x.time).collect();
            let echo: Vec<u8> = r.iter().map(|x| x.echo).collect();
            let text = serde_json::to_value(&doc)
                .and_then(|v| serde_json::to_string(&v))
                .expect("a pass's JSON serialises");
            Ok::<_, scene::Error>((cloud, ring, time, echo, text))
        });
        let (cloud, ring, time, echo, text) = made.map_err(scene_error)?;
        let out = cloud_dict(py, cloud)?;
        out.set_item("ring", PyArray1::from_vec(py, ring))?;
        out.set_item("time", PyArray1::from_vec(py, time))?;
        out.set_item("echo", PyArray1::from_vec(py, echo))?;
        let views = PyList::empty(py);
        views.append(out.copy()?)?;
        out.set_item("views", views)?;
        out.set_item("json", json(py, &text)?)?;
        Ok(out)
    }

    /// The name of the split sample `index` belongs to.
    fn split_name(&self, index: u64) -> PyResult<&'static str> {
        let recipe = self.dataset.recipe(index).map_err(scene_error)?;
        Ok(recipe.placement(index).2.name())
    }
}

/// Checks that `split` names a split a configuration assigns samples to.
fn check_split(split: &str) -> PyResult<()> {
    if ["train", "validation"].contains(&split) {
        return Ok(());
    }
    Err(PyValueError::new_err(format!(
        "split = \"{}\" is not allowed: expected \"train\" or \"validation\"",
        motorgen::shown(split)
    )))
}

#[pymethods]
impl Generator {
    /// `config` is a built-in configuration's name (`default`, `synmotor`, `zivid`, ...), a
    /// TOML file, or a dict laid over the default configuration; `overrides` sets dotted keys
    /// (`{"camera.views": 2}`) as `generate --set` does, and `seed` the global seed.
    #[new]
    #[pyo3(signature = (config = None, seed = None, overrides = None, samples = None))]
    fn new(
        config: Option<&Bound<'_, PyAny>>,
        seed: Option<u64>,
        overrides: Option<&Bound<'_, PyDict>>,
        samples: Option<u64>,
    ) -> PyResult<Generator> {
        let table = config_table(config, overrides)?;
        let dataset =
            Dataset::new(table, samples, seed, Shard::ALL, "".as_ref()).map_err(scene_error)?;
        Ok(Generator { dataset })
    }

    /// Pickles as its configuration (every key, its seed and number of samples): a copy in
    /// another process makes the same samples.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyAny>,))> {
        let config = table_dict(py, slf.get().dataset.table())?;
        Ok((slf.get_type().into_any(), (config,)))
    }

    /// The configuration's number of samples.
    fn __len__(&self) -> usize {
        self.dataset.samples as usize
    }

    /// Sample `index` (negative counts from the end): for its first view the arrays `xyz`,
    /// `normal`, `intensity`, `snr`, `rgb`, `label` and `instance` as its `.npz` holds them,
    /// `views` with those of every view, and `json`, its JSON as a dict. A hall's pass adds
    /// each return's `ring`, `time` and `echo`.
    fn __getitem__<'py>(&self, py: Python<'py>, index: i64) -> PyResult<Bound<'py, PyDict>> {
        let n = self.dataset.samples as i64;
        let i = if index < 0 { index + n } else { index };
        if !(0..n).contains(&i) {
            return Err(PyIndexError::new_err(format!(
                "sample {index} is out of range: the configuration has {n} samples"
            )));
        }
        self.sample(py, i as u64)
    }

    /// Sample `index`, any index (beyond `len()` too: sample i does not depend on the count).
    fn sample_at<'py>(&self, py: Python<'py>, index: u64) -> PyResult<Bound<'py, PyDict>> {
        self.sample(py, index)
    }

    /// The indices of the samples in `split` (`train` or `validation`, as the configuration's
    /// `augment.validation` share assigns them), or of every sample with `None`.
    #[pyo3(signature = (split = None))]
    fn indices(&self, py: Python<'_>, split: Option<&str>) -> PyResult<Vec<u64>> {
        if let Some(s) = split {
            check_split(s)?;
        }
        work(py, || {
            let mut out = Vec::new();
            for i in 0..self.dataset.samples {
                if split.is_none() || split == Some(self.split_name(i)?) {
                    out.push(i);
                }
            }
            Ok(out)
        })
    }

    /// The split (`train` or `validation`) sample `index` belongs to, any index (beyond `len()`
    /// too): what a stream of one split keeps.
    fn split_of(&self, index: u64) -> PyResult<&'static str> {
        self.split_name(index)
    }

    /// The label scheme's class names, by id.
    #[getter]
    fn classes(&self) -> Vec<&'static str> {
        self.dataset
            .scheme()
            .classes()
            .iter()
            .map(|c| c.name)
            .collect()
    }

    /// The resolved configuration, as `config.toml` of a dataset holds it (TOML text).
    #[getter]
    fn config(&self) -> String {
        self.dataset.resolved().to_string()
    }

    fn __repr__(&self) -> String {
        format!("Generator({} samples)", self.dataset.samples)
    }
}
