//! What the dataset runner's stages share: which samples a run makes (`Shard`), the manifest's
//! rows and what a run did.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

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

    pub(super) fn manifest_name(self) -> String {
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
    /// Whether the run was stopped before its shard was done.
    pub stopped: bool,
    /// Samples of the shard, with their indices, whose crops hold no point (every view).
    pub empty: Vec<u64>,
}
