//! One LiDAR pass of the shipped `hall` configuration's first hall, for each preset (the pass
//! alone: the head's returns in memory; building the hall, once for its passes, and writing
//! the files are left out), and the hall's building, on all threads.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use scene::pass::{make_hall, make_pass};
use scene::{Config, Recipe};
use sensor::LIDAR_PRESETS;

fn recipe(preset: &str) -> Recipe {
    let mut table = scene::config::builtin_table("hall").unwrap();
    scene::set_key(&mut table, "lidar.preset", preset.into()).unwrap();
    Recipe::new(Config::from_table(&table).unwrap(), Vec::new()).unwrap()
}

fn passes(c: &mut Criterion) {
    let mut g = c.benchmark_group("hall");
    g.sample_size(10);
    let hall = make_hall(&recipe(LIDAR_PRESETS[0]), 0).unwrap();
    eprintln!(
        "hall 0: {} objects, {} triangles",
        hall.cell.objects.len(),
        hall.world.triangle_count()
    );
    for name in LIDAR_PRESETS {
        let r = recipe(name);
        g.throughput(Throughput::Elements(r.hall_lidar().unwrap().rays() as u64));
        let mut index = 0;
        g.bench_function(name, |b| {
            b.iter(|| {
                index = (index + 1) % u64::from(r.config.lidar.revolutions);
                make_pass(&r, index, &hall).scan.returns.len()
            })
        });
    }
    g.throughput(Throughput::Elements(1));
    let r = recipe(LIDAR_PRESETS[0]);
    let mut number = 0;
    g.bench_function("build", |b| {
        b.iter(|| {
            number += 1;
            make_hall(&r, number).unwrap().world.triangle_count()
        })
    });
    g.finish();
}

criterion_group!(benches, passes);
criterion_main!(benches);
