//! A colour renderer on the scanner's BVH: unidirectional path tracing with the lights sampled
//! at every surface point (point and rectangular lights, multiple importance sampling with the
//! BSDF for the rectangles) and a uniform environment, Blender's Principled BSDF as the surface
//! model ([`Material`]'s colour, metallic, roughness and specular level), flat shading, a box
//! filter over each pixel, a thin lens's depth of field and the camera's motion over the
//! exposure. Every sample is a pure function of (seed, pixel, sample), so an image
//! has the same bytes for any thread count; it is measured against Cycles in
//! `docs/appearance.md`.
//!
//! [`Material`]: crate::Material

pub(crate) mod bsdf;
mod denoise;
mod fill;
mod frame;
mod light;
mod path;

use glam::{Affine3A, Vec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::camera::{Intrinsics, RayGrid};
use crate::world::World;
use denoise::{Guide, denoise};
use fill::fill;
use frame::{Frame, TILE, choices};
use light::Emitter;
pub use light::{Light, Lighting};
use path::Scene;

/// How a frame is rendered.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// Paths per pixel, 1 to 65536.
    pub samples: u32,
    /// Surface interactions after the first that a path may have (0: the light reaching the
    /// first surface straight from the lights and the environment),
    /// 0 to 64.
    pub bounces: u32,
    /// Seed of the samples.
    pub seed: u64,
    /// Radius of the lens's aperture, m: 0 for a pinhole; otherwise a thin lens focused at
    /// `focus` (see [`ColourCamera::aperture_radius`](crate::ColourCamera::aperture_radius)).
    pub aperture: f32,
    /// Distance of the plane in focus along the camera's axis, m.
    pub focus: f32,
    /// How far the camera moves during the exposure, in its own frame, m (motion blur); the
    /// pose is the exposure's middle.
    pub motion: [f32; 3],
    /// Filter the frame's path-tracing noise with an edge-aware denoiser guided by each pixel's
    /// first surface (its albedo, normal and point).
    pub denoise: bool,
    /// Pixels per side of the square blocks ([`LIGHT_BLOCK`]) in each of which the light of
    /// one pixel, drawn per block, is path-traced (1: every pixel's); the others see their
    /// first surface only and, after the traced light is denoised, take theirs from the blocks
    /// around them over like surfaces (its albedo divided out, theirs multiplied in, so every
    /// pixel keeps its own surface's colour). Above 1 it needs [`Settings::denoise`]: fewer
    /// paths for light that varies more slowly than the surfaces' colours.
    pub light_block: u32,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            samples: 64,
            bounces: 4,
            seed: 0,
            aperture: 0.0,
            focus: 1.0,
            motion: [0.0; 3],
            denoise: false,
            light_block: 1,
        }
    }
}

impl Settings {
    /// Checks the ranges.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for samples outside 1 to 65536, bounces above 64, a light block
    /// outside [`LIGHT_BLOCK`] or above 1 without the denoiser, or an aperture, focus or
    /// motion out of range.
    pub fn validate(&self) -> Result<(), Error> {
        if !(1..=65536).contains(&self.samples) {
            return Err(Error::Invalid {
                key: "render.samples".into(),
                value: self.samples.to_string(),
                allowed: "1 to 65536 paths per pixel".into(),
            });
        }
        if self.bounces > 64 {
            return Err(Error::Invalid {
                key: "render.bounces".into(),
                value: self.bounces.to_string(),
                allowed: "0 to 64".into(),
            });
        }
        if !LIGHT_BLOCK.contains(&self.light_block) || (self.light_block > 1 && !self.denoise) {
            return Err(Error::Invalid {
                key: "render.light_block".into(),
                value: self.light_block.to_string(),
                allowed: format!(
                    "{} to {} pixels, above 1 only with the denoiser",
                    LIGHT_BLOCK.start(),
                    LIGHT_BLOCK.end()
                ),
            });
        }
        let [mx, my, mz] = self.motion;
        crate::spec::within([
            ("render.aperture", self.aperture, 0.0..=1.0, "0 to 1 m"),
            ("render.focus", self.focus, 0.01..=1000.0, "0.01 to 1000 m"),
            ("render.motion", mx, -1.0..=1.0, "-1 to 1 m per axis"),
            ("render.motion", my, -1.0..=1.0, "-1 to 1 m per axis"),
            ("render.motion", mz, -1.0..=1.0, "-1 to 1 m per axis"),
        ])
    }
}

/// A rendered frame: linear RGB radiance per pixel, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Linear RGB per pixel, row-major.
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    /// The frame as 8-bit sRGB (Blender's "Standard" view transform: no tone mapping, values
    /// above 1 clipped), row-major RGB bytes.
    pub fn to_srgb8(&self) -> Vec<u8> {
        self.pixels.iter().flatten().map(|&v| srgb8(v)).collect()
    }

    /// The mean luminance of its pixels (Rec. 709 weights): what an automatic exposure meters.
    pub fn mean_luminance(&self) -> f32 {
        let sum: f32 = self.pixels.iter().map(|&p| bsdf::luminance(p.into())).sum();
        sum / self.pixels.len().max(1) as f32
    }
}

/// A linear value as 8-bit sRGB (IEC 61966-2-1), rounded.
pub fn srgb8(linear: f32) -> u8 {
    let v = linear.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

/// Draws per path vertex: the BSDF's three and, per light, two.
const DRAWS_PER_VERTEX: u64 = 16;
/// The sides of the blocks of pixels [`Settings::light_block`] may take.
pub const LIGHT_BLOCK: std::ops::RangeInclusive<u32> = 1..=8;
/// Most lights a scene may have (each takes two draws of a vertex).
pub const MAX_LIGHTS: usize = 6;
/// Offset of a ray leaving a surface along its normal, metres.
const EPSILON: f32 = 2e-5;
/// The draws of a camera ray's lens point and time, and of which pixel of a light block traces
/// its light, beyond those of any path's vertices.
const CAMERA_DRAWS: u64 = 1 << 20;

/// Renders what a camera of `intrinsics` at camera-to-world `pose` (x right, y down, z
/// forward) sees of `world` under `lighting`: a pinhole, or a thin lens of
/// [`Settings::aperture`]; the pose at the middle of the exposure.
///
/// # Errors
///
/// [`Error::Invalid`] for settings, lighting or intrinsics out of range, or more than
/// [`MAX_LIGHTS`] lights.
///
/// # Example
///
/// ```
/// use glam::Vec3;
/// use sensor::render::{Light, Lighting, Settings, render};
/// use sensor::{Intrinsics, Material, Target, World, look_at, shapes};
///
/// let plane = shapes::rectangle(Vec3::ZERO, Vec3::X, Vec3::Y);
/// let world = World::new(&[Target::from_triangles(&plane, 1, 1, Material::default())]);
/// let lighting = Lighting {
///     lights: vec![Light::Point { position: [0.0, 0.0, 1.0], power: 100.0, colour: [1.0; 3] }],
///     environment: [0.0; 3],
/// };
/// let camera = Intrinsics::from_fov(32, 24, 40.0, 30.0);
/// let pose = look_at(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Vec3::Y).unwrap();
/// let image = render(&world, &camera, &pose, &lighting, &Settings::default())?;
/// assert!(image.pixels.iter().all(|p| p[0] > 0.0));
/// # Ok::<(), sensor::Error>(())
/// ```
pub fn render(
    world: &World,
    intrinsics: &Intrinsics,
    pose: &Affine3A,
    lighting: &Lighting,
    settings: &Settings,
) -> Result<Image, Error> {
    settings.validate()?;
    lighting.validate()?;
    intrinsics.validate()?;
    if lighting.lights.len() > MAX_LIGHTS {
        return Err(Error::Invalid {
            key: "lights".into(),
            value: lighting.lights.len().to_string(),
            allowed: format!("at most {MAX_LIGHTS} lights"),
        });
    }
    let scene = Scene {
        world,
        emitters: lighting.lights.iter().map(Emitter::new).collect(),
        environment: Vec3::from(lighting.environment),
        settings: *settings,
    };
    let (width, height) = (intrinsics.width as usize, intrinsics.height as usize);
    let block = settings.light_block as usize;
    let frame = Frame {
        scene,
        pose: *pose,
        rays: RayGrid::new(intrinsics),
        width,
        motion: Vec3::from(settings.motion),
        block,
        choices: if block > 1 {
            choices(width, height, block, settings.seed)
        } else {
            Vec::new()
        },
    };
    let mut pixels = vec![[0.0f32; 3]; width * height];
    // each pixel's guide for the denoiser (without it, a placeholder per band of tiles)
    let (guides_len, guide_rows) = if settings.denoise {
        (width * height, TILE * width)
    } else {
        (height.div_ceil(TILE), 1)
    };
    let mut guides = vec![None; guides_len];
    // a task per band of tiles
    pixels
        .par_chunks_mut(TILE * width)
        .zip(guides.par_chunks_mut(guide_rows))
        .enumerate()
        .for_each(|(band, (out, guides))| frame.band(band, out, guides));
    if settings.denoise {
        let pixel_angle = (1.0 / intrinsics.fx) as f32;
        if block == 1 {
            denoise(&mut pixels, &guides, width, pixel_angle);
        } else {
            // the traced pixels as a frame of their own, a block apart, denoised, then their
            // light spread over the blocks
            let choices = &frame.choices;
            let mut light: Vec<[f32; 3]> = choices.iter().map(|&i| pixels[i]).collect();
            let traced: Vec<Option<Guide>> = choices.iter().map(|&i| guides[i]).collect();
            let across = width.div_ceil(block);
            denoise(&mut light, &traced, across, pixel_angle * block as f32);
            fill(
                &mut pixels,
                &guides,
                width,
                (&light, choices),
                block,
                pixel_angle,
            );
        }
    }
    Ok(Image {
        width: intrinsics.width,
        height: intrinsics.height,
        pixels,
    })
}

#[cfg(test)]
mod tests;
