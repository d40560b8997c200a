//! Sensor models and presets.

use glam::Vec3;
use serde::{Deserialize, Serialize};

mod colour;
mod presets;
mod processing;
mod sampling;
pub use colour::{ColourCamera, ColourCapture, PINK, blackbody};
pub use presets::PRESETS;
pub use processing::{
    ClusterFilter, ClusterRemoval, ContrastDistortion, Correction, ExperimentalFilters, Filters,
    Gaussian, HoleFilter, HoleRepair, NoiseFilter, OutlierFilter, Processing, ReflectionFilter,
    ReflectionMode, ReflectionRemoval, Removal, Repair, Smoothing, Suppression,
};
pub use sampling::Sampling;

use crate::Error;
use crate::camera::Intrinsics;
use crate::noise::{Noise, PixelRng, stream};

/// A projector beside the camera: at `baseline` metres along camera +x, toed in so that its
/// optical axis crosses the camera's at `convergence` metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Projector {
    /// Camera-to-projector distance along camera +x, m.
    pub baseline: f32,
    /// Range at which the optical axes cross, m.
    pub convergence: f32,
    /// Full horizontal field of view, degrees.
    pub hfov_deg: f32,
    /// Full vertical field of view, degrees.
    pub vfov_deg: f32,
}

impl Projector {
    /// Projector centre in the camera frame.
    pub fn centre(&self) -> Vec3 {
        Vec3::new(self.baseline, 0.0, 0.0)
    }

    /// The projector's frustum, for testing many points.
    pub fn frustum(&self) -> Frustum {
        let toe = (self.baseline / self.convergence).atan();
        let (s, c) = toe.sin_cos();
        Frustum {
            centre: self.centre(),
            x_axis: Vec3::new(c, 0.0, s),
            z_axis: Vec3::new(-s, 0.0, c),
            tan_x: (self.hfov_deg.to_radians() / 2.0).tan(),
            tan_y: (self.vfov_deg.to_radians() / 2.0).tan(),
        }
    }
}

/// A projector's field of light, in the camera frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    centre: Vec3,
    x_axis: Vec3,
    z_axis: Vec3,
    tan_x: f32,
    tan_y: f32,
}

impl Frustum {
    /// Whether a camera-frame point lies inside.
    #[inline]
    pub fn lights(&self, p: Vec3) -> bool {
        let q = p - self.centre;
        let z = q.dot(self.z_axis);
        z > 0.0 && q.dot(self.x_axis).abs() <= self.tan_x * z && q.y.abs() <= self.tan_y * z
    }

    /// The projector column that lights camera-frame point `p`, as the tangent of its angle
    /// from the projector's axis (±`half_width` at the field's edges).
    #[inline]
    pub fn column(&self, p: Vec3) -> f32 {
        let q = p - self.centre;
        q.dot(self.x_axis) / q.dot(self.z_axis)
    }

    /// The projector column and row that light camera-frame point `p`, each as the tangent of
    /// its angle from the projector's axis (±`half_width`, ±`half_height` at the field's edges),
    /// and its distance from the projector along its axis.
    #[inline]
    pub fn locate(&self, p: Vec3) -> [f32; 3] {
        let q = p - self.centre;
        let depth = q.dot(self.z_axis);
        let inverse = depth.recip();
        [q.dot(self.x_axis) * inverse, q.y * inverse, depth]
    }

    /// The distance of camera-frame point `p` from the projector along its axis.
    #[inline]
    pub fn depth(&self, p: Vec3) -> f32 {
        (p - self.centre).dot(self.z_axis)
    }

    /// The tangent of half the projector's horizontal field.
    pub fn half_width(&self) -> f32 {
        self.tan_x
    }

    /// The tangent of half the projector's vertical field.
    pub fn half_height(&self) -> f32 {
        self.tan_y
    }

    /// The distance along camera ray `dir` (from the camera's centre) to the plane of light of
    /// projector column `column`; not positive or not finite where the ray does not meet it in
    /// front of the camera.
    #[inline]
    pub fn ray_to_column(&self, dir: Vec3, column: f32) -> f32 {
        let c = self.centre;
        (c.dot(self.x_axis) - column * c.dot(self.z_axis))
            / (dir.dot(self.x_axis) - column * dir.dot(self.z_axis))
    }
}

/// How a sensor forms its measurement.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Model {
    /// Exact depth of every pixel's ray: ground truth.
    Ideal,
    /// Camera plus pattern projector: a point exists only where the projector also sees it.
    StructuredLight {
        /// The projector.
        projector: Projector,
    },
    /// A time-of-flight camera as Blensor's `tof` scanner: single return, range noise only.
    TimeOfFlight,
    /// Kinect v1 / PrimeSense as Blensor's model: projector visibility, disparity noise in
    /// pixels quantised to 1/`subpixel` px, and a `window`×`window` validity filter.
    Kinect {
        /// The IR projector.
        projector: Projector,
        /// Gaussian disparity noise, pixels (σ).
        disparity_sigma_px: f32,
        /// Disparity steps per pixel (8 on the Kinect v1).
        subpixel: f32,
        /// Side of the validity window, pixels (9 in Blensor; 0 = off).
        window: u32,
        /// Share of the window that must agree for a pixel to stay (Blensor: 1/1.5).
        window_fraction: f32,
        /// Depth difference within which window pixels agree, m (Blensor: 0.1).
        inlier_distance: f32,
    },
}

/// A complete sensor: camera, measurement model, noise and working range.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Preset or user name.
    pub name: String,
    /// The camera.
    pub intrinsics: Intrinsics,
    /// How depth is formed.
    pub model: Model,
    /// Noise models.
    #[serde(default)]
    pub noise: Noise,
    /// Working range: the nearest surface depth (camera z) measured, m.
    pub min_range: f32,
    /// Working range: the farthest surface depth (camera z) measured, m.
    pub max_range: f32,
    /// Range at which a surface of reflectivity 1 facing the light has signal 1, m.
    pub reference_range: f32,
    /// The colour image the points take their rgb from.
    #[serde(default)]
    pub colour: ColourCamera,
    /// The camera's own calibration error, the same in every capture.
    #[serde(default)]
    pub calibration: Calibration,
    /// The camera's processing of each capture, named as Zivid's settings.
    #[serde(default)]
    pub processing: Processing,
    /// The pixel samplings the camera offers, as its maker lists them (empty: any the imager
    /// allows, see [`SensorSpec::sampled`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samplings: Vec<Sampling>,
}

/// A camera's calibration error, fixed for the camera (drawn from `seed`, its serial number as
/// it were) and the same in every capture, apart from each capture's noise: the measured depth
/// is the true depth × (1 + s + a·(u² + v² - 2/3) + b·(u² - v²) + c·u·v), with (u, v) the
/// pixel's image position scaled to ±1 across the image's width and height, s a scale error
/// (Zivid's dimension trueness) and a, b, c a bowl, a saddle and a twist (Zivid's global
/// planarity: bending and warping). Points stay on their rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Calibration {
    /// Which camera: the error drawn.
    pub seed: u64,
    /// σ of the relative scale error.
    pub scale: f32,
    /// σ of each of the three relative warp coefficients.
    pub warp: f32,
}

/// The error of one camera's calibration, drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationError {
    scale: f32,
    bowl: f32,
    saddle: f32,
    twist: f32,
    /// The inverse of image x over z, and of y over z, at the edges of the image (u, v = ±1).
    per_field: [f32; 2],
}

impl CalibrationError {
    /// The factor on the depth of a point in camera direction `dir`.
    #[inline]
    pub fn factor(&self, dir: Vec3) -> f32 {
        let over_z = 1.0 / dir.z;
        let u = dir.x * over_z * self.per_field[0];
        let v = dir.y * over_z * self.per_field[1];
        1.0 + self.scale
            + self.bowl * (u * u + v * v - 2.0 / 3.0)
            + self.saddle * (u * u - v * v)
            + self.twist * u * v
    }
}

/// Checks that each (key, value, range, what the range allows) has its value in its range.
pub(crate) fn within<'a>(
    checks: impl IntoIterator<Item = (&'a str, f32, std::ops::RangeInclusive<f32>, &'a str)>,
) -> Result<(), Error> {
    for (key, value, range, allowed) in checks {
        if !range.contains(&value) {
            return Err(Error::Invalid {
                key: key.into(),
                value: value.to_string(),
                allowed: allowed.into(),
            });
        }
    }
    Ok(())
}

impl SensorSpec {
    /// Whether a surface at camera depth `z` (m) lies in the working range, both ends included
    /// (within a millionth, so that a surface placed exactly at a limit counts).
    #[inline]
    pub fn in_range(&self, z: f32) -> bool {
        z >= self.min_range * (1.0 - 1e-6) && z <= self.max_range * (1.0 + 1e-6)
    }

    /// The depth (camera z) up to which surfaces must be met: the far end of the working
    /// range and a hair beyond, for the rounding of a ray's length.
    #[inline]
    pub fn far_depth(&self) -> f32 {
        self.max_range * (1.0 + 1e-5)
    }

    /// The length up to which a ray in camera direction `dir` (unit) must be cast to meet
    /// every surface in the working range.
    #[inline]
    pub fn reach(&self, dir: Vec3) -> f32 {
        self.far_depth() / dir.z.max(1e-6)
    }

    /// This sensor with `factor`×`factor` pixel binning: the binned camera (see
    /// [`Intrinsics::binned`]), whose pixels each collect the charge of `factor`² pixels (the
    /// colour image's noise falls by `factor`), and whose noise correlates, and whose blur
    /// spreads, over as many fewer pixels.
    pub fn binned(&self, factor: u32) -> SensorSpec {
        let f = factor as f32;
        self.gathered(f, f, self.intrinsics.binned(factor))
    }

    /// This sensor's image resized to `width`×`height` (see [`Intrinsics::resized`]): each new
    /// pixel gathers the light of the old ones it covers, as binning does (the colour image's
    /// noise falls by the scale's inverse), and the noise's lengths in pixels shrink with it.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a size of 0 or one more than twice the image's along either axis.
    pub fn resized(&self, width: u32, height: u32) -> Result<SensorSpec, Error> {
        let k = &self.intrinsics;
        if width == 0 || height == 0 || width > 2 * k.width || height > 2 * k.height {
            return Err(Error::Invalid {
                key: "resolution".into(),
                value: format!("[{width}, {height}]"),
                allowed: format!(
                    "a size of 1 to {}x{} on {}",
                    2 * k.width,
                    2 * k.height,
                    self.name
                ),
            });
        }
        let (intrinsics, scale) = k.resized(width, height);
        let f = (1.0 / scale) as f32;
        Ok(self.gathered(f, f, intrinsics))
    }

    /// This sensor with camera `intrinsics`, `factor` times fewer pixels along each axis
    /// ([`SensorSpec::fewer_pixels`]), each of which gathers the light of `side`² of this
    /// one's: the charge of as many (the colour image's noise falls by `side`).
    fn gathered(&self, factor: f32, side: f32, intrinsics: Intrinsics) -> SensorSpec {
        let mut spec = self.fewer_pixels(factor, intrinsics);
        spec.noise.snr.electrons *= side * side;
        spec.colour.noise /= side;
        spec
    }

    /// This sensor with Zivid's pixel sampling: [`SensorSpec::binned`] for `by2x2` and `by4x4`;
    /// for the subsamplings that colour's pixels of each block (one of a 2×2 block, the four
    /// of a 4×4 block summed; where they lie: [`Intrinsics::sampled`]) under the projector's
    /// light of that colour, of which the pixels' colour filter passes all and of a white
    /// ambient light a third.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a sampling the camera does not offer ([`SensorSpec::samplings`],
    /// listing those it does), or a subsampling on a sensor without a colour imager under its
    /// projector (no Bayer grid to pick a colour from).
    pub fn sampled(&self, sampling: Sampling) -> Result<SensorSpec, Error> {
        let refuse = |allowed: String| Error::Invalid {
            key: "sampling".into(),
            value: format!("\"{sampling}\""),
            allowed,
        };
        if !self.samplings.is_empty() && !self.samplings.contains(&sampling) {
            let names: Vec<String> = self.samplings.iter().map(Sampling::to_string).collect();
            return Err(refuse(format!(
                "one of {} on {}",
                names.join(", "),
                self.name
            )));
        }
        if !sampling.subsamples() {
            return Ok(self.binned(sampling.factor()));
        }
        let bayer = self.projector().is_some()
            && self.colour.capture != ColourCapture::Flat
            && !self.colour.monochrome
            && self.colour.offset == [0.0; 3];
        if !bayer {
            return Err(refuse(format!(
                "all, by2x2 or by4x4 on {}, whose imager has no colour pixels under its projector",
                self.name
            )));
        }
        let factor = sampling.factor();
        let sampled = self.intrinsics.sampled(factor, sampling.offset());
        // one pixel of each 2×2 block's colour, the four of a 4×4 block's
        let side = (factor / 2) as f32;
        let mut spec = self.gathered(factor as f32, side, sampled);
        spec.noise.snr.ambient /= 3.0;
        Ok(spec)
    }

    /// This sensor with camera `intrinsics`, `factor` times fewer pixels along each axis: its
    /// noise correlates, and its blur spreads, over as many fewer pixels, and its pixels are
    /// `factor` times wider.
    fn fewer_pixels(&self, factor: f32, intrinsics: Intrinsics) -> SensorSpec {
        let mut spec = self.clone();
        spec.intrinsics = intrinsics;
        let length = &mut spec.noise.correlated.length_px;
        *length = (*length / factor).max(1.0);
        spec.noise.wings.psf_px /= factor;
        // a binned or subsampled pixel spans `factor` of the imager's along each axis
        spec.colour.pixel_um *= factor;
        spec
    }

    /// The calibration error of this camera, drawn from its calibration seed; none for a
    /// camera without one.
    pub fn calibration_error(&self) -> Option<CalibrationError> {
        let c = &self.calibration;
        if c.scale == 0.0 && c.warp == 0.0 {
            return None;
        }
        let rng = PixelRng::new(c.seed, u64::MAX);
        let draw = |k: u64| rng.normal(stream::CALIBRATION + k);
        let k = &self.intrinsics;
        Some(CalibrationError {
            scale: c.scale * draw(0),
            bowl: c.warp * draw(1),
            saddle: c.warp * draw(2),
            twist: c.warp * draw(3),
            per_field: [
                (k.fx / (f64::from(k.width) / 2.0)) as f32,
                (k.fy / (f64::from(k.height) / 2.0)) as f32,
            ],
        })
    }

    /// The product of the camera's focal length (pixels) and the projector's baseline (m),
    /// which turns disparity into depth; 0 without a projector.
    pub fn focal_baseline(&self) -> f32 {
        self.projector()
            .map_or(0.0, |p| self.intrinsics.fx as f32 * p.baseline.abs())
    }

    /// Whether the noise filter removes a point of SNR `snr`: only a sensor with the SNR model
    /// measures one.
    #[inline]
    pub fn filters_out(&self, snr: f32) -> bool {
        self.noise.snr.is_on() && self.processing.filters.noise.removal.removes(snr)
    }

    /// The projector, for models that have one.
    pub fn projector(&self) -> Option<&Projector> {
        match &self.model {
            Model::StructuredLight { projector } | Model::Kinect { projector, .. } => {
                Some(projector)
            }
            Model::Ideal | Model::TimeOfFlight => None,
        }
    }

    /// Memory a scan of this sensor holds at its peak, in bytes: its pixels
    /// ([`Pixel`](crate::Pixel), 56 bytes) and their working data (the wings' among them), 80
    /// bytes a pixel in all (measured: 402 MB for a 5 MP scan of a motor, the process's peak).
    pub fn scan_memory(&self) -> u64 {
        const PER_PIXEL: u64 = 80;
        u64::from(self.intrinsics.width) * u64::from(self.intrinsics.height) * PER_PIXEL
    }

    /// How far, in pixels, a pixel's measurement can reach beyond its own centre ray: lateral
    /// jitter moves it (16σ bounds any draw), mixed pixels read the adjacent pixels, wings the
    /// blur's reach and the Kinect window its neighbourhood; plus a pixel for rounding. Range noise keeps a point on
    /// its ray. A point can only lie in a box that its pixel's ray, or one this many pixels
    /// away, crosses.
    pub fn reach_px(&self) -> f32 {
        let window = match self.model {
            Model::Kinect { window, .. } => (window / 2) as f32,
            _ => 0.0,
        };
        let edges = if self.noise.edges.probability > 0.0 {
            1.0
        } else {
            0.0
        };
        let wings = self.noise.wings.radius() as f32;
        1.0 + (16.0 * self.noise.lateral_px)
            .max(edges)
            .max(window)
            .max(wings)
    }

    /// Checks the camera and the ranges.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] naming the first field that is out of range
    /// (intrinsics, ranges, projector, noise).
    pub fn validate(&self) -> Result<(), Error> {
        self.intrinsics.validate()?;
        self.noise.validate()?;
        self.colour.validate()?;
        if !(self.min_range >= 0.0 && self.min_range < self.max_range && self.max_range.is_finite())
        {
            return Err(Error::Invalid {
                key: "min_range/max_range".into(),
                value: format!("{}/{}", self.min_range, self.max_range),
                allowed: "0 <= min_range < max_range, finite".into(),
            });
        }
        let c = &self.calibration;
        for (key, value) in [("calibration.scale", c.scale), ("calibration.warp", c.warp)] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::Invalid {
                    key: key.into(),
                    value: value.to_string(),
                    allowed: "a finite number >= 0".into(),
                });
            }
        }
        let filters = &self.processing.filters;
        let thresholds = [
            (
                "processing.filters.noise.removal.threshold",
                filters.noise.removal.threshold,
                0.0..=f32::MAX,
                "an SNR >= 0",
            ),
            (
                "processing.filters.outlier.removal.threshold",
                filters.outlier.removal.threshold,
                0.0..=f32::MAX,
                "a distance >= 0, mm",
            ),
            (
                "processing.filters.cluster.removal.max_neighbor_distance",
                filters.cluster.removal.max_neighbor_distance,
                0.0..=f32::MAX,
                "a distance >= 0, in spacings of neighbouring pixels' points",
            ),
            (
                "processing.filters.cluster.removal.min_area",
                filters.cluster.removal.min_area,
                0.0..=f32::MAX,
                "an area >= 0, mm²",
            ),
            (
                "processing.filters.experimental.contrast_distortion.correction.strength",
                filters.experimental.contrast_distortion.correction.strength,
                0.0..=1.0,
                "a share from 0 to 1",
            ),
            (
                "processing.filters.experimental.contrast_distortion.removal.threshold",
                filters.experimental.contrast_distortion.removal.threshold,
                0.0..=1.0,
                "a value from 0 to 1 (higher removes more)",
            ),
            (
                "processing.filters.hole.repair.hole_size",
                filters.hole.repair.hole_size,
                0.0..=1.0,
                "0 to 1, relative to the hole's distance",
            ),
            (
                "processing.filters.hole.repair.strictness",
                filters.hole.repair.strictness as f32,
                1.0..=4.0,
                "1, 2, 3 or 4 sides",
            ),
            (
                "processing.filters.smoothing.gaussian.sigma",
                filters.smoothing.gaussian.sigma,
                0.0..=10.0,
                "a blur of 0 to 10 pixels",
            ),
        ];
        within(thresholds)?;
        if self.noise.snr.is_on() && self.focal_baseline() == 0.0 {
            return Err(Error::Invalid {
                key: "noise.snr.electrons".into(),
                value: self.noise.snr.electrons.to_string(),
                allowed: "0 for a sensor without a projector beside the camera (the SNR model \
                          triangulates)"
                    .into(),
            });
        }
        if self.noise.wings.psf_px > 0.0 && self.projector().is_none() {
            return Err(Error::Invalid {
                key: "noise.wings.psf_px".into(),
                value: self.noise.wings.psf_px.to_string(),
                allowed: "0 for a sensor without a projector (wings come from its stripes)".into(),
            });
        }
        if self.noise.interreflection.enabled && self.projector().is_none() {
            return Err(Error::Invalid {
                key: "noise.interreflection.enabled".into(),
                value: "true".into(),
                allowed: "false for a sensor without a projector (the mirrored light is its \
                          stripes)"
                    .into(),
            });
        }
        let reach = self.noise.interreflection.diffuse_reach;
        if !(0.0..=1.0).contains(&reach) || (reach > 0.0 && self.projector().is_none()) {
            return Err(Error::Invalid {
                key: "noise.interreflection.diffuse_reach".into(),
                value: reach.to_string(),
                allowed: "0 to 1 m, and 0 for a sensor without a projector (the diffuse light \
                          carries its stripes)"
                    .into(),
            });
        }
        if let Some(p) = self.projector() {
            let ok = p.baseline.is_finite()
                && p.convergence > 0.0
                && p.hfov_deg > 0.0
                && p.hfov_deg < 180.0
                && p.vfov_deg > 0.0
                && p.vfov_deg < 180.0;
            if !ok {
                return Err(Error::Invalid {
                    key: "projector".into(),
                    value: format!("{p:?}"),
                    allowed:
                        "a finite baseline, positive convergence and fields of view below 180°"
                            .into(),
                });
            }
        }
        Ok(())
    }
}
