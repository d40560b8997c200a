//! The armature on its own: taken out of its motor and resting by its shaft on two V-blocks on
//! a table, its axis level, split into its surfaces (shaft, lamination stack, windings,
//! commutator), each an object of its own, worn as drawn.

use glam::{Affine3A, Vec3};
use motorgen::kernel::{Mesh, cuboid};
use motorgen::{Motor, PartKind};
use rand::{Rng, RngExt};
use sensor::materials::{LAMINATE, STAINLESS_STEEL};
use sensor::wear::{ArmatureSurface, Grain, Mask, Rust, Wear};

use super::place::Objects;
use super::{Cell, Kind, Object, armature};
use crate::config::CellConfig;

/// The surfaces in the order of their labels, with their objects' names.
const SURFACES: [(ArmatureSurface, &str); 4] = [
    (ArmatureSurface::Shaft, "shaft"),
    (ArmatureSurface::Laminations, "lamination_stack"),
    (ArmatureSurface::Windings, "windings"),
    (ArmatureSurface::Commutator, "commutator"),
];

/// Gap between the armature's lowest point and the table, m.
const CLEARANCE: f32 = 0.003;

/// Composes the bench with `motor`'s armature. Every random draw comes from `rng`, in a fixed
/// order.
pub fn bench(motor: &Motor, config: &CellConfig, rng: &mut impl Rng) -> Cell {
    let a = &config.armature;
    let mut scene = Objects::default();
    scene.add(
        "table".into(),
        cuboid(Vec3::new(-0.5, -0.5, -0.03), Vec3::new(0.5, 0.5, 0.0)),
        LAMINATE,
        Kind::Background,
    );
    let part = motor
        .parts
        .iter()
        .find(|p| p.kind == PartKind::Armature)
        .expect("every motor has an armature");
    let layout = motorgen::armature_layout(&motor.params);
    let radius = part.mesh.bounds().size().truncate().max_element() / 2.0;
    let axis = part.mesh.bounds().centre().truncate();
    // the motor's axis (z) along world x, turned about the vertical, the axis at the height
    // its widest radius needs
    let yaw = rng.random_range(0.0..std::f32::consts::TAU);
    let height = radius + CLEARANCE;
    let centre = part.mesh.bounds().centre();
    let to_world = Affine3A::from_translation(Vec3::new(0.0, 0.0, height))
        * Affine3A::from_rotation_z(yaw)
        * Affine3A::from_rotation_y(std::f32::consts::FRAC_PI_2)
        * Affine3A::from_translation(-axis.extend(centre.z));
    // V-blocks under the shaft's two ends
    let ends = part.mesh.bounds();
    let top = height - layout.shaft_radius;
    for (k, z) in [ends.min.z, ends.max.z].into_iter().enumerate() {
        let inward = if k == 0 { 0.006 } else { -0.006 };
        let at = to_world.transform_point3(Vec3::new(axis.x, axis.y, z + inward));
        let block = cuboid(Vec3::new(-0.005, -0.012, 0.0), Vec3::new(0.005, 0.012, top))
            .transformed(
                &(Affine3A::from_translation(at.with_z(0.0)) * Affine3A::from_rotation_z(yaw)),
            );
        scene.add(
            format!("v_block_{}", k + 1),
            block,
            STAINLESS_STEEL,
            Kind::Background,
        );
    }
    let worn = a.worn.sample(rng);
    let seed = rng.random::<u32>() & 0xffff;
    let whole =
        armature(motor, &to_world, Kind::Loose, worn, seed).expect("every motor has an armature");
    let rust = Rust::new(rng.random_range(1..=9)).expect("rust types 1 to 9");
    let (share, dust, grease) = (a.rust.sample(rng), a.dust.sample(rng), a.grease.sample(rng));
    let offset = Vec3::new(rng.random(), rng.random(), rng.random()) * 100.0;
    for (surface, mesh) in split(&whole) {
        let wear = whole.wear.expect("the armature's surfaces are textured");
        // rust on its steel only; the copper tarnishes otherwise ([`Armature`]'s bars)
        let steel = matches!(
            surface,
            ArmatureSurface::Shaft | ArmatureSurface::Laminations
        );
        let wear = Wear {
            texture: Affine3A::from_translation(offset) * wear.texture,
            mask: Mask::Coverage {
                share: if steel { share } else { 0.0 },
            },
            rust,
            dust,
            grease,
            ..wear
        };
        let name = SURFACES.iter().find(|s| s.0 == surface).map_or("", |s| s.1);
        scene.push(Object {
            name: name.into(),
            part: Some(PartKind::Armature),
            kind: Kind::Surface(surface),
            instance: 0,
            mesh,
            pose: to_world,
            material: whole.material,
            wear: Some(wear),
        });
    }
    let look_at = to_world.transform_point3(centre);
    scene.cell(look_at, to_world, &config.table, rng)
}

/// The armature's triangles by the surface their centres lie on, each a mesh of its own (its
/// vertices those its triangles use), in label order.
fn split(armature: &Object) -> Vec<(ArmatureSurface, Mesh)> {
    let Some(Wear {
        texture,
        grain: Grain::Armature(a),
        ..
    }) = armature.wear
    else {
        return Vec::new();
    };
    let mesh = &armature.mesh;
    SURFACES
        .iter()
        .filter_map(|&(surface, _)| {
            let mut index = vec![u32::MAX; mesh.positions.len()];
            let mut out = Mesh::default();
            for t in &mesh.triangles {
                let [p, q, r] = t.map(|i| mesh.positions[i as usize]);
                if a.surface(texture.transform_point3((p + q + r) / 3.0)) != surface {
                    continue;
                }
                out.triangles.push(t.map(|i| {
                    let slot = &mut index[i as usize];
                    if *slot == u32::MAX {
                        *slot = out.positions.len() as u32;
                        out.positions.push(mesh.positions[i as usize]);
                    }
                    *slot
                }));
            }
            (!out.triangles.is_empty()).then_some((surface, out))
        })
        .collect()
}
