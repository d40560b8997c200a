//! The colour renderer against Cycles. `fidelity/appearance/reference.py` rendered each scene of
//! `fidelity/appearance/scenes.json` with Cycles (bpy 5.0.1) into `reference/`; here the same
//! scene is rendered by `sensor::render` (the motors: ours, built from the same parameters, in
//! the work cell's part materials) and compared: SSIM over the frame and the CIEDE2000
//! difference of each part's mean colour. `--nocapture` prints the table of
//! `docs/appearance.md`; `MOTORFACTORY_APPEARANCE_OUT=DIR` also writes our frames and
//! side-by-side pictures there.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use motorgen::{Detail, MotorParams, PartKind};
use palette::color_difference::Ciede2000;
use palette::{IntoColor, Lab, Srgb};
use sensor::render::{Lighting, Settings, render};
use sensor::wear::{Mask, Rust, Wear, coverage_threshold};
use sensor::{Classes, Intrinsics, Material, Target, World, look_at, shapes};
use serde::Deserialize;

#[derive(Deserialize)]
struct Spec {
    camera: CameraSpec,
    lighting: Lighting,
    #[serde(default)]
    objects: Vec<Shape>,
    motor: Option<MotorSpec>,
    #[serde(default)]
    parts: Vec<String>,
    samples: u32,
}

#[derive(Deserialize)]
struct CameraSpec {
    width: u32,
    height: u32,
    hfov_deg: f64,
    eye: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
}

#[derive(Deserialize)]
struct Shape {
    shape: String,
    #[serde(default)]
    centre: [f32; 3],
    #[serde(default)]
    radius: f32,
    #[serde(default)]
    n: usize,
    #[serde(default)]
    half_u: [f32; 3],
    #[serde(default)]
    half_v: [f32; 3],
    material: Material,
    part: Option<u32>,
}

#[derive(Deserialize)]
struct MotorSpec {
    params: BTreeMap<String, motorgen::params::Value>,
    /// The add-on's own corrosion render, if on.
    corrosion: Option<Corrosion>,
    /// Rust laid by our coverage mask, if any.
    wear: Option<WearSpec>,
}

/// The add-on's corrosion settings (its percent on the bolts and the pole pot).
#[derive(Deserialize)]
struct Corrosion {
    bolt_percent: f32,
    pole_pot_percent: f32,
}

/// Our coverage mask on some parts, with what the oracle builds from it.
#[derive(Deserialize)]
struct WearSpec {
    parts: Vec<String>,
    share: f32,
    threshold: f32,
    rust: u8,
    colour: [f32; 3],
    spread: f32,
}

/// The add-on's divisor of its percent below 50 % (it draws one from 250 to 279): the middle.
const ADDON_DIVISOR: f32 = 265.0;

/// The wear our part of `kind` takes in `m`.
fn wear(m: &MotorSpec, part: &motorgen::Part) -> Option<Wear> {
    let rust1 = Rust::new(1).unwrap();
    let texture = scene::cell::texture(part, &glam::Affine3A::IDENTITY);
    let g = group(part.kind);
    if let Some(w) = &m.wear {
        let rust = Rust::new(w.rust).unwrap();
        // the oracle's nodes are built from these: they must be ours
        assert!((w.threshold - coverage_threshold(w.share)).abs() < 1e-6);
        assert_eq!((w.colour, w.spread), rust.look());
        let mask = Mask::Coverage { share: w.share };
        return w
            .parts
            .iter()
            .any(|p| p == g)
            .then_some(Wear::new(texture, mask, rust));
    }
    let c = m.corrosion.as_ref()?;
    let percent = match g {
        "bolts" => c.bolt_percent,
        "pole pot" => c.pole_pot_percent,
        _ => return None,
    };
    let threshold = percent / ADDON_DIVISOR;
    Some(Wear::new(texture, Mask::Addon { threshold }, rust1))
}

/// The comparison's name for a part of ours (the add-on's objects are grouped alike).
fn group(kind: PartKind) -> &'static str {
    match kind {
        PartKind::PolePot => "pole pot",
        PartKind::SideBolt | PartKind::CoverBolt => "bolts",
        PartKind::ElectricConnection => "electric connection",
        PartKind::GearContainer => "gear container",
        PartKind::Cover => "cover",
        PartKind::Magnet => "magnets",
        PartKind::Armature => "armature",
        PartKind::LowerGear | PartKind::UpperGear | PartKind::SingleGear => "gears",
    }
}

fn fidelity() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fidelity/appearance")
}

/// The scene's targets, each with its part number (0 for none).
fn targets(spec: &Spec) -> Vec<(Target, u32)> {
    let mut out = Vec::new();
    for (k, s) in spec.objects.iter().enumerate() {
        let tris = match s.shape.as_str() {
            "sphere" => shapes::sphere(s.centre.into(), s.radius, s.n),
            _ => shapes::rectangle(s.centre.into(), s.half_u.into(), s.half_v.into()),
        };
        let target = Target::from_triangles(&tris, 1, k as u32 + 1, s.material);
        out.push((target, s.part.unwrap_or(0)));
    }
    if let Some(m) = &spec.motor {
        let params = MotorParams::from_values(&m.params).unwrap();
        let motor = motorgen::build(&params, Detail::Normal);
        for part in &motor.parts {
            let number = spec
                .parts
                .iter()
                .position(|g| g == group(part.kind))
                .unwrap() as u32;
            let target = Target {
                positions: part.mesh.positions.clone(),
                triangles: part.mesh.triangles.clone(),
                classes: Classes::Uniform(1),
                instance: 1000 + part.instance,
                material: scene::cell::material(part.kind),
                wear: wear(m, part),
            };
            out.push((target, number + 1));
        }
    }
    out
}

/// An 8-bit image: width, height, channels and bytes.
struct Picture {
    width: usize,
    height: usize,
    channels: usize,
    data: Vec<u8>,
}

fn read_png(path: &Path) -> Picture {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut data = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut data).unwrap();
    data.truncate(info.buffer_size());
    Picture {
        width: info.width as usize,
        height: info.height as usize,
        channels: info.color_type.samples(),
        data,
    }
}

fn write_png(path: &Path, width: usize, height: usize, rgb: &[u8]) {
    let mut e = png::Encoder::new(
        std::io::BufWriter::new(std::fs::File::create(path).unwrap()),
        width as u32,
        height as u32,
    );
    e.set_color(png::ColorType::Rgb);
    e.write_header().unwrap().write_image_data(rgb).unwrap();
}

/// Mean structural similarity (Wang et al. 2004: 11×11 Gaussian window of σ 1.5, K1 0.01,
/// K2 0.03, windows wholly inside the frame) of two 8-bit RGB frames, averaged over channels.
fn ssim(a: &[u8], b: &[u8], width: usize, height: usize) -> f64 {
    const R: usize = 5;
    let weights: Vec<f64> = (0..=2 * R)
        .map(|i| (-((i as f64 - R as f64).powi(2)) / (2.0 * 1.5 * 1.5)).exp())
        .collect();
    let total: f64 = weights.iter().sum::<f64>().powi(2);
    let (c1, c2) = ((0.01f64 * 255.0).powi(2), (0.03f64 * 255.0).powi(2));
    let mut sum = 0.0;
    let mut count = 0;
    for channel in 0..3 {
        let at = |img: &[u8], x: usize, y: usize| f64::from(img[(y * width + x) * 3 + channel]);
        for y in R..height - R {
            for x in R..width - R {
                let (mut ma, mut mb, mut aa, mut bb, mut ab) = (0.0, 0.0, 0.0, 0.0, 0.0);
                for j in 0..=2 * R {
                    for i in 0..=2 * R {
                        let w = weights[i] * weights[j] / total;
                        let (p, q) = (at(a, x + i - R, y + j - R), at(b, x + i - R, y + j - R));
                        ma += w * p;
                        mb += w * q;
                        aa += w * p * p;
                        bb += w * q * q;
                        ab += w * p * q;
                    }
                }
                let (va, vb, cov) = (aa - ma * ma, bb - mb * mb, ab - ma * mb);
                sum += ((2.0 * ma * mb + c1) * (2.0 * cov + c2))
                    / ((ma * ma + mb * mb + c1) * (va + vb + c2));
                count += 1;
            }
        }
    }
    sum / count as f64
}

/// The mean colour of the pixels `pick` selects, averaged in linear light, as CIELAB (D65).
fn mean_lab(rgb: &[u8], pick: impl Fn(usize) -> bool) -> Option<(Lab, usize)> {
    let (mut sum, mut n) = ([0.0f32; 3], 0);
    for (k, px) in rgb.chunks(3).enumerate() {
        if pick(k) {
            let linear = Srgb::new(px[0], px[1], px[2])
                .into_format::<f32>()
                .into_linear();
            sum[0] += linear.red;
            sum[1] += linear.green;
            sum[2] += linear.blue;
            n += 1;
        }
    }
    (n > 0).then(|| {
        let mean = palette::LinSrgb::new(sum[0], sum[1], sum[2]) / n as f32;
        (mean.into_color(), n)
    })
}

struct Row {
    scene: String,
    ssim: f64,
    /// Per part (the whole frame first): name, pixels in Cycles' frame, ΔE2000.
    parts: Vec<(String, usize, f32)>,
}

fn compare(name: &str, spec: &Spec) -> Row {
    let c = &spec.camera;
    let aspect = f64::from(c.height) / f64::from(c.width);
    let vfov = 2.0
        * ((c.hfov_deg.to_radians() / 2.0).tan() * aspect)
            .atan()
            .to_degrees();
    let camera = Intrinsics::from_fov(c.width, c.height, c.hfov_deg, vfov);
    let pose = look_at(c.eye.into(), c.target.into(), c.up.into()).unwrap();
    let targets = targets(spec);
    let world = World::new(&targets.iter().map(|t| t.0.clone()).collect::<Vec<_>>());
    let settings = Settings {
        samples: spec.samples,
        bounces: 4,
        seed: 0,
        ..Settings::default()
    };
    let ours = render(&world, &camera, &pose, &spec.lighting, &settings)
        .unwrap()
        .to_srgb8();
    let dir = fidelity().join("reference");
    let cycles = read_png(&dir.join(format!("{name}.png")));
    assert_eq!(
        (cycles.width, cycles.height),
        (c.width as usize, c.height as usize)
    );
    assert_eq!(cycles.channels, 3);
    let (w, h) = (cycles.width, cycles.height);
    if let Some(out) = std::env::var_os("MOTORFACTORY_APPEARANCE_OUT") {
        let out = Path::new(&out);
        std::fs::create_dir_all(out).unwrap();
        write_png(&out.join(format!("{name}-ours.png")), w, h, &ours);
        let mut both = Vec::with_capacity(2 * ours.len());
        for row in 0..h {
            both.extend_from_slice(&cycles.data[row * w * 3..(row + 1) * w * 3]);
            both.extend_from_slice(&ours[row * w * 3..(row + 1) * w * 3]);
        }
        write_png(
            &out.join(format!("{name}-cycles-ours.png")),
            2 * w,
            h,
            &both,
        );
    }
    let mut parts = Vec::new();
    let whole = |_: usize| true;
    let (a, n) = mean_lab(&cycles.data, whole).unwrap();
    parts.push((
        "frame".into(),
        n,
        a.difference(mean_lab(&ours, whole).unwrap().0),
    ));
    if !spec.parts.is_empty() {
        let theirs = read_png(&dir.join(format!("{name}-parts.png")));
        // ours: the part number of the surface each pixel's centre ray meets
        let number_of: BTreeMap<u32, u32> = targets.iter().map(|(t, p)| (t.instance, *p)).collect();
        let mine: Vec<u32> = (0..w * h)
            .map(|k| {
                let ray = camera.ray((k % w) as f64, (k / w) as f64);
                world
                    .cast(
                        pose.translation.into(),
                        pose.transform_vector3(ray),
                        f32::INFINITY,
                    )
                    .map_or(0, |hit| number_of[&hit.instance])
            })
            .collect();
        for (k, part) in spec.parts.iter().enumerate() {
            let number = k as u32 + 1;
            let in_theirs = |i: usize| (u32::from(theirs.data[i]) + 10) / 20 == number;
            let pair = (
                mean_lab(&cycles.data, in_theirs),
                mean_lab(&ours, |i| mine[i] == number),
            );
            if let (Some((a, n)), Some((b, _))) = pair {
                parts.push((part.clone(), n, a.difference(b)));
            }
        }
    }
    Row {
        scene: name.into(),
        ssim: ssim(&cycles.data, &ours, w, h),
        parts,
    }
}

#[test]
fn the_renderer_stands_beside_cycles() {
    let text = std::fs::read_to_string(fidelity().join("scenes.json")).unwrap();
    // every scene but the pattern (the wear masks' own test, sensor::wear)
    let scenes: BTreeMap<String, serde_json::Value> = serde_json::from_str(&text).unwrap();
    let rows: Vec<Row> = scenes
        .into_iter()
        .filter(|(_, s)| s.get("pattern").is_none())
        .map(|(n, s)| compare(&n, &serde_json::from_value(s).unwrap()))
        .collect();
    println!("| scene | SSIM | part | pixels | ΔE2000 |\n|---|---|---|---|---|");
    for r in &rows {
        for (k, (part, n, de)) in r.parts.iter().enumerate() {
            let head = if k == 0 {
                format!("{} | {:.3}", r.scene, r.ssim)
            } else {
                " | ".into()
            };
            println!("| {head} | {part} | {n} | {de:.2} |");
        }
    }
    for r in &rows {
        assert!(r.ssim >= 0.90, "{}: SSIM {:.3}", r.scene, r.ssim);
        for (part, n, de) in &r.parts {
            // parts of a few pixels have no meaningful mean
            if *n >= 30 {
                assert!(*de <= 5.0, "{} {part}: ΔE2000 {de:.2}", r.scene);
            }
        }
    }
}
