//! Builds `N` random motors of the add-on's parameter space at normal detail, for profiling a
//! motor's build: `build_motors N` (`valgrind --tool=callgrind target/release/examples/build_motors
//! 301`, less the same with 1, is 300 motors' instructions).

use motorgen::{Detail, ParamSpace, build};

fn main() {
    let n: u64 = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .expect("usage: build_motors N");
    let space = ParamSpace::addon();
    let triangles: usize = (1..=n)
        .map(|seed| {
            let motor = build(&space.sample(seed).unwrap(), Detail::Normal);
            motor
                .parts
                .iter()
                .map(|p| p.mesh.triangles.len())
                .sum::<usize>()
        })
        .sum();
    println!("{n} motors, {triangles} triangles");
}
