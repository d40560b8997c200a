//! One path: from the camera's ray to the lights, a surface interaction at a time.

use glam::Vec3;

use super::bsdf::Bsdf;
use super::denoise::Guide;
use super::light::{Emitter, Incoming};
use super::{DRAWS_PER_VERTEX, EPSILON, Settings};
use crate::noise::PixelRng;
use crate::world::{SurfaceHit, World};

/// What paths are traced through: the world, its lights and surroundings, the settings.
pub(super) struct Scene<'a> {
    pub(super) world: &'a World,
    pub(super) emitters: Vec<Emitter>,
    pub(super) environment: Vec3,
    pub(super) settings: Settings,
}

impl Scene<'_> {
    /// The light one path from `origin` along `dir`, whose ray meets `first`, brings back,
    /// and what its first surface shows the denoiser; without `shade`, only the light its ray
    /// meets before any surface (a lamp or the surroundings): the path ends at the surface.
    pub(super) fn path(
        &self,
        mut origin: Vec3,
        mut dir: Vec3,
        first: Option<SurfaceHit>,
        shade: bool,
        rng: PixelRng,
    ) -> (Vec3, Option<Guide>) {
        let mut radiance = Vec3::ZERO;
        let mut guide = None;
        let mut throughput = Vec3::ONE;
        // the pdf of the BSDF sample that chose `dir` (none for the camera's ray)
        let mut bsdf_pdf: Option<f32> = None;
        // the vertex after the last bounce only gathers what its ray meets: a light (the BSDF's
        // share of the last vertex's light, under multiple importance sampling) or the
        // environment
        let last = u64::from(self.settings.bounces);
        let mut hit = first;
        for vertex in 0..=last + 1 {
            let draws = 2 + vertex * DRAWS_PER_VERTEX;
            let u = |k: u64| rng.uniform(draws + k);
            if vertex > 0 {
                hit = self.world.cast(origin, dir, f32::INFINITY);
            }
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
                if !shade {
                    break;
                }
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
