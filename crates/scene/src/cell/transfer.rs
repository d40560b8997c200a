//! The transfer unit: carriers in a row on a roller conveyor (rollers between two side
//! profiles on legs, the conveyor's top at z = 0, the floor below), small load carriers (open
//! boxes, VDA KLT 4147: 400 × 300 × 147 mm) or flat workpiece trays, holding motors lying on
//! their side, some with their cover off beside them; boxes and cylinders around.

use std::f32::consts::TAU;

use glam::{Affine3A, Vec3};
use motorgen::kernel::{Mesh, cuboid};
use motorgen::{Motor, PartKind};
use rand::{Rng, RngExt};
use sensor::Material;
use sensor::materials::{BLACK_PA66, MATTE_GREY, ZINC_PLATED_STEEL};

use super::place::{Objects, block, flat, inside, lying, motor_k, paint, set_down};
use super::{Cell, Kind, cylinder};
use crate::config::{CellConfig, TransferConfig};
use crate::error::Result;

/// A carrier's outer size, m (the KLT 4147's; a tray has its footprint).
pub(super) const CARRIER: Vec3 = Vec3::new(0.4, 0.3, 0.147);
/// A carrier's wall and floor, m.
const WALL: f32 = 0.004;
/// A tray's plate and rim, m.
const TRAY: f32 = 0.012;
const RIM: f32 = 0.015;
/// Pitch of the carriers along the conveyor, m.
const PITCH: f32 = 0.46;
/// The conveyor's width between its profiles, roller radius and pitch, m.
const WIDTH: f32 = 0.5;
const ROLLER: f32 = 0.025;
const ROLLER_PITCH: f32 = 0.075;
/// Height of the conveyor's top above the floor, m.
pub(super) const HEIGHT: f32 = 0.75;

/// Blue polypropylene of small load carriers.
pub(super) const KLT_BLUE: Material = Material {
    colour: [0.03, 0.12, 0.4],
    reflectivity: 0.25,
    roughness: 0.45,
    ..MATTE_GREY
};
/// Grey polypropylene.
pub(super) const KLT_GREY: Material = Material {
    colour: [0.35, 0.36, 0.37],
    reflectivity: 0.4,
    roughness: 0.5,
    ..MATTE_GREY
};
/// Anodised aluminium of the conveyor's profiles and legs.
const PROFILE: Material = Material {
    colour: [0.6, 0.6, 0.62],
    metallic: 1.0,
    roughness: 0.45,
    ..MATTE_GREY
};

/// An open box: a floor and four walls, outer `size`, standing on z = 0.
pub(super) fn open_box(size: Vec3) -> Mesh {
    let (x, y, z) = (size.x / 2.0, size.y / 2.0, size.z);
    let w = WALL;
    let mut mesh = cuboid(Vec3::new(-x, -y, 0.0), Vec3::new(x, y, w));
    for (min, max) in [
        (Vec3::new(-x, -y, w), Vec3::new(x, -y + w, z)),
        (Vec3::new(-x, y - w, w), Vec3::new(x, y, z)),
        (Vec3::new(-x, -y + w, w), Vec3::new(-x + w, y - w, z)),
        (Vec3::new(x - w, -y + w, w), Vec3::new(x, y - w, z)),
    ] {
        mesh.append(&cuboid(min, max));
    }
    mesh
}

/// A tray: a plate with a rim, `size`'s footprint, standing on z = 0.
fn tray(size: Vec3) -> Mesh {
    let mut tray = open_box(Vec3::new(size.x, size.y, TRAY + RIM));
    tray.append(&cuboid(
        Vec3::new(-size.x / 2.0, -size.y / 2.0, 0.0),
        Vec3::new(size.x / 2.0, size.y / 2.0, TRAY),
    ));
    tray
}

/// Composes the transfer unit, its carriers holding motors `first` and those `more` builds (the
/// k-th, from 1). Every random draw comes from `rng`, in a fixed order.
///
/// # Errors
///
/// Those of `more`.
pub fn transfer_unit(
    first: &Motor,
    more: &dyn Fn(usize) -> Result<Motor>,
    config: &CellConfig,
    rng: &mut impl Rng,
) -> Result<Cell> {
    let t = &config.transfer;
    let carriers = rng.random_range(t.carriers[0]..=t.carriers[1]) as usize;
    let length = carriers as f32 * PITCH + 0.3;
    let mut scene = Objects::default();
    conveyor(&mut scene, length);
    let mut placed = 0;
    let mut first_pose = None;
    for c in 0..carriers {
        let x = -length / 2.0 + 0.15 + PITCH * (c as f32 + 0.5) + rng.random_range(-0.02..0.02);
        let y = rng.random_range(-0.03..0.03);
        let yaw = rng.random_range(-0.05..0.05);
        let is_tray = rng.random::<f32>() < t.trays;
        let (mesh, material, floor) = if is_tray {
            (tray(CARRIER), BLACK_PA66, TRAY)
        } else {
            let colour = if rng.random::<bool>() {
                KLT_BLUE
            } else {
                KLT_GREY
            };
            (open_box(CARRIER), colour, WALL)
        };
        let at = Affine3A::from_translation(Vec3::new(x, y, 0.0)) * Affine3A::from_rotation_z(yaw);
        let name = format!("carrier_{}", c + 1);
        scene.add_at(name, mesh, &at, material, Kind::Carrier);
        // the first carrier holds a motor whenever carriers may
        let count = rng.random_range(t.motors[0]..=t.motors[1]) as usize;
        let count = if c == 0 {
            count.max(t.motors[1].min(1) as usize)
        } else {
            count
        };
        for slot in 0..count {
            let k = placed;
            placed += 1;
            let motor = motor_k(first, more, k)?;
            let motor = &*motor;
            let side = if count == 1 {
                0.0
            } else {
                (slot as f32 - 0.5) * CARRIER.y / 2.0
            };
            let cover_off = rng.random::<f32>() < t.loose_cover;
            let turn = if rng.random::<bool>() {
                0.0
            } else {
                std::f32::consts::PI
            };
            let spin = turn + rng.random_range(-0.08..0.08);
            let shift = if cover_off { -0.05 } else { 0.0 };
            let place = at.transform_point3(Vec3::new(shift, side, floor));
            let to_world = lying(motor, yaw + spin, place);
            let hidden = |kind| inside(kind, cover_off);
            scene.motor(k, motor, &to_world, hidden, &config.wear, rng);
            first_pose.get_or_insert(to_world);
            if cover_off {
                // the cover lies beside it, at the carrier's free end
                let cover = motor.parts.iter().find(|p| p.kind == PartKind::Cover);
                if let Some(cover) = cover {
                    let spot = at.transform_point3(Vec3::new(0.13, side, floor));
                    let turn = flat(cover, yaw + rng.random_range(0.0..TAU), rng);
                    let to_world = set_down(&cover.mesh.bounds(), turn, spot);
                    let prefix = format!("motor_{k}_");
                    scene.part(
                        motor,
                        cover,
                        &to_world,
                        Kind::Loose,
                        (&prefix, &config.wear),
                        rng,
                    );
                }
            }
        }
    }
    distractors(&mut scene, t, length, rng);
    // the floor, the scene's first object, in the table's look
    let centre = Vec3::new(0.0, 0.0, CARRIER.z / 2.0);
    let pose = first_pose.unwrap_or(Affine3A::IDENTITY);
    Ok(scene.cell(centre, pose, &config.table, rng))
}

/// The floor, and a roller conveyor `length` long along x: rollers, two side profiles, four
/// legs.
fn conveyor(scene: &mut Objects, length: f32) {
    scene.add(
        "floor".into(),
        cuboid(
            Vec3::new(-4.0, -4.0, -HEIGHT - 0.02),
            Vec3::new(4.0, 4.0, -HEIGHT),
        ),
        MATTE_GREY,
        Kind::Background,
    );
    let rollers = (length / ROLLER_PITCH) as usize;
    for r in 0..rollers {
        let x = -length / 2.0 + ROLLER_PITCH * (r as f32 + 0.5);
        let (a, b) = (
            Vec3::new(x, -WIDTH / 2.0, -ROLLER),
            Vec3::new(x, WIDTH / 2.0, -ROLLER),
        );
        let mesh = cylinder(a, b, ROLLER, 16);
        scene.add(
            format!("roller_{}", r + 1),
            mesh,
            ZINC_PLATED_STEEL,
            Kind::Background,
        );
    }
    for (name, side) in [("profile_left", -1.0f32), ("profile_right", 1.0)] {
        let y = side * (WIDTH / 2.0 + 0.02);
        let mesh = cuboid(
            Vec3::new(-length / 2.0, y - 0.02, -0.12),
            Vec3::new(length / 2.0, y + 0.02, 0.02),
        );
        scene.add(name.into(), mesh, PROFILE, Kind::Background);
        for (k, x) in [-1.0f32, 1.0].into_iter().enumerate() {
            let x = x * (length / 2.0 - 0.05);
            let leg = cuboid(
                Vec3::new(x - 0.02, y - 0.02, -HEIGHT),
                Vec3::new(x + 0.02, y + 0.02, -0.12),
            );
            scene.add(
                format!("{name}_leg_{}", k + 1),
                leg,
                PROFILE,
                Kind::Background,
            );
        }
    }
}

/// Boxes and cylinders of random sizes and colours on the floor beside the conveyor.
fn distractors(scene: &mut Objects, t: &TransferConfig, length: f32, rng: &mut impl Rng) {
    let count = rng.random_range(t.distractors[0]..=t.distractors[1]);
    for i in 0..count {
        let x = rng.random_range(-length / 2.0 - 0.5..length / 2.0 + 0.5);
        let y = rng.random_range(0.45..1.2) * if rng.random::<bool>() { 1.0 } else { -1.0 };
        let at = Vec3::new(x, y, -HEIGHT);
        let material = paint(rng);
        let mesh = if rng.random::<bool>() {
            let half = Vec3::new(
                rng.random_range(0.03..0.2),
                rng.random_range(0.03..0.2),
                rng.random_range(0.03..0.3),
            );
            block(half, at, rng.random_range(0.0..TAU))
        } else {
            let radius = rng.random_range(0.03..0.12);
            let height = rng.random_range(0.05..0.6);
            cylinder(at, at + Vec3::Z * height, radius, 24)
        };
        scene.add(
            format!("distractor_{}", i + 1),
            mesh,
            material,
            Kind::Background,
        );
    }
}
