//! BOP scenes by their invariants: every model posed is its objects' mesh, its class the
//! scheme's; each view's figures are its pixels'; the same sample writes the same bytes.

use glam::Vec3;
use scene::bop::{self, model};
use scene::config::builtin_table;
use scene::{Config, Recipe, make};
use serde_json::Value;

fn recipe(name: &str) -> Recipe {
    let mut table = builtin_table(name).unwrap();
    scene::set_key(&mut table, "sensor.sampling", "by4x4".into()).unwrap();
    let size = toml::Value::Array(vec![306.into(), 256.into()]);
    scene::set_key(&mut table, "sensor.resolution", size).unwrap();
    scene::set_key(&mut table, "render.enabled", false.into()).unwrap();
    scene::set_key(&mut table, "output.bop", true.into()).unwrap();
    Recipe::new(Config::from_table(&table).unwrap(), Vec::new()).unwrap()
}

#[test]
fn a_models_pose_moves_it_onto_its_objects_and_its_id_is_their_class() {
    for name in ["transfer-unit", "handling", "armature"] {
        let recipe = recipe(name);
        let scheme = recipe.config.output.scheme;
        for index in 0..2 {
            let sample = make(&recipe, index).unwrap();
            let objects = &sample.cell.objects;
            let models = model::models(objects, scheme);
            let mut expected: Vec<u32> = (objects.iter())
                .filter(|o| o.class(scheme) != 0)
                .map(|o| o.instance_in(scheme))
                .collect();
            expected.sort_unstable();
            expected.dedup();
            let ids: Vec<u32> = models.iter().map(|m| m.instance).collect();
            assert_eq!(ids, expected, "{name} {index}");
            for m in &models {
                let pieces: Vec<_> = (objects.iter())
                    .filter(|o| o.class(scheme) != 0 && o.instance_in(scheme) == m.instance)
                    .collect();
                assert!(pieces.iter().all(|o| o.class(scheme) == m.obj_id));
                let world: Vec<Vec3> = pieces
                    .iter()
                    .flat_map(|o| o.mesh.positions.clone())
                    .collect();
                assert_eq!(m.mesh.positions.len(), world.len());
                let to_world = m.to_world(objects, scheme);
                let worst = (m.mesh.positions.iter().zip(&world))
                    .map(|(p, w)| to_world.transform_point3(*p / model::MM).distance(*w))
                    .fold(0.0f32, f32::max);
                assert!(worst < 2e-6, "{name} {index} {}: {worst} m", m.instance);
                // rigid, and the model about its box's centre
                let r = glam::Mat3::from(to_world.matrix3);
                assert!((r * r.transpose()).abs_diff_eq(glam::Mat3::IDENTITY, 1e-5));
                assert!(m.mesh.bounds().centre().length() < 1e-3);
            }
        }
    }
}

#[test]
fn a_models_diameter_is_its_largest_vertex_distance() {
    let motor = motorgen::build(&motorgen::MotorParams::default(), motorgen::Detail::Coarse);
    for p in &motor.parts {
        let mesh = p
            .mesh
            .clone()
            .transformed(&glam::Affine3A::from_scale(Vec3::splat(model::MM)));
        let v = &mesh.positions;
        let exact = (0..v.len())
            .flat_map(|i| (i + 1..v.len()).map(move |j| (i, j)))
            .map(|(i, j)| v[i].distance(v[j]))
            .fold(0.0f32, f32::max);
        let d = model::diameter(&mesh);
        assert!(
            d <= exact * 1.000_001 && d >= exact * 0.997,
            "{}: {d} {exact}",
            p.name
        );
    }
}

/// The scene's files written to memory, by path.
fn written(files: &[(String, bop::Writer)]) -> Vec<(String, Vec<u8>)> {
    files
        .iter()
        .map(|(path, body)| {
            let mut bytes = Vec::new();
            body(&mut bytes).unwrap();
            (path.clone(), bytes)
        })
        .collect()
}

#[test]
fn a_views_figures_are_its_pixels_and_a_sample_writes_the_same_bytes() {
    let recipe = recipe("handling");
    let output = &recipe.config.output;
    let sample = make(&recipe, 3).unwrap();
    let files = written(&bop::scene_files(&sample, output));
    let again = written(&bop::scene_files(&make(&recipe, 3).unwrap(), output));
    assert!(files == again);
    let json = |name: &str| -> Value {
        let (_, bytes) = files.iter().find(|(p, _)| p.ends_with(name)).unwrap();
        serde_json::from_slice(bytes).unwrap()
    };
    let (gt, info) = (json("scene_gt.json"), json("scene_gt_info.json"));
    let scan = sample.views[0].scan.as_ref().unwrap();
    let width = scan.width as usize;
    let entries = gt["0"].as_array().unwrap();
    assert!(entries.len() >= 4, "{}", entries.len());
    for (g, (e, i)) in entries
        .iter()
        .zip(info["0"].as_array().unwrap())
        .enumerate()
    {
        let instance = e["instance_id"].as_u64().unwrap() as u32;
        let pixels: Vec<(usize, usize)> = (scan.pixels.iter().enumerate())
            .filter(|(_, p)| p.is_valid() && p.instance == instance)
            .map(|(k, _)| (k % width, k / width))
            .collect();
        assert_eq!(
            i["px_count_visib"].as_u64().unwrap() as usize,
            pixels.len(),
            "{g}"
        );
        if let Some(&(x, y)) = pixels.first() {
            let class = scan.pixels[y * width + x].class;
            assert_eq!(e["obj_id"].as_u64().unwrap(), u64::from(class), "{g}");
            let x0 = pixels.iter().map(|p| p.0).min().unwrap();
            let x1 = pixels.iter().map(|p| p.0).max().unwrap();
            let y1 = pixels.iter().map(|p| p.1).max().unwrap();
            let b: Vec<u64> = serde_json::from_value(i["bbox_visib"].clone()).unwrap();
            assert_eq!(
                [b[0], b[1] + b[3] - 1, b[0] + b[2] - 1],
                [x0 as u64, y1 as u64, x1 as u64],
                "{g}"
            );
        }
        let all = i["px_count_all"].as_u64().unwrap();
        assert!(all >= i["px_count_visib"].as_u64().unwrap());
        assert!(i["px_count_valid"].as_u64().unwrap() <= all);
    }
    // one mask of each kind per entry, one model per instance
    let count = |dir: &str| files.iter().filter(|(p, _)| p.contains(dir)).count();
    assert_eq!(count("/mask/"), entries.len());
    assert_eq!(count("/mask_visib/"), entries.len());
    assert_eq!(count("/models/instance_"), entries.len());
}
