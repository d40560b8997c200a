//! The scenes beside the station by their invariants: the transfer unit's motors in their
//! carriers, the handling table's objects resting and apart, the armature's surfaces, and each
//! scene's labels.

use std::collections::{BTreeMap, BTreeSet};

use motorgen::Scheme;
use motorgen::kernel::Aabb;
use scene::cell::{Kind, Object};
use scene::config::builtin_table;
use scene::{Config, Recipe, make};
use sensor::wear::ArmatureSurface;

fn recipe(name: &str, keys: &[(&str, toml::Value)]) -> Recipe {
    let mut table = builtin_table(name).unwrap();
    scene::set_key(&mut table, "sensor.sampling", "by4x4".into()).unwrap();
    let size = toml::Value::Array(vec![612.into(), 512.into()]);
    scene::set_key(&mut table, "sensor.resolution", size).unwrap();
    scene::set_key(&mut table, "render.enabled", false.into()).unwrap();
    for (key, value) in keys {
        scene::set_key(&mut table, key, value.clone()).unwrap();
    }
    Recipe::new(Config::from_table(&table).unwrap(), Vec::new()).unwrap()
}

/// The union of the boxes of the objects `keep` picks, by key.
fn boxes<K: Ord>(objects: &[Object], key: impl Fn(&Object) -> Option<K>) -> BTreeMap<K, Aabb> {
    let mut out: BTreeMap<K, Aabb> = BTreeMap::new();
    for o in objects {
        if let Some(k) = key(o) {
            let b = out.entry(k).or_insert(Aabb::EMPTY);
            *b = b.union(o.mesh.bounds());
        }
    }
    out
}

fn overlap(a: &Aabb, b: &Aabb) -> f32 {
    let lo = a.min.max(b.min);
    let hi = a.max.min(b.max);
    (hi - lo).max(glam::Vec3::ZERO).element_product()
}

fn volume(a: &Aabb) -> f32 {
    a.size().element_product()
}

#[test]
fn the_transfer_units_motors_lie_in_their_carriers_and_are_one_instance_each() {
    let recipe = recipe("transfer-unit", &[]);
    let mut motors_seen = 0;
    for index in 0..8 {
        let sample = make(&recipe, index).unwrap();
        let objects = &sample.cell.objects;
        let carriers = boxes(objects, |o| (o.kind == Kind::Carrier).then_some(o.instance));
        let motors = boxes(objects, |o| match o.kind {
            Kind::Assembled { motor } => Some(motor),
            _ => None,
        });
        assert!(
            (2..=3).contains(&carriers.len()),
            "{index}: {}",
            carriers.len()
        );
        assert!(
            !motors.is_empty(),
            "{index}: the first carrier holds a motor"
        );
        motors_seen += motors.len();
        for c in carriers.values() {
            // on the rollers' top
            assert!(c.min.z.abs() < 1e-4, "{index}: carrier at {}", c.min.z);
        }
        for (m, b) in &motors {
            // over a carrier's footprint, on its floor
            let centre = b.centre();
            let home = carriers
                .values()
                .find(|c| {
                    (c.min.x..=c.max.x).contains(&centre.x)
                        && (c.min.y..=c.max.y).contains(&centre.y)
                })
                .unwrap_or_else(|| panic!("{index}: motor {m} in no carrier"));
            assert!(
                b.min.z >= home.min.z,
                "{index}: motor {m} below its carrier"
            );
            for (n, other) in &motors {
                if n != m {
                    assert!(
                        overlap(b, other) < 0.05 * volume(b),
                        "{index}: motors {m} and {n} overlap"
                    );
                }
            }
        }
        // objects9: a motor's parts one instance of class motor, a carrier of class carrier
        for t in sample.cell.targets(Scheme::Objects) {
            let sensor::Classes::Uniform(class) = t.classes else {
                panic!("uniform classes")
            };
            let o = objects
                .iter()
                .find(|o| o.instance_in(Scheme::Objects) == t.instance);
            let o = o.unwrap();
            let want = match o.kind {
                Kind::Assembled { .. } => 1,
                Kind::Carrier => 2,
                Kind::Loose => 3,
                _ => 0,
            };
            assert_eq!(class, want, "{index}: {}", o.name);
        }
        // instance ids unique among objects
        let ids: BTreeSet<u32> = objects.iter().map(|o| o.instance).collect();
        assert_eq!(ids.len(), objects.len());
    }
    assert!(
        motors_seen >= 12,
        "several motors an image: {motors_seen} in 8"
    );
}

#[test]
fn the_handling_tables_objects_rest_on_it_or_on_each_other_and_whole_motors_lie_apart() {
    let recipe = recipe("handling", &[]);
    for index in 0..8 {
        let sample = make(&recipe, index).unwrap();
        let objects = &sample.cell.objects;
        let motors = boxes(objects, |o| match o.kind {
            Kind::Assembled { motor } => Some(motor),
            _ => None,
        });
        let loose = boxes(objects, |o| (o.kind == Kind::Loose).then_some(o.instance));
        assert!((1..=2).contains(&motors.len()), "{index}");
        assert!((3..=8).contains(&loose.len()), "{index}: {}", loose.len());
        let table_top = 0.0;
        for b in motors.values().chain(loose.values()) {
            assert!(b.min.z >= table_top - 1e-4, "{index}: below the table");
            // resting: on the table, or on the top of a box beneath it
            let rests = b.min.z < 2e-3
                || motors
                    .values()
                    .chain(loose.values())
                    .any(|o| (o.max.z - b.min.z).abs() < 2e-3 && overlap_xy(o, b));
            assert!(rests, "{index}: an object floats at {}", b.min.z);
        }
        let whole: Vec<&Aabb> = motors.values().collect();
        for (i, a) in whole.iter().enumerate() {
            for b in &whole[i + 1..] {
                assert!(overlap(a, b) < 0.2 * volume(a), "{index}: motors overlap");
            }
        }
    }
}

fn overlap_xy(a: &Aabb, b: &Aabb) -> bool {
    a.min.x < b.max.x && a.max.x > b.min.x && a.min.y < b.max.y && a.max.y > b.min.y
}

#[test]
fn the_armatures_surfaces_are_objects_of_their_own_seen_and_labelled_apart() {
    let recipe = recipe("armature", &[("output.images", true.into())]);
    let mut seen = BTreeSet::new();
    for index in 0..6 {
        let sample = make(&recipe, index).unwrap();
        let surfaces: Vec<&Object> = sample
            .cell
            .objects
            .iter()
            .filter(|o| matches!(o.kind, Kind::Surface(_)))
            .collect();
        let kinds: Vec<ArmatureSurface> = surfaces
            .iter()
            .map(|o| match o.kind {
                Kind::Surface(s) => s,
                _ => unreachable!(),
            })
            .collect();
        use ArmatureSurface::*;
        assert_eq!(kinds, [Shaft, Laminations, Windings, Commutator]);
        // together the armature's whole mesh, each triangle once
        let motor_armature = sample
            .motor
            .parts
            .iter()
            .find(|p| p.kind == motorgen::PartKind::Armature)
            .unwrap();
        let triangles: usize = surfaces.iter().map(|o| o.mesh.triangles.len()).sum();
        assert_eq!(triangles, motor_armature.mesh.triangles.len());
        // its axis level, resting above the table
        let b = surfaces
            .iter()
            .fold(Aabb::EMPTY, |b, o| b.union(o.mesh.bounds()));
        assert!(b.min.z > 0.0 && b.min.z < 0.01, "{}", b.min.z);
        for (k, o) in surfaces.iter().enumerate() {
            assert_eq!(o.class(Scheme::Armature) as usize, k + 1, "{}", o.name);
            assert_eq!(
                o.class(Scheme::SynMotor),
                Scheme::SynMotor.id(motorgen::PartKind::Armature)
            );
        }
        let scan = sample.views[0].scan.as_ref().unwrap();
        seen.extend(scan.pixels.iter().map(|p| p.class));
    }
    // close-ups see every surface
    assert!((1..=4).all(|c| seen.contains(&c)), "{seen:?}");
}

#[test]
fn a_scene_is_the_same_for_the_same_seed_and_another_for_another() {
    for name in ["transfer-unit", "handling", "armature"] {
        let recipe = recipe(name, &[]);
        let a = make(&recipe, 5).unwrap();
        assert_eq!(a.cell, make(&recipe, 5).unwrap().cell, "{name}");
        assert_ne!(a.cell, make(&recipe, 6).unwrap().cell, "{name}");
    }
}
