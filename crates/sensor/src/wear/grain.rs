//! The texture of a clean surface: drawn steel's streaks, moulded plastic's grain, an
//! armature's surfaces.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::armature::{Armature, scaled};
use super::pattern::fbm;
use crate::world::Material;

/// How a clean surface's texture varies its material from point to point: its colour and
/// reflectivity by a few per cent, its roughness by a few hundredths.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Grain {
    /// An even surface.
    #[default]
    None,
    /// Drawn or brushed metal: fine streaks along texture z (a motor part's axis), 8 % in
    /// brightness (one deviation).
    Drawn,
    /// Moulded plastic: a fine, even grain, 5 % in brightness.
    Moulded,
    /// An armature's surfaces, each its own material and texture (the part's material its
    /// windings').
    Armature(Armature),
}

/// Standard deviation of the grain's fractal noise (`fbm(_, 2, 0.5)`, measured).
pub(super) const NOISE_SIGMA: f32 = 0.0866;

impl Grain {
    /// `m` at texture coordinates `q` (centimetres on a motor's parts), or `None` when even.
    pub(super) fn apply(self, m: &Material, q: Vec3) -> Option<Material> {
        let (v, depth) = match self {
            Grain::None => return None,
            Grain::Armature(a) => return Some(a.material(m, q)),
            // 2.5 streaks a millimetre across, 4 cm long
            Grain::Drawn => (
                fbm(Vec3::new(25.0 * q.x, 25.0 * q.y, 0.25 * q.z), 2.0, 0.5),
                0.08,
            ),
            // features of a few tenths of a millimetre
            Grain::Moulded => (fbm(30.0 * q, 2.0, 0.5), 0.05),
        };
        let s = ((v - 0.5) / NOISE_SIGMA).clamp(-3.0, 3.0);
        Some(Material {
            roughness: (m.roughness + 0.5 * depth * s).clamp(0.02, 1.0),
            ..scaled(m, 1.0 + depth * s)
        })
    }
}
