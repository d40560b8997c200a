//! The dataset configuration: the TOML schema of `motorfactory generate` (this module), the
//! TOML tables it is read from (`table`: the built-in configurations, overlays and dotted-key
//! overrides), its checks (`check`) and parameter sweeps (`sweep`).

mod check;
mod lidar;
mod output;
mod render;
mod scenes;
mod sensor;
mod sweep;
mod table;
mod words;

use motorgen::{Detail, ParamSpace, PartKind};
use rand::{Rng, RngExt};

use serde::{Deserialize, Serialize};

pub use self::sensor::{SensorConfig, read_sensor};
pub use lidar::LidarConfig;
pub use output::{Colouring, ImageFormat, ImageKind, Images, Layout, MAX_VIEWS, OutputConfig};
pub use render::{LightingConfig, RenderConfig};
pub use scenes::{ArmatureConfig, HallConfig, HandlingConfig, SceneKind, TransferConfig};
pub use sweep::{Combinations, MAX_COMBINATIONS, Sweep};
pub use table::{
    BUILTIN, builtin_table, default_table, named_table, overlay, parse_value, set_key,
};
pub use words::{in_words, toml_in_words};

use crate::error::{Error, Result};

/// A number drawn uniformly from `[min, max]`; written `x` (fixed) or `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(into = "[f32; 2]")]
pub struct Span {
    /// Lower bound.
    pub min: f32,
    /// Upper bound.
    pub max: f32,
}

impl<'de> Deserialize<'de> for Span {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Span, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = Span;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or [min, max]")
            }
            fn visit_f64<E: serde::de::Error>(self, x: f64) -> std::result::Result<Span, E> {
                Ok(Span::new(x as f32, x as f32))
            }
            fn visit_i64<E: serde::de::Error>(self, x: i64) -> std::result::Result<Span, E> {
                self.visit_f64(x as f64)
            }
            fn visit_u64<E: serde::de::Error>(self, x: u64) -> std::result::Result<Span, E> {
                self.visit_f64(x as f64)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<Span, A::Error> {
                let two = || serde::de::Error::custom("expected a number or [min, max]");
                let a: f32 = seq.next_element()?.ok_or_else(two)?;
                let b: f32 = seq.next_element()?.ok_or_else(two)?;
                if seq.next_element::<f32>()?.is_some() {
                    return Err(two());
                }
                Ok(Span::new(a, b))
            }
        }
        d.deserialize_any(Visitor)
    }
}

impl From<Span> for [f32; 2] {
    fn from(s: Span) -> [f32; 2] {
        [s.min, s.max]
    }
}

impl Span {
    /// The span from `min` to `max`.
    pub const fn new(min: f32, max: f32) -> Span {
        Span { min, max }
    }

    /// A uniform draw (the bound itself when the span is one value).
    pub fn sample(&self, rng: &mut impl Rng) -> f32 {
        if self.min == self.max {
            self.min
        } else {
            rng.random_range(self.min..=self.max)
        }
    }

    /// Checks `min <= max`, both finite and within `[lo, hi]`.
    fn check(&self, key: &str, lo: f32, hi: f32) -> Result<()> {
        let ok = self.min.is_finite()
            && self.max.is_finite()
            && self.min <= self.max
            && self.min >= lo
            && self.max <= hi;
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(
                key,
                format!("[{}, {}]", self.min, self.max),
                format!("a number or [min, max] with {lo} <= min <= max <= {hi}"),
            ))
        }
    }
}

/// A motor type and cover extension, as the original datasets named them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Variant {
    /// Type A without extension.
    A0,
    /// Type A, extension type 1.
    A1,
    /// Type A, extension type 2.
    A2,
    /// Type B without extension.
    B0,
    /// Type B, extension type 1.
    B1,
}

impl Variant {
    /// The motor parameters that make this variant.
    pub fn params(self) -> [(&'static str, &'static str); 2] {
        match self {
            Variant::A0 => [("type", "A"), ("extension_a", "none")],
            Variant::A1 => [("type", "A"), ("extension_a", "type1")],
            Variant::A2 => [("type", "A"), ("extension_a", "type2")],
            Variant::B0 => [("type", "B"), ("extension_b", "none")],
            Variant::B1 => [("type", "B"), ("extension_b", "type1")],
        }
    }
}

/// `[motor]`: which motors are built.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorConfig {
    /// Variants in equal numbers, each within two samples of its share in every prefix
    /// ([`crate::augment::place`]); empty: the parameter distributions decide.
    pub variants: Vec<Variant>,
    /// Tessellation.
    pub detail: Detail,
    /// Share of samples with the cover and cover bolts removed, inner gears visible (needs the
    /// `inner10` scheme).
    pub cover_removed: f32,
    /// Motor parameter distributions, as in `configs/motors.toml`.
    pub params: toml::Table,
}

/// Shifts of one fixture part along world x, y and z, m.
pub type Shift = [Span; 3];

/// `[cell.fixture]`: how far each fixture part moves in scenes with fixture shifts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FixtureConfig {
    /// Fixed jaw (the jaw on the −y side).
    pub fixed_jaw: Shift,
    /// Sliding jaw (+y side); the pneumatic cylinder follows it.
    pub sliding_jaw: Shift,
    /// Pillar.
    pub pillar: Shift,
    /// Pneumatic cylinder, on top of the sliding jaw's shift.
    pub cylinder: Shift,
}

/// `[cell.occluders]`: mask panels near the gearbox.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OccluderConfig {
    /// Number of panels (drawn uniformly between the bounds, inclusive).
    pub count: [u32; 2],
    /// Edge lengths of a panel, m.
    pub size: Span,
    /// Height of a panel's centre above the motor's top, m.
    pub height: Span,
    /// Largest horizontal offset of a panel's centre from the gearbox centre, m.
    pub spread: f32,
    /// Largest tilt of a panel from horizontal, degrees.
    pub tilt_deg: f32,
}

/// `[cell.wear]`: rust on the motor's metal parts, drawn per sample (each part its own share,
/// rust type and pattern).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearConfig {
    /// How the rust is laid out: `coverage` (the drawn share of the part's surface) or `addon`
    /// (the add-on's mask, the share as its percent / 100).
    pub mask: WearMask,
    /// The add-on's rust textures drawn from, [first, last] of 1 to 9.
    pub rust: [u8; 2],
    /// Share of each bolt's surface rusted, 0..1.
    pub bolts: Span,
    /// Share of the pole pot's surface rusted, 0..1.
    pub pole_pot: Span,
    /// Share of the electric connection's surface rusted, 0..1.
    pub electric_connection: Span,
    /// Share of the gear container's screws' seats rusted (discs of 8 mm about the bolt
    /// heads), 0..1.
    pub screw_seats: Span,
    /// Share of each motor part's surface under dust, 0..1.
    pub dust: Span,
    /// Share of each motor part's surface under grease, 0..1.
    pub grease: Span,
    /// Each motor part's colour and reflectivity scaled by 1 ± this and its roughness moved by
    /// ± half of it, drawn per part: no two parts of a kind quite alike, 0..0.5.
    pub variation: f32,
    /// Clean surfaces textured: the pole pot's drawn steel streaked along its axis, the
    /// plastics' moulded grain.
    pub grain: bool,
}

impl WearConfig {
    /// Whether any part may wear (rust, dust, grease or vary).
    pub fn enabled(&self) -> bool {
        self.variation > 0.0
            || self.grain
            || [
                self.bolts,
                self.pole_pot,
                self.electric_connection,
                self.screw_seats,
                self.dust,
                self.grease,
            ]
            .iter()
            .any(|s| s.max > 0.0)
    }

    /// The share drawn for parts of `kind`, if they may rust.
    pub fn span(&self, kind: PartKind) -> Option<Span> {
        match kind {
            PartKind::SideBolt | PartKind::CoverBolt => Some(self.bolts),
            PartKind::PolePot => Some(self.pole_pot),
            PartKind::ElectricConnection => Some(self.electric_connection),
            PartKind::GearContainer => Some(self.screw_seats),
            _ => None,
        }
    }
}

/// How rust is laid out over a part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WearMask {
    /// The drawn share of the surface rusts, in patches of a fractal noise.
    Coverage,
    /// The add-on's mask (noise, Voronoi, ramps) at percent = share × 100.
    Addon,
}

/// How the motor is clamped: the inspection station's two setups, each hiding what the other
/// shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Clamping {
    /// Lying, the motor axis along world x and the cover up; the jaws grip the pole pot.
    #[default]
    GearContainerUp,
    /// Standing, the motor axis vertical and the pole pot up; the jaws grip the gear container.
    PolePotUp,
}

impl Clamping {
    /// Both setups.
    pub const ALL: [Clamping; 2] = [Clamping::GearContainerUp, Clamping::PolePotUp];

    /// The name used in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Clamping::GearContainerUp => "gear-container-up",
            Clamping::PolePotUp => "pole-pot-up",
        }
    }
}

/// `[cell]`: the work cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellConfig {
    /// What the camera looks at: the station, the transfer unit, the handling table or the
    /// armature; or the hall, which the LiDAR scans.
    pub scene: SceneKind,
    /// Largest rotation of the motor about world x (its axis), y and z, degrees (Euler XYZ,
    /// about the motor's centre).
    pub pose_jitter_deg: [f32; 3],
    /// Gap between the motor's lowest point and the base plate at the nominal pose, m.
    pub clearance: f32,
    /// How the motor lies in the fixture.
    pub clamping: Clamping,
    /// Views alternate between the two setups: even views in `clamping`, odd views in the
    /// other (registration across a reclamping).
    pub reclamp: bool,
    /// Fixture shifts.
    pub fixture: FixtureConfig,
    /// Occluding panels.
    pub occluders: OccluderConfig,
    /// Corrosion.
    pub wear: WearConfig,
    /// The table's look, drawn per sample.
    pub table: TableConfig,
    /// The transfer unit's carriers (`scene = "transfer-unit"`).
    pub transfer: TransferConfig,
    /// What lies on the handling table (`scene = "handling"`).
    pub handling: HandlingConfig,
    /// The armature on its own (`scene = "armature"`).
    pub armature: ArmatureConfig,
    /// The hall (`scene = "hall"`).
    pub hall: HallConfig,
}

/// `[cell.table]`: the table's look, drawn per sample (domain randomisation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableConfig {
    /// The lowest and the highest linear RGB colour: each channel drawn between, the same
    /// share of the way for all three (a grey stays grey).
    pub colour: [[f32; 3]; 2],
    /// Each channel drawn on its own share of the way (0: the colour's hue is fixed).
    pub tint: f32,
    /// Roughness (Principled BSDF).
    pub roughness: Span,
}

/// How camera poses are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Rig {
    /// On a spherical cap over the motor, looking at its centre.
    Cap,
    /// One pose (`look_at`).
    Fixed,
    /// Poses from `poses`, in turn.
    List,
}

/// `[camera]`: the camera rig.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    /// cap, fixed or list.
    pub rig: Rig,
    /// Views of each cell (multi-view sequences with exact relative transforms).
    pub views: u32,
    /// Cap: distance from the motor's centre, m.
    pub distance: Span,
    /// Cap: angle from the vertical, degrees.
    pub tilt_deg: Span,
    /// Cap: azimuth about the vertical, degrees.
    pub azimuth_deg: Span,
    /// Cap: roll about the optical axis, degrees (0: the motor axis along the image rows).
    pub roll_deg: Span,
    /// Fixed: eye and target relative to the motor's centre (world axes), m.
    pub look_at: [f32; 6],
    /// List: eye and target per pose, relative to the motor's centre, m.
    pub poses: Vec<[f32; 6]>,
    /// Fixed and list: world direction that appears up in the image.
    pub up: [f32; 3],
}

/// `[crop]`: the cuboid around the motor, each face's offset from the motor's centre (world
/// axes), m, drawn per sample.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CropConfig {
    /// −x face.
    pub x_min: Span,
    /// +x face.
    pub x_max: Span,
    /// −y face.
    pub y_min: Span,
    /// +y face.
    pub y_max: Span,
    /// Bottom face (cuts into the fixture).
    pub z_min: Span,
    /// Top face.
    pub z_max: Span,
}

/// One augmentation level.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelConfig {
    /// Share of the samples at this level.
    pub share: f32,
    /// Mask panels present.
    pub occluders: bool,
    /// Fixture parts shifted.
    pub fixture_shift: bool,
    /// Factor on the sensor's axial noise σ, drawn per sample.
    pub noise_scale: Span,
    /// Uniform jitter after cropping, ± per camera axis x, y, z, m.
    pub jitter: [f32; 3],
}

/// `[augment]`: the original datasets' three levels and the validation split.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AugmentConfig {
    /// Share of each level's samples in the validation split.
    pub validation: f32,
    /// "original": no panels, fixture at rest, low noise.
    pub clean: LevelConfig,
    /// "no-noise": panels and fixture shifts, low noise.
    pub occluded: LevelConfig,
    /// "noise": everything plus higher noise and jitter.
    pub noisy: LevelConfig,
}

/// A whole dataset configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Global seed.
    pub seed: u64,
    /// Number of samples when `-n` is not given.
    pub samples: u64,
    /// Motors.
    pub motor: MotorConfig,
    /// Work cell.
    pub cell: CellConfig,
    /// Camera rig.
    pub camera: CameraConfig,
    /// Sensor.
    pub sensor: SensorConfig,
    /// The LiDAR of the hall's mobile robot (`cell.scene = "hall"`).
    pub lidar: LidarConfig,
    /// Crop cuboid.
    pub crop: CropConfig,
    /// Augmentation levels and split.
    pub augment: AugmentConfig,
    /// Outputs.
    pub output: OutputConfig,
    /// How the colour image is made.
    pub render: RenderConfig,
    /// The lights of a rendered colour image.
    pub lighting: LightingConfig,
    /// Parameter sweep: every combination of the listed keys' values (sample i takes
    /// combination i mod count).
    #[serde(default)]
    pub sweep: Vec<Sweep>,
}

impl Default for Config {
    /// The default configuration, `configs/default.toml`.
    fn default() -> Config {
        Config::from_table(&default_table()).expect("configs/default.toml is a valid configuration")
    }
}

impl Config {
    /// Reads a configuration from a TOML table, reporting the dotted path of any bad key.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] naming the dotted key of an unknown or missing key,
    /// a value of the wrong type, or a value [`Config::check`] refuses.
    pub fn from_table(table: &toml::Table) -> Result<Config> {
        let config: Config = serde_path_to_error::deserialize(toml::Value::Table(table.clone()))
            .map_err(|e| {
                let path = e.path().to_string();
                let inner = e.into_inner().to_string();
                // toml appends "in `path`", which the prefix already says
                let inner = in_words(inner.split("\nin `").next().unwrap_or_default().trim());
                Error::Config(if path == "." || path.is_empty() {
                    inner.to_string()
                } else {
                    format!("{path}: {inner}")
                })
            })?;
        config.check()?;
        Ok(config)
    }

    /// The motor parameter space of each variant, in `motor.variants` order (one space, the
    /// parameters' own, when no variants are listed).
    ///
    /// # Errors
    ///
    /// [`Error::Config`] when `motor.params` holds an unknown parameter or a
    /// distribution that does not fit, alone or with a variant's type and extension.
    pub fn param_spaces(&self) -> Result<Vec<ParamSpace>> {
        let base = ParamSpace::from_toml(&self.motor.params)
            .map_err(|e| Error::Config(format!("motor.params: {e}")))?;
        if self.motor.variants.is_empty() {
            return Ok(vec![base]);
        }
        self.motor
            .variants
            .iter()
            .map(|v| {
                let mut space = base.clone();
                for (key, value) in v.params() {
                    space
                        .set(key, motorgen::Dist::from_cli(key, value)?)
                        .map_err(|e| Error::Config(format!("motor.variants {v:?}: {e}")))?;
                }
                Ok(space)
            })
            .collect()
    }
}
