//! The dataset runner: resolves a configuration with its sweep, prepares the output folder,
//! makes and writes samples in parallel, keeps the manifest, resumes and shards.
//!
//! Layout of a dataset folder:
//! - `config.toml`: the resolved configuration (every key), `labels.json`: the label scheme;
//! - `train/` and `validation/`, or with the flat layout a folder per kind of file (`files`):
//!   per sample `{index}_{variant}_{level}.json` and its clouds (`_v{k}` per view when there
//!   are several views; `_scene` for the whole scan; images);
//! - `manifest.jsonl` (`manifest-{i}-of-{n}.jsonl` for shard i of n): one row per finished
//!   sample, sorted by index when the run ends;
//! - `dataset-card.md`: what the finished dataset holds, its classes' shares, use and licence.

mod card;
mod files;
mod folder;
mod gather;
mod passes;
mod rows;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use motorgen::Scheme;
use rayon::prelude::*;

use crate::augment::Split;
use crate::claim::{Claim, plain_dir};
use crate::config::{Combinations, Config, Layout, SceneKind, set_key};
use crate::error::{Error, Result};
use crate::pass::{Hall, Pass, make_pass};
use crate::recipe::Recipe;
use crate::sample::{Sample, make};

pub(crate) use files::SAMPLE_FOLDERS;
pub use files::sample_json;
pub(crate) use folder::{files_in, save};
use folder::{make_out, read_all_rows, unwritable, write_json, write_rows};
pub use rows::{Row, Shard, Summary};

/// A resolved dataset: its configuration and sweeps, size, shard and output folder.
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
/// let prepared = dataset.prepare(false)?; // claims the folder, writes config.toml, labels.json
/// let summary = dataset.run(prepared, &|row| println!("{} done", row.json), &|| false)?;
/// assert_eq!(summary.made, 4);
/// let manifest = std::fs::read_to_string(out.join("manifest.jsonl")).unwrap();
/// assert_eq!(manifest.lines().count(), 4);
/// # Ok::<(), scene::Error>(())
/// ```
pub struct Dataset {
    /// The recipe of the sweeps' first combination (the configuration itself without sweeps).
    base: Arc<Recipe>,
    /// The configuration table the sweeps are laid over.
    table: toml::Table,
    combinations: Combinations,
    /// Number of samples.
    pub samples: u64,
    /// The part this run makes.
    pub shard: Shard,
    /// Output folder.
    pub out: PathBuf,
    resolved: String,
    /// The halls of the LiDAR passes in flight (`cell.scene = "hall"`).
    halls: passes::Halls,
}

/// A made sample: a camera's, or a LiDAR pass with its hall.
enum Made {
    Sample(Box<Sample>),
    Pass(Box<Pass>, Arc<Hall>),
}

impl Made {
    fn index(&self) -> u64 {
        match self {
            Made::Sample(s) => s.index,
            Made::Pass(p, _) => p.index,
        }
    }
}

/// A prepared output folder: the run's claim on it, the samples of its shard already done, and
/// the first one to make, already made.
pub struct Prepared {
    claim: Claim,
    done: Vec<Row>,
    first: Mutex<Option<(Arc<Recipe>, Made)>>,
}

impl Prepared {
    /// The samples of this shard already in the folder's manifests, by index.
    pub fn done(&self) -> &[Row] {
        &self.done
    }
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
        let combinations = Combinations::new(&base.sweep)?;
        let resolved = format!(
            "# Resolved configuration of this dataset (every key; `motorfactory generate --config` \
             reads it back).\n{}",
            toml::to_string(&base).map_err(|e| Error::Config(e.to_string()))?
        );
        // the first combination stands for the dataset (its labels, sensor and memory); every
        // value of every sweep, and the first samples' combinations, are checked before anything
        // is written
        let first = combination(&table, &combinations, 0)?;
        for c in combinations
            .each_value()
            .chain(1..combinations.total().min(16))
        {
            combination(&table, &combinations, c)?;
        }
        Ok(Dataset {
            base: first,
            table,
            combinations,
            samples: base.samples,
            shard,
            out: out.to_path_buf(),
            resolved,
            halls: passes::Halls::default(),
        })
    }

    /// The recipe of sample `index`: its combination of the sweeps' values, if any.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] when that combination of values is not a valid configuration.
    pub fn recipe(&self, index: u64) -> Result<Arc<Recipe>> {
        if self.combinations.total() == 1 {
            Ok(self.base.clone())
        } else {
            combination(&self.table, &self.combinations, index)
        }
    }

    /// Memory a run with `jobs` worker threads needs at its peak, in bytes: per thread a
    /// sample's scans (each view's, when images or whole-scene clouds keep them) and its motor
    /// and world (16 MB), or in the hall a pass's returns twice over (the scan and its files'
    /// columns) and a hall kept ([`Dataset::hall_memory`], one more than the threads); and the
    /// manifest's rows (512 bytes a sample) kept to sort them.
    pub fn memory_needed(&self, jobs: usize) -> u64 {
        let c = &self.base.config;
        let views = if c.output.images.any() || c.output.scene_cloud {
            u64::from(c.camera.views)
        } else {
            1
        };
        let per_job = match self.base.hall_lidar() {
            Some(lidar) => {
                lidar.pass_memory() + self.hall_memory() * (jobs as u64 + 1) / jobs.max(1) as u64
            }
            None => views * self.sensor().scan_memory() + (16 << 20),
        };
        (jobs as u64)
            .saturating_mul(per_job)
            .saturating_add(self.shard_samples().saturating_mul(512))
            .saturating_add(32 << 20)
    }

    /// Memory a hall kept for its passes takes at most, in bytes: 16 MB and 2 MB a motor (its
    /// meshes and their share of the ray-casting tree), as many motors as `[cell.hall]` and
    /// `[cell.transfer]` allow.
    pub fn hall_memory(&self) -> u64 {
        let c = &self.base.config.cell;
        let (h, t) = (&c.hall, &c.transfer);
        let motors = h.stations[1] + h.transfer_units[1] * t.carriers[1] * t.motors[1];
        (16 << 20) + u64::from(motors) * (2 << 20)
    }

    /// The hall's LiDAR (of the sweeps' first combination), if the samples are its passes.
    pub fn lidar(&self) -> Option<&sensor::Lidar> {
        self.base.hall_lidar()
    }

    /// The sensor of the dataset's samples (of the sweeps' first combination), its sampling applied.
    pub fn sensor(&self) -> &sensor::SensorSpec {
        self.base.sensor()
    }

    /// The configuration table it was made from, its samples and seed set: a dataset made
    /// from it is this one.
    pub fn table(&self) -> &toml::Table {
        &self.table
    }

    /// The resolved configuration, as the dataset's `config.toml` holds it.
    pub fn resolved(&self) -> &str {
        &self.resolved
    }

    /// The label scheme of the dataset's samples.
    pub fn scheme(&self) -> Scheme {
        self.base.config.output.scheme
    }

    fn manifest(&self) -> PathBuf {
        self.out.join(self.shard.manifest_name())
    }

    /// Creates the folder, claims it for this run ([`Claim`]), and writes `config.toml` and
    /// `labels.json`; reads the samples of this shard already done (in any manifest of the
    /// folder) and removes the temporary files of runs that died. Refuses a folder holding
    /// another dataset, or samples of this shard without `resume`.
    ///
    /// # Errors
    ///
    /// [`Error::Output`] when the folder holds another dataset, holds samples of this shard
    /// and `resume` is false, or another run holds it; [`Error::Io`] when the folder or its
    /// first files cannot be written.
    pub fn prepare(&self, resume: bool) -> Result<Prepared> {
        let made = make_out(&self.out)?;
        let claim = Claim::take(&self.out, self.shard).map_err(|e| unwritable(&self.out, e))?;
        match self.prepare_claimed(&claim, resume) {
            Ok((done, first)) => Ok(Prepared {
                claim,
                done,
                first: Mutex::new(first),
            }),
            Err(e) => {
                if made {
                    // refused: what this run made goes again, if no other run is in the folder
                    claim.withdraw();
                }
                Err(unwritable(&self.out, e))
            }
        }
    }

    /// [`Dataset::prepare`] once the folder is claimed: the rows of this shard already done
    /// and its first sample to make, made.
    #[allow(clippy::type_complexity)]
    fn prepare_claimed(
        &self,
        claim: &Claim,
        resume: bool,
    ) -> Result<(Vec<Row>, Option<(Arc<Recipe>, Made)>)> {
        let out = &self.out;
        let unusable =
            |what: String| Error::Output(format!("output folder {}: {what}", out.display()));
        let config = out.join("config.toml");
        let same_config = || match std::fs::read_to_string(&config) {
            Ok(existing) if !same_dataset(&existing, &self.resolved) => Err(unusable(
                "holds a dataset of another configuration (its config.toml differs); choose \
                 another --out"
                    .into(),
            )),
            _ => Ok(()),
        };
        same_config()?;
        let shard = self.shard;
        let rows: Vec<Row> = read_all_rows(out)?
            .into_values()
            .filter(|r| r.index % shard.count == shard.part)
            .collect();
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
        // made before the shared files are touched, so that shards probe side by side
        let first = self.first_sample(&rows)?;
        let setup = claim.setup()?;
        same_config()?;
        save(&config, &|w| w.write_all(self.resolved.as_bytes()))?;
        let scheme = self.scheme();
        let labels = serde_json::json!({
            "scheme": scheme,
            "classes": scheme.classes(),
            "background": "everything the scheme names no class for (tables, fixtures, panels, conveyors, distractors) is class 0",
            "instances": "motor parts 1..k in build order (see each sample's objects), then the table, fixture parts and panels",
        });
        save(&out.join("labels.json"), &|w| write_json(w, &labels))?;
        let kind = self.base.config.output.yolo;
        if kind != crate::yolo::Yolo::Off {
            let folder = out.join(crate::yolo::FOLDER);
            plain_dir(&folder)?;
            let yaml = crate::yolo::data_yaml(scheme, kind);
            save(&folder.join("data.yaml"), &|w| w.write_all(yaml.as_bytes()))?;
        }
        if self.base.config.output.layout == Layout::SplitFolders {
            for split in [Split::Train, Split::Validation] {
                plain_dir(&out.join(split.name()))?;
            }
        }
        let mut dirs = vec![out.clone()];
        for folder in SAMPLE_FOLDERS {
            let dir = out.join(folder);
            if std::fs::symlink_metadata(&dir).is_ok() {
                plain_dir(&dir)?;
                dirs.push(dir);
            }
        }
        dirs.extend(files::bop_folders(out)?);
        claim.remove_stale_temporaries(&dirs)?;
        drop(setup);
        Ok((rows, first))
    }

    /// The first sample of this shard not in `done`, made to see that the configuration
    /// yields points at all.
    fn first_sample(&self, done: &[Row]) -> Result<Option<(Arc<Recipe>, Made)>> {
        let Shard { part, count } = self.shard;
        let have: std::collections::BTreeSet<u64> = done.iter().map(|r| r.index).collect();
        let Some(index) = (0..)
            .map(|k: u64| part + k * count)
            .take_while(|&i| i < self.samples)
            .find(|i| !have.contains(i))
        else {
            return Ok(None);
        };
        let recipe = self.recipe(index)?;
        let made = self.make(&recipe, index)?;
        match &made {
            Made::Sample(sample) if sample.views.iter().all(|v| v.cloud.is_empty()) => {
                return Err(Error::Config(why_empty(&recipe, sample)));
            }
            Made::Pass(pass, _) if pass.scan.returns.is_empty() => {
                return Err(crate::pass::why_empty(&recipe, pass));
            }
            _ => {}
        }
        Ok(Some((recipe, made)))
    }

    /// Makes sample `index` of `recipe`: a camera's sample, or in the hall a LiDAR pass.
    fn make(&self, recipe: &Recipe, index: u64) -> Result<Made> {
        if recipe.config.cell.scene == SceneKind::Hall {
            let hall = self.hall(recipe, index)?;
            Ok(Made::Pass(Box::new(make_pass(recipe, index, &hall)), hall))
        } else {
            make(recipe, index).map(|s| Made::Sample(Box::new(s)))
        }
    }

    /// The number of samples in this run's shard.
    pub fn shard_samples(&self) -> u64 {
        let Shard { part, count } = self.shard;
        self.samples.saturating_sub(part).div_ceil(count)
    }

    /// Makes every sample of the shard not done yet, with the current rayon pool; calls
    /// `finished` after each. The manifest gains each row once its files are in place, and is
    /// rewritten sorted by index at the end. Once `stop` says so, no new sample is begun: the
    /// ones in flight are finished, and the summary says the run stopped. The shard that
    /// finds the whole dataset done writes the merged `manifest.jsonl`.
    ///
    /// # Errors
    ///
    /// [`Error::Io`] when a sample's files or the manifest cannot be written; the
    /// samples finished before it stay in the manifest, so `resume` continues from there.
    pub fn run(
        &self,
        prepared: Prepared,
        finished: &(dyn Fn(&Row) + Sync),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<Summary> {
        let Prepared { claim, done, first } = prepared;
        let have: std::collections::BTreeSet<u64> = done.iter().map(|r| r.index).collect();
        let Shard { part, count } = self.shard;
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
        let stopped = std::sync::atomic::AtomicBool::new(false);
        let todo = usize::try_from(self.shard_samples()).map_err(|_| {
            Error::invalid(
                "samples",
                self.samples,
                "fewer samples than this machine counts",
            )
        })?;
        (0..todo)
            .into_par_iter()
            .with_max_len(1)
            .map(|k| part + k as u64 * count)
            .filter(|i| !have.contains(i))
            .try_for_each(|index| {
                if stop() {
                    stopped.store(true, std::sync::atomic::Ordering::Relaxed);
                    return Err(None);
                }
                let made = first
                    .lock()
                    .expect("first sample lock")
                    .take_if(|(_, s)| s.index() == index);
                let (recipe, made) = match made {
                    Some(made) => made,
                    None => {
                        let recipe = self.recipe(index).map_err(Some)?;
                        let made = self.make(&recipe, index).map_err(Some)?;
                        (recipe, made)
                    }
                };
                let row = match made {
                    Made::Sample(sample) => {
                        let row = self.write(&recipe, &sample).map_err(Some)?;
                        (*sample).recycle();
                        row
                    }
                    Made::Pass(pass, hall) => {
                        self.write_pass(&recipe, &pass, &hall).map_err(Some)?
                    }
                };
                let line = serde_json::to_string(&row).expect("rows serialise") + "\n";
                manifest
                    .lock()
                    .expect("manifest lock")
                    .write_all(line.as_bytes())
                    .map_err(|e| Some(Error::io(&manifest_path)(e)))?;
                finished(&row);
                rows.lock().expect("rows lock").push(row);
                Ok::<_, Option<Error>>(())
            })
            .or_else(|e| e.map_or(Ok(()), Err))?;
        let mut rows = rows.into_inner().expect("rows lock");
        rows.sort_by_key(|r| r.index);
        write_rows(&manifest_path, &rows)?;
        let stopped = stopped.into_inner();
        if !stopped && count > 1 {
            let _setup = claim.setup()?;
            let all = read_all_rows(&self.out)?;
            if (0..self.samples).all(|i| all.contains_key(&i)) {
                let all: Vec<Row> = all
                    .into_values()
                    .filter(|r| r.index < self.samples)
                    .collect();
                write_rows(&self.out.join("manifest.jsonl"), &all)?;
                self.gather(&all)?;
            }
        } else if !stopped {
            self.gather(&rows)?;
        }
        let mut summary = Summary {
            made: rows.len() as u64 - skipped,
            skipped,
            stopped,
            ..Summary::default()
        };
        for r in &rows {
            if r.points.iter().all(|&n| n == 0) {
                summary.empty.push(r.index);
            }
            summary.points += r.points.iter().sum::<usize>() as u64;
            if summary.class_counts.len() < r.class_counts.len() {
                summary.class_counts.resize(r.class_counts.len(), 0);
            }
            for (a, b) in summary.class_counts.iter_mut().zip(&r.class_counts) {
                *a += b;
            }
        }
        drop(claim);
        Ok(summary)
    }
}

/// The recipe of combination `c` of `combinations` laid over `table`.
fn combination(table: &toml::Table, combinations: &Combinations, c: u64) -> Result<Arc<Recipe>> {
    let combo = combinations.get(c);
    let mut t = table.clone();
    for (key, value) in &combo {
        set_key(&mut t, key, value.clone())?;
    }
    let config = Config::from_table(&t).map_err(|e| {
        let at: Vec<String> = combo.iter().map(|(k, v)| format!("{k} = {v}")).collect();
        Error::Config(format!("with sweep {}: {e}", at.join(", ")))
    })?;
    Ok(Arc::new(Recipe::new(config, combo)?))
}

/// Whether two resolved configurations make the same samples: equal but for `samples` (sample i
/// does not depend on how many there are, so a dataset can be extended).
fn same_dataset(a: &str, b: &str) -> bool {
    // keys added to the configuration since a folder was made take their defaults there
    let parse = |t: &str| {
        toml::from_str::<toml::Table>(t).ok().map(|t| {
            let mut full = crate::config::default_table();
            crate::config::overlay(&mut full, t);
            full.remove("samples");
            full
        })
    };
    parse(a).is_some_and(|a| Some(a) == parse(b))
}

fn to_toml_int(n: u64) -> Result<i64> {
    i64::try_from(n).map_err(|_| Error::invalid("number", n, "at most 2^63 - 1"))
}

/// Why `sample` holds no point: the sensor's range against the nearest surface in view.
fn why_empty(recipe: &Recipe, sample: &Sample) -> String {
    let sensor = &sample.sensor;
    let scheme = recipe.config.output.scheme;
    let range = format!(
        "the sensor ({}) measures depths (camera z) from {} to {} m",
        sensor.name, sensor.min_range, sensor.max_range
    );
    let nearest = sample
        .views
        .iter()
        .filter_map(|v| {
            let world = sensor::World::new(&sample.cell_of(v).targets(scheme));
            sensor::nearest_surface(&world, sensor, &v.pose)
        })
        .min_by(f32::total_cmp);
    let what = match nearest {
        None => format!("{range}, and no surface is in view; check camera"),
        Some(d) if !sensor.in_range(d) => format!(
            "{range}, and the nearest surface in view is {d:.3} m deep; set \
             camera.distance (or sensor.preset) so that the motor lies in range"
        ),
        Some(d) => format!(
            "{range}, and surfaces lie in range ({d:.3} m), but none in the crop box; check \
             [crop]"
        ),
    };
    format!("sample {} holds no point: {what}", sample.index)
}
