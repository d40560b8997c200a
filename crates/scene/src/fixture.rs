//! The two-jaw clamp fixture of the disassembly station, sized to the motor: a base plate, a
//! fixed and a sliding jaw gripping the held part (the pole pot or the gear container) from the
//! sides, a pillar and the pneumatic cylinder that drives the sliding jaw.

use glam::Vec3;
use motorgen::kernel::{Aabb, Mesh, cuboid};
use sensor::Material;
use sensor::materials::{ALUMINIUM, ANODISED_ALUMINIUM, WHITE_PLASTIC};

use crate::cell::cylinder;

/// How far each part moved from its rest position, m.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fixture {
    /// Fixed jaw.
    pub fixed_jaw: Vec3,
    /// Sliding jaw.
    pub sliding_jaw: Vec3,
    /// Pillar.
    pub pillar: Vec3,
    /// Cylinder, on top of the sliding jaw's shift.
    pub cylinder: Vec3,
}

/// Jaw width along the motor axis, thickness across it, m.
const JAW_WIDTH: f32 = 0.03;
const JAW_THICKNESS: f32 = 0.02;

/// The fixture's parts for a held part at `held` and a motor at `motor` (world boxes at the
/// nominal pose), on a plate of thickness `plate` standing on the table.
pub fn fixture(
    held: &Aabb,
    motor: &Aabb,
    plate: f32,
    shift: &Fixture,
) -> Vec<(&'static str, Mesh, Material)> {
    let axis_z = held.centre().z;
    let jaw_x = held.centre().x;
    let jaw_top = axis_z + 0.25 * (held.max.z - held.min.z);
    let jaw = |y0: f32, y1: f32, s: Vec3| {
        cuboid(
            Vec3::new(jaw_x - JAW_WIDTH / 2.0, y0, plate) + s,
            Vec3::new(jaw_x + JAW_WIDTH / 2.0, y1, jaw_top) + s,
        )
    };
    let fixed = jaw(held.min.y - JAW_THICKNESS, held.min.y, shift.fixed_jaw);
    let sliding = jaw(held.max.y, held.max.y + JAW_THICKNESS, shift.sliding_jaw);
    let base = cuboid(
        Vec3::new(motor.min.x - 0.04, -0.12, 0.0),
        Vec3::new(motor.max.x + 0.04, 0.12, plate),
    );
    let pillar_at = Vec3::new(motor.max.x + 0.05, -0.09, 0.0) + shift.pillar;
    let pillar = cuboid(
        pillar_at - Vec3::new(0.02, 0.02, 0.0),
        pillar_at + Vec3::new(0.02, 0.02, 0.14),
    );
    let cyl_start = Vec3::new(jaw_x, held.max.y + JAW_THICKNESS, (plate + jaw_top) / 2.0)
        + shift.sliding_jaw
        + shift.cylinder;
    let cyl = cylinder(cyl_start, cyl_start + Vec3::new(0.0, 0.08, 0.0), 0.012, 24);
    vec![
        ("base_plate", base, WHITE_PLASTIC),
        ("fixed_jaw", fixed, ANODISED_ALUMINIUM),
        ("sliding_jaw", sliding, ANODISED_ALUMINIUM),
        ("pillar", pillar, ALUMINIUM),
        ("cylinder", cyl, ALUMINIUM),
    ]
}
