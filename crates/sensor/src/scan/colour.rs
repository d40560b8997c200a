//! The camera's colour image ([`ColourCamera`]): the light a pixel's surface sends to the
//! camera, shaded with the colour renderer's surface model under the flash and the ambient
//! light, and the camera's response to it. Each pixel that meets a surface records its colour
//! when it is labelled, whether or not it gets a point, and again with the ambient light alone
//! should the flash's shadow fall on it; a point's rgb is its pixel's.

use std::f32::consts::PI;

use glam::Vec3;

use crate::noise::{PixelRng, stream};
use crate::render::bsdf::{Bsdf, luminance};
use crate::spec::{ColourCamera, ColourCapture, PINK};
use crate::world::Material;

/// The camera's response to linear light: gain, white balance, grey or colour, noise, sRGB.
#[derive(Clone, Copy)]
pub(super) struct Response {
    gain: Vec3,
    /// The ambient light's radiance on a white surface, per channel.
    ambient: Vec3,
    /// The colour camera's centre in the depth camera's frame, if it is not the same imager.
    pub(super) offset: Option<Vec3>,
    camera: ColourCamera,
}

/// The light a surface point sends to the camera, linear RGB: in the ambient light, and in the
/// flash should it reach the point.
#[derive(Clone, Copy)]
pub(super) struct SurfaceLight {
    pub(super) ambient: Vec3,
    pub(super) flash: Vec3,
}

impl Response {
    pub(super) fn new(camera: &ColourCamera) -> Response {
        let [red, blue] = camera.white_balance;
        Response {
            gain: Vec3::new(red, 1.0, blue) * camera.gain,
            ambient: camera.ambient_colour() * camera.ambient,
            offset: Some(Vec3::from(camera.offset)).filter(|o| *o != Vec3::ZERO),
            camera: *camera,
        }
    }

    /// What a surface of `material` with normal `n` sends towards `wo` (unit, towards the
    /// camera): the ambient light, and the flash arriving from `to_flash` (unit) at
    /// `falloff` × its light at the reference range.
    #[inline]
    pub(super) fn light(
        &self,
        material: &Material,
        n: Vec3,
        wo: Vec3,
        to_flash: Option<(Vec3, f32)>,
    ) -> SurfaceLight {
        let dark = SurfaceLight {
            ambient: Vec3::ZERO,
            flash: Vec3::ZERO,
        };
        match self.camera.capture {
            // a 3D-only capture records no light
            ColourCapture::ThreeD => return dark,
            ColourCapture::Flat => {
                return SurfaceLight {
                    ambient: Vec3::from(material.colour),
                    flash: Vec3::ZERO,
                };
            }
            ColourCapture::TwoDThreeD => {}
        }
        let Some(bsdf) = Bsdf::new(material, n, wo) else {
            return dark;
        };
        let ambient = if self.ambient == Vec3::ZERO {
            Vec3::ZERO
        } else {
            bsdf.albedo() * self.ambient
        };
        let flash = match to_flash {
            Some((dir, falloff)) if self.camera.flash => {
                bsdf.reflect(dir) * (PI * self.camera.exposure * falloff)
            }
            _ => Vec3::ZERO,
        };
        SurfaceLight { ambient, flash }
    }

    /// The 8-bit sRGB a pixel records of linear light `light`.
    #[inline]
    pub(super) fn record(&self, light: Vec3, rng: PixelRng) -> [u8; 3] {
        match self.camera.capture {
            ColourCapture::ThreeD => return PINK,
            ColourCapture::Flat => return light.to_array().map(crate::render::srgb8),
            ColourCapture::TwoDThreeD => {}
        }
        let light = if self.camera.monochrome {
            Vec3::splat(luminance(light))
        } else {
            light
        };
        let bits = rng.bits(stream::COLOUR);
        // noise of σ `noise` per channel (the sum of two uniform draws: triangular), one draw
        // for a grey imager's three equal channels
        let uniform = |k: u32| ((bits >> (10 * k)) & 0x3ff) as f32 * (1.0 / 1024.0);
        let spread = self.camera.noise * 6f32.sqrt();
        let srgb = &*SRGB;
        let value = |c: u32, v: f32, gain: f32| {
            let c = if self.camera.monochrome { 0 } else { c };
            let noisy = gain * (v + spread * (uniform(2 * c) + uniform(2 * c + 1) - 1.0));
            srgb[(noisy.clamp(0.0, 1.0) * (SRGB_STEPS - 1) as f32) as usize]
        };
        [
            value(0, light.x, self.gain.x),
            value(1, light.y, self.gain.y),
            value(2, light.z, self.gain.z),
        ]
    }
}

/// Steps of the linear-to-sRGB table.
const SRGB_STEPS: usize = 4096;

/// 8-bit sRGB of linear values k / (SRGB_STEPS - 1).
static SRGB: std::sync::LazyLock<[u8; SRGB_STEPS]> = std::sync::LazyLock::new(|| {
    std::array::from_fn(|k| crate::render::srgb8(k as f32 / (SRGB_STEPS - 1) as f32))
});
