//! Noise models, each off by default and composable, and the counter-based random numbers that
//! drive them: every draw is a pure function of (scan seed, pixel, stream), so a scan's bytes do
//! not depend on thread count or tiling.

use std::convert::Infallible;

use rand::TryRng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::world::Material;

/// Random draws keyed by (seed, pixel, stream): SplitMix64 finalisers over the key, a
/// counter-based generator in the sense of Salmon et al. (SC'11), without state to share.
#[derive(Clone, Copy, Debug)]
pub struct PixelRng {
    key: u64,
}

impl PixelRng {
    /// The generator of one pixel of a scan.
    #[inline]
    pub fn new(seed: u64, pixel: u64) -> PixelRng {
        PixelRng {
            key: mix(seed ^ mix(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15))),
        }
    }

    /// 64 random bits of stream `k`.
    #[inline]
    pub fn bits(self, k: u64) -> u64 {
        mix(self.key.wrapping_add(k.wrapping_mul(0xd1b5_4a32_d192_ed03)))
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn uniform(self, k: u64) -> f32 {
        (self.bits(k) >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Standard normal, drawn with `rand_distr`'s ziggurat from stream `k`'s own sequence.
    #[inline]
    pub fn normal(self, k: u64) -> f32 {
        let mut draws = Draws {
            key: self.bits(k),
            counter: 0,
        };
        let z: f64 = StandardNormal.sample(&mut draws);
        z as f32
    }
}

/// The sequence of 64-bit draws of one stream of a pixel, as a `rand` generator for
/// `rand_distr`'s samplers.
struct Draws {
    key: u64,
    counter: u64,
}

impl TryRng for Draws {
    type Error = Infallible;

    #[inline]
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok((self.try_next_u64()? >> 32) as u32)
    }

    #[inline]
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        // the key is itself a hash: it serves as the first draw (the ziggurat nearly always
        // needs only one), mixed with the counter after that
        let draw = if self.counter == 0 {
            self.key
        } else {
            mix(self.key ^ self.counter.wrapping_mul(0x9e37_79b9_7f4a_7c15))
        };
        self.counter += 1;
        Ok(draw)
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        rand::rand_core::utils::fill_bytes_via_next_word(dst, || self.try_next_u64())
    }
}

#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Streams of [`PixelRng`], one per use, so that switching one model on never shifts another's
/// draws.
pub mod stream {
    /// Axial noise.
    pub const AXIAL: u64 = 0;
    /// Lateral jitter: u, and v at `LATERAL + 2`.
    pub const LATERAL: u64 = 2;
    /// Random and low-signal dropout.
    pub const DROPOUT: u64 = 6;
    /// Mixed pixels at depth edges (decision and blend).
    pub const EDGE: u64 = 8;
    /// Kinect disparity noise.
    pub const DISPARITY: u64 = 10;
    /// Per-scan bias (drawn once, from the pixel index `u64::MAX`).
    pub const BIAS: u64 = 12;
    /// Colour noise (one draw for the three channels).
    pub const COLOUR: u64 = 14;
    /// The lattice of the correlated range noise (keyed by its nodes, not by pixels).
    pub const CORRELATED: u64 = 16;
    /// The camera's calibration error (drawn once, from the pixel index `u64::MAX`).
    pub const CALIBRATION: u64 = 18;
    /// Diffuse interreflection: the turn of a cell's spiral of samples.
    pub const BOUNCE: u64 = 20;
}

/// All noise models of a sensor. Each is off at its default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Noise {
    /// Gaussian range noise along the ray.
    pub axial: Axial,
    /// Growth of the axial noise towards grazing incidence.
    pub incidence: Incidence,
    /// Range noise from the pattern's signal-to-noise ratio (structured light).
    pub snr: Snr,
    /// Correlation of the range noise along the projector's stripes.
    pub correlated: Correlated,
    /// Gaussian jitter of the pixel's sampling position, pixels (σ): the point moves to where
    /// the jittered ray meets the tangent plane of the surface the pixel sees.
    pub lateral_px: f32,
    /// Range quantisation step, metres (0 = none).
    pub quantization: f32,
    /// Missing returns: at random and from low signal.
    pub dropout: Dropout,
    /// Highlights on shiny surfaces, and saturation.
    pub specular: Specular,
    /// Mixed pixels ("flying pixels") at depth discontinuities: one pixel either side.
    pub edges: Edges,
    /// Edge wings from the camera's blur of the projected pattern (structured light).
    pub wings: Wings,
    /// Shiny surfaces mirroring the stripes on other surfaces (structured light).
    pub interreflection: Interreflection,
    /// A per-scan systematic error.
    pub bias: Bias,
}

/// Axial standard deviation σ(d) = `sigma` + `per_metre`·d + `per_metre2`·d², metres at range
/// d metres: constant (Blensor's ToF), proportional to distance (Zivid's "noise proportional to
/// working distance") or quadratic (triangulation, Khoshelham and Elberink 2012).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Axial {
    /// Constant part, m.
    pub sigma: f32,
    /// Linear part, m per m of range.
    pub per_metre: f32,
    /// Quadratic part, m per m².
    pub per_metre2: f32,
}

impl Axial {
    /// σ at range `d`.
    #[inline]
    pub fn sigma_at(&self, d: f32) -> f32 {
        self.sigma + d * (self.per_metre + d * self.per_metre2)
    }
}

/// The axial σ is multiplied by 1 + `gain`·θ/(π/2 - θ) at incidence angle θ (the form of
/// Nguyen, Izadi and Lovell 2012), capped at `max_factor`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Incidence {
    /// Strength of the grazing-angle growth (0 = off).
    pub gain: f32,
    /// Largest multiplication of σ.
    pub max_factor: f32,
}

impl Default for Incidence {
    fn default() -> Incidence {
        Incidence {
            gain: 0.0,
            max_factor: 10.0,
        }
    }
}

impl Incidence {
    /// Factor on σ at incidence angle `theta` radians.
    #[inline]
    pub fn factor(&self, theta: f32) -> f32 {
        if self.gain == 0.0 {
            return 1.0;
        }
        let grazing = theta / (std::f32::consts::FRAC_PI_2 - theta).max(1e-6);
        (1.0 + self.gain * grazing).min(self.max_factor)
    }
}

/// The signal-to-noise ratio of a structured-light sensor's decoded pattern, and the range
/// noise it makes. A surface of reflectivity ρ whose signal is s (see [`Dropout`]) gives each
/// pixel A = s·`electrons` of pattern modulation over an ambient level B = ρ·`ambient`·
/// `electrons`; SNR = A / √(A + B + `read_electrons`²) (shot and read noise), capped at 255 as
/// Zivid's 8-bit SNR. The decoded disparity errs by `disparity_px` / SNR pixels (σ), which
/// triangulates into σ_z = σ·z² / (f·b) along the camera's z (f the focal length in pixels, b
/// the baseline): dark, far and grazing surfaces are noisier, and lose their points to the
/// noise filter (`processing.filters.noise.removal`) when their SNR is low.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Snr {
    /// Electrons of pattern modulation a pixel collects from a white surface facing the
    /// projector at the reference range (0 = off).
    pub electrons: f32,
    /// Ambient light on a white surface, as a share of that modulation.
    pub ambient: f32,
    /// Read noise, electrons (σ).
    pub read_electrons: f32,
    /// Disparity error at SNR 1, pixels (σ).
    pub disparity_px: f32,
}

impl Snr {
    /// Whether the model is on.
    #[inline]
    pub fn is_on(&self) -> bool {
        self.electrons > 0.0
    }

    /// The SNR of a pixel seeing a surface of `reflectivity` with signal `signal`.
    #[inline]
    pub fn ratio(&self, signal: f32, reflectivity: f32) -> f32 {
        let a = signal * self.electrons;
        let b = reflectivity * self.ambient * self.electrons;
        let noise = (a + b + self.read_electrons * self.read_electrons).sqrt();
        if noise > 0.0 {
            (a / noise).min(255.0)
        } else {
            0.0
        }
    }

    /// σ of the depth (camera z, m) at depth `z` of a pixel of SNR `snr`, for a camera of focal
    /// length × baseline `focal_baseline` (pixel·m).
    #[inline]
    pub fn sigma_z(&self, snr: f32, z: f32, focal_baseline: f32) -> f32 {
        self.disparity_px / snr.max(1e-3) * z * z / focal_baseline
    }
}

/// Range noise correlated along the projector's stripes (the image's columns, across the
/// baseline): a share `share` of the noise's variance is drawn at every `length_px`-th row of
/// each column and interpolated linearly between (normalised to unit variance), so that
/// neighbours along a column err alike; the rest stays white. Two pixels `length_px` or more
/// apart along a column, or in different columns, are uncorrelated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Correlated {
    /// Share of the range noise's variance that is correlated (0 = off).
    pub share: f32,
    /// Correlation length along the stripes, pixels.
    pub length_px: f32,
}

impl Default for Correlated {
    fn default() -> Correlated {
        Correlated {
            share: 0.0,
            length_px: 4.0,
        }
    }
}

impl Correlated {
    /// The key of the lattice of scan `seed`, for [`Correlated::draw`].
    pub fn key(seed: u64) -> u64 {
        mix(seed ^ mix(stream::CORRELATED))
    }

    /// The standard normal draw of pixel (`col`, `row`) of a `width`-wide scan, `white` being
    /// the pixel's own draw: the correlated share from the lattice of `key`.
    #[inline]
    pub fn draw(&self, white: f32, key: u64, col: usize, row: usize, width: usize) -> f32 {
        if self.share <= 0.0 {
            return white;
        }
        let at = row as f32 / self.length_px;
        let node = at as usize;
        let f = at - node as f32;
        // a node's draw: one hash (SplitMix64's stream of the key), as the sum of four of its
        // 16-bit uniforms (Irwin-Hall) scaled to unit variance, close to normal
        let lattice = |n: usize| {
            let index = (n * width + col) as u64;
            let bits = mix(key.wrapping_add(index.wrapping_mul(0x9e37_79b9_7f4a_7c15)));
            let sum: u32 = (0..4).map(|k| ((bits >> (16 * k)) & 0xffff) as u32).sum();
            (sum as f32 * (1.0 / 65536.0) - 2.0) * 3f32.sqrt()
        };
        let (n0, n1) = (lattice(node), lattice(node + 1));
        let smooth = ((1.0 - f) * n0 + f * n1) / ((1.0 - f) * (1.0 - f) + f * f).sqrt();
        (1.0 - self.share).sqrt() * white + self.share.sqrt() * smooth
    }
}

/// Dropout: a pixel is lost at random with probability `rate`, and when its signal is low: the
/// signal s = reflectivity · cos(projector incidence) · (reference range / range)² loses the
/// pixel with probability 1 / (1 + exp((s - `signal_threshold`) / `softness`)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Dropout {
    /// Probability of losing any pixel.
    pub rate: f32,
    /// Signal below which most pixels are lost (0 = off).
    pub signal_threshold: f32,
    /// Width of the transition, in signal units.
    pub softness: f32,
}

impl Default for Dropout {
    fn default() -> Dropout {
        Dropout {
            rate: 0.0,
            signal_threshold: 0.0,
            softness: 0.02,
        }
    }
}

impl Dropout {
    /// Probability of losing a pixel of signal `s`.
    #[inline]
    pub fn probability(&self, s: f32) -> f32 {
        let low = if self.signal_threshold > 0.0 {
            let x = (s - self.signal_threshold) / self.softness.max(1e-6);
            // beyond ±17.5 the logistic rounds to 0 or 1 in what follows (1 - e^-17.5 is 1.0
            // in f32): the same bits without the exponential
            if x > 17.5 {
                0.0
            } else if x < -17.5 {
                1.0
            } else {
                1.0 / (1.0 + x.exp())
            }
        } else {
            0.0
        };
        1.0 - (1.0 - self.rate) * (1.0 - low)
    }
}

/// Specular highlights and saturation. A material's mirror-like share `specular` reflects the
/// light as a lobe about the mirror direction ([`Lobe`]), falling off as
/// exp(−(1 − cos θ) / lobe²) with θ between the normal and the half vector of the light's and the
/// camera's directions (about exp(−θ² / (2·lobe²))), of the energy the material states: lit
/// straight on, the lobe returns `specular` of the light over the hemisphere, as a white diffuse
/// surface returns all of it (less at oblique light, none above it). It adds to the pixel's
/// signal. A pixel whose signal exceeds `saturation` saturates: its stripes are clipped and it
/// has no point. The saturated blob grows as the lobe widens or the exposure rises (a lower
/// `saturation`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Specular {
    /// Signal at which the camera saturates: 1 is a white diffuse surface facing the light at
    /// the reference range (0 = highlights off).
    pub saturation: f32,
}

impl Specular {
    /// The highlight's signal of a surface of specular lobe `lobe`, at cosine `cos_half`
    /// between the normal and the half vector, under light `light` (see [`Dropout`] for the
    /// signal).
    #[inline]
    pub fn highlight(&self, lobe: &Lobe, cos_half: f32, light: f32) -> f32 {
        if self.saturation <= 0.0 {
            return 0.0;
        }
        lobe.peak * (-(1.0 - cos_half) * lobe.sharpness).exp() * light
    }

    /// Whether a pixel of `signal` saturates.
    #[inline]
    pub fn saturates(&self, signal: f32) -> bool {
        self.saturation > 0.0 && signal > self.saturation
    }
}

/// A material's specular lobe as [`Specular::highlight`] reads it, worked out once per
/// material: its sharpness 1 / lobe² and its peak, the signal at the mirror direction per unit
/// of light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobe {
    /// 1 / lobe², lobe in radians.
    pub sharpness: f32,
    /// The signal at the mirror direction per unit of light: the material's specular share
    /// over the lobe's hemispherical integral lit straight on.
    pub peak: f32,
}

impl Lobe {
    /// The lobe of `material`: its specular share and lobe width.
    ///
    /// Lit straight on, the half vector of an outgoing direction at cosine u to the normal has
    /// cosine c = √((1 + u) / 2), and the lobe's share of the light is
    /// 2·∫₀¹ e^(−s(1 − c))·u du = 8·∫ e^(−s(1 − c))·(2c³ − c) dc over c from 1/√2 to 1 (a
    /// signal of 1 is a white diffuse surface, albedo 1, so the share is the signal's cosine-
    /// weighted mean over the hemisphere). The antiderivative is e^(−s(1 − c))·P(c) with
    /// P' + sP = 2c³ − c, in closed form; in f64 it stays exact for any lobe up to π.
    pub fn of(material: &Material) -> Lobe {
        let Material { specular, lobe, .. } = *material;
        let sharpness = 1.0 / (lobe * lobe).max(1e-6);
        if specular <= 0.0 {
            return Lobe {
                sharpness,
                peak: 0.0,
            };
        }
        let s = f64::from(sharpness);
        let (s2, s3, s4) = (s * s, s * s * s, s * s * s * s);
        let p = |c: f64| {
            2.0 / s * c * c * c - 6.0 / s2 * c * c + (12.0 / s3 - 1.0 / s) * c + 1.0 / s2
                - 12.0 / s4
        };
        let c0 = std::f64::consts::FRAC_1_SQRT_2;
        let share = 8.0 * (p(1.0) - (-s * (1.0 - c0)).exp() * p(c0));
        Lobe {
            sharpness,
            peak: (f64::from(specular) / share) as f32,
        }
    }
}

/// Mixed pixels: a pixel whose 4-neighbour lies more than `jump` metres further or nearer
/// becomes, with probability `probability`, a point on its own ray between the two depths.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Edges {
    /// Probability at each edge pixel (0 = off).
    pub probability: f32,
    /// Depth difference that makes an edge, metres.
    pub jump: f32,
}

impl Default for Edges {
    fn default() -> Edges {
        Edges {
            probability: 0.0,
            jump: 0.01,
        }
    }
}

/// Edge wings of a structured-light sensor: the camera's lens blurs the projected pattern (a
/// Gaussian of σ `psf_px` pixels), so that each pixel receives its neighbours' light with their
/// stripes. On a smooth surface that changes nothing; near a depth jump or a shadow the pixel
/// decodes the phase of the sum (the stripes' phasors, weighted by the blur and each surface's
/// brightness, with `stripes` periods across the projector's field; the period found from the
/// mean column, as a coarser pattern would), and its point lands on its own ray where that
/// column's light plane meets it: between the two surfaces, or a period off, a few pixels from
/// the edge, also into shadows and free space. Beside a step of brightness, or a highlight's
/// saturated core, the brighter light pulls the phase across the baseline (Zivid's contrast
/// distortion). Its SNR is the summed stripes' modulation over the summed light's noise, so the
/// noise filter removes the weakest.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Wings {
    /// σ of the camera's blur, pixels (0 = off).
    pub psf_px: f32,
    /// Finest pattern periods across the projector's field.
    pub stripes: f32,
}

impl Default for Wings {
    fn default() -> Wings {
        Wings {
            psf_px: 0.0,
            stripes: 64.0,
        }
    }
}

impl Wings {
    /// How far, in pixels, the blur reaches (2.5σ: 99 % of its weight in each direction).
    pub fn radius(&self) -> usize {
        (2.5 * self.psf_px).ceil() as usize
    }
}

/// Interreflection: a surface receives the projector's light by way of the surfaces around it,
/// and with it their stripes.
///
/// - The mirror bounce (`enabled`): a pixel that sees a surface of `specular` share > 0 also
///   receives, along its ray's mirror direction, the light of the surface found there when the
///   projector lights it: that surface's diffuse signal × `specular`, its stripes blurred by the
///   lobe (σ 2·lobe radians about the mirror direction, over the distance between the two
///   surfaces). A shiny pixel in the projector's shadow has no light of its own: the mirrored
///   light alone makes its point, a ghost, where its finest stripes survive the lobe.
/// - The diffuse bounce (`diffuse_reach` > 0): every lit surface sends its light to the surfaces
///   facing it, as a Lambertian emitter: a pixel receives its own surface's reflectivity ×
///   Σ signal·cos·cos·area / (π r²) over the lit surfaces within the reach, each patch's stripes
///   blurred over its width. The camera's own image, binned to at most 32k cells, stands for
///   those surfaces (32 samples per cell on a spiral, in rings from half a cell to the reach;
///   a pixel takes the blend of the cells round it that see its surface): surfaces the camera
///   does not see send nothing, and what lies between two surfaces is not tested, which holds
///   for the concave places where the light is strong (inside corners, a part on the table, a
///   jaw against the motor). Pixels whose indirect light is under 0.1 % of their own are left
///   as they were, so a convex scene changes nothing.
///
/// The pixel decodes its own and the indirect stripes together (as the [`Wings`] do): where the
/// indirect light is strong against the surface's own, as on shiny metal in an inside corner
/// or on a bright surface beside another, the point moves along its ray towards where the
/// indirect light's column plane meets it, or floats there as a ghost. Light that a mirror
/// throws onto a matte surface, and bounces beyond the second surface, are not modelled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Interreflection {
    /// Whether shiny surfaces mirror their surroundings' stripes.
    pub enabled: bool,
    /// How far, m, the diffuse bounce gathers light from (0: no diffuse bounce).
    pub diffuse_reach: f32,
}

/// A per-scan systematic error: range × (1 + N(0, `scale_sigma`)) + N(0, `offset_sigma`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Bias {
    /// σ of the constant range offset, m.
    pub offset_sigma: f32,
    /// σ of the relative scale error.
    pub scale_sigma: f32,
}

impl Noise {
    /// The same noise with every range-noise amplitude (the axial σ, the SNR model's
    /// disparity error) multiplied by `factor`.
    pub fn scaled(mut self, factor: f32) -> Noise {
        self.axial.sigma *= factor;
        self.axial.per_metre *= factor;
        self.axial.per_metre2 *= factor;
        self.snr.disparity_px *= factor;
        self
    }

    /// Checks that every setting is finite, non-negative, and a probability where it is one.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`](crate::Error::Invalid) naming the first noise parameter that is negative,
    /// not finite or out of its range.
    pub fn validate(&self) -> Result<(), crate::Error> {
        let amounts = [
            ("axial.sigma", self.axial.sigma),
            ("axial.per_metre", self.axial.per_metre),
            ("axial.per_metre2", self.axial.per_metre2),
            ("incidence.gain", self.incidence.gain),
            ("snr.electrons", self.snr.electrons),
            ("snr.ambient", self.snr.ambient),
            ("snr.read_electrons", self.snr.read_electrons),
            ("snr.disparity_px", self.snr.disparity_px),
            ("lateral_px", self.lateral_px),
            ("quantization", self.quantization),
            ("dropout.signal_threshold", self.dropout.signal_threshold),
            ("specular.saturation", self.specular.saturation),
            ("dropout.softness", self.dropout.softness),
            ("edges.jump", self.edges.jump),
            ("bias.offset_sigma", self.bias.offset_sigma),
            ("bias.scale_sigma", self.bias.scale_sigma),
        ];
        let shares = [
            ("dropout.rate", self.dropout.rate),
            ("edges.probability", self.edges.probability),
            ("correlated.share", self.correlated.share),
        ];
        let bad = |key: &str, value: f32, allowed: &str| crate::Error::Invalid {
            key: format!("noise.{key}"),
            value: value.to_string(),
            allowed: allowed.into(),
        };
        if let Some((k, v)) = amounts.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            return Err(bad(k, *v, "a finite number >= 0"));
        }
        if let Some((k, v)) = shares.iter().find(|(_, v)| !(0.0..=1.0).contains(v)) {
            return Err(bad(k, *v, "a probability from 0 to 1"));
        }
        let bounded = [
            (
                "correlated.length_px",
                self.correlated.length_px,
                1.0..=f32::MAX,
            ),
            ("wings.stripes", self.wings.stripes, 1.0..=f32::MAX),
            ("wings.psf_px", self.wings.psf_px, 0.0..=10.0),
            (
                "incidence.max_factor",
                self.incidence.max_factor,
                1.0..=f32::MAX,
            ),
        ];
        if let Some((k, v, range)) = bounded.iter().find(|(_, v, range)| !range.contains(v)) {
            let allowed = if *range.end() == f32::MAX {
                format!("a finite number >= {}", range.start())
            } else {
                format!("a number from {} to {}", range.start(), range.end())
            };
            return Err(bad(k, *v, &allowed));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropout_probability_skips_the_exponential_without_changing_a_bit() {
        let dropout = Dropout {
            rate: 0.002,
            signal_threshold: 0.05,
            softness: 0.02,
        };
        let logistic = |s: f32| {
            let low = 1.0 / (1.0 + ((s - 0.05) / 0.02f32).exp());
            1.0 - (1.0 - 0.002f32) * (1.0 - low)
        };
        for i in -200_000..200_000 {
            let s = 0.05 + i as f32 * 2e-6;
            assert_eq!(
                dropout.probability(s).to_bits(),
                logistic(s).to_bits(),
                "{s}"
            );
        }
    }
}
