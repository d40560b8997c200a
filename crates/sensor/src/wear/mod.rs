//! Wear: where rust, dust and grease lie on a surface (masks over its texture coordinates) and
//! how they change the surface's material for the depth model and the colour image alike.

mod armature;
mod grain;
mod pattern;
#[cfg(test)]
mod tests;

pub use armature::{Armature, ArmatureSurface, GAP, SHEET_CM, WIRE_CM};
pub use grain::Grain;

use glam::{Affine3A, Vec3};
use serde::{Deserialize, Serialize};

use crate::materials::RUST;
use crate::world::Material;

use pattern::{Ramp, fbm, fbm_colour, luminance, voronoi_colour};

/// Where rust lies, over a surface's texture coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mask {
    /// The add-on's mask (`create_corrosion`): the object coordinates' noise (scale 0.5,
    /// detail 16, roughness 0.833) ramped from black at `threshold` (the add-on's percent /
    /// 250-400) to white at 0.909, taken as a point of a Voronoi texture (scale 2) whose cell
    /// colour above 0.805 is rust.
    Addon {
        /// The first stop of the noise's ramp: percent / (250 to 400).
        threshold: f32,
    },
    /// A coverage: rust where a fractal noise (scale 0.5, 4 octaves) lies below its quantile
    /// `share`, with an edge of a few hundredths of the noise's range.
    Coverage {
        /// Share of the surface rusted, 0..1.
        share: f32,
    },
}

impl Mask {
    /// The share of rust at texture coordinates `p`, 0..1.
    pub fn share(&self, p: Vec3) -> f32 {
        match *self {
            Mask::Addon { threshold } => {
                let noise = luminance(fbm_colour(0.5 * p, 16.0, 0.833));
                let c = Ramp([(threshold, 0.0), (0.909, 1.0)]).at(noise);
                let cell = luminance(voronoi_colour(2.0 * Vec3::splat(c)));
                Ramp([(0.805, 0.0), (0.723, 1.0)]).at(cell)
            }
            Mask::Coverage { share } => {
                if share <= 0.0 {
                    return 0.0;
                }
                let v = fbm(0.5 * p, 3.0, 0.5);
                ((coverage_threshold(share) - v) / EDGE + 0.5).clamp(0.0, 1.0)
            }
        }
    }
}

/// Width of a coverage mask's edge, in the noise's values.
pub const EDGE: f32 = 0.02;

/// The noise value below which a share `q` of the coverage mask's noise lies (Blender's Noise
/// Texture at scale 0.5, detail 3, roughness 0.5; its values sampled over a lattice): a coverage
/// mask rusts `clamp((threshold - noise) / EDGE + 1/2, 0, 1)`.
pub fn coverage_threshold(q: f32) -> f32 {
    let table = QUANTILES.get_or_init(|| {
        // the noise over a lattice far larger than its period, sorted
        let mut v: Vec<f32> = (0..32_768u32)
            .map(|k| {
                let p = Vec3::new((k % 32) as f32, ((k / 32) % 32) as f32, (k / 1024) as f32);
                fbm(0.5 * (0.37 * p + 0.11), 3.0, 0.5)
            })
            .collect();
        v.sort_by(f32::total_cmp);
        v
    });
    let i = (q.clamp(0.0, 1.0) * (table.len() - 1) as f32).round() as usize;
    table[i] + if q >= 1.0 { 1.0 } else { 0.0 }
}

static QUANTILES: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();

/// Wear of one surface: where rust lies and which rust it is, dust and grease over it, and the
/// clean surface's grain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wear {
    /// World to the surface's texture coordinates (for a motor's part, the add-on's object
    /// coordinates: centimetres, millimetres on bolts).
    pub texture: Affine3A,
    /// Where rust lies.
    pub mask: Mask,
    /// What it looks like.
    pub rust: Rust,
    /// Share of the surface under dust, 0..1, over the rust.
    pub dust: f32,
    /// Share of the surface under grease, 0..1, over the rust and the dust.
    pub grease: f32,
    /// Rust kept to these places (a housing's screws' seats), if only there.
    pub seats: Option<Seats>,
    /// The clean surface's texture, under the rust and dirt.
    pub grain: Grain,
}

/// Discs about up to eight points of a surface (its screws' seats), where alone it rusts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Seats {
    centres: [Vec3; Seats::MAX],
    count: usize,
    radius: f32,
}

impl Seats {
    /// The most seats a surface has.
    pub const MAX: usize = 8;

    /// Seats about the first [`Seats::MAX`] of `centres` (texture coordinates), of `radius`.
    pub fn new(centres: &[Vec3], radius: f32) -> Seats {
        let mut seats = Seats {
            centres: [Vec3::ZERO; Seats::MAX],
            count: centres.len().min(Seats::MAX),
            radius,
        };
        seats.centres[..seats.count].copy_from_slice(&centres[..seats.count]);
        seats
    }

    /// How much of the rust stays at `q`: 1 within 70 % of the radius of a seat's centre,
    /// fading to 0 at the radius.
    fn weight(&self, q: Vec3) -> f32 {
        let d = self.centres[..self.count]
            .iter()
            .map(|c| c.distance(q))
            .fold(f32::INFINITY, f32::min);
        let t = ((self.radius - d) / (0.3 * self.radius)).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }
}

impl Wear {
    /// Rust of type `rust` where `mask` lays it over the texture coordinates `texture` gives:
    /// no dirt, no grain, no seats.
    pub fn new(texture: Affine3A, mask: Mask, rust: Rust) -> Wear {
        Wear {
            texture,
            mask,
            rust,
            dust: 0.0,
            grease: 0.0,
            seats: None,
            grain: Grain::None,
        }
    }

    /// A clean surface of `grain` over the texture coordinates `texture` gives: no rust, no
    /// dirt.
    pub fn clean(texture: Affine3A, grain: Grain) -> Wear {
        Wear {
            grain,
            ..Wear::new(texture, Mask::Coverage { share: 0.0 }, Rust(1))
        }
    }

    /// The share of rust at world point `p` and `clean` worn there, or `None` where the surface
    /// is clean.
    pub fn at(&self, clean: &Material, p: Vec3) -> Option<(f32, Material)> {
        let q = self.texture.transform_point3(p);
        let grained = self.grain.apply(clean, q);
        let clean = grained.as_ref().unwrap_or(clean);
        let rust = match &self.seats {
            Some(seats) => match seats.weight(q) {
                0.0 => 0.0,
                w => w * self.mask.share(q),
            },
            None => self.mask.share(q),
        };
        let mut m = (rust > 0.0).then(|| mix(clean, &self.rust.material(q), rust));
        // dirt in patches twice the rust's, each of its own noise
        for (share, offset, dirt) in [
            (self.dust, Vec3::new(37.1, 91.3, 12.7), &DUST),
            (self.grease, Vec3::new(-53.9, 17.2, 71.5), &GREASE),
        ] {
            let cover = Mask::Coverage { share }.share(0.5 * q + offset);
            if cover > 0.0 {
                m = Some(mix(m.as_ref().unwrap_or(clean), dirt, cover));
            }
        }
        m.or(grained).map(|m| (rust, m))
    }
}

/// Dust: a light, matte grey-brown film that hides a surface's sheen (the depth model's
/// highlights too).
const DUST: Material = Material {
    reflectivity: 0.35,
    specular: 0.0,
    lobe: 0.5,
    colour: [0.24, 0.21, 0.17],
    metallic: 0.0,
    roughness: 0.95,
    ior_level: 0.5,
};

/// Grease: a dark, glossy film (a wet dielectric highlight over a dark brown).
const GREASE: Material = Material {
    reflectivity: 0.08,
    specular: 0.3,
    lobe: 0.12,
    colour: [0.035, 0.027, 0.018],
    metallic: 0.0,
    roughness: 0.25,
    ior_level: 0.5,
};

/// `a` worn to `b` by `t`: every property of the depth model and the colour's surface mixed
/// linearly.
fn mix(a: &Material, b: &Material, t: f32) -> Material {
    let l = |x: f32, y: f32| x + (y - x) * t;
    Material {
        reflectivity: l(a.reflectivity, b.reflectivity),
        specular: l(a.specular, b.specular),
        lobe: l(a.lobe, b.lobe),
        colour: [0, 1, 2].map(|k| l(a.colour[k], b.colour[k])),
        metallic: l(a.metallic, b.metallic),
        roughness: l(a.roughness, b.roughness),
        ior_level: l(a.ior_level, b.ior_level),
    }
}

/// One of the add-on's nine rust textures ("Rust 1" to "Rust 9"), as its mean linear colour
/// and the spread of its brightness.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct Rust(u8);

/// Per rust type: the mean linear colour of the add-on's `rustN.jpg` and the relative
/// standard deviation of its luminance.
const RUSTS: [([f32; 3], f32); 9] = [
    ([0.135, 0.120, 0.127], 0.542),
    ([0.333, 0.290, 0.266], 0.305),
    ([0.276, 0.187, 0.115], 0.622),
    ([0.350, 0.052, 0.033], 0.708),
    ([0.173, 0.235, 0.201], 0.636),
    ([0.436, 0.473, 0.289], 0.353),
    ([0.601, 0.530, 0.322], 0.406),
    ([0.301, 0.279, 0.253], 0.233),
    ([0.570, 0.517, 0.418], 0.158),
];

impl Rust {
    /// Rust `n`, 1 to 9, if it is one.
    pub fn new(n: u8) -> Option<Rust> {
        (1..=9).contains(&n).then_some(Rust(n))
    }

    /// Its number, 1 to 9.
    pub fn number(self) -> u8 {
        self.0
    }

    /// Its mean linear colour and the relative spread of its brightness.
    pub fn look(self) -> ([f32; 3], f32) {
        RUSTS[usize::from(self.0 - 1)]
    }

    /// The rust at texture coordinates `q`: the add-on's rust BSDF (metallic, roughness
    /// 0.774) coloured by the texture's mean times a fractal noise of the texture's spread;
    /// dark and matte to the depth sensor ([`RUST`]'s reflectivity, specular share and lobe).
    fn material(self, q: Vec3) -> Material {
        let (mean, spread) = self.look();
        let v = fbm(2.0 * q, 3.0, 0.6);
        let shade = (1.0 + spread * (v - 0.5) / RUST_NOISE_SIGMA).max(0.0);
        Material {
            colour: mean.map(|c| (c * shade).min(1.0)),
            metallic: 1.0,
            roughness: 0.774,
            ior_level: 0.5,
            ..RUST
        }
    }
}

/// Standard deviation of the rust's fractal noise (`fbm(_, 3, 0.6)`, measured).
const RUST_NOISE_SIGMA: f32 = 0.075;

impl TryFrom<u8> for Rust {
    type Error = String;

    fn try_from(n: u8) -> Result<Rust, String> {
        Rust::new(n).ok_or_else(|| format!("rust type {n} is not one of 1 to 9"))
    }
}

impl From<Rust> for u8 {
    fn from(r: Rust) -> u8 {
        r.0
    }
}
