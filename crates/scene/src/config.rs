//! The dataset configuration: the TOML schema of `motorfactory generate`, its checks, dotted-key
//! overrides (`--set`) and parameter sweeps.

use motorgen::{Detail, ParamSpace, Scheme};
use rand::{Rng, RngExt};
use sensor::formats::CloudFormat;
use sensor::{Frame, Noise, SensorSpec, Units};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// A number drawn uniformly from `[min, max]`; written `x` (fixed) or `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "SpanForm", into = "[f32; 2]")]
pub struct Span {
    /// Lower bound.
    pub min: f32,
    /// Upper bound.
    pub max: f32,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum SpanForm {
    Fixed(f32),
    Range([f32; 2]),
}

impl From<SpanForm> for Span {
    fn from(f: SpanForm) -> Span {
        match f {
            SpanForm::Fixed(x) => Span::new(x, x),
            SpanForm::Range([a, b]) => Span::new(a, b),
        }
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
    /// Variants in turn (sample i gets `variants[i % len]`: equal numbers of each); empty: the
    /// parameter distributions decide.
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

/// `[cell]`: the work cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellConfig {
    /// Largest rotation of the motor about world x (its axis), y and z, degrees (Euler XYZ,
    /// about the motor's centre).
    pub pose_jitter_deg: [f32; 3],
    /// Gap between the motor's lowest point and the base plate at the nominal pose, m.
    pub clearance: f32,
    /// Fixture shifts.
    pub fixture: FixtureConfig,
    /// Occluding panels.
    pub occluders: OccluderConfig,
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

/// `[sensor]`: the simulated camera.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    /// A preset name (`motorfactory scan --help` lists them).
    pub preset: String,
    /// A full sensor specification instead of the preset (the `scan --sensor FILE.toml` schema).
    pub spec: Option<SensorSpec>,
    /// Noise models replacing the sensor's own (every model off unless given).
    pub noise: Option<Noise>,
    /// Pixel binning: 1, 2 or 4.
    pub binning: u32,
}

impl SensorConfig {
    /// The sensor with binning applied, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] for an unknown preset, a binning other than 1, 2 or
    /// 4, or a specification the sensor rejects.
    pub fn resolve(&self) -> Result<SensorSpec> {
        let mut spec = match &self.spec {
            Some(spec) => spec.clone(),
            None => SensorSpec::preset(&self.preset)
                .map_err(|e| Error::invalid("sensor.preset", &self.preset, e.to_string()))?,
        };
        if ![1, 2, 4].contains(&self.binning) {
            return Err(Error::invalid("sensor.binning", self.binning, "1, 2 or 4"));
        }
        spec.intrinsics = spec.intrinsics.binned(self.binning);
        if let Some(noise) = self.noise {
            spec.noise = noise;
        }
        spec.validate()
            .map_err(|e| Error::Config(format!("sensor: {e}")))?;
        Ok(spec)
    }
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

/// `[output]`: what each sample writes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    /// Formats of the cropped cloud.
    pub formats: Vec<CloudFormat>,
    /// Frame of the written points.
    pub frame: Frame,
    /// Units of the written points.
    pub units: Units,
    /// Label scheme.
    pub scheme: Scheme,
    /// Write the exact (noise-free) points instead of the measured ones.
    pub clean: bool,
    /// Also write the whole scene's cloud (uncropped) in the first format.
    pub scene_cloud: bool,
    /// Also write depth, normal, label, instance and intensity images.
    pub images: bool,
}

/// One swept key and its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// Dotted key, e.g. `motor.params.pole_pot_length` or `sensor.binning`.
    pub key: String,
    /// The values.
    pub list: Option<Vec<toml::Value>>,
    /// `[first, last, count]`: evenly spaced.
    pub linspace: Option<(f64, f64, u32)>,
    /// `[start, stop, step]`: start, start + step, ... up to stop.
    pub grid: Option<(f64, f64, f64)>,
}

impl Sweep {
    /// The values of the sweep, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] unless exactly one of `list`, `linspace` and `grid`
    /// is given, non-empty and finite.
    pub fn values(&self) -> Result<Vec<toml::Value>> {
        let key = format!("sweep {}", self.key);
        let values = match (&self.list, self.linspace, self.grid) {
            (Some(list), None, None) => list.clone(),
            (None, Some((a, b, n)), None) if n >= 1 && a.is_finite() && b.is_finite() => (0..n)
                .map(|i| {
                    let t = if n == 1 {
                        0.0
                    } else {
                        i as f64 / (n - 1) as f64
                    };
                    toml::Value::Float(a + (b - a) * t)
                })
                .collect(),
            (None, None, Some((a, b, step)))
                if step > 0.0 && a <= b && (b - a) / step <= 1e5 && a.is_finite() =>
            {
                let n = ((b - a) / step + 1e-9).floor() as u64;
                (0..=n)
                    .map(|i| toml::Value::Float(a + step * i as f64))
                    .collect()
            }
            _ => {
                return Err(Error::Config(format!(
                    "{key}: give exactly one of list = [...], linspace = [first, last, count >= 1] \
                     or grid = [start, stop, step > 0]"
                )));
            }
        };
        if values.is_empty() {
            return Err(Error::Config(format!("{key}: the list is empty")));
        }
        Ok(values)
    }
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
    /// Crop cuboid.
    pub crop: CropConfig,
    /// Augmentation levels and split.
    pub augment: AugmentConfig,
    /// Outputs.
    pub output: OutputConfig,
    /// Parameter sweep: every combination of the listed keys' values (sample i takes
    /// combination i mod count).
    #[serde(default)]
    pub sweep: Vec<Sweep>,
}

/// Sets the dotted `key` (e.g. `camera.distance`) of `table` to `value`, creating tables on the
/// way.
///
/// # Errors
///
/// [`Error::Config`] when `key` is not a dotted key or passes through a value
/// that is not a table.
pub fn set_key(table: &mut toml::Table, key: &str, value: toml::Value) -> Result<()> {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().filter(|s| !s.is_empty());
    let (Some(last), true) = (last, parts.iter().all(|p| !p.is_empty())) else {
        return Err(Error::Config(format!(
            "`{key}` is not a dotted key such as camera.distance"
        )));
    };
    let mut t = table;
    for p in parts {
        let entry = t
            .entry(p)
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        t = entry
            .as_table_mut()
            .ok_or_else(|| Error::Config(format!("{key}: `{p}` is not a table")))?;
    }
    t.insert(last.into(), value);
    Ok(())
}

/// Lays `top` over `base`: tables merge key by key, any other value replaces.
pub fn overlay(base: &mut toml::Table, top: toml::Table) {
    for (key, value) in top {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(t)) => overlay(b, t),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// Parses the right-hand side of `--set key=value`: a TOML value, or a bare word as text.
pub fn parse_value(text: &str) -> toml::Value {
    toml::from_str::<toml::Table>(&format!("v = {text}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(text.to_string()))
}

/// The configurations shipped in `configs/` and built into the library: `(name, TOML)`, the
/// default first. Every other configuration is laid over the default with [`overlay`].
pub const BUILTIN: [(&str, &str); 6] = [
    ("default", crate::DEFAULT_CONFIG),
    ("synmotor", include_str!("../configs/synmotor.toml")),
    ("zivid", include_str!("../configs/zivid.toml")),
    ("registration", include_str!("../configs/registration.toml")),
    (
        "sweep-pole-pot",
        include_str!("../configs/sweep-pole-pot.toml"),
    ),
    ("sweep-noise", include_str!("../configs/sweep-noise.toml")),
];

/// The default configuration as a TOML table, every key present: the base that configurations
/// are laid over.
pub fn default_table() -> toml::Table {
    toml::from_str(crate::DEFAULT_CONFIG).expect("configs/default.toml is valid TOML")
}

/// The built-in configuration `name` laid over the default, as a table to which overrides can
/// still be applied; `None` for a name not in [`BUILTIN`].
pub fn builtin_table(name: &str) -> Option<toml::Table> {
    let (_, text) = BUILTIN.iter().find(|(n, _)| *n == name)?;
    let mut table = default_table();
    overlay(
        &mut table,
        toml::from_str(text).expect("the built-in configurations are valid TOML"),
    );
    Some(table)
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
                let inner = inner.split("\nin `").next().unwrap_or_default().trim();
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

    /// Checks every value against what it allows.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] naming the first value that is not allowed, with
    /// what is.
    pub fn check(&self) -> Result<()> {
        let m = &self.motor;
        self.param_spaces()?;
        share("motor.cover_removed", m.cover_removed)?;
        if m.cover_removed > 0.0 && self.output.scheme != Scheme::InnerParts {
            return Err(Error::invalid(
                "motor.cover_removed",
                m.cover_removed,
                "0 unless output.scheme = \"inner10\" (the other schemes have no gear classes)",
            ));
        }
        let c = &self.cell;
        for (i, j) in c.pose_jitter_deg.iter().enumerate() {
            if !(0.0..=90.0).contains(j) {
                return Err(Error::invalid(
                    &format!("cell.pose_jitter_deg[{i}]"),
                    j,
                    "0 to 90 degrees",
                ));
            }
        }
        if !(0.0..=0.2).contains(&c.clearance) {
            return Err(Error::invalid("cell.clearance", c.clearance, "0 to 0.2 m"));
        }
        let f = &c.fixture;
        for (name, shift) in [
            ("fixed_jaw", &f.fixed_jaw),
            ("sliding_jaw", &f.sliding_jaw),
            ("pillar", &f.pillar),
            ("cylinder", &f.cylinder),
        ] {
            for (axis, s) in ["x", "y", "z"].iter().zip(shift) {
                s.check(&format!("cell.fixture.{name}.{axis}"), -0.2, 0.2)?;
            }
        }
        let o = &c.occluders;
        if o.count[0] > o.count[1] || o.count[1] > 20 {
            return Err(Error::invalid(
                "cell.occluders.count",
                format!("{:?}", o.count),
                "[min, max] with min <= max <= 20",
            ));
        }
        o.size.check("cell.occluders.size", 1e-3, 0.5)?;
        o.height.check("cell.occluders.height", -0.1, 0.5)?;
        if !(0.0..=0.5).contains(&o.spread) {
            return Err(Error::invalid(
                "cell.occluders.spread",
                o.spread,
                "0 to 0.5 m",
            ));
        }
        if !(0.0..=90.0).contains(&o.tilt_deg) {
            return Err(Error::invalid(
                "cell.occluders.tilt_deg",
                o.tilt_deg,
                "0 to 90 degrees",
            ));
        }
        self.check_camera()?;
        self.sensor.resolve()?;
        let k = &self.crop;
        for (key, s, lo, hi) in [
            ("crop.x_min", &k.x_min, -1.0, 0.0),
            ("crop.x_max", &k.x_max, 0.0, 1.0),
            ("crop.y_min", &k.y_min, -1.0, 0.0),
            ("crop.y_max", &k.y_max, 0.0, 1.0),
            ("crop.z_min", &k.z_min, -1.0, 0.0),
            ("crop.z_max", &k.z_max, 0.0, 1.0),
        ] {
            s.check(key, lo, hi)?;
        }
        let a = &self.augment;
        share("augment.validation", a.validation)?;
        for (name, l) in [
            ("clean", &a.clean),
            ("occluded", &a.occluded),
            ("noisy", &a.noisy),
        ] {
            share(&format!("augment.{name}.share"), l.share)?;
            l.noise_scale
                .check(&format!("augment.{name}.noise_scale"), 0.0, 100.0)?;
            for (axis, j) in ["x", "y", "z"].iter().zip(l.jitter) {
                if !(0.0..=0.1).contains(&j) {
                    return Err(Error::invalid(
                        &format!("augment.{name}.jitter.{axis}"),
                        j,
                        "0 to 0.1 m",
                    ));
                }
            }
        }
        let total = a.clean.share + a.occluded.share + a.noisy.share;
        if (total - 1.0).abs() > 1e-4 {
            return Err(Error::invalid(
                "augment.{clean,occluded,noisy}.share",
                total,
                "shares that add up to 1",
            ));
        }
        if self.output.formats.is_empty() && !self.output.images {
            return Err(Error::invalid(
                "output.formats",
                "[]",
                "at least one of ply, pcd, pcd-ascii, npy, npz (or images = true)",
            ));
        }
        for s in &self.sweep {
            s.values()?;
        }
        Ok(())
    }

    fn check_camera(&self) -> Result<()> {
        let c = &self.camera;
        if !(1..=64).contains(&c.views) {
            return Err(Error::invalid("camera.views", c.views, "1 to 64"));
        }
        c.distance.check("camera.distance", 0.05, 20.0)?;
        c.tilt_deg.check("camera.tilt_deg", 0.0, 90.0)?;
        c.azimuth_deg.check("camera.azimuth_deg", -720.0, 720.0)?;
        c.roll_deg.check("camera.roll_deg", -360.0, 360.0)?;
        let distinct = |p: &[f32; 6]| {
            p.iter().all(|x| x.is_finite())
                && (glam::Vec3::from_slice(&p[..3]) - glam::Vec3::from_slice(&p[3..])).length()
                    > 1e-6
        };
        match c.rig {
            Rig::Fixed if !distinct(&c.look_at) => Err(Error::invalid(
                "camera.look_at",
                format!("{:?}", c.look_at),
                "[eye x, y, z, target x, y, z] with eye != target",
            )),
            Rig::List if c.poses.is_empty() || !c.poses.iter().all(distinct) => {
                Err(Error::invalid(
                    "camera.poses",
                    format!("{:?}", c.poses),
                    "a non-empty list of [eye x, y, z, target x, y, z] with eye != target",
                ))
            }
            _ if !c.up.iter().all(|x| x.is_finite()) || glam::Vec3::from(c.up).length() < 1e-6 => {
                Err(Error::invalid(
                    "camera.up",
                    format!("{:?}", c.up),
                    "a non-zero direction",
                ))
            }
            _ => Ok(()),
        }
    }
}

fn share(key: &str, x: f32) -> Result<()> {
    if (0.0..=1.0).contains(&x) {
        Ok(())
    } else {
        Err(Error::invalid(key, x, "a share from 0 to 1"))
    }
}
