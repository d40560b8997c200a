//! Rotating multi-beam LiDARs, as Blensor simulates them: a column of lasers fired at each step
//! of a head turning about its z axis, every return's distance drawn noisy by Blensor's models
//! (a Gaussian or a distance table, plus a fixed bias per laser), returns from surfaces too
//! dark for their distance dropped (Blensor's reflectivity limit), beams bounced off mirrors.
//! Beyond Blensor: beams that spread and return several echoes ([`Beam`]), and a head that
//! moves during its pass ([`Motion`]).
//!
//! The head's frame: x forward (yaw 0), y left, z up along the axis it turns about; yaw grows
//! counter-clockwise seen from above, as in Blensor. A laser at elevation e fired at yaw α points
//! along (cos e cos α, cos e sin α, sin e).

mod beam;
mod presets;
mod scan;
#[cfg(test)]
mod tests;

use glam::{Affine3A, Mat3A, Vec3, Vec3A};
use serde::{Deserialize, Serialize};

use crate::noise::PixelRng;

pub use beam::{Beam, Echoes, MOST_SAMPLES};
pub use presets::{BLENSOR_VELODYNE_BIAS, LIDAR_PRESETS};
pub use scan::{LidarFrame, LidarReturn, LidarScan, Motion, scan_lidar};

/// One laser of a head.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Laser {
    /// Elevation above the head's xy plane, degrees.
    pub elevation: f32,
    /// Distance added to every return of this laser, metres (Blensor's fixed per-laser bias).
    #[serde(default)]
    pub bias: f32,
    /// Firing delay after its column's start, seconds.
    #[serde(default)]
    pub delay: f32,
    /// Height of the laser's origin above the head's centre, along its axis, metres (the
    /// VLP-16's vertical corrections); distances are measured from it.
    #[serde(default)]
    pub offset: f32,
}

/// Blensor's reflectivity limit: beyond `distance`, a return needs a diffuse reflectivity above
/// `limit + slope·(d − distance)` (nearer, any surface returns).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReflectivityLimit {
    /// Distance from which the limit applies, metres.
    pub distance: f32,
    /// Least reflectivity at that distance.
    pub limit: f32,
    /// Growth of the least reflectivity per metre beyond it.
    pub slope: f32,
}

impl ReflectivityLimit {
    /// Whether a surface of `reflectivity` at distance `d` returns the pulse.
    pub fn returns(&self, reflectivity: f32, d: f32) -> bool {
        d < self.distance || reflectivity > self.limit + self.slope * (d - self.distance)
    }
}

/// The distance noise of every return: `bias` of its laser plus a draw from N(mu, sigma), or,
/// where `table` is given, from N(mu(d), sigma(d)) at the return's distance d (Blensor's
/// "advanced error model").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeNoise {
    /// Mean of the draw, metres.
    pub mu: f32,
    /// Standard deviation of the draw, metres.
    pub sigma: f32,
    /// Rows (distance, mu, sigma), metres, by distance: mu and sigma are interpolated between
    /// rows and held beyond the first and the last.
    #[serde(default)]
    pub table: Vec<[f32; 3]>,
}

impl RangeNoise {
    /// (mu, sigma) at distance `d`.
    pub fn at(&self, d: f32) -> (f32, f32) {
        let t = &self.table;
        let Some(last) = t.last() else {
            return (self.mu, self.sigma);
        };
        let i = t.partition_point(|row| row[0] <= d);
        if i == 0 {
            return (t[0][1], t[0][2]);
        }
        if i == t.len() {
            return (last[1], last[2]);
        }
        let ([d0, m0, s0], [d1, m1, s1]) = (t[i - 1], t[i]);
        let f = (d - d0) / (d1 - d0);
        (m0 + (m1 - m0) * f, s0 + (s1 - s0) * f)
    }

    /// A draw of the noise at distance `d` from stream `k` of `rng` (mu alone where sigma is
    /// below 10⁻⁷, as Blensor).
    fn draw(&self, d: f32, rng: PixelRng, k: u64) -> f32 {
        let (mu, sigma) = self.at(d);
        if sigma < 1e-7 {
            mu
        } else {
            mu + sigma * rng.normal(k)
        }
    }
}

/// A rotating multi-beam LiDAR.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lidar {
    /// Preset or user name.
    pub name: String,
    /// The lasers of a column, in firing order (the ring number is the index).
    pub lasers: Vec<Laser>,
    /// Yaw of the first column, degrees.
    pub start: f32,
    /// Yaw the columns stop short of, degrees.
    pub end: f32,
    /// Yaw from one column to the next, degrees.
    pub resolution: f32,
    /// Revolutions of the head a second.
    pub rotation: f32,
    /// Longest distance that returns, metres.
    pub max_range: f32,
    /// Distance noise.
    pub noise: RangeNoise,
    /// Dark surfaces far away return nothing.
    pub reflectivity: ReflectivityLimit,
    /// How a beam spreads and which of its echoes return (by default a thin ray's one echo).
    #[serde(default)]
    pub beam: Beam,
}

impl Lidar {
    /// Columns fired in a pass from `start` to `end` (as Blensor counts them, whole steps).
    pub fn columns(&self) -> usize {
        ((self.end - self.start) / self.resolution).max(0.0) as usize
    }

    /// Rays fired in a pass.
    pub fn rays(&self) -> usize {
        self.columns() * self.lasers.len()
    }

    /// Memory a pass needs at its peak, in bytes: every ray's returns (two with dual echoes),
    /// twice over (the scan, and the rows or columns its files are built from).
    pub fn pass_memory(&self) -> u64 {
        let echoes = if self.beam.echoes == Echoes::Dual {
            2
        } else {
            1
        };
        (self.rays() as u64 * echoes).saturating_mul(2 * size_of::<LidarReturn>() as u64)
    }

    /// Checks the parameters; the message names the first that is wrong.
    ///
    /// # Errors
    ///
    /// A message naming the parameter and what it must be.
    pub fn validate(&self) -> Result<(), String> {
        let positive = [
            ("resolution", self.resolution),
            ("rotation", self.rotation),
            ("max_range", self.max_range),
        ];
        if let Some((name, _)) = positive.iter().find(|(_, v)| !(v.is_finite() && *v > 0.0)) {
            return Err(format!("{name} must be a positive number"));
        }
        if self.lasers.is_empty() || self.lasers.len() > usize::from(u16::MAX) {
            return Err(format!("lasers: give 1 to {}", u16::MAX));
        }
        if !(self.start.is_finite() && self.end.is_finite() && self.end > self.start) {
            return Err("start and end: end must be past start".into());
        }
        if self
            .lasers
            .iter()
            .any(|l| !(l.elevation.abs() <= 90.0 && l.bias.is_finite() && l.delay.is_finite()))
        {
            return Err("lasers: elevations within ±90°, finite biases and delays".into());
        }
        let n = &self.noise;
        if !(n.mu.is_finite() && n.sigma.is_finite() && n.sigma >= 0.0) {
            return Err("noise: mu finite, sigma 0 or more".into());
        }
        if n.table
            .iter()
            .any(|r| !(r.iter().all(|v| v.is_finite()) && r[2] >= 0.0))
            || n.table.windows(2).any(|w| w[1][0] <= w[0][0])
        {
            return Err(
                "noise.table: rows (distance, mu, sigma) by growing distance, sigma 0 or more"
                    .into(),
            );
        }
        if self.rays() > u32::MAX as usize {
            return Err(format!(
                "resolution: {} columns of {} lasers are more than {} rays",
                self.columns(),
                self.lasers.len(),
                u32::MAX
            ));
        }
        let r = &self.reflectivity;
        if ![r.distance, r.limit, r.slope].iter().all(|v| v.is_finite()) {
            return Err("reflectivity: finite distance, limit and slope".into());
        }
        self.beam.validate()
    }

    /// The yaw of `laser` fired in `column`, degrees: the column's, and as far as the head
    /// turns during the laser's firing delay (Velodyne's precise azimuth).
    fn yaw(&self, column: usize, laser: usize) -> f32 {
        self.start
            + column as f32 * self.resolution
            + 360.0 * self.rotation * self.lasers[laser].delay
    }

    /// The direction of `laser` fired in `column`, in the head's frame.
    pub fn direction(&self, column: usize, laser: usize) -> Vec3 {
        let (a, e) = (
            self.yaw(column, laser).to_radians(),
            self.lasers[laser].elevation.to_radians(),
        );
        Vec3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
    }

    /// When `laser` fires in `column`, seconds from the pass's start.
    pub fn time(&self, column: usize, laser: usize) -> f32 {
        let step = self.resolution / 360.0 / self.rotation;
        column as f32 * step + self.lasers[laser].delay
    }
}

/// The pose of a head at `position` whose yaw 0 faces `towards` (projected across `up`), with its
/// axis along `up`; `None` if `towards` lies along `up` from `position`.
pub fn head_pose(position: Vec3, towards: Vec3, up: Vec3) -> Option<Affine3A> {
    let z = up.try_normalize()?;
    let forward = towards - position;
    let x = (forward - z * forward.dot(z)).try_normalize()?;
    Some(Affine3A {
        matrix3: Mat3A::from_cols(x.into(), z.cross(x).into(), z.into()),
        translation: Vec3A::from(position),
    })
}
