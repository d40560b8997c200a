//! A hall's LiDAR passes in a dataset: the halls kept while their passes are made (a hall is
//! built once for its run of passes, not once a pass), and a pass's files and manifest row.

use std::sync::{Arc, Mutex, OnceLock};

use sensor::formats::LidarFormat;

use super::files::placed;
use super::folder::{save, write_json};
use super::{Dataset, Row};
use crate::claim::plain_dir;
use crate::error::{Error, Result};
use crate::pass::{Hall, Pass, PassJson, hall_of, make_hall, make_pass};
use crate::recipe::Recipe;

/// A hall being built or built, shared by the workers making its passes.
type Slot = Arc<OnceLock<std::result::Result<Arc<Hall>, String>>>;

/// The halls of the passes in flight, by (hall, sweep combination), the most recent last.
#[derive(Default)]
pub(super) struct Halls {
    slots: Mutex<Vec<((u64, u64), Slot)>>,
}

impl Dataset {
    /// The hall of pass `index` of `recipe`: kept from an earlier pass or built (once, however
    /// many workers ask for it). The most recent halls are kept, one a worker and one more.
    pub(super) fn hall(&self, recipe: &Recipe, index: u64) -> Result<Arc<Hall>> {
        let number = hall_of(recipe, index);
        let key = (number, index % self.combinations.total());
        let slot = {
            let mut slots = self.halls.slots.lock().expect("halls lock");
            match slots.iter().position(|(k, _)| *k == key) {
                Some(i) => slots[i].1.clone(),
                None => {
                    let keep = rayon::current_num_threads() + 1;
                    if slots.len() >= keep {
                        slots.remove(0);
                    }
                    let slot = Slot::default();
                    slots.push((key, slot.clone()));
                    slot
                }
            }
        };
        slot.get_or_init(|| {
            make_hall(recipe, number)
                .map(Arc::new)
                .map_err(|e| e.to_string())
        })
        .clone()
        .map_err(Error::Config)
    }

    /// Pass `index` in memory (a LiDAR pass of the hall), with the JSON a run writes for it.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] unless the samples are the hall's passes, or when a motor's
    /// parameters drawn for its hall do not form a valid motor.
    pub fn pass(&self, index: u64) -> Result<(Pass, PassJson)> {
        let recipe = self.recipe(index)?;
        if recipe.hall_lidar().is_none() {
            return Err(Error::Config(
                "the samples are a camera's, not the hall's LiDAR passes".into(),
            ));
        }
        let hall = self.hall(&recipe, index)?;
        let pass = make_pass(&recipe, index, &hall);
        let names = pass_files(&recipe, &pass)
            .into_iter()
            .map(|f| f.0)
            .collect();
        let json = pass.json(&recipe, &hall, names);
        Ok((pass, json))
    }

    /// Writes a pass's files (`lidar.formats`, a camera's cloud format as `{stem}_cloud`) and
    /// its JSON, and returns its manifest row.
    pub(super) fn write_pass(&self, recipe: &Recipe, pass: &Pass, hall: &Hall) -> Result<Row> {
        let (out, lidar) = (&recipe.config.output, &recipe.config.lidar);
        let scale = out.units.scale();
        let files = pass_files(recipe, pass);
        let json_rel = placed(
            out.layout,
            pass.split,
            "json",
            &format!("{}.json", pass.stem()),
        );
        for rel in files.iter().map(|f| &f.0).chain([&json_rel]) {
            if let Some((folder, _)) = rel.rsplit_once('/') {
                plain_dir(&self.out.join(folder))?;
            }
        }
        for (rel, format, k) in &files {
            save(&self.out.join(rel), &|w| {
                format.write(*k, w, &pass.scan, lidar.frame, scale)
            })?;
        }
        let names: Vec<String> = files.into_iter().map(|(rel, _, _)| rel).collect();
        let doc = pass.json(recipe, hall, names.clone());
        let doc = serde_json::to_value(&doc).expect("a pass's JSON serialises");
        save(&self.out.join(&json_rel), &|w| write_json(w, &doc))?;
        let mut class_counts = vec![0u64; out.scheme.classes().len()];
        for r in &pass.scan.returns {
            if let Some(n) = class_counts.get_mut(usize::from(r.class)) {
                *n += 1;
            }
        }
        Ok(Row {
            index: pass.index,
            split: pass.split.name().into(),
            level: pass.level.name().into(),
            variant: "hall".into(),
            points: vec![pass.scan.returns.len()],
            json: json_rel,
            files: names,
            class_counts,
        })
    }
}

/// A pass's files, each its path relative to the dataset folder, its format and which of the
/// format's files it is.
fn pass_files(recipe: &Recipe, pass: &Pass) -> Vec<(String, LidarFormat, usize)> {
    let layout = recipe.config.output.layout;
    let stem = pass.stem();
    let mut files = Vec::new();
    for &format in &recipe.config.lidar.formats {
        let named = match format.cloud() {
            Some(_) => format!("{stem}_cloud"),
            None => stem.clone(),
        };
        for (k, name) in format.file_names(&named).into_iter().enumerate() {
            files.push((placed(layout, pass.split, folder(format), &name), format, k));
        }
    }
    files
}

/// The folder of a pass's file of `format` in the flat layout.
fn folder(format: LidarFormat) -> &'static str {
    match format {
        LidarFormat::BlensorNumpy => "numpy",
        LidarFormat::BlensorPcd | LidarFormat::PcdAscii => "pcd",
        other => other.name(),
    }
}
