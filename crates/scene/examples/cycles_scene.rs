//! Writes a sample of a built-in configuration as a scene for Cycles
//! (`fidelity/images/render_cycles.py`), with this renderer's frames of it, for the image datasets'
//! comparison in `docs/images.md`:
//!
//!     cargo run --release -p scene --example cycles_scene -- transfer-unit 3 OUT_DIR
//!
//! `OUT_DIR/scene.json`: the camera (a pinhole: the sensor's intrinsics without distortion, no
//! depth of field, no motion), the sample's lights, every object's triangles and material, and
//! the exposure (the automatic exposure of the converged frame); `OUT_DIR/ours.png`: the
//! frame at the configuration's samples, bounces, denoising and light block;
//! `OUT_DIR/ours-converged.png`: at 256 paths and 3 bounces; both 8-bit sRGB at that exposure,
//! without the camera's noise. The seconds the sample takes in full (scan, render, annotations)
//! and each frame are printed.

use std::time::Instant;

use scene::{Config, Recipe, make};
use sensor::render::{Settings, render};
use sensor::{Distortion, World};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [name, index, out] = &args[..] else {
        eprintln!("usage: cycles_scene CONFIG INDEX OUT_DIR");
        std::process::exit(2);
    };
    let index: u64 = index.parse().expect("a sample index");
    let table = scene::config::builtin_table(name).expect("a built-in configuration");
    let recipe = Recipe::new(
        Config::from_table(&table).expect("a configuration"),
        Vec::new(),
    )
    .expect("a recipe");
    let t = Instant::now();
    let sample = make(&recipe, index).expect("the sample");
    println!(
        "sample {index} of {name}: {:.3} s in full",
        t.elapsed().as_secs_f64()
    );
    let lighting = sample
        .lighting
        .clone()
        .expect("a configuration that renders");
    let scheme = recipe.config.output.scheme;
    let world = World::new(&sample.cell.targets(scheme));
    let mut k = sample.sensor.intrinsics;
    k.distortion = Distortion::default();
    let pose = sample.views[0].pose;
    let frame = |samples, bounces, denoise, light_block| {
        let settings = Settings {
            samples,
            bounces,
            seed: 1,
            denoise,
            light_block,
            ..Settings::default()
        };
        let t = Instant::now();
        let image = render(&world, &k, &pose, &lighting, &settings).expect("a frame");
        println!(
            "{samples} paths, {bounces} bounces, denoised {denoise}, light block {light_block}: {:.3} s",
            t.elapsed().as_secs_f64()
        );
        image
    };
    let converged = frame(256, 3, false, 1);
    let r = &recipe.config.render;
    let ours = frame(r.samples, r.bounces, r.denoise, r.light_block);
    let exposure = 0.18 / converged.mean_luminance();
    std::fs::create_dir_all(out).expect("the output folder");
    for (file, image) in [("ours.png", &ours), ("ours-converged.png", &converged)] {
        let bytes: Vec<u8> = image
            .pixels
            .iter()
            .flatten()
            .map(|&v| sensor::render::srgb8(v * exposure))
            .collect();
        let f = std::fs::File::create(format!("{out}/{file}")).expect("a file");
        let mut e = png::Encoder::new(f, k.width, k.height);
        e.set_color(png::ColorType::Rgb);
        e.write_header()
            .and_then(|mut w| w.write_image_data(&bytes))
            .expect("a PNG");
    }
    let objects: Vec<serde_json::Value> = sample
        .cell
        .objects
        .iter()
        .map(|o| {
            serde_json::json!({
                "name": o.name,
                "positions": o.mesh.positions.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>(),
                "triangles": o.mesh.triangles.iter().flatten().collect::<Vec<&u32>>(),
                "material": o.material,
            })
        })
        .collect();
    let doc = serde_json::json!({
        "config": name,
        "index": index,
        "camera": {
            "width": k.width, "height": k.height, "fx": k.fx, "fy": k.fy, "cx": k.cx, "cy": k.cy,
            "camera_to_world": scene::sample::matrix(&pose),
        },
        "lighting": lighting,
        "exposure": exposure,
        "objects": objects,
    });
    std::fs::write(format!("{out}/scene.json"), doc.to_string()).expect("scene.json");
}
