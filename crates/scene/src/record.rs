//! A sample's JSON (`{stem}.json` beside its clouds): everything needed to use the sample or make
//! it again. The dataset writer fills [`SampleJson`]; readers (the preview, a user's loader in
//! Rust) parse the same type.

use std::collections::BTreeMap;

use glam::Vec3;
use motorgen::{PartKind, Scheme};
use sensor::render::Lighting;
use sensor::wear::{Grain, Mask, Wear};
use sensor::{Frame, Material, SensorSpec, Units};
use serde::{Deserialize, Serialize};

use crate::augment::{Level, Split};
use crate::cell::{Kind, Object};
use crate::coco::CocoView;
use crate::config::{Clamping, Variant};

/// A row-major 4×4 matrix.
pub type Matrix = [[f32; 4]; 4];

/// One sample's ground truth and provenance. Written with every object's keys in sorted order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleJson {
    /// Index in the dataset.
    pub index: u64,
    /// The dataset's global seed.
    pub seed: u64,
    /// Motor variant, when the configuration lists variants.
    pub variant: Option<Variant>,
    /// Augmentation level.
    pub level: Level,
    /// Split.
    pub split: Split,
    /// The swept keys' values of this sample (dotted key → value).
    pub sweep: BTreeMap<String, toml::Value>,
    /// Whether the cover and cover bolts were taken off.
    pub cover_removed: bool,
    /// `params` and `attributes` as `motorfactory motor` writes them, in the motor frame.
    pub motor: serde_json::Value,
    /// The motor's pose in the cell.
    pub motor_to_world: Matrix,
    /// Each fixture part's shift, m.
    pub fixture_shift: BTreeMap<String, Vec3>,
    /// Every scanned object.
    pub objects: Vec<ObjectJson>,
    /// The crop cuboid, world frame.
    pub crop: CropJson,
    /// Factor on the sensor's axial noise.
    pub noise_scale: f32,
    /// Half-widths of the uniform jitter after cropping, camera x, y, z, m.
    pub jitter: [f32; 3],
    /// The sensor as used.
    pub sensor: SensorSpec,
    /// The lights of its rendered colour images, if rendered.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lighting: Option<Lighting>,
    /// Frame of the written points.
    pub frame: Frame,
    /// Units of the written points.
    pub units: Units,
    /// Label scheme.
    pub scheme: Scheme,
    /// The views.
    pub views: Vec<ViewJson>,
}

/// One scanned object of a sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectJson {
    /// Part or cell object name.
    pub name: String,
    /// Instance id in the instance images (under `objects9` a motor's parts carry the whole
    /// motor's).
    pub instance: u32,
    /// Class in the sample's scheme (0: background).
    pub class: u8,
    /// Part kind, for motor parts.
    pub part: Option<PartKind>,
    /// What it is to the schemes of whole objects and of the armature's surfaces.
    pub kind: Kind,
    /// Surface material (as varied by `cell.wear.variation`).
    pub material: Material,
    /// The wear drawn for it, when it has some.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wear: Option<WearJson>,
}

/// The wear drawn for one object (`cell.wear`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WearJson {
    /// Share of its surface rusted, under the coverage mask.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rust: Option<f32>,
    /// The first stop of the noise's ramp (percent / 250-400), under the add-on's mask.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub addon_threshold: Option<f32>,
    /// The add-on's rust texture, 1 to 9.
    pub rust_type: u8,
    /// Share under dust.
    pub dust: f32,
    /// Share under grease.
    pub grease: f32,
    /// Texture of the clean surface.
    pub grain: Grain,
    /// Rust kept to the screws' seats.
    pub seats_only: bool,
}

impl ObjectJson {
    /// What a JSON says of object `o` under `scheme`.
    pub fn of(o: &Object, scheme: Scheme) -> ObjectJson {
        ObjectJson {
            name: o.name.clone(),
            instance: o.instance_in(scheme),
            class: o.class(scheme),
            part: o.part,
            kind: o.kind,
            material: o.material,
            wear: o.wear.as_ref().map(WearJson::of),
        }
    }
}

impl WearJson {
    /// What a sample's JSON says of `w`.
    pub fn of(w: &Wear) -> WearJson {
        let (rust, addon_threshold) = match w.mask {
            Mask::Coverage { share } => (Some(share), None),
            Mask::Addon { threshold } => (None, Some(threshold)),
        };
        WearJson {
            rust,
            addon_threshold,
            rust_type: w.rust.number(),
            dust: w.dust,
            grease: w.grease,
            grain: w.grain,
            seats_only: w.seats.is_some(),
        }
    }
}

/// The crop cuboid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CropJson {
    /// Smallest corner, world frame, m.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

/// One view of a sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewJson {
    /// The camera's pose.
    pub camera_to_world: Matrix,
    /// The motor's pose in the camera frame.
    pub motor_to_camera: Matrix,
    /// With `cell.reclamp`: the clamping this view was taken in.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clamping: Option<Clamping>,
    /// With `cell.reclamp`: the motor's pose in this view's cell (the motor's pose change
    /// between two views is the one's times the other's inverse).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motor_to_world: Option<Matrix>,
    /// This camera's pose in the first view's camera frame (registration ground truth).
    pub camera_to_first_camera: Matrix,
    /// Seed of the scan's per-pixel noise.
    pub noise_seed: u64,
    /// Points in the view's cropped cloud.
    pub points: usize,
    /// Per view k, the share of this view's motor points whose surface view k also measured
    /// (`output.overlap`; 1 for itself).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overlap: Option<Vec<f32>>,
    /// The view's files, relative to the dataset folder.
    pub files: Vec<String>,
    /// With `output.coco`: the colour image's COCO image and annotations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coco: Option<CocoView>,
}

impl SampleJson {
    /// The JSON text as written: pretty, keys sorted, a newline at the end.
    pub fn to_text(&self) -> String {
        // through a Value, whose maps sort their keys
        let value = serde_json::to_value(self).expect("a sample's JSON serialises");
        serde_json::to_string_pretty(&value).expect("a JSON value prints") + "\n"
    }
}
