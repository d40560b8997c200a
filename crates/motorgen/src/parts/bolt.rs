//! Socket-cap bolts as the add-on's Bolt Factory template makes them (M3 thread on a Ø7 mm cap
//! head, in centimetres), with the recess of each drive, built along local +z with the drive
//! face at z = 0.
//!
//! The profile was measured on the add-on's bolts (Blender's Bolt Factory in the oracle):
//! a head 4 mm high for Torx and 3 mm for the other drives, rounded into a Ø6 mm underside, a
//! Ø3 mm neck, the thread and a cone to a Ø1 mm tip. The thread is turned as a plain cylinder: it
//! sits inside the housing in every assembled motor, so no sensor sees it.

use std::sync::OnceLock;

use glam::Vec2;

use super::shapes::{Tess, rect};
use crate::kernel::{Mesh, Pocket, circle};
use crate::params::BoltDrive;

/// Head radius (cap head Ø7 mm).
const HEAD_RADIUS: f32 = 0.35;
/// Radius of the head's underside (Ø6 mm).
const UNDERSIDE_RADIUS: f32 = 0.30;
/// Neck radius below the head (the thread's root, Ø3 mm).
const NECK_RADIUS: f32 = 0.15;
/// Thread crest radius (Ø4 mm).
const CREST_RADIUS: f32 = 0.20;
/// Radius of the cylinder that stands for the thread: the one whose side silhouette matches the
/// threaded bolt's best (measured against the add-on's bolts).
const THREAD_RADIUS: f32 = 0.165;
/// Tip radius (Ø1 mm).
const TIP_RADIUS: f32 = 0.05;
/// Where the rounding of the head's lower edge starts, above the nominal head height.
const ROUND_START: f32 = 0.004;
/// Rounding of the head's lower edge, along the axis.
const UNDERSIDE_ROUND: f32 = 0.041;
/// Neck length below the head.
const NECK_LENGTH: f32 = 0.063;
/// Length of the cone from the neck to the thread crest.
const THREAD_RUN_IN: f32 = 0.1;
/// Thread length at the crest diameter.
const THREAD_LENGTH: f32 = 0.887;
/// Length of the cone from the crest to the tip.
const TIP_LENGTH: f32 = 0.15;

/// Head height: 4 mm for Torx, 3 mm for the others (as the add-on asks Bolt Factory).
fn head_height(drive: BoltDrive) -> f32 {
    match drive {
        BoltDrive::Torx => 0.4,
        _ => 0.3,
    }
}

/// How far the drive face lies inside the point the add-on places a bolt at, along the axis.
/// The add-on centres each Bolt Factory mesh on its vertices' median, which sits at a different
/// depth for each drive; these are the offsets measured on its bolts.
pub fn face_inset(drive: BoltDrive) -> f32 {
    match drive {
        BoltDrive::Torx => 0.0,
        BoltDrive::Slot => 0.0282,
        BoltDrive::Cross => 0.0397,
        BoltDrive::Allen => 0.0379,
    }
}

/// A bolt of `drive` along local +z: the drive face at z = 0, the head below it, the thread
/// below the head, the recess unturned. The same in every motor: built once per detail and
/// drive; a bolt in place is this turned about z and moved.
pub fn bolt(t: Tess, drive: BoltDrive) -> &'static Mesh {
    static BUILT: [[OnceLock<Mesh>; 4]; 3] = [const { [const { OnceLock::new() }; 4] }; 3];
    BUILT[t.0 as usize][drive as usize].get_or_init(|| {
        let recess = Pocket {
            outline: recess_outline(t, drive),
            depth: recess_depth(drive),
        };
        t.revolve(&profile(t, drive), &[recess])
    })
}

/// The (r, z) profile from the tip on the axis up to the rim of the drive face.
fn profile(t: Tess, drive: BoltDrive) -> Vec<Vec2> {
    let thread = THREAD_RADIUS;
    let round_top = ROUND_START - head_height(drive);
    let under = round_top - UNDERSIDE_ROUND;
    let neck_end = under - NECK_LENGTH;
    // the thread cylinder meets the run-in and the tip cone on their slopes
    let thread_top =
        neck_end - THREAD_RUN_IN * (thread - NECK_RADIUS) / (CREST_RADIUS - NECK_RADIUS);
    let crest_end = neck_end - THREAD_RUN_IN - THREAD_LENGTH;
    let thread_end = crest_end - TIP_LENGTH * (CREST_RADIUS - thread) / (CREST_RADIUS - TIP_RADIUS);
    let tip = crest_end - TIP_LENGTH;
    let mut p = vec![
        Vec2::new(0.0, tip),
        Vec2::new(TIP_RADIUS, tip),
        Vec2::new(thread, thread_end),
        Vec2::new(thread, thread_top),
        Vec2::new(NECK_RADIUS, neck_end),
        Vec2::new(NECK_RADIUS, under),
        Vec2::new(UNDERSIDE_RADIUS, under),
    ];
    // the lower edge rounds from the underside up into the head's side
    let corner = Vec2::new(UNDERSIDE_RADIUS, round_top);
    let radii = Vec2::new(HEAD_RADIUS - UNDERSIDE_RADIUS, UNDERSIDE_ROUND);
    p.extend(quarter(t, corner, radii, -1.0).skip(1));
    if drive == BoltDrive::Torx {
        // Bolt Factory rounds the rim of the Torx head's face
        let r = 0.037;
        p.push(Vec2::new(HEAD_RADIUS, -r));
        p.extend(quarter(t, Vec2::new(HEAD_RADIUS - r, -r), Vec2::splat(r), 1.0).skip(1));
    } else {
        p.push(Vec2::new(HEAD_RADIUS, 0.0));
    }
    p
}

/// Points on a quarter ellipse about `centre` with `radii`: from straight below the centre
/// (`side` = -1) or straight right of it (`side` = 1), turning counter-clockwise through 90°,
/// both ends included.
fn quarter(t: Tess, centre: Vec2, radii: Vec2, side: f32) -> impl Iterator<Item = Vec2> {
    let n = (t.n(radii.max_element()) / 4).max(2);
    let start = if side < 0.0 {
        -std::f32::consts::FRAC_PI_2
    } else {
        0.0
    };
    (0..=n).map(move |i| {
        let a = start + std::f32::consts::FRAC_PI_2 * i as f32 / n as f32;
        centre + radii * Vec2::from_angle(a)
    })
}

fn recess_depth(drive: BoltDrive) -> f32 {
    match drive {
        BoltDrive::Torx | BoltDrive::Allen => 0.2,
        BoltDrive::Slot => 0.149,
        BoltDrive::Cross => 0.223,
    }
}

/// The recess outline in the drive face.
fn recess_outline(t: Tess, drive: BoltDrive) -> Vec<Vec2> {
    match drive {
        // T20: 3.86 mm over the lobes, 2.77 mm between them, six rounded lobes
        BoltDrive::Torx => {
            let n = t.n(0.19).max(24).next_multiple_of(6) * 2;
            (0..n)
                .map(|i| {
                    let a = std::f32::consts::TAU * i as f32 / n as f32;
                    (0.166 + 0.0275 * (6.0 * a).cos()) * Vec2::from_angle(a)
                })
                .collect()
        }
        // a 1 mm slot across the face, ending 20 µm inside the rim polygon's inscribed circle
        BoltDrive::Slot => {
            let inradius = HEAD_RADIUS * (std::f32::consts::PI / t.n(HEAD_RADIUS) as f32).cos();
            let half = (inradius * inradius - 0.05 * 0.05).sqrt() - 0.002;
            rect(Vec2::new(-half, -0.05), Vec2::new(half, 0.05))
        }
        // Phillips: a cross of Ø3.2 mm with 0.9 mm arms
        BoltDrive::Cross => {
            let (l, w) = (0.158, 0.045);
            [
                (l, w),
                (w, w),
                (w, l),
                (-w, l),
                (-w, w),
                (-l, w),
                (-l, -w),
                (-w, -w),
                (-w, -l),
                (w, -l),
                (w, -w),
                (l, -w),
            ]
            .map(|(x, y)| Vec2::new(x, y))
            .to_vec()
        }
        // 3 mm hexagon socket (across flats)
        BoltDrive::Allen => circle(Vec2::ZERO, 0.3 / 3f32.sqrt(), 6, 0.0),
    }
}
