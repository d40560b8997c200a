//! BOP scenes (`output.bop`): the layout of the Benchmark for 6D Object Pose Estimation's
//! datasets (BOP-scenewise). Each sample is a scene, `bop/{train_pbr,val_pbr}/{index:06}/`, its
//! views the scene's images: the colour image, depth (0.1 mm a step), every annotated object's
//! silhouette (`mask`) and visible pixels (`mask_visib`), `scene_camera.json`, `scene_gt.json`
//! and `scene_gt_info.json` as BOP defines them. A motor differs from sample to sample, so its
//! model is the scene's own: `obj_id` is the object's class under the scheme, and each entry's
//! `instance_id` names its model, `models/instance_{id:06}.ply` (mm, about its box's centre),
//! whose diameter and box `models/models_info.json` gives.

pub mod model;

use std::collections::BTreeMap;
use std::io::{Result, Write};

use glam::{Affine3A, Mat3};
use sensor::Scan;
use sensor::formats::{DEPTH_PNG_METRES_PER_UNIT, write_depth_png, write_mask_png};
use serde_json::{Map, Value, json};

use crate::augment::Split;
use crate::config::OutputConfig;
use crate::sample::Sample;
use crate::silhouette::Silhouette;
use model::{MM, Model};

/// The BOP folder, relative to the dataset folder.
pub const FOLDER: &str = "bop";

/// BOP's name of a split's folder: physically based renderings for training and validation.
pub fn split_folder(split: Split) -> &'static str {
    match split {
        Split::Train => "train_pbr",
        Split::Validation => "val_pbr",
    }
}

/// A scene's subfolders.
pub const SCENE_FOLDERS: [&str; 5] = ["rgb", "depth", "mask", "mask_visib", "models"];

/// BOP's `depth_scale`: millimetres per step of the depth image.
pub const DEPTH_SCALE: f64 = 0.1;
const _: () = {
    let step = DEPTH_PNG_METRES_PER_UNIT * MM;
    assert!(step - DEPTH_SCALE as f32 <= 1e-7 && DEPTH_SCALE as f32 - step <= 1e-7);
};

/// Writes one file.
pub type Writer<'a> = Box<dyn Fn(&mut dyn Write) -> Result<()> + Sync + 'a>;

/// What a view shows of a model.
struct Seen<'a> {
    /// Model frame to camera, metres.
    to_camera: Affine3A,
    /// Its pixels whatever lies in front.
    silhouette: &'a Silhouette,
    /// Its silhouette's pixels with a depth.
    valid: usize,
    /// Its visible pixels and their box.
    visible: usize,
    visible_box: Option<[usize; 4]>,
}

/// What view `k` of `sample` shows of each of `models` (posed in the view's own cell).
fn seen<'a>(
    sample: &'a Sample,
    k: usize,
    models: &[Model],
    output: &OutputConfig,
) -> Vec<Seen<'a>> {
    let view = &sample.views[k];
    let scan = view.scan.as_ref().expect("a BOP view keeps its scan");
    let cell = sample.cell_of(view);
    let silhouettes = sample.silhouettes(k, output.scheme);
    let from_world = view.pose.inverse();
    let visible = visible_pixels(scan);
    let width = scan.width as usize;
    models
        .iter()
        .map(|m| {
            let to_world = m.to_world(&cell.objects, output.scheme);
            let silhouette = &silhouettes[&m.instance];
            let ([x0, y0], [w, _]) = (silhouette.origin, silhouette.size);
            let valid = (silhouette.inside.iter().enumerate())
                .filter(|&(i, &b)| b && scan.pixels[(y0 + i / w) * width + x0 + i % w].is_valid())
                .count();
            let (visible, visible_box) = visible.get(&m.instance).copied().unwrap_or_default();
            Seen {
                to_camera: from_world * to_world,
                silhouette,
                valid,
                visible,
                visible_box,
            }
        })
        .collect()
}

/// Each instance's visible pixels in `scan` (those whose surface it is) and their tight box.
fn visible_pixels(scan: &Scan) -> BTreeMap<u32, (usize, Option<[usize; 4]>)> {
    let w = scan.width as usize;
    let mut seen: BTreeMap<u32, (usize, [usize; 4])> = BTreeMap::new();
    for (i, p) in scan.pixels.iter().enumerate().filter(|(_, p)| p.is_valid()) {
        let (x, y) = (i % w, i / w);
        let e = seen.entry(p.instance).or_insert((0, [x, y, x, y]));
        let b = &mut e.1;
        e.0 += 1;
        *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    }
    seen.into_iter()
        .map(|(id, (n, [x0, y0, x1, y1]))| (id, (n, Some([x0, y0, x1 - x0 + 1, y1 - y0 + 1]))))
        .collect()
}

/// A box as BOP writes it: [-1, -1, -1, -1] for none.
fn box_json(b: Option<[usize; 4]>) -> Value {
    b.map_or(json!([-1, -1, -1, -1]), |b| json!(b))
}

/// A pose's rotation row-major and its translation in mm, as BOP writes them.
fn rotation_translation(t: &Affine3A) -> (Vec<f64>, Vec<f64>) {
    let r = Mat3::from(t.matrix3).transpose().to_cols_array();
    let t = t.translation.to_array();
    (
        r.iter().map(|&x| f64::from(x)).collect(),
        t.iter().map(|&x| f64::from(x * MM)).collect(),
    )
}

/// The folder of sample `index`'s scene, relative to the dataset folder.
pub fn scene_folder(split: Split, index: u64) -> String {
    format!("{FOLDER}/{}/{index:06}", split_folder(split))
}

/// `sample` as a BOP scene: every file (its path relative to the dataset folder, in the order
/// written) with its writer. Its views must have kept their scans.
pub fn scene_files<'a>(sample: &'a Sample, output: &'a OutputConfig) -> Vec<(String, Writer<'a>)> {
    let folder = scene_folder(sample.split, sample.index);
    let models = model::models(&sample.cell.objects, output.scheme);
    let views: Vec<Vec<Seen>> = (0..sample.views.len())
        .map(|k| seen(sample, k, &models, output))
        .collect();
    let k = &sample.sensor.intrinsics;
    let (mut cameras, mut gts, mut infos) = (Map::new(), Map::new(), Map::new());
    let mut files: Vec<(String, Writer<'a>)> = Vec::new();
    for (i, (view, seen)) in sample.views.iter().zip(views).enumerate() {
        let scan = view.scan.as_ref().expect("a BOP view keeps its scan");
        let (r, t) = rotation_translation(&view.pose.inverse());
        let mut camera = json!({
            "cam_K": [k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0],
            "depth_scale": DEPTH_SCALE,
            "cam_R_w2c": r,
            "cam_t_w2c": t,
        });
        let d = &k.distortion;
        if !d.is_none() {
            camera["dist_coeffs"] = json!([d.k1, d.k2, d.p1, d.p2, d.k3]);
        }
        cameras.insert(i.to_string(), camera);
        let gt: Vec<Value> = models
            .iter()
            .zip(&seen)
            .map(|(m, s)| {
                let (r, t) = rotation_translation(&s.to_camera);
                json!({"cam_R_m2c": r, "cam_t_m2c": t, "obj_id": m.obj_id, "instance_id": m.instance})
            })
            .collect();
        gts.insert(i.to_string(), Value::Array(gt));
        let info: Vec<Value> = seen
            .iter()
            .map(|s| {
                let all = s.silhouette.area();
                json!({
                    "bbox_obj": box_json(s.silhouette.bbox()),
                    "bbox_visib": box_json(s.visible_box),
                    "px_count_all": all,
                    "px_count_valid": s.valid,
                    "px_count_visib": s.visible,
                    "visib_fract": if all == 0 { 0.0 } else { s.visible as f64 / all as f64 },
                })
            })
            .collect();
        infos.insert(i.to_string(), Value::Array(info));
        let format = output.image_format;
        let quality = output.jpeg_quality;
        files.push((
            format!("{folder}/rgb/{i:06}.{}", format.extension()),
            Box::new(move |w| format.write(w, scan, quality)),
        ));
        files.push((
            format!("{folder}/depth/{i:06}.png"),
            Box::new(move |w| write_depth_png(w, scan, false)),
        ));
        let size = (scan.width, scan.height);
        for (g, (m, s)) in models.iter().zip(seen).enumerate() {
            let instance = m.instance;
            let silhouette = s.silhouette;
            files.push((
                format!("{folder}/mask/{i:06}_{g:06}.png"),
                Box::new(move |w| write_mask_png(w, size, &|x, y| silhouette.contains(x, y))),
            ));
            files.push((
                format!("{folder}/mask_visib/{i:06}_{g:06}.png"),
                Box::new(move |w| {
                    write_mask_png(w, size, &|x, y| {
                        let p = &scan.pixels[y * scan.width as usize + x];
                        p.is_valid() && p.instance == instance
                    })
                }),
            ));
        }
    }
    for (name, doc) in [
        ("scene_camera", cameras),
        ("scene_gt", gts),
        ("scene_gt_info", infos),
    ] {
        let doc = Value::Object(doc);
        files.push((format!("{folder}/{name}.json"), json_writer(doc)));
    }
    let info: Map<String, Value> = models
        .iter()
        .map(|m| (m.instance.to_string(), model::info(m)))
        .collect();
    files.push((
        format!("{folder}/models/models_info.json"),
        json_writer(Value::Object(info)),
    ));
    for m in models {
        files.push((
            format!("{folder}/models/instance_{:06}.ply", m.instance),
            Box::new(move |w| model::write_ply(w, &m)),
        ));
    }
    files
}

/// Writes `doc` as pretty JSON.
fn json_writer<'a>(doc: Value) -> Writer<'a> {
    Box::new(move |w| {
        serde_json::to_writer_pretty(&mut *w, &doc)?;
        w.write_all(b"\n")
    })
}

/// The dataset's `camera.json` (the first sample's `sensor`'s camera), BOP's camera for
/// simulation (each image's own is in its scene's `scene_camera.json`).
pub fn camera(sensor: &sensor::SensorSpec) -> Value {
    let k = &sensor.intrinsics;
    json!({
        "cx": k.cx,
        "cy": k.cy,
        "depth_scale": DEPTH_SCALE,
        "fx": k.fx,
        "fy": k.fy,
        "height": k.height,
        "width": k.width,
    })
}
