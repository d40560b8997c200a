//! Parameter spaces: for each parameter a fixed value, a uniform range, a weighted choice or the
//! add-on's own generator ("auto"), read from TOML and sampled deterministically from a seed.

use std::collections::BTreeMap;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

use crate::params::{Auto, Kind, MIN_UPPER_BOLT_GAP_DEG, MotorParams, PARAMS, Value, spec};
use crate::{Error, Result};

/// How one parameter is drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum Dist {
    /// The add-on's random generator for this parameter (see [`Auto`]).
    Auto,
    /// Always this value.
    Fixed(Value),
    /// Uniform between two bounds (whole allowed values only, for integer parameters).
    Uniform(f64, f64),
    /// One of the values, with probabilities proportional to the weights.
    Choice(Vec<Value>, Vec<f64>),
}

/// The TOML forms of a distribution: `key = value`, `key = "auto"`, `key = { uniform = [a, b] }`,
/// `key = { choice = [..], weights = [..] }`.
#[derive(Deserialize)]
#[serde(untagged)]
enum RawDist {
    Scalar(Value),
    Table(DistTable),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DistTable {
    uniform: Option<[f64; 2]>,
    choice: Option<Vec<Value>>,
    weights: Option<Vec<f64>>,
}

impl Dist {
    /// Parses a TOML value into a distribution (not yet checked against a parameter).
    ///
    /// # Errors
    ///
    /// [`Error::Distribution`] naming the key, for a value of the wrong
    /// type or a distribution whose form or range the parameter does not allow.
    pub fn from_toml(key: &str, value: toml::Value) -> Result<Dist> {
        let bad = |message: String| Error::Distribution {
            key: key.into(),
            message,
        };
        let raw: RawDist = value.try_into().map_err(|_| {
            bad("expected a value, \"auto\", { uniform = [min, max] } or { choice = [...], weights = [...] }".into())
        })?;
        Ok(match raw {
            RawDist::Scalar(Value::Text(s)) if s == "auto" => Dist::Auto,
            RawDist::Scalar(v) => Dist::Fixed(v),
            RawDist::Table(DistTable {
                uniform: Some([a, b]),
                choice: None,
                weights: None,
            }) => Dist::Uniform(a, b),
            RawDist::Table(DistTable {
                uniform: None,
                choice: Some(values),
                weights,
            }) => {
                let weights = weights.unwrap_or_else(|| vec![1.0; values.len()]);
                Dist::Choice(values, weights)
            }
            RawDist::Table(_) => {
                return Err(bad(
                    "give either `uniform` or `choice` (with optional `weights`)".into(),
                ));
            }
        })
    }

    /// Parses the right-hand side of `--set key=value`: any TOML value, or a bare word as text.
    ///
    /// # Errors
    ///
    /// As [`Dist::from_toml`], for the value parsed from `text`.
    pub fn from_cli(key: &str, text: &str) -> Result<Dist> {
        let value = toml::from_str::<toml::Table>(&format!("v = {text}"))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(text.to_string()));
        Dist::from_toml(key, value)
    }

    /// Smallest and largest value it can produce (numbers only).
    fn bounds(&self) -> Option<(f64, f64)> {
        let num = |v: &Value| match v {
            Value::Num(x) => Some(*x),
            _ => None,
        };
        match self {
            Dist::Fixed(v) => num(v).map(|x| (x, x)),
            Dist::Uniform(a, b) => Some((*a, *b)),
            Dist::Choice(vs, _) => vs
                .iter()
                .map(num)
                .try_fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    x.map(|x| (lo.min(x), hi.max(x)))
                }),
            Dist::Auto => None,
        }
    }
}

/// A distribution over motors: one [`Dist`] per parameter, "auto" where none is given.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamSpace {
    dists: BTreeMap<String, Dist>,
}

impl ParamSpace {
    /// The add-on's own generator for every parameter, plus varied gearbox orientation and mirror.
    pub fn addon() -> ParamSpace {
        ParamSpace::default()
    }

    /// Every parameter fixed at its default (the add-on's default motor).
    pub fn defaults() -> ParamSpace {
        let mut space = ParamSpace::default();
        for p in PARAMS {
            space
                .set(p.key, Dist::Fixed(p.default.value()))
                .expect("defaults are valid");
        }
        space
    }

    /// Reads a TOML table of `key = distribution` entries.
    ///
    /// # Errors
    ///
    /// [`Error::Unknown`] for a key that is not a parameter, or the errors
    /// of [`Dist::from_toml`] and [`ParamSpace::check`].
    pub fn from_toml(table: &toml::Table) -> Result<ParamSpace> {
        let mut space = ParamSpace::default();
        for (key, value) in table {
            space.set(key, Dist::from_toml(key, value.clone())?)?;
        }
        space.check()?;
        Ok(space)
    }

    /// Sets one parameter's distribution, checking it against the parameter.
    ///
    /// # Errors
    ///
    /// [`Error::Unknown`] for a key that is not a parameter (with the
    /// nearest key as a hint), or [`Error::Distribution`] for a
    /// distribution that cannot give an allowed value of it.
    pub fn set(&mut self, key: &str, dist: Dist) -> Result<()> {
        let spec = spec(key).ok_or_else(|| Error::unknown(key))?;
        let bad = |message: String| Error::Distribution {
            key: key.into(),
            message,
        };
        match &dist {
            Dist::Auto => {}
            Dist::Fixed(v) => spec.check(v)?,
            Dist::Uniform(a, b) => {
                let numeric = matches!(spec.kind, Kind::Real { .. } | Kind::Int { .. });
                if !numeric {
                    return Err(bad(format!(
                        "a uniform range needs a numeric parameter; expected {}",
                        spec.kind.allowed()
                    )));
                }
                if a > b {
                    return Err(bad(format!("uniform range [{a}, {b}] has min above max")));
                }
                if !spec.kind.accepts(&Value::Num(*a)) || !spec.kind.accepts(&Value::Num(*b)) {
                    return Err(bad(format!(
                        "uniform range [{a}, {b}] leaves the allowed values: {}",
                        spec.kind.allowed()
                    )));
                }
            }
            Dist::Choice(values, weights) => {
                if values.is_empty() || values.len() != weights.len() {
                    return Err(bad(format!(
                        "choice needs at least one value and one weight per value ({} values, {} weights)",
                        values.len(),
                        weights.len()
                    )));
                }
                if weights.iter().any(|w| !(*w >= 0.0 && w.is_finite()))
                    || weights.iter().sum::<f64>() <= 0.0
                {
                    return Err(bad(format!(
                        "weights {weights:?} must be finite, non-negative and not all zero"
                    )));
                }
                values.iter().try_for_each(|v| spec.check(v))?;
            }
        }
        self.dists.insert(key.into(), dist);
        Ok(())
    }

    /// The distribution of `key` ("auto" when not set).
    pub fn get(&self, key: &str) -> &Dist {
        self.dists.get(key).unwrap_or(&Dist::Auto)
    }

    /// Checks rules between parameters: the angles of the upper-gear bolts in use (up to the
    /// largest `upper_bolt_count` drawn) are all "auto" or all given, and given ones are
    /// ordered with at least 10° between any two draws.
    ///
    /// # Errors
    ///
    /// [`Error::Distribution`] naming the upper-gear bolt angle that
    /// breaks either rule.
    pub fn check(&self) -> Result<()> {
        // only the bolts that can be in use: up to the largest upper_bolt_count drawn
        let in_use = self
            .get("upper_bolt_count")
            .bounds()
            .map_or(3, |(_, most)| (most as usize).clamp(1, 3));
        let keys = &["upper_bolt_1_deg", "upper_bolt_2_deg", "upper_bolt_3_deg"][..in_use];
        let given: Vec<Option<(f64, f64)>> = keys.iter().map(|k| self.get(k).bounds()).collect();
        if given.iter().any(Option::is_some) {
            if let Some(k) = keys.iter().zip(&given).find(|(_, g)| g.is_none()) {
                return Err(Error::Distribution {
                    key: k.0.to_string(),
                    message: format!(
                        "set all of {} (the bolts in use), or none (\"auto\")",
                        keys.join(", ")
                    ),
                });
            }
            for k in 0..in_use - 1 {
                let (hi, lo) = (given[k].unwrap().1, given[k + 1].unwrap().0);
                if lo < hi + MIN_UPPER_BOLT_GAP_DEG as f64 {
                    return Err(Error::Distribution {
                        key: keys[k + 1].into(),
                        message: format!(
                            "its values (from {lo}) must start at least {MIN_UPPER_BOLT_GAP_DEG}° above {}'s (up to {hi})",
                            keys[k]
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Draws one motor. Each parameter has its own random stream (seed, parameter index), so a
    /// change to one parameter's distribution leaves every other draw unchanged.
    ///
    /// # Errors
    ///
    /// The errors of [`MotorParams::from_values`] when the drawn values do not form a valid
    /// motor (fixed values that contradict each other).
    pub fn sample(&self, seed: u64) -> Result<MotorParams> {
        let mut values: BTreeMap<String, Value> = BTreeMap::new();
        for (index, spec) in PARAMS.iter().enumerate() {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(index as u64);
            let value = match self.get(spec.key) {
                Dist::Fixed(v) => v.clone(),
                Dist::Uniform(a, b) => draw_number(&spec.kind, *a, *b, &mut rng),
                Dist::Choice(vs, ws) => vs[pick_weighted(ws, &mut rng)].clone(),
                Dist::Auto => self.draw_auto(spec.kind, spec.auto, &values, &mut rng),
            };
            values.insert(spec.key.into(), value);
        }
        MotorParams::from_values(&values)
    }

    fn draw_auto(
        &self,
        kind: Kind,
        auto: Auto,
        drawn: &BTreeMap<String, Value>,
        rng: &mut ChaCha8Rng,
    ) -> Value {
        match (auto, kind) {
            (Auto::Full, Kind::Real { min, max }) => draw_number(&kind, min, max, rng),
            (Auto::Full, Kind::Int { min, max, .. }) => {
                draw_number(&kind, min as f64, max as f64, rng)
            }
            (Auto::Full, Kind::Enum(names)) => {
                Value::Text(names[pick_index(names.len(), rng)].into())
            }
            (Auto::Full, Kind::Bool) => Value::Bool(pick_index(2, rng) == 1),
            (Auto::Range(a, b), _) => draw_number(&kind, a, b, rng),
            (Auto::List(list), _) => Value::Num(list[pick_index(list.len(), rng)]),
            (Auto::UpperBolt(k), _) => {
                let n = match drawn.get("upper_bolt_count") {
                    Some(Value::Num(n)) => *n,
                    _ => 3.0,
                };
                // a bolt beyond the count is unused; it is drawn as if the count reached it
                let k = k as f64;
                let slot = 210.0 / n.max(k);
                let lo = if k > 1.0 { (k - 0.8) * slot } else { 0.0 };
                Value::Num(lo + (k * slot - lo) * unit(rng))
            }
        }
    }
}

/// A uniform draw in [0, 1) from the top 53 bits, independent of rand's sampling algorithms.
fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn pick_index(n: usize, rng: &mut ChaCha8Rng) -> usize {
    ((unit(rng) * n as f64) as usize).min(n - 1)
}

fn pick_weighted(weights: &[f64], rng: &mut ChaCha8Rng) -> usize {
    // weights whose sum overflows are scaled by the largest first
    let sum: f64 = weights.iter().sum();
    let scale = if sum.is_finite() {
        1.0
    } else {
        1.0 / weights.iter().copied().fold(0.0, f64::max)
    };
    let mut target = unit(rng) * weights.iter().map(|w| w * scale).sum::<f64>();
    for (i, w) in weights.iter().enumerate() {
        let w = w * scale;
        if target < w {
            return i;
        }
        target -= w;
    }
    weights
        .iter()
        .rposition(|w| *w > 0.0)
        .expect("some weight is positive")
}

/// Uniform in [a, b]; for integer kinds, uniform over the allowed whole values in [a, b].
fn draw_number(kind: &Kind, a: f64, b: f64, rng: &mut ChaCha8Rng) -> Value {
    match *kind {
        Kind::Int { min, step, .. } => {
            let first = min + ((a as i64 - min) + step - 1).div_euclid(step) * step;
            let count = ((b as i64 - first).div_euclid(step) + 1).max(1);
            Value::Num((first + pick_index(count as usize, rng) as i64 * step) as f64)
        }
        _ => Value::Num(a + (b - a) * unit(rng)),
    }
}

/// The seed of item `index` of a run seeded with `seed` (SplitMix64 finalisers): independent of
/// how items are split over threads, jobs or shards.
pub fn derive_seed(seed: u64, index: u64) -> u64 {
    fn mix(mut z: u64) -> u64 {
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    mix(seed.wrapping_add(mix(index.wrapping_add(0x9e37_79b9_7f4a_7c15))))
}
