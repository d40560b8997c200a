//! Parameter sweeps: every combination of the listed keys' values, each worked out when a
//! sample needs it (a sweep of 100,000 combinations costs nothing up front).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The most combinations a configuration's sweeps may have.
pub const MAX_COMBINATIONS: u64 = 100_000;

/// One swept key and its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// Dotted key, e.g. `motor.params.pole_pot_length` or `sensor.sampling`.
    pub key: String,
    /// The values.
    pub list: Option<Vec<toml::Value>>,
    /// `[first, last, count]`: evenly spaced.
    pub linspace: Option<(f64, f64, u64)>,
    /// `[start, stop, step]`: start, start + step, ... up to stop.
    pub grid: Option<(f64, f64, f64)>,
}

impl Sweep {
    /// The number of values, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] unless exactly one of `list`, `linspace` and `grid` is given,
    /// non-empty, finite, and with at most [`MAX_COMBINATIONS`] values.
    pub fn count(&self) -> Result<u64> {
        let key = format!("sweep {}", self.key);
        let n = match (&self.list, self.linspace, self.grid) {
            (Some(list), None, None) => list.len() as u64,
            (None, Some((a, b, n)), None) if a.is_finite() && b.is_finite() => n,
            (None, None, Some((a, b, step)))
                if a.is_finite() && b.is_finite() && step > 0.0 && a <= b =>
            {
                let steps = ((b - a) / step + 1e-9).floor();
                if steps >= MAX_COMBINATIONS as f64 {
                    u64::MAX
                } else {
                    steps as u64 + 1
                }
            }
            _ => {
                return Err(Error::Config(format!(
                    "{key}: give exactly one of list = [...], linspace = [first, last, count] \
                     or grid = [start, stop, step] with finite numbers, start <= stop and \
                     step > 0"
                )));
            }
        };
        if !(1..=MAX_COMBINATIONS).contains(&n) {
            return Err(Error::Config(format!(
                "{key}: {} values; a sweep takes 1 to {MAX_COMBINATIONS}",
                if n == u64::MAX {
                    "too many".to_string()
                } else {
                    n.to_string()
                }
            )));
        }
        Ok(n)
    }

    /// Value `k` (below [`Sweep::count`]).
    pub fn value(&self, k: u64) -> toml::Value {
        match (&self.list, self.linspace, self.grid) {
            (Some(list), _, _) => list[k as usize].clone(),
            (_, Some((a, b, n)), _) => {
                let t = if n <= 1 {
                    0.0
                } else {
                    k as f64 / (n - 1) as f64
                };
                toml::Value::Float(a + (b - a) * t)
            }
            (_, _, Some((a, _, step))) => toml::Value::Float(a + step * k as f64),
            _ => unreachable!("a checked sweep has values"),
        }
    }
}

/// The sweeps of a configuration as one mixed-radix counter, the last sweep the fastest:
/// combination `c` takes value `c % n` of the last sweep (of `n` values), `(c / n) % m` of the
/// one before (of `m`), and so on.
#[derive(Clone, Debug, Default)]
pub struct Combinations {
    sweeps: Vec<(Sweep, u64)>,
    total: u64,
}

impl Combinations {
    /// Checks every sweep and their product.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] for a sweep [`Sweep::count`] refuses, a key inside `[[sweep]]`, or more
    /// than [`MAX_COMBINATIONS`] combinations in all.
    pub fn new(sweeps: &[Sweep]) -> Result<Combinations> {
        let mut total = 1u64;
        let mut out = Vec::new();
        for s in sweeps {
            if s.key.split('.').next() == Some("sweep") {
                return Err(Error::invalid(
                    "sweep key",
                    &s.key,
                    "a key outside [[sweep]]",
                ));
            }
            let n = s.count()?;
            total = total
                .checked_mul(n)
                .filter(|&t| t <= MAX_COMBINATIONS)
                .ok_or_else(|| {
                    Error::Config(format!(
                        "sweep: more than {MAX_COMBINATIONS} combinations of values"
                    ))
                })?;
            out.push((s.clone(), n));
        }
        Ok(Combinations { sweeps: out, total })
    }

    /// The number of combinations (1 without sweeps).
    pub fn total(&self) -> u64 {
        self.total
    }

    /// The combinations that differ from the first in one sweep's value: each value of each
    /// sweep once (as many as the sweeps' values together).
    pub fn each_value(&self) -> impl Iterator<Item = u64> + '_ {
        let mut stride = self.total;
        self.sweeps.iter().flat_map(move |(_, n)| {
            stride /= n;
            let step = stride;
            (1..*n).map(move |k| k * step)
        })
    }

    /// The keys and values of combination `c` (taken modulo the total).
    pub fn get(&self, c: u64) -> Vec<(String, toml::Value)> {
        let mut rest = c % self.total;
        let mut values: Vec<(String, toml::Value)> = self
            .sweeps
            .iter()
            .rev()
            .map(|(s, n)| {
                let k = rest % n;
                rest /= n;
                (s.key.clone(), s.value(k))
            })
            .collect();
        values.reverse();
        values
    }
}
