//! The dataset runner: resolves a configuration with its sweep, prepares the output folder,
//! makes and writes samples in parallel, keeps the manifest, resumes and shards.
//!
//! Layout of a dataset folder:
//! - `config.toml`: the resolved configuration (every key), `labels.json`: the label scheme;
//! - `train/` and `validation/`: per sample `{index}_{variant}_{level}.json` and its clouds
//!   (`_v{k}` per view when there are several views; `_scene` for the whole scan; images);
//! - `manifest.jsonl` (`manifest-{i}-of-{n}.jsonl` for shard i of n): one row per finished
//!   sample, sorted by index when the run ends.

use std::collections::BTreeMap;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use motorgen::export::write_atomic;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::config::{Config, set_key};
use crate::error::{Error, Result};
use crate::sample::{Recipe, Sample, make};

/// Which part of the samples a run makes: those with `index % count == part`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, from 0.
    pub part: u64,
    /// Number of shards.
    pub count: u64,
}

impl Shard {
    /// The whole dataset.
    pub const ALL: Shard = Shard { part: 0, count: 1 };

    /// Parses `I/N`.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] unless `text` is `I/N` with `0 <= I < N`.
    pub fn parse(text: &str) -> Result<Shard> {
        let bad = || Error::invalid("--shard", text, "I/N with 0 <= I < N, e.g. 0/4");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (part, count) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if part < count {
            Ok(Shard { part, count })
        } else {
            Err(bad())
        }
    }

    fn manifest_name(self) -> String {
        if self.count == 1 {
            "manifest.jsonl".into()
        } else {
            format!("manifest-{}-of-{}.jsonl", self.part, self.count)
        }
    }
}

/// One manifest row: a finished sample and its files (relative to the dataset folder).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Sample index.
    pub index: u64,
    /// train or validation.
    pub split: String,
    /// Augmentation level.
    pub level: String,
    /// Motor variant, or "motor".
    pub variant: String,
    /// Points of the cropped cloud per view.
    pub points: Vec<usize>,
    /// The sample's JSON.
    pub json: String,
    /// Every other file of the sample.
    pub files: Vec<String>,
    /// Points per class over all views, by class id.
    pub class_counts: Vec<u64>,
}

/// A resolved dataset: its recipes (one per sweep combination), size and output folder.
///
/// # Example
///
/// ```
/// use scene::{Dataset, Shard};
///
/// // 4 samples of the default configuration, written as `motorfactory generate` writes them
/// let out = std::env::temp_dir().join("dataset-doc-example");
/// # std::fs::remove_dir_all(&out).ok();
/// let table = scene::config::default_table();
/// let dataset = Dataset::new(table, Some(4), None, Shard::ALL, &out)?;
/// let done = dataset.prepare(false)?; // makes the folder, config.toml and labels.json
/// let summary = dataset.run(done, &|row| println!("{} done", row.json))?;
/// assert_eq!(summary.made, 4);
/// let manifest = std::fs::read_to_string(out.join("manifest.jsonl")).unwrap();
/// assert_eq!(manifest.lines().count(), 4);
/// # Ok::<(), scene::Error>(())
/// ```
pub struct Dataset {
    recipes: Vec<Recipe>,
    /// Number of samples.
    pub samples: u64,
    /// The part this run makes.
    pub shard: Shard,
    /// Output folder.
    pub out: PathBuf,
    resolved: String,
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Samples made by this run.
    pub made: u64,
    /// Samples already in the manifest when it started.
    pub skipped: u64,
    /// Points written (cropped clouds, all views).
    pub points: u64,
    /// Points per class id.
    pub class_counts: Vec<u64>,
}

impl Dataset {
    /// Resolves a configuration table (overrides already applied), checks every sweep
    /// combination, and remembers where it goes. Nothing is written.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] for a value the configuration does not allow (named
    /// by its dotted key), a sweep that does not apply, or counts that do not fit.
    pub fn new(
        mut table: toml::Table,
        samples: Option<u64>,
        seed: Option<u64>,
        shard: Shard,
        out: &Path,
    ) -> Result<Dataset> {
        if let Some(n) = samples {
            set_key(&mut table, "samples", toml::Value::Integer(to_toml_int(n)?))?;
        }
        if let Some(s) = seed {
            set_key(&mut table, "seed", toml::Value::Integer(to_toml_int(s)?))?;
        }
        let base = Config::from_table(&table)?;
        let mut combos: Vec<Vec<(String, toml::Value)>> = vec![Vec::new()];
        for sweep in &base.sweep {
            let values = sweep.values()?;
            combos = combos
                .into_iter()
                .flat_map(|c| {
                    values.iter().map(move |v| {
                        let mut c = c.clone();
                        c.push((sweep.key.clone(), v.clone()));
                        c
                    })
                })
                .collect();
            if combos.len() > 100_000 {
                return Err(Error::invalid(
                    "sweep",
                    format!("{} combinations", combos.len()),
                    "at most 100000 combinations",
                ));
            }
        }
        let recipes = combos
            .into_iter()
            .map(|combo| {
                let mut t = table.clone();
                for (key, value) in &combo {
                    if key.split('.').next() == Some("sweep") {
                        return Err(Error::invalid("sweep key", key, "a key outside [[sweep]]"));
                    }
                    set_key(&mut t, key, value.clone())?;
                }
                let config = Config::from_table(&t).map_err(|e| {
                    let at: Vec<String> = combo.iter().map(|(k, v)| format!("{k} = {v}")).collect();
                    Error::Config(format!("with sweep {}: {e}", at.join(", ")))
                })?;
                Recipe::new(config, combo)
            })
            .collect::<Result<Vec<_>>>()?;
        let resolved = format!(
            "# Resolved configuration of this dataset (every key; `motorfactory generate --config` \
             reads it back).\n{}",
            toml::to_string(&base).map_err(|e| Error::Config(e.to_string()))?
        );
        Ok(Dataset {
            recipes,
            samples: base.samples,
            shard,
            out: out.to_path_buf(),
            resolved,
        })
    }

    /// The recipe of sample `index`.
    pub fn recipe(&self, index: u64) -> &Recipe {
        &self.recipes[(index % self.recipes.len() as u64) as usize]
    }

    fn manifest(&self) -> PathBuf {
        self.out.join(self.shard.manifest_name())
    }

    /// Creates the folder and writes `config.toml` and `labels.json`; with `resume`, reads the
    /// rows already done. Refuses a folder holding another dataset, or this one without
    /// `resume`.
    ///
    /// # Errors
    ///
    /// [`Error::Output`] when the folder holds another dataset, or holds
    /// samples and `resume` is false; [`Error::Io`] when the folder or its first
    /// files cannot be written.
    pub fn prepare(&self, resume: bool) -> Result<Vec<Row>> {
        let out = &self.out;
        let unusable =
            |what: String| Error::Output(format!("output folder {}: {what}", out.display()));
        std::fs::create_dir_all(out).map_err(|e| unusable(e.to_string()))?;
        let config = out.join("config.toml");
        if let Ok(existing) = std::fs::read_to_string(&config)
            && !same_dataset(&existing, &self.resolved)
        {
            return Err(unusable(
                "holds a dataset of another configuration (its config.toml differs); choose \
                 another --out"
                    .into(),
            ));
        }
        let rows = read_rows(&self.manifest())?;
        if !rows.is_empty() && !resume {
            return Err(unusable(format!(
                "already holds {} samples of this dataset; pass --resume to finish or extend it",
                rows.len()
            )));
        }
        if let Some(last) = rows.last().filter(|r| r.index >= self.samples) {
            return Err(unusable(format!(
                "holds sample {}, beyond the {} asked for",
                last.index, self.samples
            )));
        }
        save(&config, &|w| w.write_all(self.resolved.as_bytes()))
            .map_err(|e| unusable(e.to_string()))?;
        let scheme = self.recipes[0].config.output.scheme;
        let labels = serde_json::json!({
            "scheme": scheme,
            "classes": scheme.classes(),
            "background": "table, fixture and mask panels are class 0",
            "instances": "motor parts 1..k in build order (see each sample's objects), then the table, fixture parts and panels",
        });
        save(&out.join("labels.json"), &|w| write_json(w, &labels))?;
        for split in ["train", "validation"] {
            let dir = out.join(split);
            std::fs::create_dir_all(&dir).map_err(|e| unusable(e.to_string()))?;
            remove_stale_temporaries(&dir, self.shard)?;
        }
        Ok(rows)
    }

    /// Makes every sample of the shard not in `done`, with the current rayon pool; calls
    /// `finished` after each. The manifest gains each row once its files are in place, and is
    /// rewritten sorted by index at the end.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] when a sample's files or the manifest cannot be written; the
    /// samples finished before it stay in the manifest, so `resume` continues from there.
    pub fn run(&self, done: Vec<Row>, finished: &(dyn Fn(&Row) + Sync)) -> Result<Summary> {
        let have: std::collections::BTreeSet<u64> = done.iter().map(|r| r.index).collect();
        let todo: Vec<u64> = (0..self.samples)
            .filter(|i| i % self.shard.count == self.shard.part && !have.contains(i))
            .collect();
        let manifest_path = self.manifest();
        // rewrite what is done (dropping a torn last line) before appending to it
        write_rows(&manifest_path, &done)?;
        let manifest = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&manifest_path)
            .map_err(Error::io(&manifest_path))?;
        let manifest = Mutex::new(manifest);
        let rows = Mutex::new(done);
        let skipped = have.len() as u64;
        todo.par_iter().with_max_len(1).try_for_each(|&index| {
            let sample = make(self.recipe(index), index)?;
            let row = self.write(&sample)?;
            let line = serde_json::to_string(&row).expect("rows serialise") + "\n";
            manifest
                .lock()
                .expect("manifest lock")
                .write_all(line.as_bytes())
                .map_err(Error::io(&manifest_path))?;
            finished(&row);
            rows.lock().expect("rows lock").push(row);
            Ok::<_, Error>(())
        })?;
        let mut rows = rows.into_inner().expect("rows lock");
        rows.sort_by_key(|r| r.index);
        write_rows(&manifest_path, &rows)?;
        let mut summary = Summary {
            made: rows.len() as u64 - skipped,
            skipped,
            ..Summary::default()
        };
        for r in &rows {
            summary.points += r.points.iter().sum::<usize>() as u64;
            if summary.class_counts.len() < r.class_counts.len() {
                summary.class_counts.resize(r.class_counts.len(), 0);
            }
            for (a, b) in summary.class_counts.iter_mut().zip(&r.class_counts) {
                *a += b;
            }
        }
        Ok(summary)
    }

    /// Writes a sample's files and returns its manifest row.
    fn write(&self, sample: &Sample) -> Result<Row> {
        let recipe = self.recipe(sample.index);
        let out = &recipe.config.output;
        let split = sample.split.name();
        let stem = sample.stem();
        let palette: Vec<[u8; 3]> = out.scheme.classes().iter().map(|c| c.color).collect();
        let many = sample.views.len() > 1;
        let mut files = Vec::new();
        let mut per_view = Vec::new();
        let mut class_counts = vec![0u64; palette.len()];
        for (k, view) in sample.views.iter().enumerate() {
            let view_stem = if many {
                format!("{stem}_v{k}")
            } else {
                stem.clone()
            };
            let mut names = Vec::new();
            let mut put = |name: String, body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>| {
                let rel = format!("{split}/{name}");
                save(&self.out.join(&rel), body)?;
                names.push(rel);
                Ok::<_, Error>(())
            };
            for f in &out.formats {
                put(f.file_name(&view_stem), &|w| {
                    f.write(w, &view.cloud, &palette)
                })?;
            }
            if let Some(cloud) = &view.scene_cloud {
                let f = out
                    .formats
                    .first()
                    .copied()
                    .unwrap_or(sensor::formats::CloudFormat::Ply);
                put(f.file_name(&format!("{view_stem}_scene")), &|w| {
                    f.write(w, cloud, &palette)
                })?;
            }
            if let Some(scan) = &view.scan {
                for (name, image) in sensor::formats::IMAGES {
                    put(format!("{view_stem}_{name}"), &|w| image(w, scan))?;
                }
            }
            for &c in &view.cloud.class {
                if let Some(n) = class_counts.get_mut(c as usize) {
                    *n += 1;
                }
            }
            files.extend(names.iter().cloned());
            per_view.push(names);
        }
        let json_rel = format!("{split}/{stem}.json");
        let doc = sample.json(recipe, &per_view);
        save(&self.out.join(&json_rel), &|w| {
            w.write_all(doc.to_text().as_bytes())
        })?;
        Ok(Row {
            index: sample.index,
            split: split.into(),
            level: sample.level.name().into(),
            variant: sample.variant.map_or("motor".into(), |v| format!("{v:?}")),
            points: sample.views.iter().map(|v| v.cloud.len()).collect(),
            json: json_rel,
            files,
            class_counts,
        })
    }
}

/// Whether two resolved configurations make the same samples: equal but for `samples` (sample i
/// does not depend on how many there are, so a dataset can be extended).
fn same_dataset(a: &str, b: &str) -> bool {
    let parse = |t: &str| {
        toml::from_str::<toml::Table>(t).ok().map(|mut t| {
            t.remove("samples");
            t
        })
    };
    parse(a).is_some_and(|a| Some(a) == parse(b))
}

fn to_toml_int(n: u64) -> Result<i64> {
    i64::try_from(n).map_err(|_| Error::invalid("number", n, "at most 2^63 - 1"))
}

/// Writes `body` to `path` through a temporary file and a rename.
fn save(path: &Path, body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    write_atomic(path, body).map_err(|e| match e {
        motorgen::Error::Io { path, source } => Error::Io { path, source },
        other => Error::Output(other.to_string()),
    })
}

fn write_json(w: &mut dyn Write, value: &serde_json::Value) -> std::io::Result<()> {
    serde_json::to_writer_pretty(&mut *w, value)?;
    w.write_all(b"\n")
}

/// Writes a manifest.
fn write_rows(path: &Path, rows: &[Row]) -> Result<()> {
    save(path, &|w| {
        for r in rows {
            serde_json::to_writer(&mut *w, r)?;
            w.write_all(b"\n")?;
        }
        Ok(())
    })
}

/// The rows of a manifest; a torn last line (a run killed while appending) is dropped, and a
/// sample listed twice counts once.
fn read_rows(path: &Path) -> Result<Vec<Row>> {
    let Ok(file) = std::fs::File::open(path) else {
        return Ok(Vec::new());
    };
    let mut rows = BTreeMap::new();
    for line in std::io::BufReader::new(file).lines() {
        let line = line.map_err(Error::io(path))?;
        if let Ok(row) = serde_json::from_str::<Row>(&line) {
            rows.insert(row.index, row);
        }
    }
    Ok(rows.into_values().collect())
}

/// Removes the temporary files a killed run of this shard left behind (those of other shards
/// sharing the folder may be in flight).
fn remove_stale_temporaries(dir: &Path, shard: Shard) -> Result<()> {
    for entry in std::fs::read_dir(dir).map_err(Error::io(dir))? {
        let path = entry.map_err(Error::io(dir))?.path();
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        let index = name.split('_').next().and_then(|i| i.parse::<u64>().ok());
        if name.ends_with(".tmp") && index.is_some_and(|i| i % shard.count == shard.part) {
            std::fs::remove_file(&path).map_err(Error::io(&path))?;
        }
    }
    Ok(())
}
