//! The cell, rigs, crop and augmentation assignment by their invariants.

use glam::Vec3;
use motorgen::kernel::inspect;
use motorgen::{Detail, ParamSpace, PartKind, Scheme, build, derive_seed};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use scene::config::{BUILTIN, CameraConfig, Config, Rig, default_table};
use scene::rig::camera_poses;
use scene::{Clamping, Recipe, Variation, compose};

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
fn a_configs_noise_and_colour_keys_change_those_keys_and_keep_the_presets_others() {
    fn table(value: &impl serde::Serialize) -> toml::Table {
        toml::Table::try_from(value).unwrap()
    }
    for (name, text) in BUILTIN {
        let mut t = default_table();
        scene::overlay(&mut t, toml::from_str(text).unwrap());
        let config = Config::from_table(&t).unwrap();
        let sensor = config.sensor.resolve().unwrap();
        // the same camera, sampled and resized alike, without the config's keys
        let mut bare = config.sensor.clone();
        (bare.noise, bare.colour) = (None, None);
        let preset = bare.resolve().unwrap();
        for (keys, ours, theirs) in [
            (
                &config.sensor.noise,
                table(&sensor.noise),
                table(&preset.noise),
            ),
            (
                &config.sensor.colour,
                table(&sensor.colour),
                table(&preset.colour),
            ),
        ] {
            let set = keys.clone().unwrap_or_default();
            for (key, value) in &theirs {
                if !set.contains_key(key) {
                    assert_eq!(ours.get(key), Some(value), "{name}: {key}");
                }
            }
        }
        if name == "zivid" {
            // the Zivid mirrors the stripes as the preset does, with the jitter it adds
            assert!(sensor.noise.interreflection.enabled);
            assert_eq!(sensor.noise.lateral_px, 0.3);
        }
    }
}

/// Each of `n` samples' depth scale: the mean of measured over true depth of its view's pixels,
/// and the calibration seed of its camera, with `sensor.cameras = cameras`.
fn depth_scales(cameras: i64, n: u64) -> Vec<(f64, u64)> {
    let mut t = default_table();
    for (key, value) in [
        ("sensor.sampling", "blueSubsample4x4".into()),
        ("sensor.cameras", cameras.into()),
        ("output.images", true.into()),
    ] {
        scene::set_key(&mut t, key, value).unwrap();
    }
    let recipe = Recipe::new(Config::from_table(&t).unwrap(), Vec::new()).unwrap();
    (0..n)
        .map(|index| {
            let sample = scene::make(&recipe, index).unwrap();
            let scan = sample.views[0].scan.as_ref().unwrap();
            let ratios: Vec<f64> = scan
                .pixels
                .iter()
                .filter(|p| p.is_valid())
                .map(|p| f64::from(p.point.z / p.clean.z))
                .collect();
            let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
            (mean, sample.sensor.calibration.seed)
        })
        .collect()
}

fn spread(values: &[f64]) -> f64 {
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64).sqrt()
}

#[test]
fn each_sample_draws_its_camera_or_one_of_the_configured_cameras() {
    // a camera per sample: the depth scale varies by the calibration's σ (5e-4 for the M60)
    let own = depth_scales(0, 8);
    let scales: Vec<f64> = own.iter().map(|s| s.0).collect();
    assert!(spread(&scales) > 2e-4, "{scales:?}");
    // one camera: every sample's scale the same, up to the noise and the warp over its pixels
    let one = depth_scales(1, 8);
    let scales: Vec<f64> = one.iter().map(|s| s.0).collect();
    assert!(spread(&scales) < 6e-5, "{scales:?}");
    assert!(one.iter().all(|s| s.1 == 0), "the preset's own camera");
    // three cameras: seeds 0, 1, 2
    let three = depth_scales(3, 12);
    let seeds: std::collections::BTreeSet<u64> = three.iter().map(|s| s.1).collect();
    assert_eq!(seeds.into_iter().collect::<Vec<_>>(), [0, 1, 2]);
}

#[test]
fn motors_lie_cover_up_or_stand_pole_pot_up_in_closed_fixtures_for_many_seeds() {
    let config = Config::default().cell;
    for seed in 0..40 {
        let params = ParamSpace::addon().sample(derive_seed(7, seed)).unwrap();
        let motor = build(&params, Detail::Coarse);
        let vary = Variation {
            occluders: seed % 2 == 0,
            fixture_shift: seed % 3 == 0,
            cover_removed: seed % 4 == 0,
            clamping: Clamping::ALL[usize::from(seed % 5 < 2)],
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let cell = compose(&motor, &config, vary, &mut rng);
        let gear = cell
            .motor_to_world
            .transform_vector3(motor.attributes.gears[0].axis);
        let axis = cell.motor_to_world.transform_vector3(Vec3::Z);
        let centre = |k: PartKind| {
            let o = cell.objects.iter().find(|o| o.part == Some(k)).unwrap();
            o.mesh.bounds().centre()
        };
        let held = match vary.clamping {
            Clamping::GearContainerUp => {
                // cover up within the pose jitter, motor axis along world x
                assert!(gear.z > (16f32).to_radians().cos(), "{gear}");
                assert!(axis.x.abs() > 0.98, "{axis}");
                PartKind::PolePot
            }
            Clamping::PolePotUp => {
                // motor axis vertical within the jitter, the pole pot above the gear container
                assert!(axis.z.abs() > (16f32).to_radians().cos(), "{axis}");
                assert!(centre(PartKind::PolePot).z > centre(PartKind::GearContainer).z + 0.02);
                assert!(gear.x > 0.98, "{gear}");
                PartKind::GearContainer
            }
        };
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
        // the jaws grip the held part: each within 2 cm of it
        let pot = cell
            .objects
            .iter()
            .find(|o| o.part == Some(held))
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
fn a_sample_json_reads_back_as_written() {
    let mut table = scene::config::builtin_table("registration").unwrap();
    scene::set_key(&mut table, "sensor.sampling", "blueSubsample4x4".into()).unwrap();
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

#[test]
fn registration_pairs_record_their_overlap() {
    let table = scene::config::builtin_table("registration").unwrap();
    let out = std::env::temp_dir().join("never-written");
    let dataset = scene::Dataset::new(table, None, None, scene::Shard::ALL, &out).unwrap();
    for index in 0..4 {
        let recipe = dataset.recipe(index).unwrap();
        let sample = scene::make(&recipe, index).unwrap();
        let files = vec![Vec::new(); sample.views.len()];
        let doc = sample.json(&recipe, &files);
        let rows = overlaps(&doc);
        eprintln!("sample {index}: {rows:?}");
        assert_eq!(rows.len(), 2);
        for (a, row) in rows.iter().enumerate() {
            assert_eq!(row.len(), 2);
            assert_eq!(row[a], 1.0);
            assert!(row.iter().all(|x| (0.5..=1.0).contains(x)), "{row:?}");
        }
    }
    // off unless asked for: the default dataset's JSON has no overlap
    let default = scene::Dataset::new(
        scene::config::builtin_table("default").unwrap(),
        None,
        None,
        scene::Shard::ALL,
        &out,
    )
    .unwrap();
    let recipe = default.recipe(0).unwrap();
    let sample = scene::make(&recipe, 0).unwrap();
    assert!(sample.overlap.is_none());
    assert!(
        !sample
            .json(&recipe, &[Vec::new()])
            .to_text()
            .contains("overlap")
    );
}

/// The crop's offsets are the lying motor's: with the motor standing the box turns with it, and
/// still holds the whole motor (untouched, the standing pole pot's end would be cut off).
#[test]
fn a_standing_motors_crop_turns_with_it_and_holds_it_whole() {
    let mut table = scene::config::builtin_table("default").unwrap();
    scene::set_key(&mut table, "cell.clamping", "pole-pot-up".into()).unwrap();
    scene::set_key(&mut table, "sensor.sampling", "blueSubsample4x4".into()).unwrap();
    let recipe = Recipe::new(Config::from_table(&table).unwrap(), Vec::new()).unwrap();
    for index in 0..5 {
        let sample = scene::make(&recipe, index).unwrap();
        let motor = scene::cell::transform_box(
            &sample.motor.attributes.bounds,
            &sample.cell.motor_to_world,
        );
        assert!(
            sample.crop.min.cmple(motor.min).all() && sample.crop.max.cmpge(motor.max).all(),
            "sample {index}: crop {:?} cuts the motor {motor:?}",
            sample.crop
        );
        // the box is the lying one turned: long along the motor's axis, now vertical
        let size = sample.crop.size();
        assert!(size.z > size.x && size.z > size.y, "sample {index}: {size}");
        // the cloud reaches the motor's top (its highest vertex)
        let highest = sample
            .motor
            .parts
            .iter()
            .flat_map(|p| &p.mesh.positions)
            .map(|&v| sample.cell.motor_to_world.transform_point3(v).z)
            .fold(f32::NEG_INFINITY, f32::max);
        let to_world = sample.views[0].pose;
        let top = sample.views[0]
            .cloud
            .xyz
            .iter()
            .zip(&sample.views[0].cloud.class)
            .filter(|(_, c)| **c > 0)
            .map(|(p, _)| to_world.transform_point3(*p).z)
            .fold(f32::NEG_INFINITY, f32::max);
        assert!(
            top > highest - 0.003,
            "sample {index}: top {top}, motor {highest}"
        );
    }
}

#[test]
fn reclamped_views_carry_the_motors_pose_in_their_own_cell() {
    let mut table = scene::config::builtin_table("registration").unwrap();
    for (key, value) in [
        ("cell.reclamp", toml::Value::Boolean(true)),
        ("output.clean", true.into()),
        ("sensor.sampling", "blueSubsample4x4".into()),
        ("camera.views", 3.into()),
    ] {
        scene::set_key(&mut table, key, value).unwrap();
    }
    let out = std::env::temp_dir().join("never-written");
    let dataset = scene::Dataset::new(table, None, None, scene::Shard::ALL, &out).unwrap();
    for index in 0..3 {
        let recipe = dataset.recipe(index).unwrap();
        let sample = scene::make(&recipe, index).unwrap();
        let doc = sample.json(&recipe, &vec![Vec::new(); 3]);
        let clampings: Vec<_> = doc.views.iter().map(|v| v.clamping.unwrap()).collect();
        assert_eq!(
            clampings,
            [
                Clamping::GearContainerUp,
                Clamping::PolePotUp,
                Clamping::GearContainerUp
            ]
        );
        let bounds = sample.motor.attributes.bounds;
        for (v, view) in sample.views.iter().zip(&doc.views) {
            // every motor point, taken back to the motor frame by its view's ground truth, lies
            // on the motor
            let to_motor = matrix(&view.motor_to_camera).inverse();
            let motor_points: Vec<Vec3> = v
                .cloud
                .xyz
                .iter()
                .zip(&v.cloud.class)
                .filter(|(_, c)| **c > 0)
                .map(|(p, _)| to_motor.transform_point3(*p))
                .collect();
            assert!(motor_points.len() > 1000, "{}", motor_points.len());
            for p in motor_points {
                assert!(
                    p.cmpge(bounds.min - 1e-3).all() && p.cmple(bounds.max + 1e-3).all(),
                    "sample {index}: {p} off the motor"
                );
            }
            let world = matrix(&view.motor_to_world.unwrap());
            assert!(world.abs_diff_eq(glam::Mat4::from(sample.cell_of(v).motor_to_world), 1e-6));
        }
        // the two clampings' motor poses differ by a quarter turn, less the pose jitter (over
        // 60°: the trace of the turn under 1 + 2 cos 60°)
        let (a, b) = (
            &sample.cell.motor_to_world,
            &sample.reclamped.as_ref().unwrap().motor_to_world,
        );
        let turn = (a.matrix3 * b.matrix3.transpose()).to_cols_array();
        let trace = turn[0] + turn[4] + turn[8];
        assert!(trace < 2.0, "{trace}");
        let overlap = overlaps(&doc);
        eprintln!("sample {index}: overlap {overlap:?}");
        assert!((0..3).all(|k| overlap[k][k] == 1.0));
    }
    // a reclamping needs two views
    let mut one = scene::config::builtin_table("registration").unwrap();
    scene::set_key(&mut one, "cell.reclamp", true.into()).unwrap();
    scene::set_key(&mut one, "camera.views", 1.into()).unwrap();
    let Err(e) = scene::Dataset::new(one, None, None, scene::Shard::ALL, &out) else {
        panic!("reclamp with one view accepted")
    };
    assert!(
        e.to_string().contains("camera.views = 1 is not allowed"),
        "{e}"
    );
}

/// Each view's overlap row of a sample's JSON.
fn overlaps(doc: &scene::SampleJson) -> Vec<Vec<f32>> {
    doc.views
        .iter()
        .map(|v| v.overlap.clone().unwrap())
        .collect()
}

/// A row-major matrix of a sample's JSON as a glam matrix.
fn matrix(m: &[[f32; 4]; 4]) -> glam::Mat4 {
    glam::Mat4::from_cols_array_2d(m).transpose()
}

/// The default dataset's colours come from the camera, not the labels: the gear container and
/// the cover share a plastic, so their rgb tells them apart no better than chance would, and
/// every class shows many colours.
#[test]
fn colour_does_not_give_the_label_away() {
    let table = scene::config::builtin_table("default").unwrap();
    let out = std::env::temp_dir().join("never-written");
    let dataset = scene::Dataset::new(table, None, None, scene::Shard::ALL, &out).unwrap();
    let recipe = dataset.recipe(0).unwrap();
    let scheme = recipe.config.output.scheme;
    let (container, cover) = (
        scheme.id(PartKind::GearContainer) as u16,
        scheme.id(PartKind::Cover) as u16,
    );
    let (mut right, mut total) = (0usize, 0usize);
    for index in 0..4 {
        let sample = scene::make(&recipe, index).unwrap();
        let cloud = &sample.views[0].cloud;
        let colours = |class: u16| -> Vec<[f32; 3]> {
            (0..cloud.len())
                .filter(|&i| cloud.class[i] == class)
                .map(|i| cloud.rgb[i].map(f32::from))
                .collect()
        };
        let (a, b) = (colours(container), colours(cover));
        if a.len() < 100 || b.len() < 100 {
            continue;
        }
        let mean = |v: &[[f32; 3]]| {
            let n = v.len() as f32;
            [0, 1, 2].map(|c| v.iter().map(|p| p[c]).sum::<f32>() / n)
        };
        let (ma, mb) = (mean(&a), mean(&b));
        let nearer_a = |p: &[f32; 3]| {
            let d = |m: [f32; 3]| (0..3).map(|c| (p[c] - m[c]).powi(2)).sum::<f32>();
            d(ma) < d(mb)
        };
        // the best a nearest-mean rule on colour does, each class weighed alike
        let hit_a = a.iter().filter(|p| nearer_a(p)).count() as f64 / a.len() as f64;
        let hit_b = b.iter().filter(|p| !nearer_a(p)).count() as f64 / b.len() as f64;
        right += ((hit_a + hit_b) * 500.0) as usize;
        total += 1000;
        // no class has a single colour
        let distinct = |v: &[[f32; 3]]| {
            let mut keys: Vec<[u32; 3]> = v.iter().map(|p| p.map(|x| x as u32)).collect();
            keys.sort_unstable();
            keys.dedup();
            keys.len()
        };
        assert!(distinct(&a) > 20 && distinct(&b) > 20);
    }
    assert!(
        total > 0,
        "no sample showed both the gear container and the cover"
    );
    let accuracy = right as f64 / total as f64;
    assert!(
        accuracy < 0.7,
        "colour tells container from cover {accuracy}"
    );
}

/// Wear drawn per sample: the bolts, the pole pot and the gear container's screws' seats carry
/// their rust in the cloud's wear channel, no other part does (dust is not rust), and the same
/// seed draws the same wear.
#[test]
fn worn_samples_carry_the_share_of_rust_on_the_parts_that_rust() {
    let mut table = scene::config::builtin_table("default").unwrap();
    let span = toml::Value::Array(vec![0.3.into(), 0.6.into()]);
    scene::set_key(&mut table, "cell.wear.bolts", span.clone()).unwrap();
    scene::set_key(&mut table, "cell.wear.pole_pot", span.clone()).unwrap();
    scene::set_key(&mut table, "cell.wear.dust", span).unwrap();
    let all = toml::Value::Array(vec![1.0.into(), 1.0.into()]);
    scene::set_key(&mut table, "cell.wear.screw_seats", all).unwrap();
    scene::set_key(&mut table, "cell.wear.variation", 0.2.into()).unwrap();
    scene::set_key(&mut table, "cell.wear.grain", true.into()).unwrap();
    scene::set_key(&mut table, "sensor.sampling", "blueSubsample4x4".into()).unwrap();
    let config = Config::from_table(&table).unwrap();
    let scheme = config.output.scheme;
    let recipe = Recipe::new(config, Vec::new()).unwrap();
    let rusting = [
        PartKind::PolePot,
        PartKind::SideBolt,
        PartKind::CoverBolt,
        PartKind::GearContainer,
    ]
    .map(|k| scheme.id(k) as u16);
    let sample = scene::make(&recipe, 1).unwrap();
    let cloud = &sample.views[0].cloud;
    let worn = |f: &dyn Fn(u16) -> bool| {
        let w: Vec<f32> = cloud
            .class
            .iter()
            .zip(&cloud.wear)
            .filter(|(c, _)| f(**c))
            .map(|(_, w)| *w)
            .collect();
        w.iter().sum::<f32>() / w.len().max(1) as f32
    };
    let on_pot = worn(&|c| c == rusting[0]);
    assert!((0.15..0.75).contains(&on_pot), "pole pot {on_pot}");
    // the gear container rusts at its screws' seats alone
    let housing = worn(&|c| c == rusting[3]);
    assert!((0.001..0.6).contains(&housing), "gear container {housing}");
    assert_eq!(worn(&|c| !rusting.contains(&c)), 0.0);
    // the sample's JSON says what was drawn
    let json = sample.json(&recipe, &[Vec::new()]);
    for o in &json.objects {
        let rust = o.wear.as_ref().and_then(|w| w.rust);
        match o.part {
            Some(PartKind::PolePot) => assert!(rust.is_some_and(|r| (0.3..=0.6).contains(&r))),
            None => assert!(o.wear.is_none(), "{}", o.name),
            _ => {}
        }
    }
    let again = scene::make(&recipe, 1).unwrap();
    assert_eq!(again.views[0].cloud.wear, cloud.wear);
    assert_eq!(again.views[0].cloud.rgb, cloud.rgb);
}

/// An armature's object shows its shaft, lamination stack, windings and commutator where its
/// mesh has them, each its material: the winding packs (the shells beyond the core) copper,
/// the core grey steel, wherever the motor stands in the world.
#[test]
fn an_armature_shows_its_shaft_laminations_windings_and_commutator() {
    use sensor::wear::{ArmatureSurface, Grain};
    let params = ParamSpace::addon().sample(derive_seed(7, 3)).unwrap();
    let motor = build(&params, Detail::Coarse);
    let layout = motorgen::armature_layout(&params);
    let to_world = glam::Affine3A::from_rotation_translation(
        glam::Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 0.3),
        Vec3::new(0.2, -0.1, 0.05),
    );
    let object =
        scene::cell::armature(&motor, &to_world, scene::cell::Kind::Loose, 0.0, 0).unwrap();
    let wear = object.wear.unwrap();
    let Grain::Armature(surfaces) = wear.grain else {
        panic!("{:?}", wear.grain)
    };
    let from_world = to_world.inverse();
    let mut area = std::collections::HashMap::new();
    let m = &object.mesh;
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let centre = (a + b + c) / 3.0;
        let surface = surfaces.surface(wear.texture.transform_point3(centre));
        *area.entry(surface).or_insert(0.0) += 0.5 * (b - a).cross(c - a).length();
        // the packs alone lie beyond the core
        let local = from_world.transform_point3(centre);
        let beyond = [a, b, c]
            .map(|p| from_world.transform_point3(p).truncate().length())
            .iter()
            .all(|&r| r > layout.core_radius + 5e-5);
        assert_eq!(surface == ArmatureSurface::Windings, beyond, "{local}");
        if surface == ArmatureSurface::Commutator {
            let [lo, hi] = layout.commutator;
            assert!((lo - 1e-4..=hi + 1e-4).contains(&local.z), "{local}");
        }
        // the surface's material: copper windings and commutator, grey steel elsewhere
        let (_, material) = wear.at(&object.material, centre).unwrap();
        let [r, g, b] = material.colour;
        let coppery = r > 1.3 * g && g > b;
        let grey = (r - b).abs() < 0.1 * r.max(0.02);
        match surface {
            ArmatureSurface::Windings => assert!(coppery, "{:?}", material.colour),
            ArmatureSurface::Shaft | ArmatureSurface::Laminations => {
                assert!(grey, "{surface:?}: {:?}", material.colour)
            }
            ArmatureSurface::Commutator => assert!(coppery || r < 0.1, "{:?}", material.colour),
        }
    }
    let total: f32 = area.values().sum();
    for s in [
        ArmatureSurface::Shaft,
        ArmatureSurface::Laminations,
        ArmatureSurface::Windings,
        ArmatureSurface::Commutator,
    ] {
        let share = area.get(&s).copied().unwrap_or(0.0) / total;
        assert!(share > 0.01, "{s:?}: {share}");
    }
}

/// Alone in a view, a part's silhouette is exactly its pixels in a noise-free scan (the same
/// rays), and
/// behind another part it is more than its visible pixels.
#[test]
fn a_parts_silhouette_alone_is_its_pixels_in_the_scan() {
    use scene::silhouette::Silhouette;
    use sensor::{Classes, SensorSpec, Target, World};
    let params = ParamSpace::addon().sample(derive_seed(7, 5)).unwrap();
    let motor = build(&params, Detail::Coarse);
    let target = |kind: PartKind, instance: u32| {
        let part = motor.parts.iter().find(|p| p.kind == kind).unwrap();
        Target {
            positions: part.mesh.positions.clone(),
            triangles: part.mesh.triangles.clone(),
            classes: Classes::Uniform(1),
            instance,
            material: sensor::Material::default(),
            wear: None,
        }
    };
    let (housing, cover) = (
        target(PartKind::GearContainer, 1),
        target(PartKind::Cover, 2),
    );
    // without noise: no flying pixels at the edges, each pixel its centre ray's surface
    let spec = SensorSpec::preset("ideal").unwrap().binned(4);
    let centre = motor.attributes.bounds.centre();
    let pose = sensor::look_at(centre + Vec3::new(0.3, -0.4, 0.35), centre, Vec3::Z).unwrap();
    let pixels = |scan: &sensor::Scan, instance: u32| -> Vec<(usize, usize)> {
        let w = scan.width as usize;
        (0..scan.pixels.len())
            .filter(|&k| scan.pixels[k].instance == instance)
            .map(|k| (k % w, k / w))
            .collect()
    };
    let within = |s: &Silhouette| -> Vec<(usize, usize)> {
        (0..s.inside.len())
            .filter(|&k| s.inside[k])
            .map(|k| (s.origin[0] + k % s.size[0], s.origin[1] + k / s.size[0]))
            .collect()
    };
    let alone = sensor::scan(&World::new(std::slice::from_ref(&housing)), &spec, &pose, 1);
    let s = Silhouette::of(std::slice::from_ref(&housing), &alone, &spec);
    assert!(s.area() > 1000, "{}", s.area());
    assert!(within(&s) == pixels(&alone, 1));
    // with the cover on, the housing shows less than its silhouette
    let both = sensor::scan(&World::new(&[housing.clone(), cover]), &spec, &pose, 1);
    let seen = pixels(&both, 1);
    let s = Silhouette::of(std::slice::from_ref(&housing), &both, &spec);
    let outline = within(&s);
    assert!(
        seen.len() < outline.len(),
        "{} of {}",
        seen.len(),
        outline.len()
    );
    assert!(seen.iter().all(|p| {
        outline
            .binary_search_by(|q| (q.1, q.0).cmp(&(p.1, p.0)))
            .is_ok()
    }));
}
