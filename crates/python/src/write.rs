//! `motorfactory.write`: a dataset folder, as `motorfactory generate` writes it.

use std::path::PathBuf;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use scene::{Dataset, Shard};

use crate::generator::config_table;
use crate::{scene_error, work};

/// Writes the dataset folder `motorfactory generate` writes into `out`, byte for byte:
/// `config`, `overrides`, `seed` and `samples` as `Generator` takes them, `shard` `(i, n)` as
/// `--shard I/N` (the samples with `index % n == i`; the shard that finds every sample done
/// writes the merged `manifest.jsonl`) and `resume` as `--resume` (the samples a killed run
/// left are made, the finished ones kept). Returns the run's counts: `made`, `skipped`
/// (already done), `points` and `empty` (the samples that hold no point).
#[pyfunction]
#[pyo3(signature = (out, config = None, samples = None, seed = None, overrides = None, shard = (0, 1), resume = false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn write<'py>(
    py: Python<'py>,
    out: PathBuf,
    config: Option<&Bound<'py, PyAny>>,
    samples: Option<u64>,
    seed: Option<u64>,
    overrides: Option<&Bound<'py, PyDict>>,
    shard: (u64, u64),
    resume: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (part, count) = shard;
    if part >= count {
        return Err(PyValueError::new_err(format!(
            "shard = ({part}, {count}) is not allowed: expected (i, n) with 0 <= i < n"
        )));
    }
    let table = config_table(config, overrides)?;
    let dataset =
        Dataset::new(table, samples, seed, Shard { part, count }, &out).map_err(scene_error)?;
    let summary = work(py, || {
        let prepared = dataset.prepare(resume)?;
        dataset.run(prepared, &|_| {}, &|| false)
    })
    .map_err(scene_error)?;
    let counts = PyDict::new(py);
    counts.set_item("made", summary.made)?;
    counts.set_item("skipped", summary.skipped)?;
    counts.set_item("points", summary.points)?;
    counts.set_item("empty", summary.empty)?;
    Ok(counts)
}
