//! Decoding the projector's stripes from the light a pixel receives, when that light comes from
//! more than one surface: its neighbours' through the camera's blur (the wings), or a surface
//! that a shiny one mirrors (interreflection).

use std::f32::consts::TAU;

use glam::Vec3;

use super::cast::Capture;
use super::measure::noisy_range;
use super::{Pixel, round};
use crate::noise::{PixelRng, Snr};
use crate::spec::{Frustum, SensorSpec};

/// How many of the finest stripes' periods make one of the middle pattern's: the pattern is
/// decoded in three steps, as phase-shifting cameras unwrap their phase (the whole field as
/// one period, then 1/8 of it, then the finest stripes), each step picking the period of the
/// next.
pub(super) const MIDDLE: f32 = 8.0;

/// Light that reaches a pixel: the phasors of the finest and the middle pattern and the column
/// it encodes, each weighted by its brightness; lights add.
#[derive(Clone, Copy, Default)]
pub(super) struct Light {
    /// Brightness (electrons with the SNR model, else the signal).
    pub(super) amplitude: f32,
    /// Modulation × cos and sin of the phase of the finest stripes, and of the middle pattern.
    pub(super) phasor: [[f32; 2]; 2],
    /// The coarsest pattern's modulation (brightness × its contrast), and that × the
    /// projector column (the phase of a pattern of one period across the field).
    pub(super) coarse: f32,
    pub(super) column: f32,
    /// Variance of the light's noise (electrons²; 0 without the SNR model).
    pub(super) variance: f32,
}

impl Light {
    /// The light of a surface at projector column `column` whose signal is `signal`, of which
    /// the finest, the middle and the coarsest pattern keep `contrast` (each 0 to 1) of their
    /// modulation. `snr` is the SNR a pixel receiving only this light measures (its noise,
    /// ambient light included), or 0 for shot noise alone.
    pub(super) fn new(
        signal: f32,
        snr: f32,
        column: f32,
        [fine, middle, coarse]: [f32; 3],
        stripes: &Stripes,
        model: &Snr,
    ) -> Light {
        let (amplitude, variance) = if model.is_on() {
            let a = signal * model.electrons;
            let read = model.read_electrons * model.read_electrons;
            let noise = if snr > 0.0 {
                (a / snr).powi(2) - read
            } else {
                a
            };
            (a, noise.max(a))
        } else {
            (signal, 0.0)
        };
        let phasor = |contrast: f32, period: f32| {
            let (sin, cos) = (TAU * column / period).sin_cos();
            [contrast * amplitude * cos, contrast * amplitude * sin]
        };
        Light {
            amplitude,
            phasor: [
                phasor(fine, stripes.period),
                phasor(middle, MIDDLE * stripes.period),
            ],
            coarse: coarse * amplitude,
            column: coarse * amplitude * column,
            variance,
        }
    }

    /// This light plus `other` × `weight`, its finest, middle and coarsest patterns' modulation
    /// × `contrast`.
    #[inline]
    pub(super) fn add_blurred(&mut self, other: &Light, weight: f32, contrast: [f32; 3]) {
        self.amplitude += weight * other.amplitude;
        for ((mine, theirs), c) in self.phasor.iter_mut().zip(&other.phasor).zip(contrast) {
            mine[0] += weight * c * theirs[0];
            mine[1] += weight * c * theirs[1];
        }
        self.coarse += weight * contrast[2] * other.coarse;
        self.column += weight * contrast[2] * other.column;
        self.variance += weight * other.variance;
    }

    /// This light plus `other` × `weight`.
    #[inline]
    pub(super) fn add(&mut self, other: &Light, weight: f32) {
        self.add_blurred(other, weight, [1.0; 3]);
    }
}

/// The projector's stripes as the blurred camera sees them.
#[derive(Clone, Copy)]
pub(super) struct Stripes {
    /// The projector's frustum, which gives a point's column.
    pub(super) frustum: Frustum,
    /// The finest period, in the frustum's column units.
    pub(super) period: f32,
    /// The contrast the blur leaves of stripes on a plane.
    pub(super) smooth: f32,
}

impl Stripes {
    /// The stripes of `sensor`'s projector (`frustum`): `noise.wings.stripes` periods across
    /// its field, blurred by `noise.wings.psf_px`.
    pub(super) fn new(sensor: &SensorSpec, frustum: Frustum) -> Stripes {
        let wings = &sensor.noise.wings;
        let period = 2.0 * frustum.half_width() / wings.stripes;
        // the contrast a Gaussian blur leaves of stripes of that period (about as many camera
        // pixels as the camera's focal length makes of it)
        let period_px = period * sensor.intrinsics.fx as f32;
        Stripes {
            frustum,
            period,
            smooth: (-2.0 * (std::f32::consts::PI * wings.psf_px / period_px).powi(2)).exp(),
        }
    }
}

/// Pixel `px` (its column and row) decoded from the light `sum` it receives: its point on its
/// own ray at the decoded column, with the SNR of that light, or none where that light
/// saturates it, a filter removes it (the noise filter; the reflection filter where its
/// patterns show light from elsewhere or an ambiguous unwrapping) or the column's light plane
/// meets the ray out of range; the point keeps the share of its light from elsewhere. A pixel
/// without a surface of its own takes the labels of `strongest`, the surface whose light
/// dominates. A pixel `pulled` by a step of brightness alone (a smooth surface) goes through
/// Zivid's contrast-distortion filters.
pub(super) fn decode(
    setup: &Capture,
    stripes: &Stripes,
    sum: &Light,
    [c, row]: [usize; 2],
    px: &Pixel,
    strongest: &Pixel,
    pulled: bool,
) -> Pixel {
    let sensor = setup.sensor;
    let k = &sensor.intrinsics;
    let snr_model = sensor.noise.snr;
    let Stripes {
        frustum,
        period,
        smooth,
    } = *stripes;
    let own = !px.clean.x.is_nan();
    // without a point the pixel is as it was, less its point
    let out = Pixel {
        point: Vec3::NAN,
        ..*px
    };
    if sum.amplitude <= 0.0 || sum.coarse <= 0.0 {
        return out;
    }
    // each pattern's phase gives the column within its period, the coarser one's column picks
    // the period; how far the two disagree, in periods (0 to 0.5), is what a reflection filter
    // sees (a single surface's patterns agree)
    let unwrap = |[c, s]: [f32; 2], period: f32, coarser: f32| {
        let within = s.atan2(c) / TAU * period;
        let column = within + period * round((coarser - within) / period);
        (column, (coarser - column).abs() / period)
    };
    let coarse = sum.column / sum.coarse;
    let (middle, middle_off) = unwrap(sum.phasor[1], MIDDLE * period, coarse);
    let (column, fine_off) = unwrap(sum.phasor[0], period, middle);
    let filters = &sensor.processing.filters;
    let column = if pulled {
        let own = frustum.column(px.clean);
        let blur = sensor.noise.wings.psf_px;
        match filters
            .experimental
            .contrast_distortion
            .filter(column, own, k.fx as f32, blur)
        {
            Some(column) => column,
            None => return out,
        }
    } else {
        column
    };
    // the stripes' contrast left after the blur, against what the blur leaves on a smooth
    // surface (which the SNR model's precision already holds)
    let fine = sum.phasor[0][0].hypot(sum.phasor[0][1]);
    let contrast = (fine / sum.amplitude / smooth).min(1.0);
    let snr = if snr_model.is_on() {
        let read = snr_model.read_electrons * snr_model.read_electrons;
        (contrast * sum.amplitude / (sum.variance + read).sqrt()).min(255.0)
    } else {
        0.0
    };
    let intensity = if snr_model.is_on() {
        sum.amplitude / snr_model.electrons
    } else {
        sum.amplitude
    };
    // a pixel the blur of a highlight saturates, or a filter removes, has no point (the
    // finest stripes' modulation against the coarsest pattern's shows the pixel's own light)
    let direct = (fine / smooth / sum.coarse).min(1.0);
    let reflection = &filters.reflection.removal;
    if sensor.filters_out(snr)
        || sensor.noise.specular.saturates(intensity)
        || reflection.removes(middle_off.max(fine_off), direct)
    {
        return out;
    }
    let dir = if own {
        px.clean.normalize()
    } else {
        k.ray(c as f64, row as f64)
    };
    let t = frustum.ray_to_column(dir, column);
    if !(t > 0.0 && sensor.in_range(t * dir.z)) {
        return out;
    }
    let rng = PixelRng::new(setup.seed, (row * k.width as usize + c) as u64);
    let incidence = if own { px.incidence } else { 0.0 };
    let at = [c as u32, row as u32];
    let Some(range) = noisy_range(setup, rng, at, dir, t, snr, incidence) else {
        return out;
    };
    // a point: the labels and normal of the pixel's own surface, or of the neighbour whose
    // light dominates where it sees none; the colour its own pixel records
    let seen = if own {
        *px
    } else {
        Pixel {
            clean: Vec3::NAN,
            incidence: f32::NAN,
            ..*strongest
        }
    };
    Pixel {
        point: dir * range,
        snr,
        intensity,
        rgb: px.rgb,
        indirect: ((1.0 - direct) * 255.0).round() as u8,
        ..seen
    }
}
