//! `[lidar]`: the rotating LiDAR on the mobile robot that drives through the hall
//! (`cell.scene = "hall"`), how it drives, and the files of each pass.

use sensor::formats::LidarFormat;
use sensor::lidar::LidarFrame;
use sensor::{LIDAR_PRESETS, Lidar};
use serde::{Deserialize, Serialize};

use super::{Config, SceneKind, Span};
use crate::error::{Error, Result};

/// `[lidar]`: the robot's LiDAR.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarConfig {
    /// A LiDAR preset (`motorfactory scan --help` lists them).
    pub preset: String,
    /// The head's centre above the floor, m.
    pub height: f32,
    /// The robot's speed along the aisle, m/s, drawn per hall.
    pub speed: Span,
    /// Passes (revolutions) in a row of one hall as the robot drives: samples k·n to
    /// k·n + n − 1 are hall k's.
    pub revolutions: u32,
    /// Frame of the written points: `head` (the head's at each firing, as the sensor reports
    /// them), `world` or `blensor` (Blensor's axes).
    pub frame: LidarFrame,
    /// The files of each pass.
    pub formats: Vec<LidarFormat>,
}

impl LidarConfig {
    /// The preset, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Config`] for a name that is no LiDAR preset, naming them.
    pub fn resolve(&self) -> Result<Lidar> {
        Lidar::preset(&self.preset).map_err(|_| {
            Error::invalid(
                "lidar.preset",
                format!("\"{}\"", self.preset),
                format!(
                    "one of {}{}",
                    LIDAR_PRESETS.join(", "),
                    motorgen::did_you_mean(&self.preset, LIDAR_PRESETS.iter().copied())
                ),
            )
        })
    }
}

impl Config {
    /// The checks of a hall's configuration: a LiDAR that resolves, and none of the camera's
    /// outputs.
    pub(super) fn check_hall(&self) -> Result<()> {
        let l = &self.lidar;
        l.resolve()?;
        if !(0.1..=3.0).contains(&l.height) {
            return Err(Error::invalid("lidar.height", l.height, "0.1 to 3 m"));
        }
        l.speed.check("lidar.speed", 0.0, 3.0)?;
        if !(1..=100_000).contains(&l.revolutions) {
            return Err(Error::invalid(
                "lidar.revolutions",
                l.revolutions,
                "1 to 100000",
            ));
        }
        if self.cell.scene != SceneKind::Hall {
            return Ok(());
        }
        if l.formats.is_empty() {
            let names: Vec<&str> = LidarFormat::ALL.iter().map(|f| f.name()).collect();
            return Err(Error::invalid(
                "lidar.formats",
                "[]",
                format!("at least one of {}", names.join(", ")),
            ));
        }
        let o = &self.output;
        let camera = [
            (
                "output.formats",
                !o.formats.is_empty(),
                "[] (a pass's files are lidar.formats)",
            ),
            (
                "output.images",
                o.images.any(),
                "false (a LiDAR takes no images)",
            ),
            (
                "output.scene_cloud",
                o.scene_cloud,
                "false (a pass is the whole scene)",
            ),
            ("output.overlap", o.overlap, "false (a pass has one view)"),
            (
                "render.enabled",
                self.render.enabled,
                "false (a LiDAR takes no images)",
            ),
        ];
        for (key, set, allowed) in camera {
            if set {
                return Err(Error::Config(format!(
                    "{key}: must be {allowed} when cell.scene = \"hall\""
                )));
            }
        }
        Ok(())
    }
}
