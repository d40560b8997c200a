//! The remanufacturing hall a mobile robot drives through with a LiDAR: a concrete floor (its
//! top z = 0) and four walls; along both sides of a central aisle, station modules (the
//! station's table on legs under a frame, the clamp fixture and a motor in it), transfer units
//! (roller conveyors with carriers holding motors) and shelving racks with small load carriers;
//! the aisle itself kept clear for the robot, which drives along x at y = 0.

use std::f32::consts::PI;

use glam::{Affine3A, Vec3};
use motorgen::Motor;
use motorgen::kernel::cuboid;
use rand::seq::SliceRandom;
use rand::{Rng, RngExt};
use sensor::Material;
use sensor::materials::MATTE_GREY;

use super::place::{Objects, motor_k};
use super::transfer::{CARRIER, HEIGHT as CONVEYOR_HEIGHT, KLT_BLUE, KLT_GREY, open_box};
use super::{Cell, Kind, Variation, compose, transfer_unit};
use crate::config::{CellConfig, Clamping};
use crate::error::Result;

/// Width of the aisle kept clear along the hall's x axis, m.
pub const AISLE: f32 = 2.0;
/// Length of a slot along the aisle that holds one station, transfer unit or rack, m.
pub const SLOT: f32 = 3.6;
/// Height of the walls, m.
const WALL_HEIGHT: f32 = 4.0;
/// Height of a station's table top above the floor, m.
const TABLE_HEIGHT: f32 = 0.9;
/// A rack's length, depth and shelves' heights, m.
const RACK: Vec3 = Vec3::new(2.7, 0.6, 2.0);
const SHELVES: [f32; 4] = [0.1, 0.6, 1.1, 1.6];

/// Power-floated concrete.
const CONCRETE: Material = Material {
    colour: [0.33, 0.32, 0.3],
    reflectivity: 0.3,
    roughness: 0.7,
    ..MATTE_GREY
};
/// White wall paint.
const WALL_PAINT: Material = Material {
    colour: [0.8, 0.8, 0.78],
    reflectivity: 0.75,
    roughness: 0.9,
    ..MATTE_GREY
};
/// Blue powder-coated steel of racks and station frames.
const POWDER_COAT: Material = Material {
    colour: [0.05, 0.15, 0.45],
    reflectivity: 0.2,
    roughness: 0.5,
    ..MATTE_GREY
};

/// What stands in one slot beside the aisle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Module {
    Station,
    TransferUnit,
    Rack,
}

/// The number of slots on each side of the aisle of a hall `length` long.
pub fn slots_per_side(length: f32) -> usize {
    ((length - 2.0) / SLOT).max(0.0) as usize
}

/// Composes the hall, its modules' motors `first` and those `more` builds (the k-th, from 1).
/// Every random draw comes from `rng`, in a fixed order.
///
/// # Errors
///
/// Those of `more`.
pub fn hall(
    first: &Motor,
    more: &dyn Fn(usize) -> Result<Motor>,
    config: &CellConfig,
    rng: &mut impl Rng,
) -> Result<Cell> {
    let h = &config.hall;
    let [length, width] = h.size;
    let mut scene = Objects::default();
    scene.add(
        "floor".into(),
        cuboid(
            Vec3::new(-length / 2.0, -width / 2.0, -0.1),
            Vec3::new(length / 2.0, width / 2.0, 0.0),
        ),
        CONCRETE,
        Kind::Background,
    );
    let (x, y, t) = (length / 2.0, width / 2.0, 0.2);
    for (name, min, max) in [
        (
            "wall_north",
            Vec3::new(-x - t, y, 0.0),
            Vec3::new(x + t, y + t, WALL_HEIGHT),
        ),
        (
            "wall_south",
            Vec3::new(-x - t, -y - t, 0.0),
            Vec3::new(x + t, -y, WALL_HEIGHT),
        ),
        (
            "wall_east",
            Vec3::new(x, -y, 0.0),
            Vec3::new(x + t, y, WALL_HEIGHT),
        ),
        (
            "wall_west",
            Vec3::new(-x - t, -y, 0.0),
            Vec3::new(-x, y, WALL_HEIGHT),
        ),
    ] {
        scene.add(name.into(), cuboid(min, max), WALL_PAINT, Kind::Background);
    }
    let count = |c: [u32; 2], rng: &mut _| RngExt::random_range(rng, c[0]..=c[1]) as usize;
    let mut modules = vec![Module::Station; count(h.stations, rng)];
    modules.extend(vec![Module::TransferUnit; count(h.transfer_units, rng)]);
    modules.extend(vec![Module::Rack; count(h.racks, rng)]);
    let per_side = slots_per_side(length);
    let mut slots: Vec<usize> = (0..2 * per_side).collect();
    slots.shuffle(rng);
    let mut motors = 0;
    for (n, (&module, &slot)) in modules.iter().zip(&slots).enumerate() {
        // slot s: side s % 2 (north, south), place s / 2 along the aisle; facing the aisle
        let side = if slot % 2 == 0 { 1.0 } else { -1.0 };
        let along = -(per_side as f32) * SLOT / 2.0 + SLOT * ((slot / 2) as f32 + 0.5);
        let x = along + rng.random_range(-0.2..0.2);
        let yaw = if side > 0.0 { 0.0 } else { PI } + rng.random_range(-0.03..0.03);
        let prefix = format!("module_{}_", n + 1);
        match module {
            Module::Station => {
                let motor = motor_k(first, more, motors)?;
                motors += 1;
                let vary = Variation {
                    occluders: false,
                    fixture_shift: true,
                    cover_removed: false,
                    clamping: Clamping::GearContainerUp,
                };
                let cell = compose(&motor, config, vary, rng);
                let depth = AISLE / 2.0 + 0.6 + rng.random_range(0.3..0.8);
                let pose = Affine3A::from_translation(Vec3::new(x, side * depth, TABLE_HEIGHT))
                    * Affine3A::from_rotation_z(yaw);
                scene.merge(cell, &pose, &prefix);
                station_frame(&mut scene, &pose, &prefix);
            }
            Module::TransferUnit => {
                let first = motor_k(first, more, motors)?;
                let from = motors;
                let cell = transfer_unit(&first, &|k| more(from + k), config, rng)?;
                // the motors it placed, of the hall's from `from` on
                motors += cell
                    .objects
                    .iter()
                    .filter_map(|o| match o.kind {
                        Kind::Assembled { motor } => Some(motor),
                        _ => None,
                    })
                    .collect::<std::collections::BTreeSet<_>>()
                    .len();
                // its distractors lie up to 1.4 m off the conveyor's axis
                let depth = AISLE / 2.0 + 1.5 + rng.random_range(0.0..0.4);
                let pose = Affine3A::from_translation(Vec3::new(x, side * depth, CONVEYOR_HEIGHT))
                    * Affine3A::from_rotation_z(yaw);
                // the hall's floor replaces the transfer unit's
                let mut cell = cell;
                cell.objects.retain(|o| o.name != "floor");
                scene.merge(cell, &pose, &prefix);
            }
            Module::Rack => {
                let depth = AISLE / 2.0 + RACK.y / 2.0 + rng.random_range(0.1..0.6);
                let pose = Affine3A::from_translation(Vec3::new(x, side * depth, 0.0))
                    * Affine3A::from_rotation_z(yaw);
                rack(&mut scene, &pose, &prefix, rng);
            }
        }
    }
    let centre = Vec3::new(0.0, 0.0, 1.0);
    let first_motor = scene
        .list
        .iter()
        .find(|o| matches!(o.kind, Kind::Assembled { .. }))
        .map_or(Affine3A::IDENTITY, |o| o.pose);
    Ok(Cell {
        objects: scene.list,
        motor_to_world: first_motor,
        motor_centre: centre,
        fixture: Vec::new(),
        clamping: Clamping::GearContainerUp,
    })
}

/// A station module's frame (its table at `pose`, top at the pose's origin): four legs under
/// the table's corners, two posts at its back and a beam across them.
fn station_frame(scene: &mut Objects, pose: &Affine3A, prefix: &str) {
    let (half, post) = (0.6 - 0.03, 0.03);
    let below = -TABLE_HEIGHT;
    for (k, (sx, sy)) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        let c = Vec3::new(sx * half, sy * half, 0.0);
        let leg = cuboid(
            c + Vec3::new(-post, -post, below),
            c + Vec3::new(post, post, -0.02),
        );
        scene.add_at(
            format!("{prefix}leg_{}", k + 1),
            leg,
            pose,
            POWDER_COAT,
            Kind::Background,
        );
    }
    // the back: the side away from the aisle (+y before the pose turns it)
    for (k, sx) in [-1.0, 1.0].into_iter().enumerate() {
        let c = Vec3::new(sx * half, half + 2.0 * post, 0.0);
        let upright = cuboid(
            c + Vec3::new(-post, -post, 0.0),
            c + Vec3::new(post, post, 1.2),
        );
        scene.add_at(
            format!("{prefix}post_{}", k + 1),
            upright,
            pose,
            POWDER_COAT,
            Kind::Background,
        );
    }
    let beam = cuboid(
        Vec3::new(-half - post, half + post, 1.15),
        Vec3::new(half + post, half + 3.0 * post, 1.25),
    );
    scene.add_at(
        format!("{prefix}beam"),
        beam,
        pose,
        POWDER_COAT,
        Kind::Background,
    );
}

/// A shelving rack at `pose` (its footprint centred on the pose's origin, long along x):
/// four uprights, its shelves, and on each shelf up to four small load carriers.
fn rack(scene: &mut Objects, pose: &Affine3A, prefix: &str, rng: &mut impl Rng) {
    let (x, y, post) = (RACK.x / 2.0, RACK.y / 2.0, 0.04);
    for (k, (sx, sy)) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
        .into_iter()
        .enumerate()
    {
        let c = Vec3::new(sx * (x - post), sy * (y - post), 0.0);
        let upright = cuboid(
            c + Vec3::new(-post, -post, 0.0),
            c + Vec3::new(post, post, RACK.z),
        );
        scene.add_at(
            format!("{prefix}upright_{}", k + 1),
            upright,
            pose,
            POWDER_COAT,
            Kind::Background,
        );
    }
    for (k, &z) in SHELVES.iter().enumerate() {
        let shelf = cuboid(Vec3::new(-x, -y, z - 0.03), Vec3::new(x, y, z));
        scene.add_at(
            format!("{prefix}shelf_{}", k + 1),
            shelf,
            pose,
            POWDER_COAT,
            Kind::Background,
        );
        let carriers = rng.random_range(0..=4usize);
        for c in 0..carriers {
            let at = Vec3::new(
                -x + 0.3 + 0.65 * c as f32 + rng.random_range(-0.05..0.05),
                rng.random_range(-0.05..0.05),
                z,
            );
            // along the rack: the KLT's short side faces the aisle
            let turn = Affine3A::from_translation(at)
                * Affine3A::from_rotation_z(PI / 2.0 + rng.random_range(-0.05..0.05));
            let colour = if rng.random::<bool>() {
                KLT_BLUE
            } else {
                KLT_GREY
            };
            let name = format!("{prefix}shelf_{}_carrier_{}", k + 1, c + 1);
            scene.add_at(
                name,
                open_box(CARRIER),
                &(*pose * turn),
                colour,
                Kind::Carrier,
            );
        }
    }
}
