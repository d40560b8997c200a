//! The inspection station at the default 612×512 (the Zivid 2+ M60, 4×4 pixels summed), on all
//! threads: a station set up (a motor built and clamped, its surface sampled at 2·10⁵ per m²
//! with the hidden samples tested and left out), one view taken (the scan, the coverage update
//! and the points kept), the coverage update alone, and an ideal view's predicted gain.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use scene::coverage::{Rule, observe};
use scene::rig::on_cap;
use scene::{Clamping, Config, Recipe, Station};

const RULE: Rule = Rule {
    radius: 0.002,
    max_angle_deg: 75.0,
};

fn recipe(diffuse: bool) -> Recipe {
    let mut config = Config::default();
    config.sensor.sampling = sensor::Sampling::BlueSubsample4x4;
    if !diffuse {
        config.sensor.noise = Some(toml::from_str("interreflection.diffuse_reach = 0.0").unwrap());
    }
    Recipe::new(config, Vec::new()).unwrap()
}

fn coverage(c: &mut Criterion) {
    let mut g = c.benchmark_group("coverage");
    g.sample_size(10);
    let recipe = recipe(true);
    let mut index = 0;
    g.bench_function("station_new", |b| {
        b.iter(|| {
            index += 1;
            let s = Station::new(&recipe, index, Clamping::GearContainerUp, 2e5, RULE).unwrap();
            black_box(s.surface.len())
        })
    });
    for (name, recipe) in [
        ("station_capture", recipe.clone()),
        (
            "station_capture_without_diffuse_interreflection",
            self::recipe(false),
        ),
    ] {
        let mut station = Station::new(&recipe, 1, Clamping::GearContainerUp, 2e5, RULE).unwrap();
        let pose = on_cap(station.cell.motor_centre, 0.6, 0.8, 0.6, 0.0);
        g.bench_function(name, |b| {
            b.iter(|| {
                station.clouds.clear();
                black_box(station.capture(&pose))
            })
        });
    }
    let station = Station::new(&recipe, 1, Clamping::GearContainerUp, 2e5, RULE).unwrap();
    let pose = on_cap(station.cell.motor_centre, 0.6, 0.8, 0.6, 0.0);
    let world = sensor::World::new(&station.cell.targets(motorgen::Scheme::SynMotor));
    let scan = sensor::scan(&world, station.sensor(), &pose, 1);
    g.bench_function("observe_one_view", |b| {
        b.iter(|| {
            let mut seen = vec![false; station.surface.len()];
            observe(&station.surface, &scan, station.sensor(), RULE, &mut seen);
            black_box(seen)
        })
    });
    g.bench_function("predict_one_view", |b| {
        b.iter(|| black_box(station.predict(&pose)))
    });
    g.finish();
}

criterion_group!(benches, coverage);
criterion_main!(benches);
