//! Augmentation levels and the validation split of the original datasets, assigned by sample
//! index so that every prefix of each motor variant's samples holds the configured shares.

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

/// The (level, split) cells in a fixed order, each with its share of the samples.
fn cells(a: &AugmentConfig) -> [((Level, Split), f64); 6] {
    let v = f64::from(a.validation);
    Level::ALL
        .map(|l| {
            let share = f64::from(l.config(a).share);
            [
                ((l, Split::Train), share * (1.0 - v)),
                ((l, Split::Validation), share * v),
            ]
        })
        .concat()
        .try_into()
        .expect("six cells")
}

/// Integer weights proportional to `shares`, summing to a period `d`: the smallest `d` up to
/// 10,000 at which every share is a whole number, else 10,000 with the largest remainders
/// rounded up.
fn weights(shares: [f64; 6]) -> ([u64; 6], u64) {
    const MOST: u64 = 10_000;
    let total: f64 = shares.iter().sum();
    let exact = (1..=MOST).find(|&d| {
        shares.iter().all(|s| {
            let x = s / total * d as f64;
            (x - x.round()).abs() < 1e-6
        })
    });
    let d = exact.unwrap_or(MOST);
    let scaled = shares.map(|s| s / total * d as f64);
    let mut w = scaled.map(|x| x.floor() as u64);
    let short = d - w.iter().sum::<u64>();
    let mut order: Vec<usize> = (0..6).collect();
    order.sort_by(|&i, &j| {
        (scaled[j] - scaled[j].floor()).total_cmp(&(scaled[i] - scaled[i].floor()))
    });
    for &i in order.iter().take(short as usize) {
        w[i] += 1;
    }
    (w, d)
}

/// The level and split of the `k`-th sample of its variant (`slot` numbers the variant, to vary
/// the order among variants). The cells (level × split) follow Tijdeman's solution of the
/// chairman assignment problem, so that in every prefix of a variant's samples each cell's count
/// is within one sample of its share (at most 1 − 1/(2m − 2) away, m cells): for every n,
/// each variant × level × split cell of the first n samples holds its target ±1.
pub fn assign(k: u64, slot: u64, a: &AugmentConfig) -> (Level, Split) {
    let cells = cells(a);
    let (w, d) = weights(cells.map(|(_, s)| s));
    let live: Vec<usize> = (0..6).filter(|&c| w[c] > 0).collect();
    let m = live.len() as u64;
    if m == 1 {
        return cells[live[0]].0;
    }
    // in units of 1/(d·(2m − 2)): a cell may be chosen at step t when its deficit
    // t·w/d − s reaches 1/(2m − 2), and the one whose deficit would reach 1 − 1/(2m − 2)
    // first, (s + 1 − 1/(2m − 2))/w smallest, is
    let q = 2 * m - 2;
    let mut s = [0u64; 6];
    let mut chosen = live[0];
    for t in 1..=(k % d) + 1 {
        let mut best: Option<(usize, u64)> = None;
        for r in 0..live.len() {
            let c = live[(r + slot as usize) % live.len()];
            let deficit = (t * w[c]) as i128 - (d * s[c]) as i128;
            if deficit * q as i128 >= d as i128 {
                let key = (s[c] + 1) * q - 1;
                let better = best.is_none_or(|(b, bk)| {
                    u128::from(key) * u128::from(w[b]) < u128::from(bk) * u128::from(w[c])
                });
                if better {
                    best = Some((c, key));
                }
            }
        }
        // (Tijdeman's theorem: some cell is always eligible; the largest deficit otherwise)
        chosen = best.map_or_else(
            || {
                *live
                    .iter()
                    .max_by_key(|&&c| (t * w[c]) as i128 - (d * s[c]) as i128)
                    .expect("a live cell")
            },
            |(c, _)| c,
        );
        s[chosen] += 1;
    }
    cells[chosen].0
}
