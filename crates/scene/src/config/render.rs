//! `[render]` and `[lighting]`: the colour image path-traced under lights drawn per sample
//! (domain randomisation), instead of the sensor's own light.

use glam::Vec3;
use rand::{Rng, RngExt};
use sensor::render::{Light, Lighting};
use sensor::spec::blackbody;
use serde::{Deserialize, Serialize};

use super::Span;
use crate::error::{Error, Result};

/// `[render]`: how a view's colour image is made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderConfig {
    /// Path-trace the colour image under `[lighting]` (`sensor::render`, measured against
    /// Cycles), developed by the sensor's colour camera; off: the sensor's own light and the
    /// room's ambient light, one ray per pixel.
    pub enabled: bool,
    /// Paths per pixel.
    pub samples: u32,
    /// Surface interactions after the first that a path may have.
    pub bounces: u32,
    /// Filter the paths' noise with an edge-aware denoiser guided by each pixel's first
    /// surface (`sensor::render::Settings::denoise`).
    pub denoise: bool,
    /// Pixels per side of the blocks in each of which one pixel's light is path-traced, the
    /// others taking theirs from the blocks around after the denoiser
    /// (`sensor::render::Settings::light_block`).
    pub light_block: u32,
    /// The camera's automatic exposure: the frame's mean luminance brought to 0.18 (a mid
    /// grey) before `exposure`, as a camera's auto-exposure meters a scene.
    pub auto_exposure: bool,
    /// Exposure, stops (Blender's film exposure: the light times 2^this).
    pub exposure: Span,
    /// How far the camera moves during the exposure, m, in a direction across the image drawn
    /// per view (motion blur).
    pub motion: Span,
}

/// `[lighting]`: the lights of a rendered colour image, drawn per sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingConfig {
    /// Rectangular lights above the scene: [min, max] count.
    pub lights: [u32; 2],
    /// Power of each, W (Blender's convention).
    pub power: Span,
    /// Length of each side, m.
    pub size: Span,
    /// Height above the scene's centre, m.
    pub height: Span,
    /// Largest horizontal offset from the scene's centre, m, along each axis.
    pub spread: f32,
    /// Colour temperature of each light, kelvin.
    pub kelvin: Span,
    /// The surroundings' uniform radiance (grey; Blender's world strength).
    pub environment: Span,
}

impl RenderConfig {
    /// Checks the ranges.
    pub(super) fn check(&self) -> Result<()> {
        if !(1..=4096).contains(&self.samples) {
            return Err(Error::invalid("render.samples", self.samples, "1 to 4096"));
        }
        if self.bounces > 16 {
            return Err(Error::invalid("render.bounces", self.bounces, "0 to 16"));
        }
        let blocks = sensor::render::LIGHT_BLOCK;
        if !blocks.contains(&self.light_block) {
            return Err(Error::invalid(
                "render.light_block",
                self.light_block,
                format!("{} to {} pixels", blocks.start(), blocks.end()),
            ));
        }
        if self.light_block > 1 && !self.denoise {
            return Err(Error::Config(format!(
                "render.light_block = {} needs render.denoise = true: the blocks' light is spread after denoising",
                self.light_block
            )));
        }
        self.exposure.check("render.exposure", -16.0, 16.0)?;
        self.motion.check("render.motion", 0.0, 0.5)
    }
}

impl LightingConfig {
    /// Checks the ranges.
    pub(super) fn check(&self) -> Result<()> {
        let [lo, hi] = self.lights;
        if lo > hi || hi as usize > sensor::render::MAX_LIGHTS {
            return Err(Error::invalid(
                "lighting.lights",
                format!("{:?}", self.lights),
                format!(
                    "[min, max] with min <= max <= {}",
                    sensor::render::MAX_LIGHTS
                ),
            ));
        }
        self.power.check("lighting.power", 0.0, 1e5)?;
        self.size.check("lighting.size", 0.01, 10.0)?;
        self.height.check("lighting.height", 0.05, 20.0)?;
        if !(0.0..=20.0).contains(&self.spread) {
            return Err(Error::invalid("lighting.spread", self.spread, "0 to 20 m"));
        }
        self.kelvin.check("lighting.kelvin", 1667.0, 25000.0)?;
        self.environment.check("lighting.environment", 0.0, 100.0)
    }

    /// The lights over `centre` (world, z up), drawn from `rng`: each a square facing down,
    /// turned about the vertical, of a colour temperature's colour at luminance 1.
    pub fn draw(&self, centre: Vec3, rng: &mut impl Rng) -> Lighting {
        let count = rng.random_range(self.lights[0]..=self.lights[1]);
        let lights = (0..count)
            .map(|_| {
                let mut offset = || {
                    if self.spread > 0.0 {
                        rng.random_range(-self.spread..=self.spread)
                    } else {
                        0.0
                    }
                };
                let (dx, dy) = (offset(), offset());
                let at = centre + Vec3::new(dx, dy, self.height.sample(rng));
                let half = self.size.sample(rng) / 2.0;
                let turn = rng.random_range(0.0..std::f32::consts::TAU);
                let u = Vec3::new(turn.cos(), turn.sin(), 0.0) * half;
                // facing down: u × v along -z
                let v = Vec3::new(turn.sin(), -turn.cos(), 0.0) * half;
                Light::Rect {
                    centre: at.to_array(),
                    half_u: u.to_array(),
                    half_v: v.to_array(),
                    power: self.power.sample(rng),
                    colour: blackbody(self.kelvin.sample(rng)).to_array(),
                }
            })
            .collect();
        Lighting {
            lights,
            environment: [self.environment.sample(rng); 3],
        }
    }
}
