//! A beam's footprint and its echoes, beyond Blensor's thin rays: rays cast across the cone a
//! beam diverges into, weighted by its Gaussian profile; their hits, nearer to each other than
//! the sensor's range separation, merge into one echo at their power-weighted mean distance (a
//! mixed edge return); the strongest, the last or both return.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::world::SurfaceHit;

/// Most rays a beam's footprint is sampled with.
pub const MOST_SAMPLES: u32 = 64;

/// How a beam spreads and which of its echoes return (the default: a thin ray's one echo, its
/// intensity the surface's reflectivity, as Blensor's).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Beam {
    /// Full divergence angle at 1/e² of the beam's power, radians (0: a thin ray).
    pub divergence: f32,
    /// Rays cast across the footprint, 1 to [`MOST_SAMPLES`] (1: its centre alone).
    pub samples: u32,
    /// Hits nearer to each other than this merge into one echo, metres: the sensor's range
    /// separation, about the length of its pulse (5 ns: 0.75 m).
    pub separation: f32,
    /// Which echoes a beam returns.
    pub echoes: Echoes,
    /// Distance at which a return's intensity is its surface's reflectivity at normal
    /// incidence: intensity = reflectivity · cos(incidence) · (reference / d)², at most 1;
    /// 0: the reflectivity alone (Blensor's colour-only returns have none).
    pub intensity_reference: f32,
}

impl Default for Beam {
    fn default() -> Beam {
        Beam {
            divergence: 0.0,
            samples: 1,
            separation: 0.75,
            echoes: Echoes::Strongest,
            intensity_reference: 0.0,
        }
    }
}

/// Which echoes of a beam return.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Echoes {
    /// The echo of the most power.
    Strongest,
    /// The furthest echo.
    Last,
    /// The strongest and the last (one where they are the same): the VLP-16's dual mode.
    Dual,
}

impl Beam {
    /// Checks the parameters; the message names the first that is wrong.
    pub(super) fn validate(&self) -> Result<(), String> {
        if !(self.divergence.is_finite() && (0.0..0.2).contains(&self.divergence)) {
            return Err("beam.divergence: radians from 0 to 0.2".into());
        }
        if !(1..=MOST_SAMPLES).contains(&self.samples) {
            return Err(format!("beam.samples: 1 to {MOST_SAMPLES}"));
        }
        if !(self.separation.is_finite() && self.separation >= 0.0) {
            return Err("beam.separation: metres, 0 or more".into());
        }
        if !(self.intensity_reference.is_finite() && self.intensity_reference >= 0.0) {
            return Err("beam.intensity_reference: metres, 0 or more".into());
        }
        Ok(())
    }

    /// The rays of the footprint of a beam along unit `dir`, with their share of its power:
    /// its centre, or points of a sunflower spiral over the disc out to the 1/e² radius.
    pub(super) fn footprint(&self, dir: Vec3) -> impl Iterator<Item = (Vec3, f32)> {
        let n = if self.divergence > 0.0 {
            self.samples
        } else {
            1
        };
        let half = self.divergence / 2.0;
        let (u, v) = dir.any_orthonormal_pair();
        let weights: f32 = (0..n).map(|k| profile(radius(k, n))).sum();
        (0..n).map(move |k| {
            let r = radius(k, n);
            let phi = k as f32 * GOLDEN_ANGLE;
            let off = (r * half).tan();
            let ray = if off > 0.0 {
                (dir + (u * phi.cos() + v * phi.sin()) * off).normalize()
            } else {
                dir // the centre, to the bit
            };
            (ray, profile(r) / weights)
        })
    }
}

/// The sunflower spiral's turn between points, radians.
const GOLDEN_ANGLE: f32 = 2.399_963_2;

/// The radius of spiral point `k` of `n`, as a share of the disc's (equal areas: √((k + ½)/n)).
fn radius(k: u32, n: u32) -> f32 {
    if n == 1 {
        0.0
    } else {
        ((k as f32 + 0.5) / n as f32).sqrt()
    }
}

/// The Gaussian beam's power at radius `r` (a share of the 1/e² radius).
fn profile(r: f32) -> f32 {
    (-2.0 * r * r).exp()
}

/// One footprint ray's hit: its path's length, its share of the beam's power and the surface.
pub(super) struct Sample {
    pub distance: f32,
    pub share: f32,
    pub hit: SurfaceHit,
}

/// An echo: hits merged, at their power-weighted mean distance.
pub(super) struct Echo {
    pub distance: f32,
    /// The beam's power it returns relative to a white wall filling the footprint at normal
    /// incidence (share · reflectivity · cos), before falloff.
    pub power: f32,
    /// Its hits' reflectivity, weighted by their shares of the beam (a partly filled
    /// footprint returns less): what the reflectivity limit reads.
    pub reflectivity: f32,
    /// Its strongest hit: the surface it is labelled with.
    pub hit: SurfaceHit,
}

impl Beam {
    /// The echoes `samples` make (sorted by distance on return), as the beam returns them, in
    /// `echoes` (cleared first).
    pub(super) fn echoes(&self, samples: &mut [Sample], dir: Vec3, echoes: &mut Vec<Echo>) {
        samples.sort_by(|a, b| a.distance.total_cmp(&b.distance));
        echoes.clear();
        let mut strongest = 0.0;
        let mut last_distance = f32::NEG_INFINITY;
        for s in samples.iter() {
            let cos = s.hit.normal.dot(-dir).abs();
            let power = s.share * s.hit.material.reflectivity * cos;
            let merge = s.distance - last_distance < self.separation;
            last_distance = s.distance;
            match echoes.last_mut() {
                Some(e) if merge => {
                    let total = e.power + power;
                    if total > 0.0 {
                        e.distance = (e.distance * e.power + s.distance * power) / total;
                    }
                    if power > strongest {
                        (strongest, e.hit) = (power, s.hit);
                    }
                    e.power = total;
                    e.reflectivity += s.share * s.hit.material.reflectivity;
                }
                _ => {
                    strongest = power;
                    echoes.push(Echo {
                        distance: s.distance,
                        power,
                        reflectivity: s.share * s.hit.material.reflectivity,
                        hit: s.hit,
                    });
                }
            }
        }
        let Some(last) = echoes.len().checked_sub(1) else {
            return;
        };
        // the most power received (falling with the square of the distance); of equals, the
        // nearest
        let received = |e: &Echo| e.power / (e.distance * e.distance);
        let strongest = (0..echoes.len())
            .rev()
            .max_by(|&a, &b| received(&echoes[a]).total_cmp(&received(&echoes[b])))
            .unwrap_or(last);
        let mut i = 0;
        echoes.retain(|_| {
            let keep = match self.echoes {
                Echoes::Strongest => i == strongest,
                Echoes::Last => i == last,
                Echoes::Dual => i == strongest || i == last,
            };
            i += 1;
            keep
        });
    }

    /// The intensity of `echo` (see [`Beam::intensity_reference`]).
    pub(super) fn intensity(&self, echo: &Echo) -> f32 {
        if self.intensity_reference > 0.0 {
            let falloff = (self.intensity_reference / echo.distance).powi(2);
            (echo.power * falloff).min(1.0)
        } else {
            echo.reflectivity
        }
    }
}
