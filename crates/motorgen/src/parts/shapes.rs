//! Reusable solids for the part builders, in centimetres along local +z.

use std::f32::consts::TAU;

use glam::{Affine3A, Mat3A, Vec2, Vec3, Vec3A};

use crate::kernel::{Detail, Extrusion, Mesh, Pocket, Section, circle, extrude, sweep};

/// Tessellation in centimetre units.
#[derive(Clone, Copy, Debug)]
pub struct Tess(pub Detail);

impl Tess {
    /// Vertices of a full circle of radius `r_cm`.
    pub fn n(self, r_cm: f32) -> usize {
        self.0.segments(r_cm * 0.01)
    }

    /// A circle outline.
    pub fn circle(self, c: Vec2, r: f32) -> Vec<Vec2> {
        circle(c, r, self.n(r), 0.0)
    }

    /// The outline of [`Tess::circle`] of radius `r` grown by `by`: every side `by` further out.
    pub fn circle_grown(self, c: Vec2, r: f32, by: f32) -> Vec<Vec2> {
        let n = self.n(r);
        circle(c, r + by / (std::f32::consts::PI / n as f32).cos(), n, 0.0)
    }

    /// A solid of revolution about z from an open (r, z) profile whose ends lie on the axis.
    pub fn revolve(self, profile: &[Vec2], pockets: &[Pocket]) -> Mesh {
        let r_max = profile.iter().map(|p| p.x).fold(0.0, f32::max);
        sweep(
            &Section::Circle {
                segments: self.n(r_max),
            },
            profile,
            pockets,
        )
    }

    /// A cylinder of radius `r` from `z0` to `z1`.
    pub fn cylinder(self, r: f32, z0: f32, z1: f32) -> Mesh {
        self.revolve(
            &[
                Vec2::new(0.0, z0),
                Vec2::new(r, z0),
                Vec2::new(r, z1),
                Vec2::new(0.0, z1),
            ],
            &[],
        )
    }

    /// A boss of radius `r` from z = 0 to `length`, with a blind hole of `hole_r` sunk `hole_depth`
    /// from its z = 0 end (where the bolt enters).
    pub fn boss(self, r: f32, length: f32, hole_r: f32, hole_depth: f32) -> Mesh {
        self.revolve(
            &[
                Vec2::new(0.0, hole_depth),
                Vec2::new(hole_r, hole_depth),
                Vec2::new(hole_r, 0.0),
                Vec2::new(r, 0.0),
                Vec2::new(r, length),
                Vec2::new(0.0, length),
            ],
            &[],
        )
    }

    /// A flat ring (annulus) from `z0` to `z1`.
    pub fn ring(self, c: Vec2, r_out: f32, r_in: f32, z0: f32, z1: f32) -> Mesh {
        plate(self.circle(c, r_out), vec![self.circle(c, r_in)], z0, z1)
    }
}

/// A plate: a polygon with holes extruded from `z0` to `z1`.
pub fn plate(outer: Vec<Vec2>, holes: Vec<Vec<Vec2>>, z0: f32, z1: f32) -> Mesh {
    extrude(&Extrusion {
        outer,
        holes,
        z0,
        z1,
    })
}

/// The rectangle of half-width `w` along the segment from `a` to `b`.
pub fn strip(a: Vec2, b: Vec2, w: f32) -> Vec<Vec2> {
    let side = (b - a).normalize().perp() * w;
    vec![a - side, b - side, b + side, a + side]
}

/// An axis-aligned rectangle.
pub fn rect(min: Vec2, max: Vec2) -> Vec<Vec2> {
    vec![min, Vec2::new(max.x, min.y), max, Vec2::new(min.x, max.y)]
}

/// The annular sector between radii `r_in` and `r_out` from angle `a0` to `a1` (radians).
pub fn sector(r_in: f32, r_out: f32, a0: f32, a1: f32, segments: usize) -> Vec<Vec2> {
    let arc = |r: f32| {
        (0..=segments)
            .map(move |i| r * Vec2::from_angle(a0 + (a1 - a0) * i as f32 / segments as f32))
    };
    arc(r_out)
        .chain(arc(r_in).collect::<Vec<_>>().into_iter().rev())
        .collect()
}

/// The add-on's internal gear (its `normal_gear`) seen along its axis, scaled by `scale`: a ring
/// of radius 1.1 with `teeth` trapezoid teeth whose bases span a whole pitch on the unit circle,
/// 2.3 half-pitch chords high, their tips 40 % as wide as their bases. Returns the outline
/// (counter-clockwise, the first tooth on +x) and the tip radius.
pub fn gear_outline(t: Tess, teeth: usize, scale: f32) -> (Vec<Vec2>, f32) {
    const RING: f32 = 1.1;
    let pitch = TAU / teeth as f32;
    let (s, c) = (0.5 * pitch).sin_cos();
    let base = Vec2::new(c, s);
    let tip = Vec2::new(c + 2.3 * s, 0.4 * s);
    // where the tooth's side leaves the ring: |base + k (tip - base)| = RING
    let side = tip - base;
    let (qa, qb, qc) = (
        side.dot(side),
        2.0 * base.dot(side),
        base.dot(base) - RING * RING,
    );
    let k = (-qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    let exit = base + k * side;
    let exit_angle = exit.y.atan2(exit.x);
    assert!(
        exit_angle < 0.5 * pitch,
        "teeth of a ring gear may not overlap"
    );
    let gap = pitch - 2.0 * exit_angle;
    let arc_segments = ((t.n(RING * scale) as f32 * gap / TAU).ceil() as usize).max(1);
    let mirror = |p: Vec2| Vec2::new(p.x, -p.y);
    let tooth: Vec<Vec2> =
        [mirror(exit), mirror(tip), tip, exit]
            .into_iter()
            .chain((1..arc_segments).map(|i| {
                RING * Vec2::from_angle(exit_angle + gap * i as f32 / arc_segments as f32)
            }))
            .collect();
    let outline = (0..teeth)
        .flat_map(|i| {
            let turn = Vec2::from_angle(i as f32 * pitch);
            tooth.iter().map(move |&p| scale * turn.rotate(p))
        })
        .collect();
    (outline, scale * tip.length())
}

/// The transform taking local +z to `axis` (by the shortest-arc rotation) and the local origin
/// to `origin`.
pub fn frame(origin: Vec3, axis: Vec3) -> Affine3A {
    let rotation = glam::Quat::from_rotation_arc(Vec3::Z, axis.normalize());
    Affine3A::from_rotation_translation(rotation, origin)
}

/// The transform from a plane frame (u, v, w) to world, given the world directions of u, v, w
/// (right-handed) and the world position of the frame origin.
pub fn plane_frame(u: Vec3, v: Vec3, w: Vec3, origin: Vec3) -> Affine3A {
    Affine3A {
        matrix3: Mat3A::from_cols(u.into(), v.into(), w.into()),
        translation: Vec3A::from(origin),
    }
}
