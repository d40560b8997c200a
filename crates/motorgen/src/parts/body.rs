//! The parts that do not turn with the gearbox: pole pot, magnets, armature, electric
//! connection, and the gear container's collar and brush tower (centimetres, motor frame).

use std::f32::consts::{PI, TAU};

use glam::{Affine3A, Vec2, Vec3};

use super::Dims;
use super::shapes::{Tess, plate, sector};
use crate::kernel::{Mesh, Pocket, Section, cuboid, sweep, sweep_loop};

/// Pole-pot radius (the add-on's BOTTOM_DIA / 2).
const POT_RADIUS: f32 = 2.0;
/// Half the width across the pot's flats (BOTTOM_HEIGHT / 2).
const POT_HALF_WIDTH: f32 = 1.5;
/// Floor thickness of the hollow pot.
const POT_FLOOR: f32 = 0.2;
/// The cavity: the pot outline scaled by 0.9 across (as the add-on cuts it), so the wall is 2 mm
/// thick at the arcs and 1.5 mm at the flats.
const CAVITY_RADIUS: f32 = 0.9 * POT_RADIUS;
const CAVITY_HALF_WIDTH: f32 = 0.9 * POT_HALF_WIDTH;
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
    let arc = PI - 2.0 * (half_width / radius).acos();
    // even, so that the apex on ±y is a vertex and the outline keeps its full 4 cm depth
    let arc_segments = ((t.n(radius) as f32 * arc / TAU).ceil() as usize)
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
        outline: pot_section(t, CAVITY_RADIUS, CAVITY_HALF_WIDTH).ring(0.0),
        depth: d.bottom - POT_FLOOR,
    };
    let mut pot = sweep(
        &s,
        &[Vec2::new(0.0, d.sub), Vec2::new(0.0, d.top)],
        &[cavity],
    );
    pot.append(&t.boss(0.5, d.sub, 0.25, 0.5));
    pot
}

/// The two magnet shells on ±y inside the pot, 3/4 of its length, 0.5 below its centre. As the
/// add-on cuts them: the pot's cavity outline, against whose wall they sit, less an ellipse of
/// radii 1.82 × 1.5, leaving a crescent on each side.
pub fn magnets(t: Tess, d: &Dims) -> [Mesh; 2] {
    let (r_out, flat, ellipse) = (CAVITY_RADIUS, CAVITY_HALF_WIDTH, Vec2::new(1.82, 1.5));
    let centre = d.sub + 0.5 * d.bottom - 0.5;
    let half = 0.375 * d.bottom;
    let outer_from = (flat / r_out).acos();
    let inner_from = (flat / ellipse.x).acos();
    let n = (t.n(r_out) / 4).max(3);
    let mut crescent: Vec<Vec2> = (0..=n)
        .map(|i| {
            let a = outer_from + (PI - 2.0 * outer_from) * i as f32 / n as f32;
            r_out * Vec2::from_angle(a)
        })
        .collect();
    crescent.extend((0..=n).map(|i| {
        let a = PI - inner_from - (PI - 2.0 * inner_from) * i as f32 / n as f32;
        ellipse * Vec2::from_angle(a)
    }));
    [0.0, PI].map(|turn| {
        let rot = Vec2::from_angle(turn);
        let outline = crescent.iter().map(|p| rot.rotate(*p)).collect();
        plate(outline, vec![], centre - half, centre + half)
    })
}

/// Core radius of the armature.
const CORE_RADIUS: f32 = 1.2;

/// Shaft, rounded core and commutator turned as one solid, and the eight winding packs around the
/// core (as the add-on: 36° packs every 45° from +x, 1.5 mm thick, 80 % of the core's length,
/// here 0.1 mm clear of the core so that each is a shell of its own).
pub fn armature(t: Tess, d: &Dims) -> Mesh {
    let core_len = 0.6 * (d.bottom + d.sub);
    let (core_lo, core_hi) = (d.sub + 1.0, d.sub + 1.0 + core_len);
    let (shaft, comm) = (0.15, 0.4);
    let (comm_lo, comm_hi) = (core_len + 2.0, core_len + 4.0);
    let mut profile = vec![Vec2::new(shaft, 0.5), Vec2::new(shaft, core_lo)];
    profile.extend(round(
        t,
        Vec2::new(CORE_RADIUS - 0.5, core_lo + 0.5),
        0.5,
        -PI / 2.0,
        PI / 2.0,
    ));
    profile.extend(round(
        t,
        Vec2::new(CORE_RADIUS - 0.5, core_hi - 0.5),
        0.5,
        0.0,
        PI / 2.0,
    ));
    if comm_lo > core_hi {
        profile.extend([Vec2::new(shaft, core_hi), Vec2::new(shaft, comm_lo)]);
    }
    profile.push(Vec2::new(comm, comm_lo.max(core_hi)));
    // the commutator's far end rounds in with 3.5 mm until it meets the shaft
    let meets_shaft = ((shaft - (comm - 0.35)) / 0.35).acos();
    profile.extend(round(
        t,
        Vec2::new(comm - 0.35, comm_hi - 0.35),
        0.35,
        0.0,
        meets_shaft,
    ));
    profile.push(Vec2::new(shaft, d.top + d.tower_height() - 0.5));
    let mut m = sweep(
        &Section::Circle {
            segments: t.n(CORE_RADIUS),
        },
        &profile,
        &[],
    );
    let (mid, half) = (0.5 * (core_lo + core_hi), 0.4 * core_len);
    let span = 36f32.to_radians();
    let n = (t.n(1.285) / 10).max(2);
    for k in 0..8 {
        let from = (k as f32 * 45.0 - 0.75).to_radians();
        m.append(&plate(
            sector(1.21, 1.285, from, from + span, n),
            vec![],
            mid - half,
            mid + half,
        ));
    }
    m
}

/// An arc of radius `r` about `centre` from angle `from` turning counter-clockwise through `span`,
/// both ends included.
fn round(t: Tess, centre: Vec2, r: f32, from: f32, span: f32) -> impl Iterator<Item = Vec2> {
    let n = ((t.n(r) as f32 * span / TAU).ceil() as usize).max(2);
    (0..=n).map(move |i| centre + r * Vec2::from_angle(from + span * i as f32 / n as f32))
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
