//! Augmentation levels and the validation split of the original datasets, and the motor
//! variants, assigned by sample index: in every prefix of the samples each split and each level
//! is within one sample of its share, validation comes spread (at most two in a row at shares
//! up to a half) and in every shard, and over each full period every variant gets its exact
//! share of every level and split.

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

/// The (level, split) cells in a fixed order (cell `2 l + s`), each with its share.
fn cells(a: &AugmentConfig) -> [f64; 6] {
    let v = f64::from(a.validation);
    Level::ALL
        .map(|l| {
            let share = f64::from(l.config(a).share);
            [share * (1.0 - v), share * v]
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

/// Where a sample falls: its variant (a slot of `motor.variants`, 0 without them), level and
/// split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Place {
    /// The variant's slot.
    pub slot: u32,
    /// The augmentation level.
    pub level: Level,
    /// The split.
    pub split: Split,
}

/// The place of sample `index` among `variants` slots (1 without variants).
///
/// The samples come in blocks of `variants × d` (`d` the period of the level × split weights),
/// each laid out step by step: the split keeps both splits' counts within one sample of their
/// shares (where both may come, validation's place is drawn uniformly, seeded by the block,
/// over the steps left before it must come, so that it is spread and falls into every shard);
/// the level keeps its count within the split within one sample of its share there, preferring
/// a level that keeps every level's count overall within one sample of its share, then the
/// level furthest behind; the
/// variant is the one with the fewest samples of that level and split (each variant gets its
/// exact share of every cell per block), the one furthest behind overall among them. Each block
/// ends with every count exact, so the guarantees hold over every prefix.
pub fn place(index: u64, variants: u32, a: &AugmentConfig) -> Place {
    let shares = cells(a);
    let n = u64::from(variants.max(1));
    thread_local! {
        static BLOCK: std::cell::RefCell<Option<Cached>> = const { std::cell::RefCell::new(None) };
    }
    BLOCK.with_borrow_mut(|cached| {
        // the weights' period search runs once per configuration, a block once per block
        let same = |c: &Cached| c.shares == shares.map(f64::to_bits) && c.n == n;
        if !cached.as_ref().is_some_and(same) {
            let (w, d) = weights(shares);
            *cached = Some(Cached {
                shares: shares.map(f64::to_bits),
                n,
                w,
                d,
                number: u64::MAX,
                places: Vec::new(),
            });
        }
        let c = cached.as_mut().expect("a cached configuration");
        let period = n * c.d;
        if c.number != index / period {
            c.number = index / period;
            c.places = block(&c.w, c.d, n, c.number);
        }
        c.places[(index % period) as usize]
    })
}

/// A thread's last block of [`place`] and what it depends on: the cells' shares (as bits) and
/// their weights, the variants, the block's number.
struct Cached {
    shares: [u64; 6],
    n: u64,
    w: [u64; 6],
    d: u64,
    number: u64,
    places: Vec<Place>,
}

/// Block `b` of [`place`]: `n × d` places.
fn block(w: &[u64; 6], d: u64, n: u64, b: u64) -> Vec<Place> {
    let split_w = [0, 1].map(|s| w[s] + w[2 + s] + w[4 + s]);
    let level_w = [0, 1, 2].map(|l| w[2 * l] + w[2 * l + 1]);
    let (mut in_split, mut in_cell, mut in_level) = ([0u64; 2], [0u64; 6], [0u64; 3]);
    let mut per_variant = vec![0u64; n as usize];
    let mut variant_cell = vec![[0u64; 6]; n as usize];
    let mut places = Vec::with_capacity((n * d) as usize);
    for t in 1..=n * d {
        let coin = |tag: u64, k: u64| splitmix(splitmix(splitmix(b) ^ t) ^ (tag << 32 | k));
        // the split: both counts within one sample of their shares after this step
        let fits = |s: usize| {
            let o = 1 - s;
            split_w[s] > 0
                && d * (in_split[s] + 1) < t * split_w[s] + d
                && d * in_split[o] + d > t * split_w[o]
        };
        // where both may come, validation with a chance of one in the steps left before it
        // must: its place uniform over them
        let s = match (fits(0), fits(1)) {
            (true, true) => {
                let due = (d * (in_split[1] + 1)).div_ceil(split_w[1]);
                usize::from(coin(0, 0) % (due + 1 - t) == 0)
            }
            (false, true) => 1,
            _ => 0,
        };
        let r = in_split[s] + 1;
        in_split[s] = r;
        // the level: its count in the split within one sample of its share there
        let ws = split_w[s];
        let level_fits = |l: usize| {
            w[2 * l + s] > 0
                && ws * (in_cell[2 * l + s] + 1) < r * w[2 * l + s] + ws
                && (0..3).all(|m| m == l || ws * in_cell[2 * m + s] + ws > r * w[2 * m + s])
        };
        let overall_fits = |l: usize| {
            d * (in_level[l] + 1) < t * level_w[l] + d
                && (0..3).all(|m| m == l || d * in_level[m] + d > t * level_w[m])
        };
        let behind = |l: usize| (t * level_w[l]) as i128 - (d * in_level[l]) as i128;
        let l = (0..3)
            .filter(|&l| w[2 * l + s] > 0)
            .max_by_key(|&l| (level_fits(l), overall_fits(l), behind(l), coin(1, l as u64)))
            .expect("a level of the split");
        let c = 2 * l + s;
        in_cell[c] += 1;
        in_level[l] += 1;
        // the variant: fewest of this cell, then furthest behind overall
        let fewest = variant_cell.iter().map(|v| v[c]).min().expect("a variant");
        let v = (0..n as usize)
            .filter(|&v| variant_cell[v][c] == fewest)
            .max_by_key(|&v| (t as i128 - (n * per_variant[v]) as i128, coin(2, v as u64)))
            .expect("a variant");
        variant_cell[v][c] += 1;
        per_variant[v] += 1;
        places.push(Place {
            slot: v as u32,
            level: Level::ALL[l],
            split: if s == 1 {
                Split::Validation
            } else {
                Split::Train
            },
        });
    }
    places
}

/// SplitMix64's mix of `x` (Steele et al. 2014): a seeded choice's bits.
fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
