//! `preview`: a sample's cloud drawn from its camera in class colours, or a contact sheet of the
//! first samples of a dataset.

use std::path::{Path, PathBuf};

use clap::Args;
use glam::{Affine3A, Mat4, Vec3};
use motorgen::export::write_atomic;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::DefaultElement;
use scene::preview::{Image, contact_sheet, render};
use scene::{Row, SampleJson};

use crate::error::{CliError, CliResult};
use sensor::mesh::number;

/// Draw a sample's cloud from its camera, coloured by class; or, for a dataset folder, a contact
/// sheet of its first samples.
#[derive(Debug, Args)]
pub struct PreviewCmd {
    /// A sample's `.json`, or a dataset folder.
    sample: PathBuf,
    /// Output PNG (a `.png` file in an existing folder).
    #[arg(long)]
    out: PathBuf,
    /// Width of each preview, 16 to 8192 pixels.
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Samples on a contact sheet, from 1.
    #[arg(long, default_value_t = 16, value_parser = crate::error::count)]
    count: u64,
}

impl PreviewCmd {
    /// Runs the command.
    pub fn run(&self) -> CliResult<()> {
        if !(16..=8192).contains(&self.width) {
            return Err(CliError::Usage(format!(
                "--width {}: expected 16 to 8192 pixels",
                self.width
            )));
        }
        if !self
            .out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"))
        {
            return Err(CliError::Usage(format!(
                "--out {}: a preview is a PNG image; name it NAME.png",
                self.out.display()
            )));
        }
        let folder = self.out.parent().filter(|p| !p.as_os_str().is_empty());
        if folder.is_some_and(|p| !p.is_dir()) {
            return Err(CliError::Usage(format!(
                "--out {}: the folder {} does not exist",
                self.out.display(),
                folder.unwrap_or(Path::new(".")).display()
            )));
        }
        let image = if self.sample.is_dir() {
            let count = usize::try_from(self.count).unwrap_or(usize::MAX);
            let jsons = first_samples(&self.sample, count)?;
            let images = jsons
                .iter()
                .map(|j| preview(j, self.width))
                .collect::<CliResult<Vec<_>>>()?;
            let columns = (images.len() as f64).sqrt().ceil() as usize;
            contact_sheet(&images, columns)
        } else {
            preview(&self.sample, self.width)?
        };
        write_atomic(&self.out, &|w| image.write_png(w))
            .map_err(|e| CliError::Runtime(e.to_string()))?;
        note!(
            "{}x{} preview written to {}",
            image.width,
            image.height,
            self.out.display()
        );
        Ok(())
    }
}

/// The most bytes a manifest may hold (a row is about 300 bytes).
const MANIFEST_LIMIT: u64 = 4 << 30;

/// The JSON files of the first `count` samples listed in a dataset's manifests.
fn first_samples(dir: &Path, count: usize) -> CliResult<Vec<PathBuf>> {
    let bad = |why: String| CliError::Usage(format!("dataset {}: {why}", dir.display()));
    let mut rows = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| bad(e.to_string()))? {
        let path = entry.map_err(|e| bad(e.to_string()))?.path();
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with("manifest") && name.ends_with(".jsonl") {
            let text =
                sensor::files::read_text(&path, MANIFEST_LIMIT).map_err(|e| bad(e.to_string()))?;
            rows.extend(
                text.lines()
                    .filter_map(|l| serde_json::from_str::<Row>(l).ok()),
            );
        }
    }
    if rows.is_empty() {
        return Err(bad("no manifest rows: is it a motorfactory dataset?".into()));
    }
    // a sharded dataset lists its samples in the shards' manifests and in the merged one
    rows.sort_by_key(|r| r.index);
    rows.dedup_by_key(|r| r.index);
    Ok(rows
        .into_iter()
        .take(count)
        .map(|r| dir.join(r.json))
        .collect())
}

/// The preview of one sample's first view.
fn preview(json: &Path, width: u32) -> CliResult<Image> {
    let bad = |why: String| CliError::Usage(format!("sample {}: {why}", json.display()));
    let text = sensor::files::read_text(json, sensor::files::CONFIG_LIMIT)
        .map_err(|e| bad(e.to_string()))?;
    let doc: SampleJson = serde_json::from_str(&text).map_err(|e| {
        if serde_json::from_str::<scene::pass::PassJson>(&text).is_ok() {
            bad("a LiDAR pass of the hall; preview draws a camera's samples".into())
        } else {
            bad(e.to_string())
        }
    })?;
    let view = doc.views.first().ok_or_else(|| bad("no views".into()))?;
    let root = json
        .parent()
        .and_then(Path::parent)
        .unwrap_or(Path::new("."));
    let file = view
        .files
        .iter()
        .find(|f| f.ends_with(".ply") || f.ends_with(".npy"))
        .ok_or_else(|| bad("no .ply or .npy cloud: add ply or npy to output.formats".into()))?;
    let (points, classes) = read_cloud(&root.join(file)).map_err(bad)?;
    let pose = Affine3A::from_mat4(Mat4::from_cols_array_2d(&view.camera_to_world).transpose());
    let to_camera = doc.frame.from_camera(&pose).inverse();
    let scale = 1.0 / doc.units.scale();
    let camera: Vec<Vec3> = points
        .iter()
        .map(|p| to_camera.transform_point3(*p * scale))
        .collect();
    let palette = doc.scheme.classes();
    let colors: Vec<[u8; 3]> = classes
        .iter()
        .map(|&c| palette.get(c as usize).map_or([255; 3], |k| k.color))
        .collect();
    Ok(render(&camera, &colors, &doc.sensor.intrinsics, width))
}

/// Points and classes of a PLY (x y z class) or SynMotor NPY (x y z r g b label) cloud.
fn read_cloud(path: &Path) -> Result<(Vec<Vec3>, Vec<u16>), String> {
    let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    if path.extension().is_some_and(|e| e == "npy") {
        let bytes = std::fs::read(path).map_err(|e| fail(&e))?;
        let npy = npyz::NpyFile::new(&bytes[..]).map_err(|e| fail(&e))?;
        if npy.shape().get(1) != Some(&7) {
            return Err(fail(&"expected an N x 7 array"));
        }
        let v: Vec<f32> = npy.into_vec().map_err(|e| fail(&e))?;
        Ok(v.chunks_exact(7)
            .map(|r| (Vec3::new(r[0], r[1], r[2]), r[6] as u16))
            .unzip())
    } else {
        let mut f = std::io::BufReader::new(std::fs::File::open(path).map_err(|e| fail(&e))?);
        let ply = Parser::<DefaultElement>::new()
            .read_ply(&mut f)
            .map_err(|e| fail(&e))?;
        let vertices = ply
            .payload
            .get("vertex")
            .ok_or_else(|| fail(&"no vertex element"))?;
        Ok(vertices
            .iter()
            .map(|v| {
                let get = |k: &str| v.get(k).and_then(number).unwrap_or(f64::NAN) as f32;
                (
                    Vec3::new(get("x"), get("y"), get("z")),
                    v.get("class").and_then(number).unwrap_or(0.0) as u16,
                )
            })
            .unzip())
    }
}
