//! Samples per second of the shipped dataset configurations (one sample made in memory: motor,
//! cell, scan, crop; writing is left to `bench/generate.py`), on all threads.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use scene::{Config, Recipe, make};

fn recipe(name: &str) -> Recipe {
    let table = scene::config::builtin_table(name).unwrap();
    Recipe::new(Config::from_table(&table).unwrap(), Vec::new()).unwrap()
}

fn samples(c: &mut Criterion) {
    let mut group = c.benchmark_group("sample");
    group.sample_size(10).throughput(Throughput::Elements(1));
    for name in ["default", "synmotor", "zivid"] {
        let r = recipe(name);
        let mut index = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                index += 1;
                black_box(make(&r, index).unwrap().views[0].cloud.len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, samples);
criterion_main!(benches);
