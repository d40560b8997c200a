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
mod light;

use glam::{Affine3A, Vec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::camera::Intrinsics;
use crate::noise::PixelRng;
use crate::world::World;
use bsdf::Bsdf;
use denoise::{Guide, denoise};
use light::{Emitter, Incoming};
pub use light::{Light, Lighting};

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
    /// The share of paths that go on past their first surface, drawn per path
    /// ([`BOUNCE_SHARE`]): the others end with the light that surface receives straight from
    /// the lights, and the light those that go on bring back counts 1 / share times (unbiased:
    /// fewer rays, more noise for the denoiser to take).
    pub bounce_share: f32,
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
            bounce_share: 1.0,
        }
    }
}

impl Settings {
    /// Checks the ranges.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for samples outside 1 to 65536 or bounces above 64.
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
        let [mx, my, mz] = self.motion;
        crate::spec::within([
            ("render.aperture", self.aperture, 0.0..=1.0, "0 to 1 m"),
            ("render.focus", self.focus, 0.01..=1000.0, "0.01 to 1000 m"),
            (
                "render.bounce_share",
                self.bounce_share,
                BOUNCE_SHARE,
                "0.001 to 1",
            ),
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
/// The shares of paths going on past their first surface that [`Settings::bounce_share`] may
/// take.
pub const BOUNCE_SHARE: std::ops::RangeInclusive<f32> = 0.001..=1.0;
/// Most lights a scene may have (each takes two draws of a vertex).
pub const MAX_LIGHTS: usize = 6;
/// Offset of a ray leaving a surface along its normal, metres.
const EPSILON: f32 = 2e-5;
/// The draws of a camera ray's lens point and time, and of whether its path goes on past the
/// first surface, beyond those of any path's vertices.
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
    let motion = Vec3::from(settings.motion);
    let mut pixels = vec![[0.0f32; 3]; width * height];
    // each row's guides for the denoiser (a placeholder per row without it)
    let per_row = if settings.denoise { width } else { 1 };
    let mut guides = vec![None; per_row * height];
    pixels
        .par_chunks_mut(width)
        .zip(guides.par_chunks_mut(per_row))
        .enumerate()
        .for_each(|(row, (out, guides))| {
            for (col, px) in out.iter_mut().enumerate() {
                let index = (row * width + col) as u64;
                let mut sum = Vec3::ZERO;
                for s in 0..settings.samples {
                    let rng = PixelRng::new(settings.seed, index * 65536 + u64::from(s));
                    let (u, v) = (
                        col as f64 - 0.5 + f64::from(rng.uniform(0)),
                        row as f64 - 0.5 + f64::from(rng.uniform(1)),
                    );
                    let (origin, dir) = camera_ray(intrinsics.ray(u, v), settings, motion, rng);
                    let (origin, dir) =
                        (pose.transform_point3(origin), pose.transform_vector3(dir));
                    let (radiance, guide) = scene.path(origin, dir.normalize(), rng);
                    sum += radiance;
                    if s == 0 && settings.denoise {
                        guides[col] = guide;
                    }
                }
                *px = (sum / settings.samples as f32).to_array();
            }
        });
    if settings.denoise {
        denoise(&mut pixels, &guides, width, (1.0 / intrinsics.fx) as f32);
    }
    Ok(Image {
        width: intrinsics.width,
        height: intrinsics.height,
        pixels,
    })
}

/// A camera ray in the camera's frame for the pinhole ray `pinhole` (unit): from a point of a
/// thin lens's aperture through the pinhole ray's point on the plane in focus, and from where
/// the camera is at a moment of the exposure.
#[inline]
fn camera_ray(pinhole: Vec3, settings: &Settings, motion: Vec3, rng: PixelRng) -> (Vec3, Vec3) {
    let mut origin = Vec3::ZERO;
    let mut dir = pinhole;
    if settings.aperture > 0.0 {
        // a uniform point of the aperture's disc
        let r = settings.aperture * rng.uniform(CAMERA_DRAWS).sqrt();
        let phi = std::f32::consts::TAU * rng.uniform(CAMERA_DRAWS + 1);
        let lens = Vec3::new(r * phi.cos(), r * phi.sin(), 0.0);
        let focused = pinhole * (settings.focus / pinhole.z);
        origin = lens;
        dir = (focused - lens).normalize();
    }
    if motion != Vec3::ZERO {
        origin += motion * (rng.uniform(CAMERA_DRAWS + 2) - 0.5);
    }
    (origin, dir)
}

struct Scene<'a> {
    world: &'a World,
    emitters: Vec<Emitter>,
    environment: Vec3,
    settings: Settings,
}

impl Scene<'_> {
    /// The radiance one path from `origin` along `dir` brings back, and what its first surface
    /// shows the denoiser.
    fn path(&self, mut origin: Vec3, mut dir: Vec3, rng: PixelRng) -> (Vec3, Option<Guide>) {
        let mut radiance = Vec3::ZERO;
        let mut guide = None;
        let mut throughput = Vec3::ONE;
        // the pdf of the BSDF sample that chose `dir` (none for the camera's ray)
        let mut bsdf_pdf: Option<f32> = None;
        // the vertex after the last bounce only gathers what its ray meets: a light (the BSDF's
        // share of the last vertex's light, under multiple importance sampling) or the
        // environment
        let last = u64::from(self.settings.bounces);
        for vertex in 0..=last + 1 {
            let draws = 2 + vertex * DRAWS_PER_VERTEX;
            let u = |k: u64| rng.uniform(draws + k);
            let hit = self.world.cast(origin, dir, f32::INFINITY);
            let t_max = hit.map_or(f32::INFINITY, |h| h.t);
            if let Some((_, emitted, light_pdf)) = self
                .emitters
                .iter()
                .filter_map(|e| e.hit(origin, dir, t_max))
                .min_by(|a, b| a.0.total_cmp(&b.0))
            {
                let weight = bsdf_pdf.map_or(1.0, |p| power_heuristic(p, light_pdf));
                radiance += throughput * emitted * weight;
                break;
            }
            let Some(hit) = hit else {
                radiance += throughput * self.environment;
                break;
            };
            if vertex > last {
                break;
            }
            let x = origin + dir * hit.t;
            let wo = -dir;
            let Some(bsdf) = Bsdf::new(&hit.material, hit.normal, wo) else {
                break;
            };
            if vertex == 0 {
                guide = Some(Guide {
                    albedo: bsdf.albedo(),
                    normal: hit.normal,
                    point: x,
                    distance: hit.t,
                });
            }
            let lift = x + hit.normal * EPSILON;
            for (k, emitter) in self.emitters.iter().enumerate() {
                let k = 3 + 2 * k as u64;
                let Some(Incoming {
                    wi,
                    distance,
                    value,
                    pdf,
                }) = emitter.sample(x, [u(k), u(k + 1)])
                else {
                    continue;
                };
                let (f, pdf_bsdf) = bsdf.eval(wi);
                if f == Vec3::ZERO || self.world.occluded(lift, wi, distance * (1.0 - 1e-4)) {
                    continue;
                }
                radiance += if pdf == 0.0 {
                    throughput * f * value
                } else {
                    throughput * f * value * (power_heuristic(pdf, pdf_bsdf) / pdf)
                };
            }
            if vertex == 0 && self.settings.bounce_share < 1.0 {
                if rng.uniform(CAMERA_DRAWS + 3) >= self.settings.bounce_share {
                    break;
                }
                throughput /= self.settings.bounce_share;
            }
            let Some(sampled) = bsdf.sample([u(0), u(1), u(2)]) else {
                break;
            };
            throughput *= sampled.weight;
            bsdf_pdf = Some(sampled.pdf);
            origin = lift;
            dir = sampled.wi;
        }
        (radiance, guide)
    }
}

fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2.is_infinite() {
        1.0
    } else {
        a2 / (a2 + b2)
    }
}

#[cfg(test)]
mod tests;
