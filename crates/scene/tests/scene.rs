//! The cell, rigs, crop and augmentation assignment by their invariants.

use glam::Vec3;
use motorgen::kernel::inspect;
use motorgen::{Detail, ParamSpace, PartKind, Scheme, build, derive_seed};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use scene::augment::{Level, Split, assign};
use scene::config::{BUILTIN, CameraConfig, Config, Rig, default_table};
use scene::rig::camera_poses;
use scene::{Variation, compose};

#[test]
fn every_builtin_config_is_valid_over_the_default_and_shipped_in_configs() {
    // the default states every key: it reads without any other default to fall back on
    let default = default_table();
    assert_eq!(Config::from_table(&default).unwrap(), Config::default());
    let names: Vec<&str> = BUILTIN.iter().map(|(name, _)| *name).collect();
    let mut shipped: Vec<String> = std::fs::read_dir("configs")
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter_map(|f| f.strip_suffix(".toml").map(str::to_string))
        .filter(|f| f != "motors")
        .collect();
    shipped.sort();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(
        sorted, shipped,
        "BUILTIN lists every dataset config in configs/"
    );
    for (name, text) in BUILTIN {
        assert_eq!(
            std::fs::read_to_string(format!("configs/{name}.toml")).unwrap(),
            text
        );
        let mut t = default_table();
        scene::overlay(&mut t, toml::from_str(text).unwrap());
        Config::from_table(&t).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    // a key missing from the base is an error, not a silent default
    let mut partial = default_table();
    partial["camera"].as_table_mut().unwrap().remove("distance");
    let e = Config::from_table(&partial).unwrap_err().to_string();
    assert!(e.contains("camera") && e.contains("distance"), "{e}");
}

#[test]
fn motors_lie_cover_up_in_closed_fixtures_for_many_seeds() {
    let config = Config::default().cell;
    for seed in 0..40 {
        let params = ParamSpace::addon().sample(derive_seed(7, seed)).unwrap();
        let motor = build(&params, Detail::Coarse);
        let vary = Variation {
            occluders: seed % 2 == 0,
            fixture_shift: seed % 3 == 0,
            cover_removed: seed % 4 == 0,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let cell = compose(&motor, &config, vary, &mut rng);
        // cover up within the pose jitter, motor axis along world x
        let up = cell
            .motor_to_world
            .transform_vector3(motor.attributes.gears[0].axis);
        assert!(up.z > (16f32).to_radians().cos(), "{up}");
        let axis = cell.motor_to_world.transform_vector3(Vec3::Z);
        assert!(axis.x.abs() > 0.98, "{axis}");
        // every object a closed solid; unique instances; motor above the table
        let mut instances = std::collections::BTreeSet::new();
        for o in &cell.objects {
            let report = inspect(&o.mesh);
            assert!(report.is_valid_solid(), "{}: {report:?}", o.name);
            assert!(
                instances.insert(o.instance),
                "{} repeats an instance",
                o.name
            );
            if o.part.is_some() {
                assert!(o.mesh.bounds().min.z > 0.0, "{} below the table", o.name);
            }
        }
        let has = |k: PartKind| cell.objects.iter().any(|o| o.part == Some(k));
        assert_eq!(has(PartKind::Cover), !vary.cover_removed);
        assert_eq!(
            has(PartKind::LowerGear) || has(PartKind::SingleGear),
            vary.cover_removed
        );
        assert!(!has(PartKind::Magnet) && !has(PartKind::Armature));
        let panels = cell
            .objects
            .iter()
            .filter(|o| o.name.starts_with("panel"))
            .count();
        assert_eq!(panels > 0, vary.occluders);
        let shifted = cell.fixture.iter().any(|(_, s)| *s != Vec3::ZERO);
        assert_eq!(shifted, vary.fixture_shift);
        // the jaws grip the pole pot: each within 2 cm of it
        let pot = cell
            .objects
            .iter()
            .find(|o| o.part == Some(PartKind::PolePot))
            .unwrap()
            .mesh
            .bounds();
        for jaw in ["fixed_jaw", "sliding_jaw"] {
            let b = cell
                .objects
                .iter()
                .find(|o| o.name == jaw)
                .unwrap()
                .mesh
                .bounds();
            let gap = (b.min.y - pot.max.y).max(pot.min.y - b.max.y);
            assert!(gap < 0.02, "{jaw} {gap}");
        }
        // labels: background 0, parts by the scheme
        for t in cell.targets(Scheme::InnerParts) {
            let o = cell
                .objects
                .iter()
                .find(|o| o.instance == t.instance)
                .unwrap();
            let expected = o.part.map_or(0, |k| Scheme::InnerParts.id(k)) as u16;
            assert_eq!(t.classes, sensor::Classes::Uniform(expected));
        }
    }
}

#[test]
fn cap_cameras_look_at_the_motor_from_the_configured_cap() {
    let config = CameraConfig {
        views: 3,
        ..Config::default().camera
    };
    let centre = Vec3::new(0.01, -0.02, 0.06);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for i in 0..200 {
        for pose in camera_poses(&config, centre, i, &mut rng) {
            let eye = Vec3::from(pose.translation);
            let forward = pose.transform_vector3(Vec3::Z);
            let to_centre = (centre - eye).normalize();
            assert!(forward.dot(to_centre) > 0.99999);
            let d = (centre - eye).length();
            assert!((0.56 - 1e-4..=0.64 + 1e-4).contains(&d), "{d}");
            let tilt = (eye - centre).normalize().z.acos().to_degrees();
            assert!(tilt <= 15.0 + 1e-2, "{tilt}");
            // roll within ±25° of the motor axis along the image rows
            let x = pose.transform_vector3(Vec3::X);
            let flat = (Vec3::X - forward * forward.dot(Vec3::X)).normalize();
            assert!(x.dot(flat) >= (25.0f32 + 0.1).to_radians().cos(), "{x}");
        }
    }
    let fixed = CameraConfig {
        rig: Rig::Fixed,
        look_at: [0.0, 0.0, 0.5, 0.0, 0.0, 0.0],
        ..Config::default().camera
    };
    let pose = camera_poses(&fixed, centre, 0, &mut rng)[0];
    assert!((Vec3::from(pose.translation) - (centre + Vec3::new(0.0, 0.0, 0.5))).length() < 1e-6);
    // world +y appears up in the image (camera y is down)
    assert!(pose.transform_vector3(Vec3::Y).dot(Vec3::Y) < -0.999);
}

#[test]
fn levels_and_splits_hold_their_shares_in_every_prefix() {
    let a = Config::default().augment;
    let levels = [
        (Level::Clean, 0.2),
        (Level::Occluded, 0.2),
        (Level::Noisy, 0.6),
    ];
    let mut counts = std::collections::HashMap::new();
    let (mut worst_level, mut worst_split, mut worst_level_split) = (0f64, 0f64, 0f64);
    let mut validation = 0f64;
    for k in 0..10_000u64 {
        let (level, split) = assign(k, &a);
        *counts.entry((level, split)).or_insert(0u32) += 1;
        validation += f64::from(u8::from(split == Split::Validation));
        let n = (k + 1) as f64;
        worst_split = worst_split.max((validation - 0.2 * n).abs());
        for (l, share) in levels {
            let count = |s: Split| f64::from(counts.get(&(l, s)).copied().unwrap_or(0));
            let c = count(Split::Train) + count(Split::Validation);
            // low-discrepancy sequences: every prefix within three samples of its shares
            worst_level = worst_level.max((c - share * n).abs());
            // the split follows its own sequence: within a level, its share holds more loosely
            let v = count(Split::Validation);
            worst_level_split = worst_level_split.max((v - 0.2 * c).abs());
        }
    }
    assert!(
        worst_level <= 3.0,
        "a level's count is {worst_level} off its share"
    );
    assert!(
        worst_split <= 3.0,
        "the validation count is {worst_split} off its share"
    );
    assert!(
        worst_level_split <= 12.0,
        "a level's validation count is {worst_level_split} off its share"
    );
}

#[test]
fn a_sample_json_reads_back_as_written() {
    let mut table = scene::config::builtin_table("registration").unwrap();
    scene::set_key(&mut table, "sensor.binning", 4.into()).unwrap();
    let out = std::env::temp_dir().join("never-written");
    let dataset = scene::Dataset::new(table, None, None, scene::Shard::ALL, &out).unwrap();
    let sample = scene::make(&dataset.recipe(5).unwrap(), 5).unwrap();
    let files = vec![vec!["train/a.ply".to_string()]; sample.views.len()];
    let doc = sample.json(&dataset.recipe(5).unwrap(), &files);
    let text = doc.to_text();
    let back: scene::SampleJson = serde_json::from_str(&text).unwrap();
    let again = back.to_text();
    if again != text {
        let line = again.lines().zip(text.lines()).position(|(a, b)| a != b);
        let at = line.unwrap_or(0);
        panic!(
            "line {at}: {:?} vs {:?}",
            again.lines().nth(at),
            text.lines().nth(at)
        );
    }
    assert_eq!(back.views.len(), 2);
    assert_eq!(back.views[1].files, files[1]);
    assert!(back.objects.iter().any(|o| o.part.is_some() && o.class > 0));
    // the keys of every object in sorted order, as the dataset writes them
    let at = |key: &str| text.find(&format!("\n  \"{key}\"")).unwrap();
    assert!(
        at("cover_removed") < at("crop") && at("sensor") < at("split") && at("units") < at("views")
    );
}
