//! The hall by its invariants (on its floor, inside its walls, its aisle clear, every object
//! its own instance) and its passes (the robot's drive, returns on the floor, labels), and the
//! configurations it refuses.

use std::collections::BTreeSet;

use glam::Vec3;
use scene::cell::{AISLE, Kind};
use scene::config::builtin_table;
use scene::pass::{make_hall, make_pass};
use scene::{Config, Recipe};
use sensor::lidar::LidarFrame;

fn table(keys: &[(&str, toml::Value)]) -> toml::Table {
    let mut table = builtin_table("hall").unwrap();
    for (key, value) in keys {
        scene::set_key(&mut table, key, value.clone()).unwrap();
    }
    table
}

fn recipe(keys: &[(&str, toml::Value)]) -> Recipe {
    Recipe::new(Config::from_table(&table(keys)).unwrap(), Vec::new()).unwrap()
}

fn refused(keys: &[(&str, toml::Value)]) -> String {
    Config::from_table(&table(keys)).unwrap_err().to_string()
}

#[test]
fn a_hall_stands_on_its_floor_inside_its_walls_and_keeps_its_aisle_clear() {
    let narrowest = toml::Value::Array(vec![24.0.into(), 9.0.into()]);
    let (mut motors, mut carriers) = (0, 0);
    for (keys, number) in (0..6).map(|n| (vec![], n)).chain([
        (vec![("cell.hall.size", narrowest.clone())], 0),
        (vec![("cell.hall.size", narrowest.clone())], 1),
    ]) {
        let recipe = recipe(&keys);
        let [length, width] = recipe.config.cell.hall.size;
        let hall = make_hall(&recipe, number).unwrap();
        let objects = &hall.cell.objects;
        assert_eq!(objects[0].name, "floor");
        let mut instances = BTreeSet::new();
        let mut wholes = BTreeSet::new();
        for o in &objects[1..] {
            let b = o.mesh.bounds();
            assert!(b.min.z >= -1e-4, "{} below the floor: {}", o.name, b.min.z);
            if o.name.starts_with("wall_") {
                continue;
            }
            assert!(
                b.min.x >= -length / 2.0 && b.max.x <= length / 2.0,
                "{} beyond the end walls: {b:?}",
                o.name
            );
            assert!(
                b.min.y >= -width / 2.0 && b.max.y <= width / 2.0,
                "{} beyond the side walls: {b:?}",
                o.name
            );
            assert!(
                b.min.y >= AISLE / 2.0 || b.max.y <= -AISLE / 2.0,
                "{} in the aisle: {b:?}",
                o.name
            );
            assert!(
                instances.insert(o.instance),
                "{} shares its instance",
                o.name
            );
            if let Kind::Assembled { motor } = o.kind {
                wholes.insert(motor);
            }
            carriers += usize::from(o.kind == Kind::Carrier);
        }
        assert!(
            wholes.is_disjoint(&instances),
            "a whole motor's id is an object's"
        );
        motors += wholes.len();
    }
    assert!(motors >= 8 * 2, "{motors} motors in 8 halls");
    assert!(carriers >= 8, "{carriers} carriers in 8 halls");
}

#[test]
fn a_halls_passes_follow_the_robot_and_label_what_they_hit() {
    let recipe = recipe(&[("lidar.preset", "velodyne-vlp16".into())]);
    let hall = make_hall(&recipe, 0).unwrap();
    let period = 1.0 / recipe.hall_lidar().unwrap().rotation;
    let passes: Vec<_> = (0..3).map(|i| make_pass(&recipe, i, &hall)).collect();
    for pair in passes.windows(2) {
        let step = pair[1].pose.translation - pair[0].pose.translation;
        // the robot's speed times a revolution, along the aisle (or back at its end)
        assert!((step.length() - hall.speed * period).abs() < 1e-4, "{step}");
        assert_eq!(step.y, 0.0);
        assert_eq!(pair[0].motion.velocity.length(), hall.speed);
    }
    let pass = &passes[0];
    assert_eq!(pass.scan.rays, recipe.hall_lidar().unwrap().rays());
    let height = recipe.config.lidar.height;
    let mut floor = 0;
    let (mut labelled, mut instances) = (BTreeSet::new(), BTreeSet::new());
    for r in &pass.scan.returns {
        let world = pass.scan.to_frame(r, LidarFrame::World, 1.0);
        let p = world.transform_point3(r.point);
        // every downward laser's return on the floor or on something standing on it
        assert!(p.z > -1e-3, "below the floor: {p}");
        if r.instance == hall.cell.objects[0].instance {
            assert!(p.z.abs() < 1e-3, "a floor return at {p}");
            floor += 1;
        }
        labelled.insert(r.class);
        instances.insert(r.instance);
    }
    // VLP-16: 8 lasers point down; the floor takes most of their returns
    assert!(floor > pass.scan.returns.len() / 4, "{floor} floor returns");
    assert!(
        labelled.contains(&0) && labelled.len() >= 2,
        "classes {labelled:?}"
    );
    assert!(instances.len() > 10, "{} instances", instances.len());
    let head = pass.pose.translation;
    assert_eq!(Vec3::from(head).z, height);
}

#[test]
fn a_pass_is_the_same_whoever_makes_it() {
    let recipe = recipe(&[("lidar.preset", "velodyne-vlp16".into())]);
    let (a, b) = (
        make_hall(&recipe, 1).unwrap(),
        make_hall(&recipe, 1).unwrap(),
    );
    let index = u64::from(recipe.config.lidar.revolutions) + 7;
    let (p, q) = (make_pass(&recipe, index, &a), make_pass(&recipe, index, &b));
    assert_eq!(p.scan.returns, q.scan.returns);
    assert_eq!(p.revolution, 7);
    assert_eq!(p.hall, 1);
}

#[test]
fn a_hall_refuses_the_cameras_outputs_and_names_what_it_takes() {
    let e = refused(&[("output.formats", toml::Value::Array(vec!["ply".into()]))]);
    assert!(
        e.contains("output.formats") && e.contains("lidar.formats"),
        "{e}"
    );
    let e = refused(&[("output.images", true.into())]);
    assert!(e.contains("output.images"), "{e}");
    let e = refused(&[("lidar.preset", "velodyne-vlp15".into())]);
    assert!(
        e.contains("lidar.preset") && e.contains("velodyne-vlp16"),
        "{e}"
    );
    let e = refused(&[("lidar.formats", toml::Value::Array(vec![]))]);
    assert!(e.contains("lidar.formats") && e.contains("las"), "{e}");
    let e = refused(&[("lidar.revolutions", 0.into())]);
    assert!(e.contains("lidar.revolutions"), "{e}");
    let many = toml::Value::Array(vec![6.into(), 7.into()]);
    let e = refused(&[("cell.hall.racks", many)]);
    assert!(e.contains("cell.hall") && e.contains("do not fit"), "{e}");
    // too short; too narrow for a transfer unit's distractors
    for size in [[5.0, 10.0], [24.0, 8.0]] {
        let size = toml::Value::Array(size.map(toml::Value::from).to_vec());
        let e = refused(&[("cell.hall.size", size)]);
        assert!(e.contains("cell.hall.size"), "{e}");
    }
}
