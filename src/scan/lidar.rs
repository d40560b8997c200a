//! `motorfactory scan` with a rotating LiDAR: one pass of the head at `--look-at`'s eye, its
//! yaw 0 towards the target, its axis along `--up`.

use glam::Vec3;
use sensor::formats::LidarFormat;
use sensor::lidar::{LidarFrame, Motion};
use sensor::{LIDAR_PRESETS, Lidar, LidarScan, World, head_pose, scan_lidar};

use super::{ScanCmd, mesh_bytes, numbers, pose_matrix, targets};
use crate::error::{CliError, CliResult, choice};

/// The LiDAR called `name`: a preset, or a TOML file with a `lasers` table; `None` for a
/// camera's preset or file; an error naming every preset for any other name.
pub(super) fn named(name: &str) -> CliResult<Option<Lidar>> {
    if LIDAR_PRESETS.contains(&name) {
        return Lidar::preset(name)
            .map(Some)
            .map_err(|e| CliError::Usage(e.to_string()));
    }
    let shown = motorgen::shown(name);
    if !name.ends_with(".toml") {
        if sensor::PRESETS.contains(&name) {
            return Ok(None);
        }
        let all = sensor::PRESETS.iter().chain(&LIDAR_PRESETS).copied();
        return Err(CliError::Usage(format!(
            "--sensor \"{shown}\" is not allowed: expected a preset or a .toml file{}\n  \
             cameras: {}\n  LiDARs: {}",
            motorgen::did_you_mean(name, all),
            sensor::PRESETS.join(", "),
            LIDAR_PRESETS.join(", "),
        )));
    }
    let text = sensor::files::read_text(name.as_ref(), sensor::files::CONFIG_LIMIT)
        .map_err(|e| CliError::Usage(format!("--sensor {shown}: {e}")))?;
    let table: toml::Table = text
        .parse()
        .map_err(|e| CliError::Usage(format!("--sensor {shown}: {e}")))?;
    if !table.contains_key("lasers") {
        return Ok(None);
    }
    let lidar: Lidar = toml::from_str(&text)
        .map_err(|e| CliError::Usage(format!("--sensor {shown}: {}", e.message())))?;
    lidar
        .validate()
        .map_err(|e| CliError::Usage(format!("--sensor {shown}: {e}")))?;
    Ok(Some(lidar))
}

impl ScanCmd {
    /// Scans with `lidar`.
    pub(super) fn run_lidar(&self, lidar: &Lidar) -> CliResult<()> {
        let meshes = self.meshes()?;
        crate::memory::ensure_fits(
            lidar
                .pass_memory()
                .saturating_add(mesh_bytes(&meshes).saturating_mul(4)),
            &format!("a pass of {} ({} rays)", lidar.name, lidar.rays()),
            "scan a smaller mesh, or with a coarser resolution",
        )?;
        if self.sampling != "all" || self.images {
            return Err(CliError::Usage(format!(
                "--sensor {}: a LiDAR takes neither --sampling nor --images",
                self.sensor
            )));
        }
        let pose = self.look(
            head_pose,
            &format!("the target must lie off the head's axis (--up {})", self.up),
        )?;
        let frame = choice(
            "frame",
            &self.frame,
            &[
                ("camera", LidarFrame::Head),
                ("world", LidarFrame::World),
                ("blensor", LidarFrame::Blensor),
            ],
        )?;
        let units = self.units()?;
        let scale = units.scale();
        let velocity = numbers("velocity", &self.velocity, 3)?;
        if !self.turn.is_finite() {
            return Err(CliError::Usage(format!(
                "--turn {}: expected degrees a second",
                self.turn
            )));
        }
        let motion = Motion {
            velocity: Vec3::from_slice(&velocity),
            turn: self.turn,
        };
        let options = LidarFormat::ALL.map(|f| (f.name(), f));
        let formats = self
            .format
            .iter()
            .map(|f| choice("format", f, &options))
            .collect::<CliResult<Vec<_>>>()?;
        let targets = targets(&meshes)?;
        let start = std::time::Instant::now();
        let world = World::new(&targets);
        let scan = scan_lidar(&world, lidar, &pose, &motion, self.seed);
        if scan.returns.is_empty() {
            return Err(CliError::Usage(format!(
                "the scan holds no return: no surface within {} m of --look-at's eye in the \
                 lasers' field; move the eye or point --look-at at the mesh",
                lidar.max_range
            )));
        }
        self.create_out()?;
        for f in formats {
            self.write(f, &scan, frame, scale)?;
        }
        let summary = serde_json::json!({
            "sensor": lidar,
            "head_to_world": pose_matrix(&pose),
            "motion": motion,
            "seed": self.seed,
            "frame": frame,
            "units": units,
            "rays": scan.rays,
            "returns": scan.returns.len(),
            "triangles": world.triangle_count(),
        });
        self.save_summary(&summary)?;
        note!(
            "{} returns of {} rays ({} triangles) in {:.2} s, written to {}",
            scan.returns.len(),
            scan.rays,
            world.triangle_count(),
            start.elapsed().as_secs_f64(),
            self.out.display()
        );
        Ok(())
    }

    /// Writes the files of `format` (`scan.*`, a camera's cloud format `cloud.*`), points in
    /// `frame` scaled by `scale`.
    fn write(
        &self,
        format: LidarFormat,
        scan: &LidarScan,
        frame: LidarFrame,
        scale: f32,
    ) -> CliResult<()> {
        let stem = if format.cloud().is_some() {
            "cloud"
        } else {
            "scan"
        };
        for (k, name) in format.file_names(stem).iter().enumerate() {
            self.save(name, &|w| format.write(k, w, scan, frame, scale))?;
        }
        Ok(())
    }
}
