//! The handling table: whole motors lying on their side and the parts taken off other motors
//! (covers, bolts, gears, armatures, gear containers, pole pots) lying flat on a table, some on
//! what lies below them, some against the one before.

use std::f32::consts::TAU;

use glam::{Affine3A, Vec3};
use motorgen::kernel::cuboid;
use motorgen::{Motor, Part, PartKind};
use rand::{Rng, RngExt};
use sensor::materials::LAMINATE;

use super::place::{Objects, flat, inside, lying, motor_k, set_down};
use super::{Cell, Kind, transform_box};
use crate::config::CellConfig;
use crate::error::Result;

/// The parts that are taken off a motor and laid down.
fn takes_off(kind: PartKind) -> bool {
    kind != PartKind::Magnet && kind != PartKind::ElectricConnection
}

/// Composes the handling table: motor `first` and those `more` builds (the k-th, from 1)
/// whole, then parts of further motors. Every random draw comes from `rng`, in a fixed order.
///
/// # Errors
///
/// Those of `more`.
pub fn handling(
    first: &Motor,
    more: &dyn Fn(usize) -> Result<Motor>,
    config: &CellConfig,
    rng: &mut impl Rng,
) -> Result<Cell> {
    let h = &config.handling;
    let mut scene = Objects::default();
    scene.add(
        "table".into(),
        cuboid(Vec3::new(-0.8, -0.8, -0.03), Vec3::new(0.8, 0.8, 0.0)),
        LAMINATE,
        Kind::Background,
    );
    let spot = |rng: &mut dyn Rng| {
        let s = h.spread;
        Vec3::new(rng.random_range(-s..=s), rng.random_range(-s..=s), 0.0)
    };
    let whole = rng.random_range(h.motors[0]..=h.motors[1]).max(1) as usize;
    let mut first_pose = Affine3A::IDENTITY;
    for k in 0..whole {
        let motor = motor_k(first, more, k)?;
        // clear of the motors before it (a few tries)
        let yaw = rng.random_range(0.0..TAU);
        let size = transform_box(&motor.attributes.bounds, &lying(&motor, yaw, Vec3::ZERO)).size();
        let at = spot(rng);
        let at = scene.clear(at, size, || spot(rng));
        let to_world = lying(&motor, yaw, at);
        if k == 0 {
            first_pose = to_world;
        }
        let hidden = |kind| inside(kind, false);
        scene.motor(k, &motor, &to_world, hidden, &config.wear, rng);
    }
    let parts = rng.random_range(h.parts[0]..=h.parts[1]) as usize;
    let mut donor = None;
    for i in 0..parts {
        // a donor motor gives up to four parts
        if i % 4 == 0 {
            donor = Some(motor_k(first, more, whole + i / 4)?.into_owned());
        }
        let motor = donor.as_ref().expect("a donor for every part");
        let candidates: Vec<&Part> = motor.parts.iter().filter(|p| takes_off(p.kind)).collect();
        let p = candidates[rng.random_range(0..candidates.len())];
        let turn = flat(p, rng.random_range(0.0..TAU), rng);
        let size = transform_box(&p.mesh.bounds(), &turn).size();
        let previous = scene.list.last().map(|o| o.mesh.bounds());
        let mut at = spot(rng);
        if let Some(b) = previous.filter(|_| rng.random::<f32>() < h.touch) {
            // against the last object, on the side away from the centre
            let side = if b.centre().x >= 0.0 { 1.0 } else { -1.0 };
            let reach = (b.max.x - b.min.x + size.x) / 2.0 + 0.001;
            at = Vec3::new(b.centre().x + side * reach, b.centre().y, 0.0);
        }
        // on what lies below (the top of the boxes under its footprint), or on the table
        // where nothing does (a few tries)
        if rng.random::<f32>() >= h.stack {
            at = scene.clear(at, size, || spot(rng));
        }
        let below = scene.top(at, size);
        let to_world = set_down(&p.mesh.bounds(), turn, at.with_z(below + 0.0005));
        let prefix = format!("part_{}_", i + 1);
        scene.part(
            motor,
            p,
            &to_world,
            Kind::Loose,
            (&prefix, &config.wear),
            rng,
        );
    }
    let centre = Vec3::new(0.0, 0.0, 0.03);
    Ok(scene.cell(centre, first_pose, &config.table, rng))
}
