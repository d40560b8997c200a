//! Path-traced colour images in datasets: lit by the drawn lights, through the colour camera's
//! lens and response, deterministic, and refused where they cannot be made.

use scene::config::{Config, default_table};
use scene::{Recipe, make};

/// The default configuration with a colour camera, its images rendered, `keys` set.
fn rendered(keys: &[(&str, toml::Value)]) -> toml::Table {
    let mut table = default_table();
    for (key, value) in [
        ("sensor.preset", "industrial-5mp".into()),
        ("sensor.sampling", "by4x4".into()),
        ("render.enabled", true.into()),
        ("render.samples", 2.into()),
        ("output.images", true.into()),
    ]
    .iter()
    .chain(keys)
    {
        scene::set_key(&mut table, key, value.clone()).unwrap();
    }
    table
}

fn rgb(table: &toml::Table, index: u64) -> Vec<[u8; 3]> {
    let recipe = Recipe::new(Config::from_table(table).unwrap(), Vec::new()).unwrap();
    let sample = make(&recipe, index).unwrap();
    let scan = sample.views[0].scan.as_ref().unwrap();
    scan.pixels.iter().map(|p| p.rgb).collect()
}

fn mean_luminance(rgb: &[[u8; 3]]) -> f32 {
    let linear = |v: u8| (f32::from(v) / 255.0).powf(2.2);
    let sum: f32 = rgb
        .iter()
        .map(|p| 0.2126 * linear(p[0]) + 0.7152 * linear(p[1]) + 0.0722 * linear(p[2]))
        .sum();
    sum / rgb.len() as f32
}

#[test]
fn a_rendered_colour_image_is_exposed_to_mid_grey_and_the_same_for_the_same_seed() {
    let table = rendered(&[]);
    let image = rgb(&table, 3);
    assert_eq!(image, rgb(&table, 3));
    assert_ne!(image, rgb(&table, 4));
    // the automatic exposure brings the mean luminance to 0.18 (what clips above 1 falls
    // short of it)
    let mean = mean_luminance(&image);
    assert!((0.12..0.2).contains(&mean), "{mean}");
    // a stop more: twice the light, within what clipping takes
    let brighter = rgb(&rendered(&[("render.exposure", 1.0.into())]), 3);
    let ratio = mean_luminance(&brighter) / mean;
    assert!((1.6..2.05).contains(&ratio), "{ratio}");
    // the lights drawn, recorded in the sample's JSON
    let recipe = Recipe::new(Config::from_table(&table).unwrap(), Vec::new()).unwrap();
    let sample = make(&recipe, 3).unwrap();
    let doc = scene::sample_json(&recipe, &sample);
    let lights = doc.lighting.as_ref().map_or(0, |l| l.lights.len());
    assert!((1..=2).contains(&lights), "{lights} lights");
    // lit by lights, not by the scan's flash: the two images differ
    let mut flash = table.clone();
    scene::set_key(&mut flash, "render.enabled", false.into()).unwrap();
    assert_ne!(image, rgb(&flash, 3));
}

#[test]
fn the_table_takes_the_drawn_colour() {
    let recipe = |colour: toml::Value| {
        let t = rendered(&[("cell.table.colour", colour)]);
        Recipe::new(Config::from_table(&t).unwrap(), Vec::new()).unwrap()
    };
    let red: toml::Value = toml::from_str::<toml::Table>("c = [[0.5, 0.1, 0.1], [0.7, 0.1, 0.1]]")
        .unwrap()["c"]
        .clone();
    for index in 0..4 {
        let sample = make(&recipe(red.clone()), index).unwrap();
        let table = sample
            .cell
            .objects
            .iter()
            .find(|o| o.name == "table")
            .unwrap();
        let [r, g, b] = table.material.colour;
        assert!(
            (0.5..=0.7).contains(&r) && g == 0.1 && b == 0.1,
            "{r} {g} {b}"
        );
    }
}

#[test]
fn renders_that_cannot_be_made_are_refused_by_key() {
    for (keys, key) in [
        (
            vec![("sensor.preset", "kinect-v1".into())],
            "render.enabled",
        ),
        (
            vec![("output.jpeg_quality", 0.into())],
            "output.jpeg_quality",
        ),
        (vec![("render.samples", 0.into())], "render.samples"),
        (vec![("render.light_block", 0.into())], "render.light_block"),
        (
            vec![
                ("render.light_block", 2.into()),
                ("render.denoise", false.into()),
            ],
            "render.light_block",
        ),
        (
            vec![(
                "lighting.lights",
                toml::Value::Array(vec![1.into(), 9.into()]),
            )],
            "lighting.lights",
        ),
        (vec![("lighting.kelvin", 100.0.into())], "lighting.kelvin"),
        (vec![("cell.table.tint", 2.0.into())], "cell.table.tint"),
    ] {
        let e = Config::from_table(&rendered(&keys))
            .unwrap_err()
            .to_string();
        assert!(e.contains(key), "{e}");
    }
}
