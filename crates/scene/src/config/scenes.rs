//! The scenes a sample may be of (`cell.scene`) and the settings of those beside the station:
//! `[cell.transfer]`, `[cell.handling]`, `[cell.armature]`.

use serde::{Deserialize, Serialize};

use super::Span;
use crate::error::{Error, Result};

/// What a sample's camera looks at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SceneKind {
    /// The disassembly station: one motor clamped in the fixture on the table.
    Station,
    /// Carriers on a roller conveyor's transfer unit, holding motors, seen from a mobile
    /// robot's camera.
    TransferUnit,
    /// Motors and the parts taken off them on a table, some stacked or touching.
    Handling,
    /// A motor's armature on its own, resting on two V-blocks.
    Armature,
    /// The hall: station modules, transfer units and racks beside an aisle, scanned by the
    /// LiDAR (`[lidar]`) of a mobile robot driving along it.
    Hall,
}

impl SceneKind {
    /// Its name in a configuration.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Station => "station",
            SceneKind::TransferUnit => "transfer-unit",
            SceneKind::Handling => "handling",
            SceneKind::Armature => "armature",
            SceneKind::Hall => "hall",
        }
    }
}

/// `[cell.transfer]`: the transfer unit's carriers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferConfig {
    /// `[min, max]` carriers in a row on the conveyor.
    pub carriers: [u32; 2],
    /// Share of the carriers that are flat workpiece trays (the others small load carriers,
    /// open boxes).
    pub trays: f32,
    /// `[min, max]` motors in a carrier (0: an empty carrier).
    pub motors: [u32; 2],
    /// Chance that a motor in a carrier has its cover off, lying beside it.
    pub loose_cover: f32,
    /// `[min, max]` distractors (boxes and cylinders of any colour) on the floor and the
    /// conveyor's frame.
    pub distractors: [u32; 2],
}

/// `[cell.handling]`: what lies on the table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandlingConfig {
    /// `[min, max]` whole motors.
    pub motors: [u32; 2],
    /// `[min, max]` parts taken off other motors: covers, bolts, gears, armatures, gear
    /// containers, pole pots.
    pub parts: [u32; 2],
    /// Chance that a part lands on what lies below it rather than on the table.
    pub stack: f32,
    /// Chance that a part is laid against the one before it (touching).
    pub touch: f32,
    /// Half the side of the square the objects lie in, m.
    pub spread: f32,
}

/// `[cell.armature]`: the armature on its own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmatureConfig {
    /// Share of the commutator's bars worn dark, drawn per sample.
    pub worn: Span,
    /// Share of the armature under dust, drawn per sample.
    pub dust: Span,
    /// Share of the armature under grease, drawn per sample.
    pub grease: Span,
    /// Share of the armature's steel rusted (shaft and laminations), drawn per sample.
    pub rust: Span,
}

/// `[cell.hall]`: the hall's size and what stands in it, drawn per hall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HallConfig {
    /// Length (along the aisle, x) and width (y) inside the walls, m.
    pub size: [f32; 2],
    /// `[min, max]` station modules: the station's table on legs, the fixture and a motor.
    pub stations: [u32; 2],
    /// `[min, max]` transfer units: roller conveyors, their carriers as `[cell.transfer]` draws.
    pub transfer_units: [u32; 2],
    /// `[min, max]` shelving racks with small load carriers.
    pub racks: [u32; 2],
}

impl HallConfig {
    pub(super) fn check(&self) -> Result<()> {
        let [length, width] = self.size;
        // a transfer unit's distractors reach 4.3 m from the aisle's middle
        if !(8.0..=100.0).contains(&length) || !(9.0..=60.0).contains(&width) {
            return Err(Error::invalid(
                "cell.hall.size",
                format!("{:?}", self.size),
                "[length, width] with 8 <= length <= 100 and 9 <= width <= 60 m",
            ));
        }
        let slots = 2 * crate::cell::slots_per_side(length) as u32;
        for (key, count) in [
            ("cell.hall.stations", self.stations),
            ("cell.hall.transfer_units", self.transfer_units),
            ("cell.hall.racks", self.racks),
        ] {
            check_count(key, count, slots)?;
        }
        let most = self.stations[1] + self.transfer_units[1] + self.racks[1];
        if most > slots {
            return Err(Error::Config(format!(
                "cell.hall: up to {most} stations, transfer units and racks do not fit in a \
                 hall {length} m long ({slots} places of {} m along the aisle); lower their \
                 maxima or lengthen cell.hall.size",
                crate::cell::SLOT
            )));
        }
        Ok(())
    }
}

/// `[min, max]` with min <= max <= `most`, or the error naming `key`.
pub(super) fn check_count(key: &str, count: [u32; 2], most: u32) -> Result<()> {
    if count[0] <= count[1] && count[1] <= most {
        Ok(())
    } else {
        Err(Error::invalid(
            key,
            format!("{count:?}"),
            format!("[min, max] with min <= max <= {most}"),
        ))
    }
}

impl TransferConfig {
    pub(super) fn check(&self) -> Result<()> {
        check_count("cell.transfer.carriers", self.carriers, 6)?;
        check_count("cell.transfer.motors", self.motors, 2)?;
        check_count("cell.transfer.distractors", self.distractors, 12)?;
        super::check::share("cell.transfer.trays", self.trays)?;
        super::check::share("cell.transfer.loose_cover", self.loose_cover)
    }
}

impl HandlingConfig {
    pub(super) fn check(&self) -> Result<()> {
        check_count("cell.handling.motors", self.motors, 4)?;
        check_count("cell.handling.parts", self.parts, 24)?;
        super::check::share("cell.handling.stack", self.stack)?;
        super::check::share("cell.handling.touch", self.touch)?;
        if !(0.05..=1.0).contains(&self.spread) {
            return Err(Error::invalid(
                "cell.handling.spread",
                self.spread,
                "0.05 to 1 m",
            ));
        }
        Ok(())
    }
}

impl ArmatureConfig {
    pub(super) fn check(&self) -> Result<()> {
        self.worn.check("cell.armature.worn", 0.0, 1.0)?;
        self.dust.check("cell.armature.dust", 0.0, 1.0)?;
        self.grease.check("cell.armature.grease", 0.0, 1.0)?;
        self.rust.check("cell.armature.rust", 0.0, 1.0)
    }
}
