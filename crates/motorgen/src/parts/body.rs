//! The parts that do not turn with the gearbox: pole pot, magnets, armature, electric
//! connection, and the gear container's collar and brush tower (centimetres, motor frame).

use std::f32::consts::{PI, TAU};
use std::sync::OnceLock;

use glam::{Affine3A, Vec2, Vec3};

use super::Dims;
use super::shapes::{Tess, plate, sector};

use crate::kernel::{Mesh, Section, Stretch, csg, cuboid, stack, sweep, sweep_loop};

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
/// Radius of the side-bolt bosses' holes: the add-on's 2 mm would pass exactly through the
/// collar boards' inner edges, 0.1 mm less keeps those edges inside the boss.
const HOLE_RADIUS_SIDE: f32 = 0.19;

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

/// The pot's outline scaled by `sx` across the flats and `sy` along them (the add-on's scaled
/// copies of the pot for the insert, the collar and their cavities).
fn pot_outline_scaled(t: Tess, sx: f32, sy: f32) -> Vec<Vec2> {
    pot_section(t, POT_RADIUS, POT_HALF_WIDTH)
        .ring(0.0)
        .into_iter()
        .map(|p| p * Vec2::new(sx, sy))
        .collect()
}

/// Hollow pole pot (a cylinder with two flats, open towards the gearbox) on the shaft boss with
/// its blind hole, one closed shell.
pub fn pole_pot(t: Tess, d: &Dims) -> Mesh {
    let along = |outline: Vec<Vec2>, z0: f32, z1: f32| Stretch {
        outline,
        z0,
        z1,
        turn: [0.0; 2],
    };
    let outline = |radius: f32, half_width: f32| pot_section(t, radius, half_width).ring(0.0);
    stack(
        &[
            along(t.circle(Vec2::ZERO, 0.5), 0.0, d.sub),
            along(outline(POT_RADIUS, POT_HALF_WIDTH), d.sub, d.top),
        ],
        &[
            along(t.circle(Vec2::ZERO, 0.25), 0.0, 0.5),
            along(
                outline(CAVITY_RADIUS, CAVITY_HALF_WIDTH),
                d.sub + POT_FLOOR,
                d.top,
            ),
        ],
    )
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

/// Where an armature's surfaces lie along its axis and about it (its units: cm in the add-on's
/// frame, m in the motor's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmatureLayout {
    /// Radius of the shaft.
    pub shaft_radius: f32,
    /// Radius of the lamination stack's core (the windings lie beyond it).
    pub core_radius: f32,
    /// The core's span along the axis.
    pub core: [f32; 2],
    /// Radius of the commutator.
    pub commutator_radius: f32,
    /// The commutator's span along the axis.
    pub commutator: [f32; 2],
    /// Winding packs about the core (and bars of the commutator, one for each).
    pub coils: u32,
}

impl ArmatureLayout {
    /// The armature of a motor of dimensions `d`, in the add-on's frame (cm).
    pub(super) fn new(d: &Dims) -> ArmatureLayout {
        let core_len = 0.6 * (d.bottom + d.sub);
        let core_lo = d.sub + 1.0;
        let core_hi = core_lo + core_len;
        ArmatureLayout {
            shaft_radius: 0.15,
            core_radius: CORE_RADIUS,
            core: [core_lo, core_hi],
            commutator_radius: 0.4,
            commutator: [(core_len + 2.0).max(core_hi), core_len + 4.0],
            coils: 8,
        }
    }
}

/// Shaft, rounded core and commutator turned as one solid, and the eight winding packs around the
/// core (as the add-on: 36° packs every 45° from +x, 1.5 mm thick, 80 % of the core's length,
/// here 0.1 mm clear of the core so that each is a shell of its own).
pub fn armature(t: Tess, d: &Dims) -> Mesh {
    let a = ArmatureLayout::new(d);
    let [core_lo, core_hi] = a.core;
    let (shaft, comm) = (a.shaft_radius, a.commutator_radius);
    let core_len = 0.6 * (d.bottom + d.sub);
    let (comm_lo, comm_hi) = (core_len + 2.0, a.commutator[1]);
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
    profile.push(Vec2::new(comm, a.commutator[0]));
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
    // the chords of the packs' inner arcs 0.1 mm clear of the core
    let inner = (CORE_RADIUS + 0.01) / (0.5 * span / n as f32).cos();
    for k in 0..a.coils {
        let from = (k as f32 * 45.0 - 0.75).to_radians();
        m.append(&plate(
            sector(inner, 1.285, from, from + span, n),
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

/// The electric connection as the add-on builds it: the connector on the −y side of the pot's
/// top (three boards, a cap and four pins) and, inside the collar, the brush-plate insert (the
/// pot outline scaled to 0.8 × 0.95, open below, a Ø13.6 mm hole in its top) with the brush dome
/// on it. The same in every motor but for its height: built once per detail, then moved.
pub fn electric_connection(t: Tess, d: &Dims) -> Mesh {
    static BUILT: [OnceLock<Mesh>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    let detail = t.0 as usize;
    BUILT[detail]
        .get_or_init(|| connection_at_origin(t))
        .clone()
        .transformed(&Affine3A::from_translation(Vec3::Z * d.top))
}

/// The electric connection with the pot's top at z = 0.
fn connection_at_origin(t: Tess) -> Mesh {
    let b = |x0: f32, x1: f32, y0: f32, y1: f32, z0: f32, z1: f32| {
        cuboid(Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1))
    };
    // boards that touch in the add-on overlap by 0.1 mm here, so that they unite
    let e = 0.01;
    let mut parts = vec![
        b(0.05, 1.45, -2.1 - e, -1.9, -1.6, 1.4),
        b(0.4, 1.1, -2.5 - e, -2.1 + e, -1.6, 1.4),
        b(0.05, 1.45, -2.6, -2.5 + e, -1.6, 1.4),
        b(0.05, 1.45, -3.4, -1.9, 1.35, 1.45),
        b(0.65, 0.85, -3.1, -2.6 + e, 0.3, 1.3),
        b(0.65, 0.85, -2.85, -2.6 + e, -0.7, 0.3 + e),
        b(0.15, 0.35, -2.975, -2.6 + e, -0.2, 0.8),
        b(1.15, 1.35, -2.975, -2.6 + e, -0.2, 0.8),
    ];
    let outline = |sx: f32, sy: f32| pot_outline_scaled(t, sx, sy);
    let insert = csg::difference(
        &plate(outline(0.8, 0.95), vec![], -0.75, 0.75),
        &[
            plate(outline(0.7, 0.8), vec![], -0.95, 0.55),
            // the add-on's hole is Ø13.6 mm, so the dome's rounding grazes its rim; cut
            // smaller, the hole stays inside the dome's wall and only the dome crosses the plate
            t.cylinder(0.3, 0.0, 1.0),
        ],
    );
    // the dome: Ø13.7 mm, rounded with 3.5 mm at both ends, on the insert, a Ø3.5 mm hole through
    let (r, hole, round_r, lo, hi) = (0.686, 0.175, 0.35, 0.42, 1.82);
    let mut profile = vec![Vec2::new(hole, lo)];
    profile.extend(round(
        t,
        Vec2::new(r - round_r, lo + round_r),
        round_r,
        -PI / 2.0,
        PI / 2.0,
    ));
    profile.extend(round(
        t,
        Vec2::new(r - round_r, hi - round_r),
        round_r,
        0.0,
        PI / 2.0,
    ));
    profile.push(Vec2::new(hole, hi));
    parts.push(sweep_loop(&Section::Circle { segments: t.n(r) }, &profile));
    parts.push(insert);
    csg::union(&parts)
}

/// The gear container's fixed part as the add-on builds it (its "middle" and tower): the collar
/// on the pot (the pot outline, hollow from below up to 7 mm under its top, a Ø14 mm hole
/// through the top), a board on each flat, the side-bolt bosses (closed at the top) and the
/// brush tower of four thin nested tubes, each the add-on's C length high, capped on top. The
/// same in every motor of a type but for its height: built once per type and detail, then moved.
pub fn collar_and_tower(t: Tess, d: &Dims) -> Mesh {
    static BUILT: [[OnceLock<Mesh>; 3]; 2] = [
        [OnceLock::new(), OnceLock::new(), OnceLock::new()],
        [OnceLock::new(), OnceLock::new(), OnceLock::new()],
    ];
    let steps = d.tower_steps();
    BUILT[d.motor_type as usize][t.0 as usize]
        .get_or_init(|| collar_and_tower_at_origin(t, steps))
        .clone()
        .transformed(&Affine3A::from_translation(Vec3::Z * d.top))
}

/// The boxes (motor frame, cm) that the collar, the brush tower and the side-bolt bosses of
/// [`collar_and_tower`] fill: what the gearbox's plates keep clear of.
pub fn collar_and_tower_boxes(d: &Dims) -> Vec<(Vec3, Vec3)> {
    let top = d.top;
    let mut boxes = vec![
        (
            Vec3::new(-POT_HALF_WIDTH, -POT_RADIUS, top - 0.1),
            Vec3::new(POT_HALF_WIDTH, POT_RADIUS, top + COLLAR_HEIGHT),
        ),
        (
            Vec3::new(-0.7, -0.7, top),
            Vec3::new(0.7, 0.7, top + d.tower_height()),
        ),
    ];
    for p in SIDE_BOLTS {
        boxes.push((
            (p - BOSS_RADIUS).extend(top + 0.15),
            (p + BOSS_RADIUS).extend(top + 1.55),
        ));
    }
    boxes
}

/// The collar and tower with the pot's top at z = 0; `steps` are the tubes' heights.
fn collar_and_tower_at_origin(t: Tess, steps: [f32; 4]) -> Mesh {
    let outline = |sx: f32, sy: f32| pot_outline_scaled(t, sx, sy);
    // the add-on's hole is as wide as the outer tube; 0.1 mm narrower, the tube fills it
    let collar = csg::difference(
        &plate(outline(1.0, 1.0), vec![], -0.1, COLLAR_HEIGHT),
        &[t.cylinder(0.69, 0.65, 2.15)],
    );
    let mut parts = vec![collar];
    // the boards' outer faces and tops lie 10 µm inside the collar's flats and top, so that no
    // faces of the union are coplanar
    let e = 0.001;
    for (x0, x1) in [(-1.5 + e, -1.3), (1.3, 1.5 - e)] {
        parts.push(cuboid(
            Vec3::new(x0, -2.0, 0.0),
            Vec3::new(x1, 1.6, COLLAR_HEIGHT - e),
        ));
    }
    for p in SIDE_BOLTS {
        // open below, where the bolt enters, from 1.5 mm above the pot's top; 1 mm deck on top
        let boss = t.boss(BOSS_RADIUS, 1.4, HOLE_RADIUS_SIDE, 1.3);
        parts.push(boss.transformed(&Affine3A::from_translation(p.extend(0.15))));
    }
    for (k, (radius, height)) in [0.7, 0.6, 0.5, 0.4].into_iter().zip(steps).enumerate() {
        parts.push(t.ring(Vec2::ZERO, radius, radius - 0.1 / 3.0, 0.0, height));
        if k == 3 {
            // its cap, 10 µm inside the tube's wall and top, and its underside 10 µm off the
            // next tube's top (type B's stand at the same height), so that no faces are coplanar
            parts.push(t.cylinder(radius - e, height - 0.2 + e, height - e));
        }
    }
    let united = csg::union(&parts);
    csg::difference(&united, &[plate(outline(0.8, 0.9), vec![], -0.8, 0.7)])
}
