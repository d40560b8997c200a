//! The camera's colour image ([`ColourCamera`]): the light a pixel's surface sends to the
//! camera, shaded with the colour renderer's surface model under the flash and the ambient
//! light, and the camera's response to it. Each pixel that meets a surface records its colour
//! when it is labelled, whether or not it gets a point, and again with the ambient light alone
//! should the flash's shadow fall on it; a point's rgb is its pixel's. A rendered frame is
//! developed by the same response ([`ColourCamera::develop`]).

use std::f32::consts::PI;

use glam::Vec3;

use rayon::prelude::*;

use crate::camera::Intrinsics;
use crate::noise::{PixelRng, stream};
use crate::render::Image;
use crate::render::bsdf::{Bsdf, luminance};
use crate::spec::{ColourCamera, ColourCapture, PINK};
use crate::world::Material;

/// The camera's response to linear light: vignetting, gain, white balance, grey or colour,
/// noise, sRGB.
#[derive(Clone, Copy)]
pub(super) struct Response {
    gain: Vec3,
    /// The principal point and the share of light lost per squared pixel of distance from it.
    centre: [f32; 2],
    falloff: f32,
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
    pub(super) fn new(camera: &ColourCamera, k: &Intrinsics) -> Response {
        let [red, blue] = camera.white_balance;
        let (cx, cy) = (k.cx as f32, k.cy as f32);
        let (w, h) = (k.width as f32 - 0.5, k.height as f32 - 0.5);
        let corner = [(-0.5, -0.5), (w, -0.5), (-0.5, h), (w, h)]
            .map(|(u, v)| (u - cx).powi(2) + (v - cy).powi(2))
            .into_iter()
            .fold(0.0f32, f32::max);
        Response {
            gain: Vec3::new(red, 1.0, blue) * camera.gain,
            centre: [cx, cy],
            falloff: camera.vignetting / corner.max(1.0),
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

    /// The 8-bit sRGB pixel `[col, row]` records of linear light `light` reaching its lens.
    #[inline]
    pub(super) fn record(&self, light: Vec3, [col, row]: [u32; 2], rng: PixelRng) -> [u8; 3] {
        match self.camera.capture {
            ColourCapture::ThreeD => return PINK,
            ColourCapture::Flat => return light.to_array().map(crate::render::srgb8),
            ColourCapture::TwoDThreeD => {}
        }
        let light = if self.falloff > 0.0 {
            let [cx, cy] = self.centre;
            let r2 = (col as f32 - cx).powi(2) + (row as f32 - cy).powi(2);
            light * (1.0 - self.falloff * r2)
        } else {
            light
        };
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

impl ColourCamera {
    /// The 8-bit sRGB image this camera records of `frame`, the linear light reaching its lens
    /// (a rendered frame of a camera of `intrinsics`): vignetting, gain, white balance, grey
    /// or colour and noise keyed by (`seed`, pixel) as in a scan's colour image, row-major.
    pub fn develop(&self, intrinsics: &Intrinsics, frame: &Image, seed: u64) -> Vec<[u8; 3]> {
        let response = Response::new(self, intrinsics);
        let width = frame.width as usize;
        frame
            .pixels
            .par_iter()
            .enumerate()
            .map(|(i, &p)| {
                let pixel = [(i % width) as u32, (i / width) as u32];
                response.record(Vec3::from(p), pixel, PixelRng::new(seed, i as u64))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// sRGB byte back to linear.
    fn linear(v: u8) -> f32 {
        let e = f32::from(v) / 255.0;
        if e <= 0.04045 {
            e / 12.92
        } else {
            ((e + 0.055) / 1.055).powf(2.4)
        }
    }

    /// A frame of `value` everywhere on a camera of `width`×`height`.
    fn uniform(width: u32, height: u32, value: f32) -> (Intrinsics, Image) {
        let k = Intrinsics::from_fov(width, height, 60.0, 50.0);
        let pixels = vec![[value; 3]; (width * height) as usize];
        let frame = Image {
            width,
            height,
            pixels,
        };
        (k, frame)
    }

    #[test]
    fn vignetting_takes_its_share_at_the_corners_and_none_at_the_centre() {
        let (k, frame) = uniform(101, 81, 0.5);
        let camera = ColourCamera {
            vignetting: 0.4,
            noise: 0.0,
            ..ColourCamera::default()
        };
        let rgb = camera.develop(&k, &frame, 0);
        let at = |col: usize, row: usize| linear(rgb[row * 101 + col][1]);
        assert!((at(50, 40) - 0.5).abs() < 0.005, "{}", at(50, 40));
        // the corner pixels' centres lie half a pixel inside the image's corners
        for (col, row) in [(0, 0), (100, 0), (0, 80), (100, 80)] {
            assert!((at(col, row) - 0.3).abs() < 0.006, "{}", at(col, row));
        }
        // halfway along the diagonal, a quarter of the loss
        assert!(
            (at(25, 20) - 0.5 * (1.0 - 0.1)).abs() < 0.006,
            "{}",
            at(25, 20)
        );
    }

    #[test]
    fn a_developed_frame_has_the_cameras_noise_and_gain() {
        let (k, frame) = uniform(200, 200, 0.2);
        let camera = ColourCamera {
            noise: 0.01,
            gain: 2.0,
            ..ColourCamera::default()
        };
        let values: Vec<f32> = camera
            .develop(&k, &frame, 7)
            .iter()
            .map(|p| linear(p[0]))
            .collect();
        let n = values.len() as f32;
        let mean = values.iter().sum::<f32>() / n;
        let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / n).sqrt();
        assert!((mean - 0.4).abs() < 0.003, "mean {mean}");
        // σ 0.01 before the gain of 2, and the 8-bit steps' own spread at 0.4 (~0.0024)
        assert!((sd - 0.0201).abs() < 0.002, "σ {sd}");
        assert_eq!(camera.develop(&k, &frame, 7), camera.develop(&k, &frame, 7));
        assert_ne!(camera.develop(&k, &frame, 7), camera.develop(&k, &frame, 8));
    }
}
