//! Builds `N` random motors of the add-on's parameter space at normal detail, for profiling a
//! motor's build: `build_motors N` (`valgrind --tool=callgrind target/release/examples/build_motors
//! 301`, less the same with 1, is 300 motors' instructions). It prints a checksum of the meshes,
//! so that a change meant to keep them can be checked to.

use std::hash::{DefaultHasher, Hash, Hasher};

use motorgen::{Detail, ParamSpace, build};

fn main() {
    let n: u64 = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .expect("usage: build_motors N");
    let space = ParamSpace::addon();
    let mut triangles = 0;
    let mut hash = DefaultHasher::new();
    for seed in 1..=n {
        let motor = build(&space.sample(seed).unwrap(), Detail::Normal);
        for part in &motor.parts {
            triangles += part.mesh.triangles.len();
            part.mesh.triangles.hash(&mut hash);
            for p in &part.mesh.positions {
                p.to_array().map(f32::to_bits).hash(&mut hash);
            }
        }
    }
    println!(
        "{n} motors, {triangles} triangles, checksum {:016x}",
        hash.finish()
    );
}
