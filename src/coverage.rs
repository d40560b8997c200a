//! `motorfactory coverage`: how much of a motor's surface the views of a configuration's camera
//! rig cover at the inspection station.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use motorgen::export::write_atomic;
use scene::coverage::Rule;
use scene::sample::matrix;
use scene::{Clamping, Dataset, Shard, Station};
use sensor::PointCloud;
use sensor::formats::{CloudFormat, write_npy_i32, write_surface_ply};

use crate::error::{CliError, CliResult, choice};
use crate::generate::{config_table, scene_error};

/// Measure the surface coverage of a motor clamped at the inspection station.
#[derive(Debug, Args)]
pub struct CoverageCmd {
    /// Dataset configuration (TOML) whose motors, cell, camera rig and sensor are used; the
    /// built-in default when absent, or a name from `motorfactory config --list`.
    #[arg(long)]
    config: Option<String>,
    /// Override a config key, as for `generate` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// The sample whose motor is inspected (the motor `generate` makes for it).
    #[arg(long, default_value_t = 0, value_parser = crate::error::seed)]
    index: u64,
    /// How the motor is clamped: gear-container-up or pole-pot-up (default: the config's
    /// cell.clamping).
    #[arg(long)]
    clamping: Option<String>,
    /// Views, their poses drawn from the config's camera rig (default: camera.views).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1000))]
    views: Option<u32>,
    /// Surface samples per square metre.
    #[arg(long, default_value_t = 2e5)]
    density: f32,
    /// A measured point within this distance of a sample observes it, m.
    #[arg(long, default_value_t = 0.002)]
    radius: f32,
    /// Largest angle between a sample's normal and the directions to the camera and the
    /// projector, degrees.
    #[arg(long, default_value_t = 75.0)]
    max_angle: f32,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

impl CoverageCmd {
    /// Runs the command.
    pub fn run(&self) -> CliResult<()> {
        let mut table = config_table(self.config.as_deref(), &self.sets)?;
        if let Some(v) = self.views {
            scene::set_key(&mut table, "camera.views", i64::from(v).into()).map_err(scene_error)?;
        }
        let dataset =
            Dataset::new(table, None, None, Shard::ALL, "".as_ref()).map_err(scene_error)?;
        let recipe = dataset.recipe(self.index).map_err(scene_error)?;
        let config = &recipe.config;
        let clamping = match &self.clamping {
            Some(c) => choice("clamping", c, &Clamping::ALL.map(|c| (c.name(), c)))?,
            None => config.cell.clamping,
        };
        let rule = Rule {
            radius: self.radius,
            max_angle_deg: self.max_angle,
        };
        let start = std::time::Instant::now();
        let mut station =
            Station::new(&recipe, self.index, clamping, self.density, rule).map_err(scene_error)?;
        let poses = station.rig_poses(&config.camera, self.index);
        let mut first_view = vec![-1i32; station.surface.len()];
        let mut views = Vec::new();
        for (k, pose) in poses.iter().enumerate() {
            let got = station.capture(pose);
            for (f, &seen) in first_view.iter_mut().zip(&station.seen) {
                if seen && *f < 0 {
                    *f = k as i32;
                }
            }
            views.push(serde_json::json!({
                "camera_to_world": matrix(pose),
                "gain": got.gain,
                "coverage": station.coverage().0,
                "points": got.points,
            }));
        }
        let (total, parts) = station.coverage();
        std::fs::create_dir_all(&self.out).map_err(|e| {
            CliError::Usage(format!(
                "cannot create output folder {}: {e}",
                self.out.display()
            ))
        })?;
        let save = |name: &str, body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>| {
            write_atomic(&self.out.join(name), body).map_err(|e| CliError::Runtime(e.to_string()))
        };
        let scheme = config.output.scheme;
        let s = &station.surface;
        // the surface samples: observed green, never observed red
        let surface = PointCloud {
            xyz: s.points.clone(),
            normal: s.normals.clone(),
            intensity: vec![0.0; s.len()],
            snr: vec![0.0; s.len()],
            rgb: station
                .seen
                .iter()
                .map(|&seen| if seen { [40, 200, 60] } else { [220, 40, 40] })
                .collect(),
            class: s.parts.iter().map(|&k| scheme.id(k) as u16).collect(),
            instance: s.instances.clone(),
            wear: vec![0.0; s.len()],
        };
        save("surface.ply", &|w| write_surface_ply(w, &surface))?;
        save("first_view.npy", &|w| write_npy_i32(w, &first_view))?;
        for (k, cloud) in station.clouds.iter().enumerate() {
            save(&format!("view_{k}.ply"), &|w| {
                CloudFormat::Ply.write(w, cloud)
            })?;
        }
        let summary = serde_json::json!({
            "config_index": self.index,
            "variant": station.variant,
            "clamping": clamping.name(),
            "sensor": recipe.sensor().name,
            "surface": {
                "samples": s.len(),
                "area_per_sample_m2": s.area,
                "density_per_m2": self.density,
            },
            "rule": { "radius_m": self.radius, "max_angle_deg": self.max_angle },
            "coverage": total,
            "coverage_per_part": parts.iter().map(|(k, c)| (k.name(), *c)).collect::<std::collections::BTreeMap<_, _>>(),
            "views": views,
            "frame": "world",
            "scheme": scheme,
        });
        save("coverage.json", &|w| {
            serde_json::to_writer_pretty(&mut *w, &summary)?;
            w.write_all(b"\n")
        })?;
        note!(
            "{} views of motor {} ({}) cover {:.1} % of its surface ({} samples) in {:.2} s; \
             written to {}",
            poses.len(),
            self.index,
            clamping.name(),
            100.0 * total,
            s.len(),
            start.elapsed().as_secs_f64(),
            self.out.display()
        );
        Ok(())
    }
}
