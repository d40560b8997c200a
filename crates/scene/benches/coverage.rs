//! Surface coverage: a motor's surface sampled (2·10⁵ samples per m², the hidden ones tested
//! and left out), and one view's observation of the samples (a 612×512 scan), on all threads.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use scene::Object;
use scene::coverage::{Rule, Surface, observe};
use sensor::{Intrinsics, SensorSpec, World, look_at};

/// Motor `seed`'s parts as cell objects, in the motor's frame, about its centre.
fn motor(seed: u64) -> Vec<Object> {
    let params = motorgen::ParamSpace::addon().sample(seed).unwrap();
    let m = motorgen::build(&params, motorgen::Detail::Normal);
    let centre = m.attributes.bounds.centre();
    let to_centre = glam::Affine3A::from_translation(-centre);
    m.parts
        .iter()
        .map(|p| Object::part(p, &to_centre))
        .collect()
}

fn coverage(c: &mut Criterion) {
    let mut g = c.benchmark_group("coverage");
    g.sample_size(10);
    let mut seed = 0;
    g.bench_function("sample_surface", |b| {
        b.iter(|| {
            seed += 1;
            black_box(Surface::sample(&motor(seed), 2e5, seed).len())
        })
    });
    let objects = motor(1);
    let surface = Surface::sample(&objects, 2e5, 1);
    let cell = scene::Cell {
        objects: objects.clone(),
        motor_to_world: glam::Affine3A::IDENTITY,
        motor_centre: Vec3::ZERO,
        fixture: Vec::new(),
    };
    let world = World::new(&cell.targets(motorgen::Scheme::SynMotor));
    let mut sensor = SensorSpec::preset("ideal").unwrap();
    sensor.intrinsics = Intrinsics::from_fov(612, 512, 30.0, 25.0);
    let pose = look_at(Vec3::new(0.3, -0.2, 0.4), Vec3::ZERO, Vec3::Z).unwrap();
    let scan = sensor::scan(&world, &sensor, &pose, 1);
    let rule = Rule {
        radius: 0.002,
        max_angle_deg: 75.0,
    };
    g.bench_function("observe_one_view", |b| {
        b.iter(|| {
            let mut seen = vec![false; surface.len()];
            observe(&surface, &scan, &sensor, rule, &mut seen);
            black_box(seen)
        })
    });
    g.finish();
}

criterion_group!(benches, coverage);
criterion_main!(benches);
