//! The disassembly station's work cell: a table, the clamp fixture and the motor in it (lying
//! cover up, or standing), with optional mask panels.

use glam::{Affine3A, EulerRot, Mat3, Vec3};
use motorgen::kernel::{Aabb, Mesh, cuboid};
use motorgen::{Motor, PartKind};
use rand::{Rng, RngExt};
use sensor::Material;
use sensor::materials::{LAMINATE, MATTE_GREY};

use super::{Cell, Kind, Object, Variation, draw_wear, table_material, transform_box};
use crate::config::{CellConfig, Clamping, Shift};
use crate::fixture::{Fixture, fixture};

/// Thickness of the base plate, m.
const PLATE: f32 = 0.012;

/// The rotation that clamps a motor. Lying (`GearContainerUp`): its axis (motor +z) along world
/// +x and its gear axis (out of the cover) along world +z. Standing (`PolePotUp`): its axis
/// vertical with the pole pot's end up and the gear axis along world +x.
pub(super) fn orientation(motor: &Motor, clamping: Clamping) -> Mat3 {
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

/// `b` turned as the motor turns from lying (gear container up) into `clamping`, about
/// `centre`, the motor's centre (the nominal turn, without the pose jitter).
pub(crate) fn turned_with_motor(b: &Aabb, motor: &Motor, clamping: Clamping, centre: Vec3) -> Aabb {
    let lying = orientation(motor, Clamping::GearContainerUp);
    let turn = Affine3A::from_mat3(orientation(motor, clamping) * lying.transpose());
    let about = Affine3A::from_translation(centre) * turn * Affine3A::from_translation(-centre);
    transform_box(b, &about)
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
            let mut o = Object::part(p, &motor_to_world, Kind::Assembled { motor: 0 });
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
            kind: Kind::Background,
            instance: next,
            mesh,
            pose: Affine3A::IDENTITY,
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
    // the whole motor: the instance after the cell's objects
    for o in &mut objects {
        if let Kind::Assembled { motor } = &mut o.kind {
            *motor = next;
        }
    }
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
