//! Takes `N` views of motor 1 at the inspection station with the default configuration at
//! 612×512, all from one pose, for profiling a view-planning step: `station_steps N`
//! (`valgrind --tool=callgrind target/release/examples/station_steps 11`, less the same with 1,
//! is ten steps' instructions).

use scene::coverage::Rule;
use scene::rig::on_cap;
use scene::{Clamping, Config, Recipe, Station};

/// The Python package's allocator, which the environment's steps run with.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .expect("usage: station_steps N");
    let mut config = Config::default();
    config.sensor.sampling = sensor::Sampling::By4x4;
    let recipe = Recipe::new(config, Vec::new()).unwrap();
    let rule = Rule {
        radius: 0.002,
        max_angle_deg: 75.0,
    };
    let mut station = Station::new(&recipe, 1, Clamping::GearContainerUp, 2e5, rule).unwrap();
    let pose = on_cap(station.cell.motor_centre, 0.6, 0.8, 0.6, 0.0);
    for _ in 0..steps {
        station.clouds.clear();
        let capture = station.capture(&pose);
        println!("{} points", capture.points);
    }
}
