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
    /// What a camera ray from `origin` along `dir` that meets `first` sees without tracing
    /// light: the light it meets before any surface (a lamp, or the surroundings where it
    /// meets none), and what its first surface shows the denoiser. A path's first vertex
    /// gets the same ([`Scene::path`]).
    pub(super) fn seen(
        &self,
        origin: Vec3,
        dir: Vec3,
        first: Option<SurfaceHit>,
    ) -> (Vec3, Option<Guide>) {
        let t_max = first.map_or(f32::INFINITY, |h| h.t);
        if let Some((emitted, _)) = self.lamp(origin, dir, t_max) {
            return (emitted, None);
        }
        let Some(hit) = first else {
            return (self.environment, None);
        };
        let guide = Bsdf::new(&hit.material, hit.normal, -dir)
            .map(|bsdf| guide_of(&bsdf, &hit, origin + dir * hit.t));
        (Vec3::ZERO, guide)
    }

    /// The nearest lamp the ray from `origin` along `dir` meets within `t_max`: its radiance
    /// and the pdf of sampling that point of it.
    fn lamp(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<(Vec3, f32)> {
        self.emitters
            .iter()
            .filter_map(|e| e.hit(origin, dir, t_max))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, emitted, pdf)| (emitted, pdf))
    }

    /// The light one path from `origin` along `dir`, whose ray meets `first`, brings back,
    /// and what its first surface shows the denoiser.
    pub(super) fn path(
        &self,
        mut origin: Vec3,
        mut dir: Vec3,
        first: Option<SurfaceHit>,
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
            if let Some((emitted, light_pdf)) = self.lamp(origin, dir, t_max) {
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
                guide = Some(guide_of(&bsdf, &hit, x));
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

/// What a camera ray's first surface, `hit` at `point`, shows the denoiser.
fn guide_of(bsdf: &Bsdf, hit: &SurfaceHit, point: Vec3) -> Guide {
    Guide {
        albedo: bsdf.albedo(),
        normal: hit.normal,
        point,
        distance: hit.t,
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
