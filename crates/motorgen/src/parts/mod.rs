//! Part builders. They work in centimetres, the add-on's unit, so that its constants read as in
//! its source; [`build`] scales the finished motor to metres once.

mod body;

pub use body::ArmatureLayout;
mod bolt;
mod gearbox;
pub mod shapes;

use glam::{Affine3A, Vec3};
use rand::{Rng, SeedableRng};

use crate::kernel::{Aabb, Detail, Mesh};
use crate::model::{Attributes, BoltAttr, GearAttr, Motor, Part, PartAttr, PartKind};
use crate::params::{BoltOrientation, MotorParams, MotorType};
use shapes::{Tess, frame};

/// Metres per centimetre.
const M_PER_CM: f32 = 0.01;
/// How far a Torx side bolt's drive face lies inside the pole pot's top (as the add-on places it).
const SIDE_BOLT_SINK: f32 = 0.1771;

/// The parameters in centimetres.
pub(crate) struct Dims {
    sub: f32,
    bottom: f32,
    top: f32,
    lower_dia: f32,
    lower_pos: f32,
    upper_dia: f32,
    h1: f32,
    h2: f32,
    right_bolt: f32,
    motor_type: MotorType,
}

impl Dims {
    fn new(p: &MotorParams) -> Dims {
        let cm = |m: f32| m / M_PER_CM;
        Dims {
            sub: cm(p.shaft_boss_length),
            bottom: cm(p.pole_pot_length),
            top: cm(p.shaft_boss_length + p.pole_pot_length),
            lower_dia: cm(p.lower_gear_diameter),
            lower_pos: cm(p.lower_gear_position),
            upper_dia: cm(p.upper_gear_diameter),
            h1: cm(p.type_b_height_1),
            h2: cm(p.type_b_height_2),
            right_bolt: cm(p.type_b_right_bolt_height),
            motor_type: p.motor_type,
        }
    }

    /// Tops of the brush tower's four steps above the pot top (the add-on's C1..C4, summed).
    fn tower_steps(&self) -> [f32; 4] {
        let c = match self.motor_type {
            MotorType::A => [1.9, 2.7, 1.1, 0.8],
            MotorType::B => [1.9, 2.7, 0.5, 0.2],
        };
        [
            c[0],
            c[0] + c[1],
            c[0] + c[1] + c[2],
            c[0] + c[1] + c[2] + c[3],
        ]
    }

    fn tower_height(&self) -> f32 {
        self.tower_steps()[3]
    }
}

/// Where the armature of the motor of `params` has its shaft, lamination stack, windings and
/// commutator: in the motor frame (m), about its z axis.
pub fn armature_layout(params: &MotorParams) -> ArmatureLayout {
    let a = ArmatureLayout::new(&Dims::new(params));
    ArmatureLayout {
        shaft_radius: a.shaft_radius * M_PER_CM,
        core_radius: a.core_radius * M_PER_CM,
        core: a.core.map(|z| z * M_PER_CM),
        commutator_radius: a.commutator_radius * M_PER_CM,
        commutator: a.commutator.map(|z| z * M_PER_CM),
        coils: a.coils,
    }
}

/// Builds the motor of `params` at the given tessellation detail.
///
/// # Example
///
/// ```
/// use motorgen::{Detail, MotorParams, PartKind, build};
///
/// let params = MotorParams::from_values(
///     &[("type".to_string(), motorgen::params::Value::Text("B".into()))].into(),
/// )?;
/// let motor = build(&params, Detail::Coarse);
/// assert_eq!(motor.attributes.variant, "B1");
/// // type B has one inner gear, and its centre is exact ground truth
/// assert_eq!(motor.attributes.gears.len(), 1);
/// assert!(motor.parts.iter().any(|p| p.kind == PartKind::SingleGear));
/// # Ok::<(), motorgen::Error>(())
/// ```
pub fn build(params: &MotorParams, detail: Detail) -> Motor {
    let t = Tess(detail);
    let d = Dims::new(params);
    let gb = gearbox::Layout::new(params, &d);
    let out = gb.axis();
    let mut asm = Assembly::default();

    asm.add(PartKind::PolePot, body::pole_pot(t, &d), -6.0 * Vec3::Z);
    for (m, side) in body::magnets(t, &d).into_iter().zip([1.0, -1.0]) {
        asm.add(PartKind::Magnet, m, Vec3::new(0.0, 3.0 * side, -6.0));
    }
    asm.add(PartKind::Armature, body::armature(t, &d), -14.0 * Vec3::Z);
    asm.add(
        PartKind::ElectricConnection,
        body::electric_connection(t, &d),
        Vec3::new(0.0, -4.0, -2.0),
    );
    let mut container = body::collar_and_tower(t, &d);
    container.append(&gb.container(t, params, &d));
    asm.add(PartKind::GearContainer, container, Vec3::ZERO);
    asm.add(PartKind::Cover, gb.cover(t, params), 5.0 * out);

    let rotations = bolt_rotations(params, 2 + gb.bolts.len());
    let side_axis = Vec3::Z; // screwed up into the collar, head towards the pot
    for (k, p) in body::SIDE_BOLTS.iter().enumerate() {
        let head = p.extend(d.top - SIDE_BOLT_SINK + bolt::face_inset(params.bolt_drive));
        asm.add_bolt(
            t,
            params,
            PartKind::SideBolt,
            head,
            side_axis,
            rotations[k],
            -8.0 * Vec3::Z,
        );
    }
    for (k, b) in gb.bolts.iter().enumerate() {
        let head = gb.point(*b, gb.bolt_face - bolt::face_inset(params.bolt_drive));
        asm.add_bolt(
            t,
            params,
            PartKind::CoverBolt,
            head,
            -out,
            rotations[2 + k],
            9.0 * out,
        );
    }
    for g in &gb.gears {
        let (mesh, tip) = gb.inner_gear(t, params, g);
        let explode = if g.kind == PartKind::LowerGear {
            2.5
        } else {
            3.0
        };
        asm.add(g.kind, mesh, explode * out);
        asm.gears.push(GearAttr {
            kind: g.kind,
            centre: gb.point(g.centre, 0.0),
            axis: out,
            housing_diameter: 2.0 * g.radius,
            gear_diameter: tip,
        });
    }
    asm.finish(params, d.top)
}

/// Drive rotations of `n` bolts, degrees: all the same, or whole degrees drawn from the seed.
fn bolt_rotations(p: &MotorParams, n: usize) -> Vec<f32> {
    match p.bolt_orientation {
        BoltOrientation::Same => vec![p.bolt_rotation_deg % 360.0; n],
        BoltOrientation::Random => {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(p.bolt_seed as u64);
            (0..n).map(|_| (rng.next_u32() % 360) as f32).collect()
        }
    }
}

/// Parts in the making (centimetres) and their ground truth.
#[derive(Default)]
struct Assembly {
    parts: Vec<Part>,
    bolts: Vec<BoltAttr>,
    gears: Vec<GearAttr>,
}

impl Assembly {
    /// Adds a part; bolts and magnets are numbered from 1 within their kind.
    fn add(&mut self, kind: PartKind, mesh: Mesh, explode_cm: Vec3) -> (String, u32) {
        let instance = self.parts.len() as u32 + 1;
        let name = if matches!(
            kind,
            PartKind::SideBolt | PartKind::CoverBolt | PartKind::Magnet
        ) {
            let k = self.parts.iter().filter(|p| p.kind == kind).count() + 1;
            format!("{}_{k}", kind.name())
        } else {
            kind.name().to_string()
        };
        self.parts.push(Part {
            name: name.clone(),
            kind,
            instance,
            mesh,
            explode: explode_cm,
        });
        (name, instance)
    }

    /// Adds a bolt whose drive face is centred at `head` and which screws in along `axis`.
    #[allow(clippy::too_many_arguments)]
    fn add_bolt(
        &mut self,
        t: Tess,
        p: &MotorParams,
        kind: PartKind,
        head: Vec3,
        axis: Vec3,
        rotation_deg: f32,
        explode_cm: Vec3,
    ) {
        let place = frame(head, -axis) * Affine3A::from_rotation_z(rotation_deg.to_radians());
        let mesh = bolt::bolt(t, p.bolt_drive).clone().transformed(&place);
        let (name, instance) = self.add(kind, mesh, explode_cm);
        self.bolts.push(BoltAttr {
            name,
            kind,
            instance,
            head_centre: head,
            axis,
            drive: p.bolt_drive,
            rotation_deg,
            rotation_mod_deg: rotation_deg % p.bolt_drive.symmetry_deg(),
        });
    }

    /// Scales everything to metres and summarises it.
    fn finish(mut self, params: &MotorParams, top_cm: f32) -> Motor {
        let to_m = Affine3A::from_scale(Vec3::splat(M_PER_CM));
        for part in &mut self.parts {
            part.mesh.transform(&to_m);
            part.explode *= M_PER_CM;
        }
        for b in &mut self.bolts {
            b.head_centre *= M_PER_CM;
        }
        for g in &mut self.gears {
            g.centre *= M_PER_CM;
            g.housing_diameter *= M_PER_CM;
            g.gear_diameter *= M_PER_CM;
        }
        let parts: Vec<PartAttr> = self
            .parts
            .iter()
            .map(|p| PartAttr {
                name: p.name.clone(),
                kind: p.kind,
                class: p.kind.class(),
                instance: p.instance,
                bounds: p.mesh.bounds(),
                triangles: p.mesh.triangle_count(),
                volume: p.mesh.signed_volume(),
            })
            .collect();
        let bounds = parts.iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds));
        Motor {
            params: params.clone(),
            attributes: Attributes {
                variant: params.variant(),
                pole_pot_top: top_cm * M_PER_CM,
                gears: self.gears,
                bolts: self.bolts,
                parts,
                bounds,
            },
            parts: self.parts,
        }
    }
}

impl Motor {
    /// The motor with every part moved `factor` times its exploded-view offset along its
    /// assembly axis (1 = fully exploded).
    pub fn exploded(&self, factor: f32) -> Motor {
        let mut m = self.clone();
        for p in &mut m.parts {
            p.mesh
                .transform(&Affine3A::from_translation(p.explode * factor));
        }
        m
    }
}
