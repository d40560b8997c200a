//! What a built motor is: labelled parts with materials, and its ground truth.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::kernel::{Aabb, Mesh};
use crate::params::{BoltDrive, MotorParams};

/// Every kind of part the add-on builds, in build order (`kind as u8` is its index in [`PartKind::ALL`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PartKind {
    /// Pole pot (the add-on's "Bottom") with its shaft boss.
    PolePot,
    /// One of the two magnet shells inside the pole pot.
    Magnet,
    /// Armature: shaft, slotted core, commutator.
    Armature,
    /// Electric connection ("Charger").
    ElectricConnection,
    /// Gear container: collar, tower, gear housings, boards and bolt bosses.
    GearContainer,
    /// Cover over the gears, with its extension.
    Cover,
    /// A bolt joining the gear container to the pole pot.
    SideBolt,
    /// A bolt holding the cover.
    CoverBolt,
    /// Type A lower inner gear with its pinion.
    LowerGear,
    /// Type A upper inner gear.
    UpperGear,
    /// Type B inner gear.
    SingleGear,
}

/// Semantic class of a part: the gears' roles merged into one class.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PartClass {
    /// Pole pot.
    PolePot,
    /// Electric connection.
    ElectricConnection,
    /// Gear container.
    GearContainer,
    /// Cover.
    Cover,
    /// Side bolt.
    SideBolt,
    /// Cover bolt.
    CoverBolt,
    /// Magnet.
    Magnet,
    /// Armature.
    Armature,
    /// Inner gear.
    InnerGear,
}

impl PartKind {
    /// All kinds, in build order.
    pub const ALL: [PartKind; 11] = [
        PartKind::PolePot,
        PartKind::Magnet,
        PartKind::Armature,
        PartKind::ElectricConnection,
        PartKind::GearContainer,
        PartKind::Cover,
        PartKind::SideBolt,
        PartKind::CoverBolt,
        PartKind::LowerGear,
        PartKind::UpperGear,
        PartKind::SingleGear,
    ];

    /// The semantic class.
    pub fn class(self) -> PartClass {
        match self {
            PartKind::PolePot => PartClass::PolePot,
            PartKind::ElectricConnection => PartClass::ElectricConnection,
            PartKind::GearContainer => PartClass::GearContainer,
            PartKind::Cover => PartClass::Cover,
            PartKind::SideBolt => PartClass::SideBolt,
            PartKind::CoverBolt => PartClass::CoverBolt,
            PartKind::Magnet => PartClass::Magnet,
            PartKind::Armature => PartClass::Armature,
            PartKind::LowerGear | PartKind::UpperGear | PartKind::SingleGear => {
                PartClass::InnerGear
            }
        }
    }

    /// Whether `stem` names a part's files: a kind's [`PartKind::name`], numbered `_1`, `_2`, …
    /// for bolts and magnets.
    pub fn is_file_stem(stem: &str) -> bool {
        PartKind::ALL.iter().any(|k| {
            let numbered = matches!(
                k,
                PartKind::SideBolt | PartKind::CoverBolt | PartKind::Magnet
            );
            match stem.strip_prefix(k.name()) {
                Some("") => !numbered,
                Some(n) => {
                    numbered
                        && n.strip_prefix('_').is_some_and(|d| {
                            !d.is_empty()
                                && !d.starts_with('0')
                                && d.bytes().all(|b| b.is_ascii_digit())
                        })
                }
                None => false,
            }
        })
    }

    /// File-name stem (snake case).
    pub fn name(self) -> &'static str {
        match self {
            PartKind::PolePot => "pole_pot",
            PartKind::ElectricConnection => "electric_connection",
            PartKind::GearContainer => "gear_container",
            PartKind::Cover => "cover",
            PartKind::SideBolt => "side_bolt",
            PartKind::CoverBolt => "cover_bolt",
            PartKind::Magnet => "magnet",
            PartKind::Armature => "armature",
            PartKind::LowerGear => "lower_gear",
            PartKind::UpperGear => "upper_gear",
            PartKind::SingleGear => "gear",
        }
    }

    /// The add-on's material for this part (its `Materia_Tables`).
    pub fn material(self) -> &'static Material {
        let name = match self {
            PartKind::PolePot => "Metall",
            PartKind::ElectricConnection => "Energy",
            PartKind::GearContainer | PartKind::Cover => "Plastic",
            PartKind::SideBolt | PartKind::CoverBolt => "Bit",
            PartKind::Magnet => "Magnet",
            PartKind::Armature => "Wire",
            PartKind::LowerGear | PartKind::UpperGear | PartKind::SingleGear => "Gear",
        };
        MATERIALS
            .iter()
            .find(|m| m.name == name)
            .expect("every part has a material")
    }
}

/// A physically based material as the add-on's Principled BSDF settings.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Material {
    /// The add-on's material name.
    pub name: &'static str,
    /// Linear RGBA base colour.
    pub base_color: [f32; 4],
    /// Metalness 0..1.
    pub metallic: f32,
    /// Roughness 0..1.
    pub roughness: f32,
    /// Strength of the specular reflection 0..1 (the add-on's `specular_intensity`, the
    /// Principled BSDF's specular level: 0.5 reflects 4 % at normal incidence).
    pub specular: f32,
}

/// The add-on's materials (its `Materia_Tables`); the armature takes the add-on's windings
/// ("Wire"), which cover most of it.
pub static MATERIALS: &[Material] = &[
    Material {
        name: "Metall",
        base_color: [0.3, 0.3, 0.3, 1.0],
        metallic: 0.8,
        roughness: 0.4,
        specular: 0.9,
    },
    Material {
        name: "Energy",
        base_color: [0.781, 0.775, 0.308, 1.0],
        metallic: 0.0,
        roughness: 0.5,
        specular: 0.5,
    },
    Material {
        name: "Plastic",
        base_color: [0.0, 0.0, 0.0, 1.0],
        metallic: 0.4,
        roughness: 0.7,
        specular: 0.5,
    },
    Material {
        name: "Bit",
        base_color: [0.9, 0.9, 0.9, 1.0],
        metallic: 0.9,
        roughness: 0.1,
        specular: 0.7,
    },
    Material {
        name: "Magnet",
        base_color: [0.099, 0.099, 0.099, 1.0],
        metallic: 0.1,
        roughness: 1.0,
        specular: 0.5,
    },
    Material {
        name: "Wire",
        base_color: [0.940_392, 0.266_226, 0.005_395_73, 1.0],
        metallic: 1.0,
        roughness: 0.245,
        specular: 0.5,
    },
    Material {
        name: "Gear",
        base_color: [1.0, 1.0, 1.0, 1.0],
        metallic: 0.1,
        roughness: 0.7,
        specular: 0.5,
    },
];

/// One part: a labelled mesh in the motor frame (metres).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Unique name within the motor, e.g. `cover_bolt_2`.
    pub name: String,
    /// What it is.
    pub kind: PartKind,
    /// Instance id, unique within the motor, from 1 (0 is reserved for background).
    pub instance: u32,
    /// The closed shells that make up the part.
    pub mesh: Mesh,
    /// Offset of the part in a fully exploded view (along its assembly axis), metres.
    pub explode: Vec3,
}

/// A built motor: its parameters, parts and ground truth.
#[derive(Clone, Debug, PartialEq)]
pub struct Motor {
    /// The parameters it was built from.
    pub params: MotorParams,
    /// The parts, in build order.
    pub parts: Vec<Part>,
    /// Ground truth as built.
    pub attributes: Attributes,
}

/// Exact ground truth of a built motor, in the motor frame (metres; z along the motor axis from
/// the free end of the shaft boss).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Attributes {
    /// A0, A1, A2, B0 or B1.
    pub variant: &'static str,
    /// z of the pole-pot top (where the gearbox starts).
    pub pole_pot_top: f32,
    /// The gears: lower and upper (A) or the single gear (B).
    pub gears: Vec<GearAttr>,
    /// Every bolt, side bolts first.
    pub bolts: Vec<BoltAttr>,
    /// Every part.
    pub parts: Vec<PartAttr>,
    /// Bounding box of the whole motor.
    pub bounds: Aabb,
}

/// Ground truth of one gear.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GearAttr {
    /// lower_gear, upper_gear or gear.
    pub kind: PartKind,
    /// Centre of the gear housing on the cover plane.
    #[serde(rename = "center")]
    pub centre: Vec3,
    /// Gear axis, pointing out of the cover.
    pub axis: Vec3,
    /// Outer diameter of the gear housing (the parameter).
    pub housing_diameter: f32,
    /// Tip diameter of the inner gear.
    pub gear_diameter: f32,
}

/// Ground truth of one bolt.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BoltAttr {
    /// Part name.
    pub name: String,
    /// side_bolt or cover_bolt.
    pub kind: PartKind,
    /// Instance id of the part.
    pub instance: u32,
    /// Centre of the head's drive face (where a screwdriver engages).
    #[serde(rename = "head_center")]
    pub head_centre: Vec3,
    /// Unit screwing direction, from the head into the part.
    pub axis: Vec3,
    /// Screw drive.
    pub drive: BoltDrive,
    /// Rotation of the drive about the axis, degrees 0..360.
    pub rotation_deg: f32,
    /// The rotation modulo the drive's symmetry (what a camera can tell apart).
    pub rotation_mod_deg: f32,
}

/// Summary of one part's mesh.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PartAttr {
    /// Part name.
    pub name: String,
    /// Kind.
    pub kind: PartKind,
    /// Semantic class.
    pub class: PartClass,
    /// Instance id.
    pub instance: u32,
    /// Bounding box.
    pub bounds: Aabb,
    /// Triangle count.
    pub triangles: usize,
    /// Sum of the shells' volumes, m³.
    pub volume: f64,
}
