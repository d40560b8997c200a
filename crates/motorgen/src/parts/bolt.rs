//! Socket-cap bolts (M3×14 as the add-on's Bolt Factory template, in centimetres) with the
//! recess of each drive, built along local +z with the drive face at z = 0.

use glam::Vec2;

use super::shapes::{Tess, rect};
use crate::kernel::{Mesh, Pocket, circle};
use crate::params::BoltDrive;

/// Head radius (cap head Ø7 mm).
pub const HEAD_RADIUS: f32 = 0.35;
const SHANK_RADIUS: f32 = 0.15;
/// Shank length below the head.
pub const SHANK_LENGTH: f32 = 1.4;
const CHAMFER: f32 = 0.03;

/// Head height: 4 mm for Torx, 3 mm for the others (as the add-on).
pub fn head_height(drive: BoltDrive) -> f32 {
    match drive {
        BoltDrive::Torx => 0.4,
        _ => 0.3,
    }
}

/// A bolt along local +z: the drive face at z = 0, the head below it, the shank below the head.
/// The recess is turned by `rotation` radians about the axis.
pub fn bolt(t: Tess, drive: BoltDrive, rotation: f32) -> Mesh {
    let h = head_height(drive);
    let turn = Vec2::from_angle(rotation);
    let recess = Pocket {
        outline: recess_outline(t, drive)
            .into_iter()
            .map(|p| turn.rotate(p))
            .collect(),
        depth: recess_depth(drive),
    };
    t.revolve(
        &[
            Vec2::new(0.0, -h - SHANK_LENGTH),
            Vec2::new(SHANK_RADIUS, -h - SHANK_LENGTH),
            Vec2::new(SHANK_RADIUS, -h),
            Vec2::new(HEAD_RADIUS, -h),
            Vec2::new(HEAD_RADIUS, -CHAMFER),
            Vec2::new(HEAD_RADIUS - CHAMFER, 0.0),
        ],
        &[recess],
    )
}

fn recess_depth(drive: BoltDrive) -> f32 {
    match drive {
        BoltDrive::Torx | BoltDrive::Allen => 0.2,
        BoltDrive::Slot => 0.15,
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
        // 1 mm slot across most of the head
        BoltDrive::Slot => rect(Vec2::new(-0.28, -0.05), Vec2::new(0.28, 0.05)),
        // Phillips: a cross of Ø3 mm with 0.9 mm arms
        BoltDrive::Cross => {
            let (l, w) = (0.15, 0.045);
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
