//! Parameter sweeps: every combination of the listed keys' values.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// One swept key and its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// Dotted key, e.g. `motor.params.pole_pot_length` or `sensor.binning`.
    pub key: String,
    /// The values.
    pub list: Option<Vec<toml::Value>>,
    /// `[first, last, count]`: evenly spaced.
    pub linspace: Option<(f64, f64, u32)>,
    /// `[start, stop, step]`: start, start + step, ... up to stop.
    pub grid: Option<(f64, f64, f64)>,
}

impl Sweep {
    /// The values of the sweep, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] unless exactly one of `list`, `linspace` and `grid`
    /// is given, non-empty and finite.
    pub fn values(&self) -> Result<Vec<toml::Value>> {
        let key = format!("sweep {}", self.key);
        let values = match (&self.list, self.linspace, self.grid) {
            (Some(list), None, None) => list.clone(),
            (None, Some((a, b, n)), None) if n >= 1 && a.is_finite() && b.is_finite() => (0..n)
                .map(|i| {
                    let t = if n == 1 {
                        0.0
                    } else {
                        i as f64 / (n - 1) as f64
                    };
                    toml::Value::Float(a + (b - a) * t)
                })
                .collect(),
            (None, None, Some((a, b, step)))
                if step > 0.0 && a <= b && (b - a) / step <= 1e5 && a.is_finite() =>
            {
                let n = ((b - a) / step + 1e-9).floor() as u64;
                (0..=n)
                    .map(|i| toml::Value::Float(a + step * i as f64))
                    .collect()
            }
            _ => {
                return Err(Error::Config(format!(
                    "{key}: give exactly one of list = [...], linspace = [first, last, count >= 1] \
                     or grid = [start, stop, step > 0]"
                )));
            }
        };
        if values.is_empty() {
            return Err(Error::Config(format!("{key}: the list is empty")));
        }
        Ok(values)
    }
}
