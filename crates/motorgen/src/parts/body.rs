//! The parts that do not turn with the gearbox: pole pot, magnets, armature, electric
//! connection, and the gear container's collar and brush tower (centimetres, motor frame).

use glam::{Affine3A, Vec2, Vec3};

use super::Dims;
use super::shapes::{Tess, gear_outline, plate, sector};
use crate::kernel::{Mesh, Pocket, Section, cuboid, sweep, sweep_loop};

/// Pole-pot radius (the add-on's BOTTOM_DIA / 2).
const POT_RADIUS: f32 = 2.0;
/// Half the width across the pot's flats (BOTTOM_HEIGHT / 2).
const POT_HALF_WIDTH: f32 = 1.5;
/// Wall and floor thickness of the hollow pot.
const POT_WALL: f32 = 0.2;
/// Height of the gear-container collar (the add-on's BOLT_LENGTH).
pub const COLLAR_HEIGHT: f32 = 1.4;
/// Side-bolt positions (x, y) about the motor axis.
pub const SIDE_BOLTS: [Vec2; 2] = [Vec2::new(1.1, 2.0), Vec2::new(-1.1, -2.0)];
/// Bolt-boss radius (BOLT_RAD).
pub const BOSS_RADIUS: f32 = 0.4;
/// Radius of the holes bolts enter.
pub const HOLE_RADIUS: f32 = 0.175;

/// The pot outline offset outwards by `u`, as a sweep section.
fn pot_section(t: Tess, radius: f32, half_width: f32) -> Section {
    let arc = std::f32::consts::PI - 2.0 * (half_width / radius).acos();
    // even, so that the apex on ±y is a vertex and the outline keeps its full 4 cm depth
    let arc_segments = ((t.n(radius) as f32 * arc / std::f32::consts::TAU).ceil() as usize)
        .max(2)
        .next_multiple_of(2);
    Section::FlatCircle {
        radius,
        half_width,
        arc_segments,
    }
}

/// Hollow pole pot (a cylinder with two flats, open towards the gearbox) and the shaft boss
/// with its blind hole.
pub fn pole_pot(t: Tess, d: &Dims) -> Mesh {
    let s = pot_section(t, POT_RADIUS, POT_HALF_WIDTH);
    let cavity = Pocket {
        outline: s.ring(-POT_WALL),
        depth: d.bottom - POT_WALL,
    };
    let mut pot = sweep(
        &s,
        &[Vec2::new(0.0, d.sub), Vec2::new(0.0, d.top)],
        &[cavity],
    );
    pot.append(&t.boss(0.5, d.sub, 0.25, 0.5));
    pot
}

/// The two magnet shells on ±y inside the pot, 3/4 of its length, 0.5 below its centre.
pub fn magnets(t: Tess, d: &Dims) -> [Mesh; 2] {
    let (r_in, r_out) = (1.45, POT_RADIUS - POT_WALL - 0.02);
    let centre = d.sub + 0.5 * d.bottom - 0.5;
    let half = 0.375 * d.bottom;
    let n = (t.n(r_out) / 4).max(3);
    let quarter = std::f32::consts::FRAC_PI_4;
    [1.0f32, 5.0].map(|k| {
        plate(
            sector(r_in, r_out, k * quarter, (k + 2.0) * quarter, n),
            vec![],
            centre - half,
            centre + half,
        )
    })
}

/// Shaft, slotted core and commutator.
pub fn armature(t: Tess, d: &Dims) -> Mesh {
    let span = d.bottom + d.sub;
    let core_mid = 0.3 * span + d.sub + 1.0;
    let (core_lo, core_hi) = (core_mid - 0.3 * span, core_mid + 0.3 * span);
    let mut m = t.cylinder(0.15, 0.5, d.top + d.tower_height() - 0.5);
    m.append(&plate(gear_outline(0.9, 12, 0.3), vec![], core_lo, core_hi));
    m.append(&t.revolve(
        &[
            Vec2::new(0.0, core_hi + 0.3),
            Vec2::new(0.35, core_hi + 0.3),
            Vec2::new(0.4, core_hi + 0.35),
            Vec2::new(0.4, core_hi + 2.25),
            Vec2::new(0.35, core_hi + 2.3),
            Vec2::new(0.0, core_hi + 2.3),
        ],
        &[],
    ));
    m
}

/// Connector on the -y side at the pot/gearbox joint: stacked plates, four pins, the insert
/// inside the collar and the brush dome with its shaft hole.
pub fn electric_connection(t: Tess, d: &Dims) -> Mesh {
    let top = d.top;
    let b = |x0: f32, x1: f32, y0: f32, y1: f32, z0: f32, z1: f32| {
        cuboid(Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1))
    };
    let mut m = b(0.05, 1.45, -2.2, -2.0, top - 1.6, top + 1.45);
    m.append(&b(0.15, 1.35, -2.55, -2.2, top - 1.2, top + 0.9));
    m.append(&b(0.05, 1.45, -2.65, -2.55, top - 1.0, top + 0.6));
    m.append(&b(0.05, 1.45, -2.65, -2.2, top + 1.2, top + 1.45));
    for i in 0..4 {
        let x = 0.2 + 0.3 * i as f32;
        m.append(&b(
            x,
            x + 0.15,
            -2.9,
            -2.65,
            top - 0.7 - 0.15 * i as f32,
            top + 0.2,
        ));
    }
    let insert = pot_section(t, 1.6, 1.2);
    m.append(&sweep_loop(
        &insert,
        &[
            Vec2::new(0.0, top - 0.1),
            Vec2::new(0.0, top + 1.1),
            Vec2::new(-0.15, top + 1.1),
            Vec2::new(-0.15, top - 0.1),
        ],
    ));
    let dome = Section::Circle {
        segments: t.n(0.69),
    };
    m.append(&sweep_loop(
        &dome,
        &[
            Vec2::new(0.175, top + 0.1),
            Vec2::new(0.69, top + 0.1),
            Vec2::new(0.69, top + 0.95),
            Vec2::new(0.54, top + 1.1),
            Vec2::new(0.175, top + 1.1),
        ],
    ));
    m
}

/// The gear container's fixed part: the collar (pot outline, hollow from below), the two side
/// boards, the side-bolt bosses and the stepped brush tower on the axis.
pub fn collar_and_tower(t: Tess, d: &Dims) -> Mesh {
    let top = d.top;
    let s = pot_section(t, POT_RADIUS, POT_HALF_WIDTH);
    let cavity = Pocket {
        outline: s.ring(-0.15),
        depth: COLLAR_HEIGHT - 0.2,
    };
    // built open at the top, then turned over onto the pot
    let turn_over = Affine3A::from_translation(Vec3::Z * (top + COLLAR_HEIGHT))
        * Affine3A::from_scale(Vec3::new(1.0, 1.0, -1.0));
    let mut m = sweep(
        &s,
        &[Vec2::new(0.0, 0.0), Vec2::new(0.0, COLLAR_HEIGHT)],
        &[cavity],
    )
    .transformed(&turn_over);
    for sign in [1.0f32, -1.0] {
        let (x0, x1) = if sign > 0.0 { (1.5, 1.6) } else { (-1.6, -1.5) };
        m.append(&cuboid(
            Vec3::new(x0, -1.2, top - 1.0),
            Vec3::new(x1, 1.2, top + COLLAR_HEIGHT),
        ));
    }
    for p in SIDE_BOLTS {
        m.append(&t.ring(p, BOSS_RADIUS, HOLE_RADIUS, top, top + COLLAR_HEIGHT));
    }
    let steps = d.tower_steps();
    let mut profile = vec![
        Vec2::new(0.0, top + d.tower_height() - 0.3),
        Vec2::new(0.2, top + d.tower_height() - 0.3),
    ];
    let mut z = top + COLLAR_HEIGHT;
    profile.push(Vec2::new(0.2, z));
    for (radius, step_top) in [0.7, 0.6, 0.5, 0.4].into_iter().zip(steps) {
        profile.push(Vec2::new(radius, z));
        z = top + step_top;
        profile.push(Vec2::new(radius, z));
    }
    profile.push(Vec2::new(0.0, z));
    m.append(&t.revolve(&profile, &[]));
    m
}
