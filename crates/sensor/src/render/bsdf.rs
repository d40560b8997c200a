//! The surface model of the colour renderer: Blender's Principled BSDF with its defaults (no
//! coat, sheen, subsurface or transmission): a Lambertian base under a GGX specular layer,
//! metals a GGX lobe tinted by their base colour, with the energy the single-scattering lobe
//! loses restored (Turquin, "Practical multiple scattering compensation for microfacet
//! models", 2019) as Cycles' multiscatter GGX restores it.

use std::f32::consts::{FRAC_1_PI, PI};
use std::sync::LazyLock;

use glam::Vec3;

use crate::world::Material;

/// Roughness below this renders as this (α = roughness², a mirror is out of reach of sampling).
const MIN_ALPHA: f32 = 1e-3;

/// A local frame about a unit normal (Duff et al., "Building an orthonormal basis, revisited",
/// JCGT 2017).
#[derive(Clone, Copy)]
struct Frame {
    t: Vec3,
    b: Vec3,
    n: Vec3,
}

impl Frame {
    fn new(n: Vec3) -> Frame {
        let sign = 1f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Frame {
            t: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            b: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    fn to_local(self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    fn to_world(self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

/// A material's reflection at one surface point towards one viewing direction.
#[derive(Clone, Copy)]
pub(crate) struct Bsdf {
    /// The unit normal and the direction towards the viewer.
    n: Vec3,
    wo: Vec3,
    /// The cosine between them.
    mu: f32,
    alpha: f32,
    /// The single-scattering lobe's directional albedo towards the viewer at Fresnel 1, and its
    /// Schlick term's share.
    energy: [f32; 2],
    /// Smith's Λ towards the viewer.
    lambda_o: f32,
    /// The factor restoring the energy single scattering loses, per channel.
    compensation: Vec3,
    /// Lambertian reflectance of the base (zero for metals).
    diffuse: Vec3,
    /// The specular lobe's reflectance at normal incidence.
    f0: Vec3,
    /// The share of a dielectric's Fresnel term kept (specular levels below 0.5 fade it out,
    /// so that level 0 reflects nothing, as Blender's); metals keep theirs whole.
    fade: f32,
}

/// What a sampled direction carries: the direction, the BSDF × cosine / pdf, and the pdf.
pub(super) struct Sampled {
    pub(super) wi: Vec3,
    pub(super) weight: Vec3,
    pub(super) pdf: f32,
}

impl Bsdf {
    /// The BSDF of `material` at a point of normal `n`, seen from direction `wo` (towards the
    /// viewer); `None` when `wo` lies in the surface.
    pub(crate) fn new(material: &Material, n: Vec3, wo: Vec3) -> Option<Bsdf> {
        let mu = n.dot(wo);
        if mu <= 1e-6 {
            return None;
        }
        let base = Vec3::from(material.colour);
        let metallic = material.metallic;
        let roughness = material.roughness.clamp(0.0, 1.0);
        let alpha = (roughness * roughness).max(MIN_ALPHA);
        let f0_dielectric = (0.08 * material.ior_level).clamp(0.0, 1.0);
        let f0 = Vec3::splat(f0_dielectric).lerp(base, metallic);
        let fade_dielectric = (2.0 * material.ior_level).clamp(0.0, 1.0);
        let fade = fade_dielectric + (1.0 - fade_dielectric) * metallic;
        let energy = lookup(mu, roughness);
        let layer = 1.0 - fade_dielectric * albedo(energy, f0_dielectric);
        let diffuse = base * ((1.0 - metallic) * layer);
        Some(Bsdf {
            n,
            wo,
            mu,
            alpha,
            energy,
            lambda_o: lambda(mu, alpha),
            compensation: Vec3::ONE + f0 * (1.0 / energy[0].max(1e-3) - 1.0),
            diffuse,
            f0,
            fade,
        })
    }

    /// The probability of sampling the specular lobe: its share of the reflected light.
    fn p_specular(&self) -> f32 {
        if self.diffuse == Vec3::ZERO {
            return 1.0;
        }
        let specular = self.fade * albedo(self.energy, luminance(self.f0));
        if specular == 0.0 {
            0.0
        } else {
            (specular / (specular + luminance(self.diffuse))).clamp(0.1, 0.9)
        }
    }

    /// BSDF × cosine for light arriving from `wi` and the pdf of sampling `wi`.
    pub(crate) fn eval(&self, wi: Vec3) -> (Vec3, f32) {
        let cos_i = self.n.dot(wi);
        if cos_i <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let (f, d) = self.reflect_cos(wi, cos_i);
        let pdf_specular = d / ((1.0 + self.lambda_o) * 4.0 * self.mu);
        let p = self.p_specular();
        (f, p * pdf_specular + (1.0 - p) * cos_i * FRAC_1_PI)
    }

    /// BSDF × cosine for light arriving from `wi`.
    #[inline]
    pub(crate) fn reflect(&self, wi: Vec3) -> Vec3 {
        if wi == self.wo {
            // light from the viewer (a camera's own light): the half vector is `wo` itself
            let d = ggx_d(self.mu, self.alpha);
            let g2 = 1.0 / (1.0 + 2.0 * self.lambda_o);
            let specular = self.f0 * self.compensation * (self.fade * d * g2 / (4.0 * self.mu));
            return specular + self.diffuse * (FRAC_1_PI * self.mu);
        }
        let cos_i = self.n.dot(wi);
        if cos_i <= 0.0 {
            return Vec3::ZERO;
        }
        self.reflect_cos(wi, cos_i).0
    }

    /// BSDF × cosine for light from `wi` at cosine `cos_i` (positive) to the normal, and GGX's
    /// D of the half vector.
    #[inline]
    fn reflect_cos(&self, wi: Vec3, cos_i: f32) -> (Vec3, f32) {
        let h = (self.wo + wi).normalize();
        let d = ggx_d(self.n.dot(h), self.alpha);
        let g2 = 1.0 / (1.0 + self.lambda_o + lambda(cos_i, self.alpha));
        let fresnel = schlick(self.f0, self.wo.dot(h)) * self.fade;
        let specular = fresnel * self.compensation * (d * g2 / (4.0 * self.mu));
        (specular + self.diffuse * (FRAC_1_PI * cos_i), d)
    }

    /// The share of uniform light from every direction of the hemisphere that the surface sends
    /// towards the viewer, per channel (its directional albedo).
    pub(crate) fn albedo(&self) -> Vec3 {
        let [e, e5] = self.energy;
        let single = self.f0 * (e - e5) + Vec3::splat(e5);
        self.diffuse + (single * self.compensation).min(Vec3::ONE) * self.fade
    }

    /// Draws a direction from the BSDF with the uniform numbers `u`.
    pub(super) fn sample(&self, u: [f32; 3]) -> Option<Sampled> {
        let frame = Frame::new(self.n);
        let o = frame.to_local(self.wo);
        let i = if u[0] < self.p_specular() {
            let h = sample_vndf(o, self.alpha, u[1], u[2]);
            2.0 * o.dot(h) * h - o
        } else {
            cosine(u[1], u[2])
        };
        if i.z <= 0.0 {
            return None;
        }
        let wi = frame.to_world(i);
        let (f, pdf) = self.eval(wi);
        (pdf > 0.0).then(|| Sampled {
            wi,
            weight: f / pdf,
            pdf,
        })
    }
}

/// Rec. 709 luminance of linear RGB.
pub(crate) fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m5 = (m * m) * (m * m) * m;
    f0 + (Vec3::ONE - f0) * m5
}

/// GGX's distribution of normals at cosine `cos` to the surface normal.
fn ggx_d(cos: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let c2 = cos * cos;
    let k = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * k * k)
}

/// Smith's Λ of the GGX distribution for a direction at cosine `cos` to the normal.
fn lambda(cos: f32, alpha: f32) -> f32 {
    let c2 = cos * cos;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// A normal drawn from GGX's distribution of visible normals (Dupuy and Benyoub, "Sampling
/// visible GGX normals with spherical caps", 2023).
fn sample_vndf(o: Vec3, alpha: f32, u1: f32, u2: f32) -> Vec3 {
    let v = Vec3::new(alpha * o.x, alpha * o.y, o.z).normalize();
    let phi = 2.0 * PI * u1;
    let z = (1.0 - u2) * (1.0 + v.z) - v.z;
    let s = (1.0 - z * z).max(0.0).sqrt();
    let h = Vec3::new(s * phi.cos(), s * phi.sin(), z) + v;
    Vec3::new(alpha * h.x, alpha * h.y, h.z.max(0.0)).normalize()
}

fn cosine(u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt())
}

/// Grid of the directional-albedo tables: cosine of the view angle × roughness.
const GRID: usize = 32;

/// The single-scattering GGX lobe's directional albedo at Fresnel 1 (`[0]`) and its Schlick
/// term's share ∫(1 − cos θ_h)⁵ (`[1]`), on a grid of view cosine and roughness, each cell from
/// 64×64 stratified visible-normal samples: computed once (the test
/// `the_albedo_table_is_the_tabulated_one`, a tenth of a second) and kept in `albedo.bin`
/// (little-endian f32 pairs, roughness-major).
static ALBEDO: LazyLock<Vec<[f32; 2]>> = LazyLock::new(|| {
    include_bytes!("albedo.bin")
        .chunks_exact(8)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            [f(0), f(4)]
        })
        .collect()
});

/// The albedo tables bilinearly at view cosine `mu` and `roughness`.
fn lookup(mu: f32, roughness: f32) -> [f32; 2] {
    let scale = (GRID - 1) as f32;
    let (x, y) = (
        mu.clamp(0.0, 1.0) * scale,
        roughness.clamp(0.0, 1.0) * scale,
    );
    let (x0, y0) = ((x as usize).min(GRID - 2), (y as usize).min(GRID - 2));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let table = &*ALBEDO;
    let at = |m: usize, r: usize| table[r * GRID + m];
    let mut out = [0.0; 2];
    for (k, v) in out.iter_mut().enumerate() {
        let row = |r| at(x0, r)[k] * (1.0 - fx) + at(x0 + 1, r)[k] * fx;
        *v = row(y0) * (1.0 - fy) + row(y0 + 1) * fy;
    }
    out
}

/// Directional albedo, multiple scattering included, of a GGX lobe whose single-scattering
/// albedo at Fresnel 1 and Schlick share are `[e, e5]` ([`lookup`]) and whose reflectance at
/// normal incidence is `f0`.
fn albedo([e, e5]: [f32; 2], f0: f32) -> f32 {
    let single = f0 * (e - e5) + e5;
    (single * (1.0 + f0 * (1.0 / e.max(1e-3) - 1.0))).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::PixelRng;

    fn material(colour: f32, metallic: f32, roughness: f32) -> Material {
        Material {
            colour: [colour; 3],
            metallic,
            roughness,
            ..Material::default()
        }
    }

    /// The directional albedo by sampling: the mean of the sampled weights.
    fn sampled_albedo(m: &Material, mu: f32, n: u64) -> Vec3 {
        let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let bsdf = Bsdf::new(m, Vec3::Z, wo).unwrap();
        let mut sum = Vec3::ZERO;
        for k in 0..n {
            let rng = PixelRng::new(7, k);
            let u = [rng.uniform(0), rng.uniform(1), rng.uniform(2)];
            if let Some(s) = bsdf.sample(u) {
                sum += s.weight;
            }
        }
        sum / n as f32
    }

    #[test]
    fn a_white_metal_keeps_its_energy_at_every_roughness_and_angle() {
        for roughness in [0.1, 0.4, 0.7, 1.0] {
            for mu in [0.2, 0.5, 1.0] {
                let a = sampled_albedo(&material(1.0, 1.0, roughness), mu, 20_000);
                assert!(
                    (a.x - 1.0).abs() < 0.04,
                    "roughness {roughness} mu {mu}: {a}"
                );
            }
        }
    }

    #[test]
    fn a_white_dielectric_reflects_no_more_than_it_receives() {
        for roughness in [0.1, 0.5, 1.0] {
            for mu in [0.1, 0.5, 1.0] {
                let a = sampled_albedo(&material(1.0, 0.0, roughness), mu, 20_000);
                assert!(
                    a.x < 1.03 && a.x > 0.9,
                    "roughness {roughness} mu {mu}: {a}"
                );
            }
        }
    }

    /// Stratified visible-normal samples per side of a cell of `ALBEDO`.
    const STRATA: usize = 64;

    /// `ALBEDO`'s cells, each from `n`×`n` stratified visible-normal samples.
    fn tabulate(n: usize) -> Vec<[f32; 2]> {
        let mut table = Vec::with_capacity(GRID * GRID);
        for r in 0..GRID {
            let roughness = r as f32 / (GRID - 1) as f32;
            let alpha = (roughness * roughness).max(MIN_ALPHA);
            for m in 0..GRID {
                let mu = (m as f32 / (GRID - 1) as f32).max(1e-3);
                let o = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let (mut e, mut e5) = (0.0f64, 0.0f64);
                for a in 0..n {
                    for b in 0..n {
                        let (u1, u2) = ((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
                        let h = sample_vndf(o, alpha, u1, u2);
                        let i = 2.0 * o.dot(h) * h - o;
                        if i.z <= 0.0 {
                            continue;
                        }
                        // BSDF × cos / pdf of the visible-normal sample: G2 / G1(o)
                        let w = (1.0 + lambda(o.z, alpha))
                            / (1.0 + lambda(o.z, alpha) + lambda(i.z, alpha));
                        let m5 = (1.0 - o.dot(h)).clamp(0.0, 1.0).powi(5);
                        e += f64::from(w);
                        e5 += f64::from(w * m5);
                    }
                }
                let n2 = (n * n) as f64;
                table.push([(e / n2) as f32, (e5 / n2) as f32]);
            }
        }
        table
    }

    /// `albedo.bin` is what `tabulate` computes (within the last bits libm's sine and cosine
    /// may differ by between machines); `MOTORFACTORY_WRITE_ALBEDO=1` rewrites it.
    #[test]
    fn the_albedo_table_is_the_tabulated_one() {
        let fresh = tabulate(STRATA);
        if std::env::var_os("MOTORFACTORY_WRITE_ALBEDO").is_some() {
            let bytes: Vec<u8> = fresh
                .iter()
                .flatten()
                .flat_map(|v| v.to_le_bytes())
                .collect();
            let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/render/albedo.bin");
            std::fs::write(path, bytes).unwrap();
        }
        assert_eq!(ALBEDO.len(), GRID * GRID);
        for (k, (a, b)) in ALBEDO.iter().zip(&fresh).enumerate() {
            assert!(
                (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) < 1e-6,
                "cell {k}: {a:?} against {b:?}"
            );
        }
    }

    #[test]
    fn the_tabulated_albedo_is_the_sampled_one() {
        for m in [
            material(0.8, 0.0, 0.5),
            material(0.3, 0.8, 0.4),
            material(0.9, 0.9, 0.1),
            material(0.0, 0.4, 0.7),
        ] {
            for mu in [0.3f32, 0.7, 1.0] {
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let table = Bsdf::new(&m, Vec3::Z, wo).unwrap().albedo();
                let sampled = sampled_albedo(&m, mu, 40_000);
                assert!(
                    (table - sampled).abs().max_element() < 0.02,
                    "{m:?} mu {mu}: {table} against {sampled}"
                );
            }
        }
    }

    #[test]
    fn light_from_the_viewer_reflects_as_from_any_direction() {
        let m = material(0.6, 0.5, 0.3);
        let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
        let bsdf = Bsdf::new(&m, Vec3::Z, wo).unwrap();
        let nudged = (wo + Vec3::new(1e-4, 0.0, 0.0)).normalize();
        let (retro, near) = (bsdf.reflect(wo), bsdf.reflect(nudged));
        assert!(
            (retro - near).abs().max_element() < 1e-3 * near.max_element(),
            "{retro} {near}"
        );
        assert!((retro - bsdf.eval(nudged).0).abs().max_element() < 1e-3 * near.max_element());
    }

    #[test]
    fn sampling_and_evaluation_agree() {
        // ∫ pdf dω = 1 over the hemisphere, by a uniform estimate, for a mixed material
        let m = material(0.5, 0.4, 0.3);
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let bsdf = Bsdf::new(&m, Vec3::Z, wo).unwrap();
        let n = 200_000;
        let mut total = 0.0f64;
        for k in 0..n {
            let rng = PixelRng::new(3, k);
            let (u1, u2) = (rng.uniform(0), rng.uniform(1));
            let z = u1;
            let r = (1.0 - z * z).sqrt();
            let phi = 2.0 * PI * u2;
            let wi = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            total += f64::from(bsdf.eval(wi).1) * 2.0 * std::f64::consts::PI;
        }
        let integral = total / n as f64;
        assert!((integral - 1.0).abs() < 0.03, "∫pdf = {integral}");
    }
}
