//! The work cell: a table, the clamp fixture and the motor in it (lying cover up, or standing),
//! with optional mask panels; every object a labelled, closed mesh in world coordinates (z up,
//! table top z = 0).

use glam::{Affine3A, EulerRot, Mat3, Vec2, Vec3};
use motorgen::kernel::{Aabb, Extrusion, Mesh, cuboid, extrude};
use motorgen::{Motor, Part, PartKind, Scheme};
use rand::{Rng, RngExt};
use sensor::materials::{
    BLACK_PA66, COPPER, FERRITE, GREY_PLASTIC, LAMINATE, MATTE_GREY, STAINLESS_STEEL,
    WHITE_PLASTIC, ZINC_PLATED_STEEL,
};
use sensor::wear::{Armature, Grain, Mask, Rust, Seats, Wear};
use sensor::{Classes, Material, Target};

use crate::config::{CellConfig, Clamping, Shift, TableConfig, WearConfig, WearMask};
use crate::fixture::{Fixture, fixture};

/// One object of the cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Name, e.g. `cover_bolt_2`, `sliding_jaw`, `panel_1`.
    pub name: String,
    /// The motor part it is, or `None` for background (table, fixture, panels).
    pub part: Option<PartKind>,
    /// Instance id: the motor's part instances first, then the background objects.
    pub instance: u32,
    /// Closed mesh in world coordinates, m.
    pub mesh: Mesh,
    /// What the sensor's noise models read.
    pub material: Material,
    /// Rust on it, if any.
    pub wear: Option<Wear>,
}

impl Object {
    /// Motor part `p` as an object, its mesh moved by `to_world`, of its part's material.
    pub fn part(p: &Part, to_world: &Affine3A) -> Object {
        Object {
            name: p.name.clone(),
            part: Some(p.kind),
            instance: p.instance,
            mesh: p.mesh.clone().transformed(to_world),
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

/// The armature of `motor` (motor frame to world `to_world`) as an object: its shaft, lamination
/// stack, windings and commutator each its own material and texture (the windings' the
/// add-on's).
pub fn armature(motor: &Motor, to_world: &Affine3A) -> Option<Object> {
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
    };
    Some(Object {
        wear: Some(Wear::clean(texture, Grain::Armature(surfaces))),
        ..Object::part(p, to_world)
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

/// Thickness of the base plate, m.
const PLATE: f32 = 0.012;

/// The rotation that clamps a motor. Lying (`GearContainerUp`): its axis (motor +z) along world
/// +x and its gear axis (out of the cover) along world +z. Standing (`PolePotUp`): its axis
/// vertical with the pole pot's end up and the gear axis along world +x.
fn orientation(motor: &Motor, clamping: Clamping) -> Mat3 {
    let axis = Vec3::Z;
    let gear = motor
        .attributes
        .gears
        .first()
        .map_or(Vec3::NEG_Y, |g| g.axis);
    // motor-frame axes that go to world x, y, z
    let (x, z) = match clamping {
        Clamping::GearContainerUp => (axis, gear),
        Clamping::PolePotUp => {
            let centre = |k: PartKind| {
                motor
                    .parts
                    .iter()
                    .find(|p| p.kind == k)
                    .map_or(Vec3::ZERO, |p| p.mesh.bounds().centre())
            };
            let up = (centre(PartKind::PolePot) - centre(PartKind::GearContainer)).z;
            (gear, if up >= 0.0 { axis } else { -axis })
        }
    };
    Mat3::from_cols(x, z.cross(x), z).transpose()
}

/// The part the fixture's jaws grip.
fn gripped(clamping: Clamping) -> PartKind {
    match clamping {
        Clamping::GearContainerUp => PartKind::PolePot,
        Clamping::PolePotUp => PartKind::GearContainer,
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

/// `b` turned as the motor turns from lying (gear container up) into `clamping`, about
/// `centre`, the motor's centre (the nominal turn, without the pose jitter).
pub(crate) fn turned_with_motor(b: &Aabb, motor: &Motor, clamping: Clamping, centre: Vec3) -> Aabb {
    let lying = orientation(motor, Clamping::GearContainerUp);
    let turn = Affine3A::from_mat3(orientation(motor, clamping) * lying.transpose());
    let about = Affine3A::from_translation(centre) * turn * Affine3A::from_translation(-centre);
    transform_box(b, &about)
}

/// The box of `b` moved by `t`.
pub fn transform_box(b: &Aabb, t: &Affine3A) -> Aabb {
    corners(b).iter().fold(Aabb::EMPTY, |acc, &c| {
        let p = t.transform_point3(c);
        acc.union(Aabb { min: p, max: p })
    })
}

fn draw(s: &Shift, rng: &mut impl Rng) -> Vec3 {
    Vec3::new(s[0].sample(rng), s[1].sample(rng), s[2].sample(rng))
}

/// Composes a cell around `motor`. Every random draw comes from `rng`, in a fixed order.
pub fn compose(motor: &Motor, config: &CellConfig, vary: Variation, rng: &mut impl Rng) -> Cell {
    let lay = Affine3A::from_mat3(orientation(motor, vary.clamping));
    let laid = transform_box(&motor.attributes.bounds, &lay);
    let c = laid.centre();
    let nominal =
        Affine3A::from_translation(Vec3::new(-c.x, -c.y, PLATE + config.clearance - laid.min.z))
            * lay;
    let motor_centre = nominal.transform_point3(motor.attributes.bounds.centre());
    let [jx, jy, jz] = config.pose_jitter_deg.map(|d| {
        let d = d.to_radians();
        if d > 0.0 {
            rng.random_range(-d..=d)
        } else {
            0.0
        }
    });
    let jitter = Affine3A::from_translation(motor_centre)
        * Affine3A::from_mat3(Mat3::from_euler(EulerRot::XYZ, jx, jy, jz))
        * Affine3A::from_translation(-motor_centre);
    let motor_to_world = jitter * nominal;

    let hidden = |k: PartKind| match k {
        PartKind::Magnet | PartKind::Armature => true,
        PartKind::Cover | PartKind::CoverBolt => vary.cover_removed,
        PartKind::LowerGear | PartKind::UpperGear | PartKind::SingleGear => !vary.cover_removed,
        _ => false,
    };
    let wear = &config.wear;
    let mut objects: Vec<Object> = motor
        .parts
        .iter()
        .filter(|p| !hidden(p.kind))
        .map(|p| {
            let mut o = Object::part(p, &motor_to_world);
            if wear.enabled() {
                o.wear = draw_wear(p, motor, &motor_to_world, wear, &mut o.material, rng);
            }
            o
        })
        .collect();

    let grip = gripped(vary.clamping);
    let held = motor
        .parts
        .iter()
        .find(|p| p.kind == grip)
        .map(|p| transform_box(&p.mesh.bounds(), &nominal))
        .expect("every motor has a pole pot and a gear container");
    let motor_box = transform_box(&motor.attributes.bounds, &nominal);
    let mut shift = |s: &Shift| {
        if vary.fixture_shift {
            draw(s, rng)
        } else {
            Vec3::ZERO
        }
    };
    let f = &config.fixture;
    let shifts = Fixture {
        fixed_jaw: shift(&f.fixed_jaw),
        sliding_jaw: shift(&f.sliding_jaw),
        pillar: shift(&f.pillar),
        cylinder: shift(&f.cylinder),
    };
    let mut next = motor.parts.iter().map(|p| p.instance).max().unwrap_or(0) + 1;
    let mut add = |objects: &mut Vec<Object>, name: String, mesh: Mesh, material: Material| {
        objects.push(Object {
            name,
            part: None,
            instance: next,
            mesh,
            material,
            wear: None,
        });
        next += 1;
    };
    add(
        &mut objects,
        "table".into(),
        cuboid(Vec3::new(-0.6, -0.6, -0.02), Vec3::new(0.6, 0.6, 0.0)),
        LAMINATE,
    );
    let table = objects.len() - 1;
    for (name, mesh, material) in fixture(&held, &motor_box, PLATE, &shifts) {
        add(&mut objects, name.into(), mesh, material);
    }
    if vary.occluders {
        let top = transform_box(&motor.attributes.bounds, &motor_to_world)
            .max
            .z;
        let gears = &motor.attributes.gears;
        let gearbox = gears.iter().map(|g| g.centre).sum::<Vec3>() / gears.len().max(1) as f32;
        let gearbox = motor_to_world.transform_point3(gearbox);
        let o = &config.occluders;
        let count = rng.random_range(o.count[0]..=o.count[1]);
        for i in 0..count {
            let (a, b) = (o.size.sample(rng) / 2.0, o.size.sample(rng) / 2.0);
            let spread = |rng: &mut _| {
                if o.spread > 0.0 {
                    RngExt::random_range(rng, -o.spread..=o.spread)
                } else {
                    0.0
                }
            };
            let centre = Vec3::new(
                gearbox.x + spread(rng),
                gearbox.y + spread(rng),
                top + o.height.sample(rng),
            );
            let tilt = o.tilt_deg.to_radians();
            let tilt = if tilt > 0.0 {
                rng.random_range(-tilt..=tilt)
            } else {
                0.0
            };
            let yaw = rng.random_range(0.0..std::f32::consts::TAU);
            let pose = Affine3A::from_translation(centre)
                * Affine3A::from_rotation_z(yaw)
                * Affine3A::from_rotation_x(tilt);
            let panel = cuboid(Vec3::new(-a, -b, -0.001), Vec3::new(a, b, 0.001));
            add(
                &mut objects,
                format!("panel_{}", i + 1),
                panel.transformed(&pose),
                MATTE_GREY,
            );
        }
    }
    // drawn last: the table's look leaves the draws before it alone
    objects[table].material = table_material(&config.table, rng);
    Cell {
        objects,
        motor_to_world,
        motor_centre,
        clamping: vary.clamping,
        fixture: [
            ("fixed_jaw", shifts.fixed_jaw),
            ("sliding_jaw", shifts.sliding_jaw),
            ("pillar", shifts.pillar),
            ("cylinder", shifts.sliding_jaw + shifts.cylinder),
        ]
        .map(|(n, s)| (n.to_string(), s))
        .into(),
    }
}

impl Cell {
    /// The sensor's targets, labelled with `scheme` (background objects 0).
    pub fn targets(&self, scheme: Scheme) -> Vec<Target> {
        self.objects
            .iter()
            .map(|o| Target {
                positions: o.mesh.positions.clone(),
                triangles: o.mesh.triangles.clone(),
                classes: Classes::Uniform(o.part.map_or(0, |k| scheme.id(k)) as u16),
                instance: o.instance,
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
