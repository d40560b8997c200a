//! Motor parameters: every user parameter of the MotorFactory add-on, in SI units (lengths in
//! metres, angles in degrees as the add-on shows them), with its range, default and the add-on's
//! own random distribution, all in one table ([`PARAMS`]).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::Error;

/// A parameter value as written in TOML, JSON or on the command line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    /// true / false.
    Bool(bool),
    /// Any number; integer parameters require a whole number.
    Num(f64),
    /// An enumeration member.
    Text(String),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{b}"),
            Value::Num(x) => write!(f, "{x}"),
            Value::Text(s) => write!(f, "\"{s}\""),
        }
    }
}

/// What a parameter accepts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A real number in `min..=max`.
    Real {
        /// Smallest allowed value.
        min: f64,
        /// Largest allowed value.
        max: f64,
    },
    /// A whole number in `min..=max` that is `min` plus a multiple of `step`.
    Int {
        /// Smallest allowed value.
        min: i64,
        /// Largest allowed value.
        max: i64,
        /// Spacing of the allowed values.
        step: i64,
    },
    /// One of the listed names.
    Enum(&'static [&'static str]),
    /// true or false.
    Bool,
}

/// How the add-on's own random generator (`auto_generate.py`, SynMotor) draws a parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Auto {
    /// Uniform over the whole allowed range (or over all members).
    Full,
    /// Uniform over a sub-range.
    Range(f64, f64),
    /// Uniform over a list, repeated entries weigh more.
    List(&'static [f64]),
    /// The k-th (1-based) upper-gear cover bolt of the add-on's random mode: the 210° arc split
    /// into `n = upper_bolt_count` slots of `a = 210/n`, bolt k drawn from
    /// `[(k - 1 + 0.2·[k>1])·a, k·a]`.
    UpperBolt(u8),
}

/// One user parameter.
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    /// Key in TOML and `--set`.
    pub key: &'static str,
    /// Accepted values.
    pub kind: Kind,
    /// Value when nothing is set.
    pub default: DefaultValue,
    /// The add-on's random distribution ("auto").
    pub auto: Auto,
    /// Meaning, unit and add-on name.
    pub doc: &'static str,
}

/// A default, stored without allocation.
#[derive(Clone, Copy, Debug)]
pub enum DefaultValue {
    /// A number.
    Num(f64),
    /// An enumeration member.
    Text(&'static str),
    /// A flag.
    Bool(bool),
}

impl DefaultValue {
    /// As a [`Value`].
    pub fn value(self) -> Value {
        match self {
            DefaultValue::Num(x) => Value::Num(x),
            DefaultValue::Text(s) => Value::Text(s.to_string()),
            DefaultValue::Bool(b) => Value::Bool(b),
        }
    }
}

use Auto::*;
use DefaultValue as D;
use Kind::*;

/// Declares every parameter once: the typed field of [`MotorParams`] and its [`ParamSpec`] in
/// [`PARAMS`] (key, accepted values, default, the add-on's distribution and the meaning, which
/// is also the field's documentation), in sampling order.
macro_rules! motor_params {
    ($($field:ident: $ty:ty = $key:literal {
        kind: $kind:expr,
        default: $default:expr,
        auto: $auto:expr,
        doc: $doc:literal,
    },)*) => {
        /// One motor's parameters: the typed view of [`PARAMS`] (a field's serialised name is its
        /// key).
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct MotorParams {
            $(
                #[doc = $doc]
                #[serde(rename = $key)]
                pub $field: $ty,
            )*
        }

        /// Every motor parameter, in sampling order (a parameter may depend on earlier ones).
        pub static PARAMS: &[ParamSpec] = &[$(ParamSpec {
            key: $key,
            kind: $kind,
            default: $default,
            auto: $auto,
            doc: $doc,
        },)*];
    };
}

motor_params! {
    motor_type: MotorType = "type" {
        kind: Enum(&["A", "B"]),
        default: D::Text("A"),
        auto: Full,
        doc: "Motor type: A has two gears (lower and upper), B one. Add-on: mf_Top_Type.",
    },
    extension_a: Extension = "extension_a" {
        kind: Enum(&["type1", "type2", "none"]),
        default: D::Text("type1"),
        auto: Full,
        doc: "Cover extension shape of type A: one mounting eye (type1), two eyes (type2) or \
               none. Add-on: mf_Extension_Type_A.",
    },
    extension_b: Extension = "extension_b" {
        kind: Enum(&["type1", "none"]),
        default: D::Text("type1"),
        auto: Full,
        doc: "Cover extension shape of type B. Add-on: mf_Extension_Type_B.",
    },
    gearbox_orientation_deg: u32 = "gearbox_orientation_deg" {
        kind: Int { min: 0, max: 270, step: 90 },
        default: D::Num(0.0),
        auto: Full,
        doc: "Rotation of gear housings, cover and cover bolts about the motor axis, \
               degrees. The add-on offered only 90-270 for A type2 and its datasets never \
               varied it; every value is valid here. Add-on: mf_Gear_Orientation_1/_2.",
    },
    mirror: bool = "mirror" {
        kind: Bool,
        default: D::Bool(false),
        auto: Full,
        doc: "Mirror the gearbox to the other side of the motor axis. Add-on: mf_Mirror.",
    },
    pole_pot_length: f32 = "pole_pot_length" {
        kind: Real { min: 0.062, max: 0.082 },
        default: D::Num(0.068),
        auto: Range(0.062, 0.08),
        doc: "Pole-pot length along the motor axis, m. The add-on's property limits (its \
               README and scripts said 4-8 cm, which Blender clamped). Add-on: \
               mf_Bottom_Length.",
    },
    shaft_boss_length: f32 = "shaft_boss_length" {
        kind: Real { min: 0.006, max: 0.02 },
        default: D::Num(0.012),
        auto: Full,
        doc: "Length of the shaft boss under the pole pot, m. Add-on: mf_Sub_Bottom_Length.",
    },
    lower_gear_diameter: f32 = "lower_gear_diameter" {
        kind: Real { min: 0.035, max: 0.045 },
        default: D::Num(0.04),
        auto: Full,
        doc: "Outer diameter of the lower (A) or only (B) gear housing, m. Add-on: \
               mf_Lower_Gear_Dia.",
    },
    lower_gear_position: f32 = "lower_gear_position" {
        kind: Real { min: 0.036, max: 0.042 },
        default: D::Num(0.036),
        auto: Full,
        doc: "Height of the lower (or only) gear centre above the pole-pot top, m. Add-on: \
               mf_Lower_Gear_Position.",
    },
    upper_gear_diameter: f32 = "upper_gear_diameter" {
        kind: Real { min: 0.05, max: 0.065 },
        default: D::Num(0.055),
        auto: Full,
        doc: "Outer diameter of the upper gear housing (type A only), m. Add-on: \
               mf_Upper_Gear_Dia.",
    },
    type_b_height_1: f32 = "type_b_height_1" {
        kind: Real { min: 0.063, max: 0.075 },
        default: D::Num(0.07),
        auto: Full,
        doc: "Type B: height of the upper end (the eye) of the gear-extension board above the \
               pole-pot top, m. The add-on's README range (1.7-4) and its script's U(6.3, 8) disagree \
               with its property limits; these are the limits. Add-on: mf_Type_B_Height_1.",
    },
    type_b_height_2: f32 = "type_b_height_2" {
        kind: Real { min: 0.03, max: 0.06 },
        default: D::Num(0.035),
        auto: Full,
        doc: "Type B: height of the lower end (the eye) of the gear-extension board above the \
               pole-pot top, m. Add-on: mf_Type_B_Height_2.",
    },
    type_b_right_bolt_height: f32 = "type_b_right_bolt_height" {
        kind: Real { min: 0.017, max: 0.04 },
        default: D::Num(0.025),
        auto: Full,
        doc: "Type B: height of the cover bolt beside the brush tower above the pole-pot \
               top, m. Add-on: mf_Gear_Bolt_Right_B.",
    },
    teeth_inclination_deg: f32 = "teeth_inclination_deg" {
        kind: Real { min: -20.0, max: 20.0 },
        default: D::Num(10.0),
        auto: Full,
        doc: "Inclination (shear) of the inner gears' teeth, degrees. Add-on: \
               mf_Teeth_Inclination.",
    },
    bolt_drive: BoltDrive = "bolt_drive" {
        kind: Enum(&["torx", "slot", "cross", "allen"]),
        default: D::Text("torx"),
        auto: Full,
        doc: "Screw drive of every bolt head. Add-on: mf_Bit_Type.",
    },
    bolt_orientation: BoltOrientation = "bolt_orientation" {
        kind: Enum(&["same", "random"]),
        default: D::Text("same"),
        auto: Full,
        doc: "Rotation of the drive about each screw axis: all bolts at bolt_rotation_deg \
               (same) or each its own angle drawn from bolt_seed (random). Add-on: \
               mf_Bolt_Orientation.",
    },
    bolt_rotation_deg: f32 = "bolt_rotation_deg" {
        kind: Real { min: 0.0, max: 360.0 },
        default: D::Num(0.0),
        auto: Full,
        doc: "Drive rotation of every bolt when bolt_orientation = \"same\", degrees.",
    },
    bolt_seed: u32 = "bolt_seed" {
        kind: Int { min: 0, max: 4_294_967_295, step: 1 },
        default: D::Num(0.0),
        auto: Full,
        doc: "Seed of the per-bolt drive rotations when bolt_orientation = \"random\" (whole \
               degrees 0-359, as the add-on).",
    },
    lower_bolt_1_deg: f32 = "lower_bolt_1_deg" {
        kind: Real { min: 190.0, max: 230.0 },
        default: D::Num(200.0),
        auto: Full,
        doc: "Type A: angle of the first lower-gear cover bolt about the gear centre, \
               degrees from the gearbox's +x towards the motor's +z. Add-on: \
               mf_Lower_Gear_Bolt_Position_1.",
    },
    lower_bolt_2_deg: f32 = "lower_bolt_2_deg" {
        kind: Real { min: 310.0, max: 350.0 },
        default: D::Num(320.0),
        auto: Full,
        doc: "Type A: angle of the second lower-gear cover bolt, degrees. The add-on's \
               property allowed 320-350 and its random mode 310-350; this is the union. \
               Add-on: mf_Lower_Gear_Bolt_Position_2.",
    },
    upper_bolt_count: u32 = "upper_bolt_count" {
        kind: Int { min: 1, max: 3, step: 1 },
        default: D::Num(2.0),
        auto: List(&[1.0, 2.0, 2.0, 3.0]),
        doc: "Type A: number of cover bolts round the upper gear. Add-on: \
               mf_Upper_Bolt_Nummber; auto as SynMotor (1, 2, 2, 3).",
    },
    upper_bolt_1_deg: f32 = "upper_bolt_1_deg" {
        kind: Real { min: 0.0, max: 210.0 },
        default: D::Num(13.0),
        auto: UpperBolt(1),
        doc: "Type A: angle of upper-gear cover bolt 1 on the 0-210° arc, degrees. Used \
               bolts must increase by at least 10°. Add-on: mf_Upper_Gear_Bolt_Position_*.",
    },
    upper_bolt_2_deg: f32 = "upper_bolt_2_deg" {
        kind: Real { min: 0.0, max: 210.0 },
        default: D::Num(110.0),
        auto: UpperBolt(2),
        doc: "Type A: angle of upper-gear cover bolt 2, degrees (the add-on's default 100 \
               lay below its own minimum 110).",
    },
    upper_bolt_3_deg: f32 = "upper_bolt_3_deg" {
        kind: Real { min: 0.0, max: 210.0 },
        default: D::Num(200.0),
        auto: UpperBolt(3),
        doc: "Type A: angle of upper-gear cover bolt 3, degrees.",
    },
    b_bolt_count: u32 = "b_bolt_count" {
        kind: Int { min: 2, max: 3, step: 1 },
        default: D::Num(2.0),
        auto: Full,
        doc: "Type B: cover bolts round the gear (the bolt beside the tower comes on top). \
               Add-on: mf_Gear_Bolt_Nummber_B, whose script always drew 2.",
    },
    b_bolt_1_deg: f32 = "b_bolt_1_deg" {
        kind: Real { min: 210.0, max: 225.0 },
        default: D::Num(215.0),
        auto: Full,
        doc: "Type B: angle of gear bolt 1 about the gear centre, degrees from the gearbox's \
               +y towards +z. Add-on: mf_Gear_Bolt_Position_B_1.",
    },
    b_bolt_2_deg: f32 = "b_bolt_2_deg" {
        kind: Real { min: 70.0, max: 110.0 },
        default: D::Num(90.0),
        auto: Full,
        doc: "Type B: angle of gear bolt 2, degrees. Add-on: mf_Gear_Bolt_Position_B_2.",
    },
    b_bolt_3_deg: f32 = "b_bolt_3_deg" {
        kind: Real { min: 130.0, max: 190.0 },
        default: D::Num(180.0),
        auto: Full,
        doc: "Type B: angle of gear bolt 3 (when b_bolt_count = 3), degrees. Add-on: \
               mf_Gear_Bolt_Position_B_3.",
    },
}

/// The spec of `key`, if it is a parameter.
pub fn spec(key: &str) -> Option<&'static ParamSpec> {
    PARAMS.iter().find(|p| p.key == key)
}

impl Kind {
    /// Human-readable description of what is allowed.
    pub fn allowed(&self) -> String {
        match *self {
            Real { min, max } => format!("a number from {min} to {max}"),
            Int { min, max, step: 1 } => format!("a whole number from {min} to {max}"),
            Int { min, max, step } => format!("one of {min} to {max} in steps of {step}"),
            Enum(names) => format!(
                "one of {}",
                names
                    .iter()
                    .map(|n| format!("\"{n}\""))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Bool => "true or false".into(),
        }
    }

    /// Whether `v` is an allowed value.
    pub fn accepts(&self, v: &Value) -> bool {
        match (*self, v) {
            // compared at the f32 precision the parameters are stored in, so values read back
            // from written parameters pass again
            (Real { min, max }, Value::Num(x)) => (min as f32..=max as f32).contains(&(*x as f32)),
            (Int { min, max, step }, Value::Num(x)) => {
                x.fract() == 0.0
                    && (min as f64..=max as f64).contains(x)
                    && (*x as i64 - min) % step == 0
            }
            (Enum(names), Value::Text(s)) => names.contains(&s.as_str()),
            (Bool, Value::Bool(_)) => true,
            _ => false,
        }
    }
}

impl ParamSpec {
    /// Checks a value for this parameter.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] naming the key, the value and what is allowed.
    pub fn check(&self, value: &Value) -> Result<(), Error> {
        if self.kind.accepts(value) {
            Ok(())
        } else {
            Err(Error::Invalid {
                key: self.key.into(),
                value: value.to_string(),
                allowed: self.kind.allowed(),
            })
        }
    }
}

/// Motor type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum MotorType {
    /// Two gears.
    A,
    /// One gear.
    B,
}

/// Cover extension shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Extension {
    /// One mounting eye (A) or an arm over the gear-extension board (B).
    Type1,
    /// Two mounting eyes (A only).
    Type2,
    /// No extension.
    None,
}

/// Screw drive of the bolt heads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoltDrive {
    /// Hexalobular (T20).
    Torx,
    /// Straight slot.
    Slot,
    /// Phillips cross.
    Cross,
    /// Hexagon socket (3 mm).
    Allen,
}

impl BoltDrive {
    /// Rotational symmetry of the recess, degrees: the saved angle is the rotation modulo this.
    pub fn symmetry_deg(self) -> f32 {
        match self {
            BoltDrive::Slot => 180.0,
            BoltDrive::Cross => 90.0,
            BoltDrive::Torx | BoltDrive::Allen => 60.0,
        }
    }
}

/// How the bolts' drives are rotated about their axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BoltOrientation {
    /// All at `bolt_rotation_deg`.
    Same,
    /// Each its own whole-degree angle from `bolt_seed`.
    Random,
}

impl Default for MotorParams {
    fn default() -> Self {
        MotorParams::from_values(&BTreeMap::new()).expect("the defaults are valid")
    }
}

/// Smallest angular gap between used upper-gear bolts, degrees (their bosses are 8 mm wide).
pub const MIN_UPPER_BOLT_GAP_DEG: f32 = 10.0;

impl MotorParams {
    /// Builds parameters from key/value pairs; missing keys take their defaults. Unknown keys,
    /// wrong types, out-of-range values and inconsistent combinations are refused.
    ///
    /// # Errors
    ///
    /// [`Error::Unknown`] for a key that is not a parameter,
    /// [`Error::Invalid`] for a value it does not allow, or the errors of
    /// [`MotorParams::validate`].
    pub fn from_values(values: &BTreeMap<String, Value>) -> Result<MotorParams, Error> {
        if let Some(key) = values.keys().find(|k| spec(k).is_none()) {
            return Err(Error::unknown(key));
        }
        let mut map = serde_json::Map::new();
        for p in PARAMS {
            let v = values
                .get(p.key)
                .cloned()
                .unwrap_or_else(|| p.default.value());
            p.check(&v)?;
            let json = match (p.kind, v) {
                (Int { .. }, Value::Num(x)) => serde_json::Value::from(x as i64),
                (_, v) => serde_json::to_value(v).expect("values serialise"),
            };
            map.insert(p.key.into(), json);
        }
        let params: MotorParams = serde_json::from_value(serde_json::Value::Object(map))
            .expect("checked values fit the typed view");
        params.validate()?;
        Ok(params)
    }

    /// The parameters as key/value pairs, in table order.
    pub fn values(&self) -> Vec<(&'static str, Value)> {
        let json = serde_json::to_value(self).expect("parameters serialise");
        PARAMS
            .iter()
            .map(|p| {
                (
                    p.key,
                    serde_json::from_value(json[p.key].clone()).expect("values deserialise"),
                )
            })
            .collect()
    }

    /// Checks the rules that tie parameters together.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a value out of range,
    /// [`Error::Conflict`] for values that cannot hold together (bolt
    /// angles too close).
    pub fn validate(&self) -> Result<(), Error> {
        if self.motor_type == MotorType::A {
            let used = &self.upper_bolt_angles_deg();
            for (k, pair) in used.windows(2).enumerate() {
                if pair[1] < pair[0] + MIN_UPPER_BOLT_GAP_DEG {
                    return Err(Error::Conflict(format!(
                        "upper_bolt_{}_deg = {} must be at least {MIN_UPPER_BOLT_GAP_DEG}° above upper_bolt_{}_deg = {}",
                        k + 2,
                        pair[1],
                        k + 1,
                        pair[0]
                    )));
                }
            }
        }
        Ok(())
    }

    /// The cover extension of this motor's type.
    pub fn extension(&self) -> Extension {
        match self.motor_type {
            MotorType::A => self.extension_a,
            MotorType::B => self.extension_b,
        }
    }

    /// The dataset variant name: A0 (no extension), A1, A2, B0, B1.
    pub fn variant(&self) -> &'static str {
        match (self.motor_type, self.extension()) {
            (MotorType::A, Extension::None) => "A0",
            (MotorType::A, Extension::Type1) => "A1",
            (MotorType::A, Extension::Type2) => "A2",
            (MotorType::B, Extension::None) => "B0",
            (MotorType::B, _) => "B1",
        }
    }

    /// Angles of the used upper-gear bolts (type A).
    pub fn upper_bolt_angles_deg(&self) -> Vec<f32> {
        [
            self.upper_bolt_1_deg,
            self.upper_bolt_2_deg,
            self.upper_bolt_3_deg,
        ][..self.upper_bolt_count as usize]
            .to_vec()
    }

    /// Angles of the used gear bolts of type B.
    pub fn b_bolt_angles_deg(&self) -> Vec<f32> {
        [self.b_bolt_1_deg, self.b_bolt_2_deg, self.b_bolt_3_deg][..self.b_bolt_count as usize]
            .to_vec()
    }
}
