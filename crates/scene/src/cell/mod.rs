//! The scenes a sample's camera looks at, every object a labelled, closed mesh in world
//! coordinates (z up): the disassembly station's work cell (`station`: a table, the clamp
//! fixture and the motor in it, lying cover up or standing, with optional mask panels; table top
//! z = 0), carriers on a roller conveyor's transfer unit (`transfer`), motors and the parts
//! taken off them on a table (`handling`), an armature on its own (`bench`) and the hall a
//! mobile robot's LiDAR scans (`hall`).

mod bench;
mod hall;
mod handling;
mod place;
mod station;
mod transfer;

use glam::{Affine3A, Vec2, Vec3};
use motorgen::kernel::{Aabb, Extrusion, Mesh, extrude};
use motorgen::{Motor, Part, PartKind, Scheme};
use rand::{Rng, RngExt};
use sensor::materials::{
    BLACK_PA66, COPPER, FERRITE, GREY_PLASTIC, LAMINATE, STAINLESS_STEEL, WHITE_PLASTIC,
    ZINC_PLATED_STEEL,
};
use sensor::wear::{Armature, ArmatureSurface, Grain, Mask, Rust, Seats, Wear};
use sensor::{Classes, Material, Target};
use serde::{Deserialize, Serialize};

use crate::config::{Clamping, TableConfig, WearConfig, WearMask};

pub use bench::bench;
pub use hall::{AISLE, SLOT, hall, slots_per_side};
pub use handling::handling;
pub use station::compose;
pub(crate) use station::turned_with_motor;
pub use transfer::transfer_unit;

/// What an object is to the label schemes of whole objects (`objects9`) and of the armature's
/// surfaces (`armature5`), beside the motor part it may be.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A part of an assembled motor; the whole motor is instance `motor` under `objects9`.
    Assembled {
        /// The whole motor's instance id.
        motor: u32,
    },
    /// A motor part taken off its motor.
    Loose,
    /// One surface of an armature on its own (0 shaft, 1 lamination stack, 2 windings,
    /// 3 commutator).
    Surface(ArmatureSurface),
    /// A workpiece carrier or a small load carrier.
    Carrier,
    /// The rest: tables, fixtures, conveyors, panels, distractors.
    Background,
}

/// One object of the cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Name, e.g. `cover_bolt_2`, `sliding_jaw`, `panel_1`.
    pub name: String,
    /// The motor part it is, or `None` for background (table, fixture, panels).
    pub part: Option<PartKind>,
    /// What it is to the schemes of whole objects and surfaces.
    pub kind: Kind,
    /// Instance id: in the station, the motor's part instances first, then the background
    /// objects; in the other scenes, objects in order.
    pub instance: u32,
    /// Closed mesh in world coordinates, m.
    pub mesh: Mesh,
    /// Its model's frame to world: a motor part's the motor's frame, a carrier's the frame it
    /// was built in (the mesh is the model moved by it); the world's for background.
    pub pose: Affine3A,
    /// What the sensor's noise models read.
    pub material: Material,
    /// Rust on it, if any.
    pub wear: Option<Wear>,
}

impl Object {
    /// Its label under `scheme`.
    pub fn class(&self, scheme: Scheme) -> u8 {
        match (self.kind, self.part) {
            (Kind::Assembled { .. }, Some(k)) => scheme.assembled(k),
            (Kind::Surface(s), _) => scheme.armature_surface(s as usize),
            (Kind::Carrier, _) => scheme.carrier(),
            (_, Some(k)) => scheme.id(k),
            (_, None) => 0,
        }
    }

    /// Its instance id under `scheme`: the whole motor's for a part of an assembled motor
    /// under `objects9`, its own otherwise.
    pub fn instance_in(&self, scheme: Scheme) -> u32 {
        match self.kind {
            Kind::Assembled { motor } if scheme.whole_motors() => motor,
            _ => self.instance,
        }
    }

    /// Motor part `p` as an object of `kind`, its mesh moved by `to_world`, of its part's
    /// material.
    pub fn part(p: &Part, to_world: &Affine3A, kind: Kind) -> Object {
        Object {
            name: p.name.clone(),
            part: Some(p.kind),
            kind,
            instance: p.instance,
            mesh: p.mesh.clone().transformed(to_world),
            pose: *to_world,
            material: material(p.kind),
            wear: None,
        }
    }
}

/// Wear drawn for part `p` of `motor` (motor frame to world `to_world`) by `config`: its
/// material varied within its range, its grain, and rust (bolts, pole pot, electric connection,
/// the gear container's screws' seats), dust and grease with the part's [`texture`] coordinates, shifted at random by up to 100 units under coverage masks so
/// that no two parts wear alike.
fn draw_wear(
    p: &Part,
    motor: &Motor,
    to_world: &Affine3A,
    config: &WearConfig,
    material: &mut Material,
    rng: &mut impl Rng,
) -> Option<Wear> {
    let v = config.variation;
    if v > 0.0 {
        let scale = rng.random_range(1.0 - v..=1.0 + v);
        material.colour = material.colour.map(|c| (c * scale).min(1.0));
        material.reflectivity = (material.reflectivity * scale).min(1.0);
        let shift = rng.random_range(-v / 2.0..=v / 2.0);
        material.roughness = (material.roughness + shift).clamp(0.0, 1.0);
    }
    let share = config.span(p.kind).map_or(0.0, |s| s.sample(rng));
    let (dust, grease) = (config.dust.sample(rng), config.grease.sample(rng));
    let rust = Rust::new(rng.random_range(config.rust[0]..=config.rust[1]))?;
    let (mask, offset) = match config.mask {
        WearMask::Coverage => {
            let offset = Vec3::new(rng.random(), rng.random(), rng.random()) * 100.0;
            (Mask::Coverage { share }, offset)
        }
        WearMask::Addon => {
            // the add-on's divisor of the percent, by the percent
            let percent = 100.0 * share;
            let divisor = match percent {
                x if x < 50.0 => rng.random_range(250..280),
                x if x <= 95.0 => rng.random_range(300..400),
                _ => rng.random_range(280..300),
            };
            let threshold = percent / divisor as f32;
            (Mask::Addon { threshold }, Vec3::ZERO)
        }
    };
    let texture = Affine3A::from_translation(offset) * texture(p, to_world);
    // a housing rusts only at its screws' seats: about its bolts' heads
    let seats = (p.kind == PartKind::GearContainer).then(|| {
        let heads: Vec<Vec3> = motor
            .attributes
            .bolts
            .iter()
            .map(|b| texture.transform_point3(to_world.transform_point3(b.head_centre)))
            .collect();
        Seats::new(&heads, SEAT_RADIUS_CM)
    });
    let grain = match p.kind {
        _ if !config.grain => Grain::None,
        PartKind::PolePot => Grain::Drawn,
        PartKind::GearContainer
        | PartKind::Cover
        | PartKind::ElectricConnection
        | PartKind::LowerGear
        | PartKind::UpperGear
        | PartKind::SingleGear => Grain::Moulded,
        _ => Grain::None,
    };
    (share > 0.0 || dust > 0.0 || grease > 0.0 || grain != Grain::None).then_some(Wear {
        texture,
        mask,
        rust,
        dust,
        grease,
        seats,
        grain,
    })
}

/// The armature of `motor` (motor frame to world `to_world`) as an object of `kind`: its shaft,
/// lamination stack, windings and commutator each its own material and texture (the windings'
/// the add-on's), `worn` of the commutator's bars worn dark (which, by `seed`).
pub fn armature(
    motor: &Motor,
    to_world: &Affine3A,
    kind: Kind,
    worn: f32,
    seed: u32,
) -> Option<Object> {
    let p = motor.parts.iter().find(|p| p.kind == PartKind::Armature)?;
    let a = motorgen::armature_layout(&motor.params);
    let texture = texture(p, to_world);
    let to_texture = texture * *to_world;
    let at = |z: f32| to_texture.transform_point3(Vec3::new(0.0, 0.0, z));
    let units = to_texture.transform_vector3(Vec3::X).length();
    let axis = at(0.0);
    let surfaces = Armature {
        axis: [axis.x, axis.y],
        shaft_radius: a.shaft_radius * units,
        core_radius: a.core_radius * units,
        core: a.core.map(|z| at(z).z),
        commutator: a.commutator.map(|z| at(z).z),
        bars: a.coils,
        worn,
        seed,
    };
    Some(Object {
        wear: Some(Wear::clean(texture, Grain::Armature(surfaces))),
        ..Object::part(p, to_world, kind)
    })
}

/// Radius of a screw's seat about its bolt's head, in the housing's texture units (cm).
const SEAT_RADIUS_CM: f32 = 0.8;

/// World to part `p`'s texture coordinates (motor frame to world `to_world`): the add-on's
/// object coordinates, centimetres about the part's centre, millimetres on bolts (the add-on
/// scales its bolts by 0.1).
pub fn texture(p: &Part, to_world: &Affine3A) -> Affine3A {
    let units = match p.kind {
        PartKind::SideBolt | PartKind::CoverBolt => 1000.0,
        _ => 100.0,
    };
    Affine3A::from_scale(Vec3::splat(units))
        * Affine3A::from_translation(-p.mesh.bounds().centre())
        * to_world.inverse()
}

/// A composed cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// Every object.
    pub objects: Vec<Object>,
    /// Motor frame to world.
    pub motor_to_world: Affine3A,
    /// Centre of the motor's bounding box at its nominal pose (before jitter), world: the point
    /// cameras look at and crop boxes are centred on.
    pub motor_centre: Vec3,
    /// Fixture parts and how far each moved from rest, m.
    pub fixture: Vec<(String, Vec3)>,
    /// How the motor lies in the fixture.
    pub clamping: Clamping,
}

/// What varies between cells besides the motor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Variation {
    /// Mask panels present.
    pub occluders: bool,
    /// Fixture parts shifted.
    pub fixture_shift: bool,
    /// Cover and cover bolts removed.
    pub cover_removed: bool,
    /// How the motor lies in the fixture.
    pub clamping: Clamping,
}

/// The table's laminate in a colour and roughness drawn by `config`.
fn table_material(config: &TableConfig, rng: &mut impl Rng) -> Material {
    let [lo, hi] = config.colour.map(Vec3::from);
    let share: f32 = rng.random();
    let tint = Vec3::new(rng.random(), rng.random(), rng.random());
    let t = Vec3::splat(share) * (1.0 - config.tint) + tint * config.tint;
    Material {
        colour: (lo + (hi - lo) * t).to_array(),
        roughness: config.roughness.sample(rng),
        ..LAMINATE
    }
}

fn corners(b: &Aabb) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    })
}

/// The box of `b` moved by `t`.
pub fn transform_box(b: &Aabb, t: &Affine3A) -> Aabb {
    corners(b).iter().fold(Aabb::EMPTY, |acc, &c| {
        let p = t.transform_point3(c);
        acc.union(Aabb { min: p, max: p })
    })
}

impl Cell {
    /// The sensor's targets, labelled with `scheme` (background objects 0).
    pub fn targets(&self, scheme: Scheme) -> Vec<Target> {
        self.objects
            .iter()
            .map(|o| Target {
                positions: o.mesh.positions.clone(),
                triangles: o.mesh.triangles.clone(),
                classes: Classes::Uniform(u16::from(o.class(scheme))),
                instance: o.instance_in(scheme),
                material: o.material,
                wear: o.wear,
            })
            .collect()
    }
}

/// The sensor material of a motor part: the depth model's reflectivity and specular lobe of its
/// real material (the pole pot stainless steel and the bolts zinc-plated, specular; the gear
/// container and the cover one black plastic, so that colour does not tell the two apart; the
/// armature's windings copper), its colour, metalness, roughness and specular level the
/// add-on's (`PartKind::material`).
pub fn material(kind: PartKind) -> Material {
    let depth = match kind {
        PartKind::PolePot => STAINLESS_STEEL,
        PartKind::SideBolt | PartKind::CoverBolt => ZINC_PLATED_STEEL,
        PartKind::GearContainer | PartKind::Cover => BLACK_PA66,
        PartKind::ElectricConnection => GREY_PLASTIC,
        PartKind::Magnet => FERRITE,
        PartKind::Armature => COPPER,
        PartKind::LowerGear | PartKind::UpperGear | PartKind::SingleGear => WHITE_PLASTIC,
    };
    let look = kind.material();
    let [r, g, b, _] = look.base_color;
    Material {
        colour: [r, g, b],
        metallic: look.metallic,
        roughness: look.roughness,
        ior_level: look.specular,
        ..depth
    }
}

/// A closed cylinder of `radius` from `a` to `b`, `n` sides.
pub(crate) fn cylinder(a: Vec3, b: Vec3, radius: f32, n: usize) -> Mesh {
    let d = b - a;
    let outer = motorgen::kernel::circle(Vec2::ZERO, radius, n, 0.0);
    let mesh = extrude(&Extrusion {
        outer,
        z0: 0.0,
        z1: d.length(),
        ..Extrusion::default()
    });
    let rotation = glam::Quat::from_rotation_arc(Vec3::Z, d.normalize());
    mesh.transformed(&Affine3A::from_rotation_translation(rotation, a))
}
