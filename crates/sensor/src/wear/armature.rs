//! The armature's surfaces: its shaft, the lamination stack of its core, the enamelled copper
//! windings and the commutator's bars, each its own material and texture.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::pattern::{draw, fbm};
use crate::materials::{ELECTRICAL_STEEL, STAINLESS_STEEL, mat};
use crate::world::Material;

/// One surface of an armature.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ArmatureSurface {
    /// The steel shaft, drawn.
    Shaft,
    /// The core's stack of electrical-steel sheets.
    Laminations,
    /// The enamelled copper wire wound over the core.
    Windings,
    /// The commutator's copper bars and the mica between them.
    Commutator,
}

/// Where an armature's surfaces lie, in its texture coordinates (centimetres; the axis along
/// texture z): radii about the axis and spans along it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Armature {
    /// The axis' x and y.
    pub axis: [f32; 2],
    /// Radius of the shaft.
    pub shaft_radius: f32,
    /// Radius of the core (the windings lie beyond it).
    pub core_radius: f32,
    /// The core's span along the axis.
    pub core: [f32; 2],
    /// The commutator's span along the axis.
    pub commutator: [f32; 2],
    /// The commutator's bars.
    pub bars: u32,
    /// Share of the bars worn dark: burnt and oxidised under the brushes, 0 to 1.
    #[serde(default)]
    pub worn: f32,
    /// Which bars wear (and the texture's other draws per bar).
    #[serde(default)]
    pub seed: u32,
}

/// Thickness of a lamination sheet, cm (0.5 mm electrical steel).
pub const SHEET_CM: f32 = 0.05;
/// Diameter of a winding's wire, cm (0.3 mm enamelled copper).
pub const WIRE_CM: f32 = 0.03;
/// Share of a commutator bar's pitch that is the mica gap between bars.
pub const GAP: f32 = 0.1;

/// Bare copper of a commutator's bars, polished by the brushes.
const BAR: Material = mat(0.55, 0.6, 0.15, [0.8, 0.45, 0.3], 1.0, 0.25);

/// A worn bar: copper burnt and oxidised dark under the brushes, matte.
const BURNT: Material = mat(0.15, 0.1, 0.4, [0.16, 0.07, 0.04], 0.6, 0.6);

/// Mica between the bars: dark brown and matte.
const MICA: Material = mat(0.1, 0.0, 0.4, [0.08, 0.05, 0.03], 0.0, 0.7);

impl Armature {
    /// The surface at texture coordinates `q` (on the armature).
    pub fn surface(&self, q: Vec3) -> ArmatureSurface {
        let r = (q.truncate() - glam::Vec2::from(self.axis)).length();
        let within = |[lo, hi]: [f32; 2]| (lo - TOLERANCE..=hi + TOLERANCE).contains(&q.z);
        if r > self.core_radius + TOLERANCE {
            ArmatureSurface::Windings
        } else if r <= self.shaft_radius + TOLERANCE {
            ArmatureSurface::Shaft
        } else if within(self.core) {
            ArmatureSurface::Laminations
        } else if within(self.commutator) {
            ArmatureSurface::Commutator
        } else {
            ArmatureSurface::Shaft
        }
    }

    /// The material at texture coordinates `q`, its surface's (`windings` the part's own)
    /// with its texture: the sheets of the stack each a little brighter or darker, the
    /// varnished seams between them dark; the wires' round profiles across the windings; the
    /// bars and the mica between them.
    pub(super) fn material(&self, windings: &Material, q: Vec3) -> Material {
        let d = q.truncate() - glam::Vec2::from(self.axis);
        let turn = d.y.atan2(d.x);
        match self.surface(q) {
            ArmatureSurface::Shaft => super::Grain::Drawn
                .apply(&STAINLESS_STEEL, q)
                .unwrap_or(STAINLESS_STEEL),
            ArmatureSurface::Laminations => {
                let t = q.z / SHEET_CM;
                let (sheet, along) = (t.floor(), t - t.floor());
                // a seam a tenth of the pitch at each sheet's face
                let seam = if along < 0.1 { 0.55 } else { 1.0 };
                scaled(
                    &ELECTRICAL_STEEL,
                    seam * (0.92 + 0.16 * draw(sheet as i32, 1)),
                )
            }
            ArmatureSurface::Windings => {
                let t = turn * d.length() / WIRE_CM;
                let (wire, across) = (t.floor(), t - t.floor());
                // the wire's round profile: bright along its crest, dark in the grooves
                let x = 2.0 * across - 1.0;
                let profile = 0.45 + 0.55 * (1.0 - x * x).max(0.0).sqrt();
                scaled(windings, profile * (0.94 + 0.12 * draw(wire as i32, 2)))
            }
            ArmatureSurface::Commutator => {
                let t = (turn / std::f32::consts::TAU).rem_euclid(1.0) * self.bars as f32;
                let (bar, across) = (t.floor(), t - t.floor());
                let bar = bar as i32 + self.seed as i32;
                if across < GAP {
                    MICA
                } else if draw(bar, 4) < self.worn {
                    // burnt most along the brushes' track, the middle of the bar's length
                    let middle = (2.0 * (q.z - self.commutator[0])
                        / (self.commutator[1] - self.commutator[0]).max(1e-6)
                        - 1.0)
                        .abs();
                    let streak = fbm(Vec3::new(40.0 * turn, 0.0, 0.5 * q.z), 2.0, 0.5);
                    scaled(&BURNT, (0.8 + 0.5 * middle) * (0.9 + 0.2 * streak))
                } else {
                    // each bar's own tarnish, a faint streak along the brushes' path
                    let streak = fbm(Vec3::new(40.0 * turn, 0.0, 0.5 * q.z), 2.0, 0.5);
                    let b = (0.9 + 0.2 * draw(bar, 3)) * (0.9 + 0.2 * streak);
                    scaled(&BAR, b)
                }
            }
        }
    }
}

/// Distance within which a point lies on a surface's boundary, cm.
const TOLERANCE: f32 = 0.005;

/// `m` a factor `b` brighter: its colour and reflectivity.
pub(super) fn scaled(m: &Material, b: f32) -> Material {
    Material {
        colour: m.colour.map(|c| (c * b).clamp(0.0, 1.0)),
        reflectivity: (m.reflectivity * b).clamp(0.0, 1.0),
        ..*m
    }
}
