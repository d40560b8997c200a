//! Augmentation levels and the validation split of the original datasets, assigned by sample
//! index so that every prefix of a dataset holds the configured shares.

use serde::{Deserialize, Serialize};

use crate::config::{AugmentConfig, LevelConfig};

/// An augmentation level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    /// "original": no panels, fixture at rest, low noise.
    Clean,
    /// "no-noise": panels and fixture shifts, low noise.
    Occluded,
    /// "noise": everything, higher noise, jitter after cropping.
    Noisy,
}

impl Level {
    /// All levels.
    pub const ALL: [Level; 3] = [Level::Clean, Level::Occluded, Level::Noisy];

    /// Name in file names and the manifest.
    pub fn name(self) -> &'static str {
        match self {
            Level::Clean => "clean",
            Level::Occluded => "occluded",
            Level::Noisy => "noisy",
        }
    }

    /// The level's settings.
    pub fn config(self, a: &AugmentConfig) -> &LevelConfig {
        match self {
            Level::Clean => &a.clean,
            Level::Occluded => &a.occluded,
            Level::Noisy => &a.noisy,
        }
    }
}

/// Training or validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    /// Training.
    Train,
    /// Validation.
    Validation,
}

impl Split {
    /// Folder name.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Validation => "validation",
        }
    }
}

/// Fractional part of `k·α`: a low-discrepancy sequence in [0, 1) (Weyl), so that the shares
/// hold closely in every prefix of the samples.
fn weyl(k: u64, alpha: f64) -> f64 {
    (k as f64 * alpha + 0.5).fract()
}

/// The level and split of the `k`-th sample of its variant. Levels and splits use two
/// independent irrational steps (golden ratio and √2), so each level has the validation share.
pub fn assign(k: u64, a: &AugmentConfig) -> (Level, Split) {
    let u = weyl(k, 0.618_033_988_749_894_9) as f32;
    let mut acc = 0.0;
    let level = Level::ALL
        .into_iter()
        .find(|l| {
            acc += l.config(a).share;
            u < acc
        })
        .or_else(|| {
            // rounding left u past the last share: the last level that has samples
            Level::ALL
                .into_iter()
                .rev()
                .find(|l| l.config(a).share > 0.0)
        })
        .unwrap_or(Level::Noisy);
    let split = if (weyl(k, std::f64::consts::SQRT_2 - 1.0) as f32) < a.validation {
        Split::Validation
    } else {
        Split::Train
    };
    (level, split)
}
