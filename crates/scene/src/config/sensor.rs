//! `[sensor]`: the simulated camera, a preset or a full specification with keys set over its
//! own, and sensors named as `scan --sensor` takes them.

use sensor::{Sampling, SensorSpec};
use serde::{Deserialize, Serialize};

use super::{in_words, overlay, toml_in_words};
use crate::error::{Error, Result};

/// `[sensor]`: the simulated camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    /// A preset name (`motorfactory scan --help` lists them).
    pub preset: String,
    /// A full sensor specification instead of the preset (the `scan --sensor FILE.toml` schema).
    pub spec: Option<SensorSpec>,
    /// Keys of the sensor's noise models set over its own (`[noise]` of a sensor file), the
    /// rest kept.
    pub noise: Option<toml::Table>,
    /// Keys of the sensor's colour camera set over its own (`[colour]` of a sensor file:
    /// exposure, gain, lens, …), the rest kept.
    pub colour: Option<toml::Table>,
    /// Keys of the camera's calibration error set over its own (`[calibration]` of a sensor
    /// file: `seed`, `scale`, `warp`), the rest kept.
    pub calibration: Option<toml::Table>,
    /// How many cameras (units, each its own calibration error) the samples are taken with:
    /// 0, a new one every sample; n, one of n drawn per sample, unit k's seed the
    /// calibration's seed + k (n = 1: the sensor's own camera).
    pub cameras: u64,
    /// Which pixels make a point, by Zivid's names, those the sensor offers (see
    /// [`sensor::SensorSpec::samplings`]).
    pub sampling: Sampling,
    /// The image resized to `[width, height]` after the sampling (scaled to cover, centred,
    /// the excess cut off), if given.
    pub resolution: Option<[u32; 2]>,
}

impl SensorConfig {
    /// The sensor with its sampling applied, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] for an unknown preset or a specification the sensor rejects.
    pub fn resolve(&self) -> Result<SensorSpec> {
        let mut spec = match &self.spec {
            Some(spec) => spec.clone(),
            None => SensorSpec::preset(&self.preset).map_err(|_| {
                Error::invalid(
                    "sensor.preset",
                    format!("\"{}\"", self.preset),
                    format!(
                        "one of {}{}",
                        sensor::PRESETS.join(", "),
                        motorgen::did_you_mean(&self.preset, sensor::PRESETS.iter().copied())
                    ),
                )
            })?,
        };
        if let Some(keys) = &self.noise {
            spec.noise = overlaid(&spec.noise, keys, "sensor.noise")?;
        }
        if let Some(keys) = &self.colour {
            spec.colour = overlaid(&spec.colour, keys, "sensor.colour")?;
        }
        if let Some(keys) = &self.calibration {
            spec.calibration = overlaid(&spec.calibration, keys, "sensor.calibration")?;
        }
        let mut spec = spec
            .sampled(self.sampling)
            .map_err(|e| Error::Config(format!("sensor.{e}")))?;
        if let Some([width, height]) = self.resolution {
            spec = spec
                .resized(width, height)
                .map_err(|e| Error::Config(format!("sensor.{e}")))?;
        }
        spec.validate()
            .map_err(|e| Error::Config(format!("sensor: {e}")))?;
        Ok(spec)
    }
}

/// `base` with `keys` set over its own (tables merged key by key), read back; errors name
/// `key`.
fn overlaid<T: Serialize + serde::de::DeserializeOwned>(
    base: &T,
    keys: &toml::Table,
    key: &str,
) -> Result<T> {
    let mut table =
        toml::Table::try_from(base).map_err(|e| Error::Config(format!("{key}: {e}")))?;
    overlay(&mut table, keys.clone());
    table
        .try_into()
        .map_err(|e: toml::de::Error| Error::Config(format!("{key}: {}", in_words(e.message()))))
}

/// The sensor `name` names, as `scan --sensor` takes it: a preset, or a sensor TOML file (a
/// name ending in `.toml`).
///
/// # Errors
///
/// [`Error::Config`] for a name that is neither (the message starts with the name, quoted, for
/// the caller to prefix with how it was given) or a file that is not a sensor (in words);
/// [`Error::Io`] for a file that cannot be read.
pub fn read_sensor(name: &str) -> Result<SensorSpec> {
    let shown = motorgen::shown(name);
    if name.ends_with(".toml") {
        let text = sensor::files::read_text(name.as_ref(), sensor::files::CONFIG_LIMIT)
            .map_err(Error::io(name.as_ref()))?;
        toml::from_str(&text)
            .map_err(|e| Error::Config(format!("{shown}: {}", toml_in_words(&text, &e))))
    } else {
        SensorSpec::preset(name).map_err(|_| {
            Error::Config(format!(
                "\"{shown}\" is not allowed: expected a preset ({}) or a .toml file{}",
                sensor::PRESETS.join(", "),
                motorgen::did_you_mean(name, sensor::PRESETS.iter().copied())
            ))
        })
    }
}
