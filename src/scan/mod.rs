//! `motorfactory scan`: scan OBJ, STL or PLY meshes with a simulated sensor.

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use glam::Vec3;
use motorgen::export::write_atomic;
use sensor::formats::*;
use sensor::{Frame, Units, World, look_at, nearest_surface, scan};

use crate::error::{CliError, CliResult, choice};

mod lidar;

/// Scan meshes with a simulated depth sensor and write the cloud and images.
#[derive(Debug, Args)]
pub struct ScanCmd {
    /// A mesh to scan (OBJ, STL or PLY; repeatable), FILE or FILE@MATERIAL. Each file is its own
    /// instance; a PLY written by `motorfactory motor` keeps its per-part classes and instances.
    #[arg(long = "mesh", required = true)]
    meshes: Vec<String>,
    /// The material of the meshes given without one (see `sensor::MATERIALS`).
    #[arg(long, default_value = "grey-plastic")]
    material: String,
    /// Sensor preset, or a TOML file with a full sensor specification.
    #[arg(long, default_value = "zivid-2plus-m130")]
    sensor: String,
    /// Camera position and the point it looks at: EYE_X,EYE_Y,EYE_Z,TARGET_X,TARGET_Y,TARGET_Z (m).
    #[arg(long, allow_hyphen_values = true)]
    look_at: String,
    /// World direction that appears up in the image.
    #[arg(long, default_value = "0,0,1", allow_hyphen_values = true)]
    up: String,
    /// Which pixels make a point, by Zivid's names, those the sensor offers: all; by2x2 or
    /// by4x4 (each 2×2 or 4×4 block summed into one: the Zivid 2+ R line, non-Zivid sensors);
    /// blueSubsample2x2, redSubsample2x2, blueSubsample4x4 or redSubsample4x4 (one colour's
    /// pixels of each block, under the projector's light of that colour: the Zivid 2 and 2+).
    #[arg(long, default_value = "all")]
    sampling: String,
    /// Cloud formats, comma-separated: ply, pcd, pcd-ascii, npy (SynMotor N×7), npz.
    #[arg(long, value_delimiter = ',', default_value = "ply")]
    format: Vec<String>,
    /// Also write depth, normal, label, instance and intensity images.
    #[arg(long)]
    images: bool,
    /// Frame of the written points: camera (OpenCV), world or blensor.
    #[arg(long, default_value = "camera")]
    frame: String,
    /// Units of the written points: metres or millimetres (m and mm also work).
    #[arg(long, default_value = "metres")]
    units: String,
    /// A LiDAR's velocity during its pass, metres a second along the world's axes: each laser
    /// fires from where the head is then.
    #[arg(long, default_value = "0,0,0", allow_hyphen_values = true)]
    velocity: String,
    /// A LiDAR's turn about its axis during its pass, degrees a second.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    turn: f32,
    /// Noise seed.
    #[arg(long, default_value_t = 0, allow_negative_numbers = true, value_parser = crate::error::seed)]
    seed: u64,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

fn numbers(flag: &str, text: &str, n: usize) -> CliResult<Vec<f32>> {
    let v: Vec<f32> = text
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .unwrap_or_default();
    if v.len() != n || v.iter().any(|x| !x.is_finite()) {
        return Err(CliError::Usage(format!(
            "--{flag} {text}: expected {n} comma-separated numbers"
        )));
    }
    Ok(v)
}

impl ScanCmd {
    /// Runs the command.
    pub fn run(&self) -> CliResult<()> {
        if let Some(lidar) = lidar::named(&self.sensor)? {
            return self.run_lidar(&lidar);
        }
        if self.velocity != "0,0,0" || self.turn != 0.0 {
            return Err(CliError::Usage(format!(
                "--sensor {}: a camera takes neither --velocity nor --turn (a LiDAR does)",
                self.sensor
            )));
        }
        let spec = scene::config::read_sensor(&self.sensor).map_err(|e| match e {
            scene::Error::Io { .. } => CliError::Usage(e.to_string()),
            _ => CliError::Usage(format!("--sensor {e}")),
        })?;
        let sampling: sensor::Sampling = self
            .sampling
            .parse()
            .map_err(|e| CliError::Usage(format!("--{e}")))?;
        let spec = spec
            .sampled(sampling)
            .map_err(|e| CliError::Usage(format!("--{e}")))?;
        spec.validate()
            .map_err(|e| CliError::Usage(format!("sensor {}: {e}", self.sensor)))?;
        let meshes = self.meshes()?;
        let bytes = mesh_bytes(&meshes);
        crate::memory::ensure_fits(
            spec.scan_memory().saturating_add(bytes.saturating_mul(4)),
            &format!(
                "a scan with a {}x{} sensor of {} of meshes",
                spec.intrinsics.width,
                spec.intrinsics.height,
                crate::memory::size(bytes)
            ),
            "scan at a lower resolution (a --sampling of 2x2 or 4x4 blocks) or a smaller mesh",
        )?;
        let pose = self.look(look_at, "eye and target must differ")?;
        let frame = choice(
            "frame",
            &self.frame,
            &[
                ("camera", Frame::Camera),
                ("world", Frame::World),
                ("blensor", Frame::Blensor),
            ],
        )?;
        let units = self.units()?;
        let formats = self
            .format
            .iter()
            .map(|f| choice("format", f, &CloudFormat::ALL.map(|c| (c.name(), c))))
            .collect::<CliResult<Vec<_>>>()?;
        let targets = targets(&meshes)?;
        let start = std::time::Instant::now();
        let world = World::new(&targets);
        let result = scan(&world, &spec, &pose, self.seed);
        if result.valid_count() == 0 {
            let range = format!(
                "the sensor {} measures depths (camera z) from {} to {} m",
                spec.name, spec.min_range, spec.max_range
            );
            return Err(CliError::Usage(
                match nearest_surface(&world, &spec, &pose) {
                    Some(d) => format!(
                        "the scan holds no point: {range}, and the nearest surface in view is \
                     {d:.3} m deep; move --look-at's eye"
                    ),
                    None => format!(
                        "the scan holds no point: {range}, and no surface is in view; point \
                     --look-at at the mesh"
                    ),
                },
            ));
        }
        self.create_out()?;
        let cloud = result.cloud(false, frame, units);
        for f in &formats {
            self.save(&f.file_name("cloud"), &|w| f.write(w, &cloud))?;
        }
        if self.images {
            for (name, image) in IMAGES {
                self.save(name, &|w| image(w, &result))?;
            }
        }
        let summary = serde_json::json!({
            "sensor": spec,
            "camera_to_world": pose_matrix(&pose),
            "seed": self.seed,
            "frame": frame,
            "units": units,
            "points": cloud.len(),
            "pixels": { "width": result.width, "height": result.height, "valid": result.valid_count() },
            "depth_png_metres_per_unit": DEPTH_PNG_METRES_PER_UNIT,
            "triangles": world.triangle_count(),
        });
        self.save_summary(&summary)?;
        note!(
            "{} points from {} of {} pixels ({} triangles) in {:.2} s, written to {}",
            cloud.len(),
            result.valid_count(),
            result.pixels.len(),
            world.triangle_count(),
            start.elapsed().as_secs_f64(),
            self.out.display()
        );
        Ok(())
    }
    /// The meshes and their materials: FILE@MATERIAL, or FILE with `--material`'s (a file
    /// whose name holds an @ is taken whole).
    fn meshes(&self) -> CliResult<Vec<(&Path, sensor::Material)>> {
        let material = |flag: &str, name: &str| {
            sensor::Material::named(name).map_err(|e| CliError::Usage(format!("{flag}: {e}")))
        };
        let default = material("--material", &self.material)?;
        self.meshes
            .iter()
            .map(|mesh| match mesh.rsplit_once('@') {
                Some((path, name)) if !Path::new(mesh).exists() => {
                    Ok((Path::new(path), material(&format!("--mesh {mesh}"), name)?))
                }
                _ => Ok((Path::new(mesh.as_str()), default)),
            })
            .collect()
    }

    /// `--look-at`'s eye and target and `--up`, as `pose(eye, target, up)` makes a pose of them
    /// (`None`: `needs` says what it needs).
    fn look(
        &self,
        pose: fn(Vec3, Vec3, Vec3) -> Option<glam::Affine3A>,
        needs: &str,
    ) -> CliResult<glam::Affine3A> {
        let v = numbers("look-at", &self.look_at, 6)?;
        let up = numbers("up", &self.up, 3)?;
        pose(
            Vec3::new(v[0], v[1], v[2]),
            Vec3::new(v[3], v[4], v[5]),
            Vec3::from_slice(&up),
        )
        .ok_or_else(|| CliError::Usage(format!("--look-at {}: {needs}", self.look_at)))
    }

    /// `--units`.
    fn units(&self) -> CliResult<Units> {
        choice(
            "units",
            &self.units,
            &[
                ("metres", Units::Metres),
                ("millimetres", Units::Millimetres),
                ("m", Units::Metres),
                ("mm", Units::Millimetres),
            ],
        )
    }

    /// Writes `name` in the output folder, whole or not at all.
    fn save(
        &self,
        name: &str,
        body: &dyn Fn(&mut dyn Write) -> std::io::Result<()>,
    ) -> CliResult<()> {
        write_atomic(&self.out.join(name), body).map_err(|e| CliError::Runtime(e.to_string()))
    }

    /// Writes `summary` as `scan.json`.
    fn save_summary(&self, summary: &serde_json::Value) -> CliResult<()> {
        self.save("scan.json", &|w| {
            serde_json::to_writer_pretty(&mut *w, summary)?;
            w.write_all(b"\n")
        })
    }

    /// Creates the output folder.
    fn create_out(&self) -> CliResult<()> {
        std::fs::create_dir_all(&self.out).map_err(|e| {
            CliError::Usage(format!(
                "cannot create output folder {}: {e}",
                self.out.display()
            ))
        })
    }
}

/// The bytes of the mesh files: read whole, then held as targets and in the BVH, they take
/// about four times that.
fn mesh_bytes(meshes: &[(&Path, sensor::Material)]) -> u64 {
    meshes
        .iter()
        .filter_map(|(path, _)| std::fs::metadata(path).ok())
        .map(|m| m.len())
        .sum()
}

/// The meshes as targets, each file its own instances.
fn targets(meshes: &[(&Path, sensor::Material)]) -> CliResult<Vec<sensor::Target>> {
    let mut targets = Vec::new();
    for &(path, material) in meshes {
        let offset = targets
            .iter()
            .map(|t: &sensor::Target| t.instance)
            .max()
            .unwrap_or(0);
        targets.extend(
            sensor::mesh::read(path)
                .map_err(|e| CliError::Usage(e.to_string()))?
                .into_iter()
                .map(|mut t| {
                    t.instance += offset;
                    t.material = material;
                    t
                }),
        );
    }
    Ok(targets)
}

/// Row-major 4×4 matrix.
fn pose_matrix(pose: &glam::Affine3A) -> [[f32; 4]; 4] {
    glam::Mat4::from(*pose).transpose().to_cols_array_2d()
}
