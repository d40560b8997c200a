//! Scans `N` frames of the frame benchmark's scene (a polished steel ball on a grey table, 200k
//! triangles) with the Zivid 2+ M130, for profiling: `zivid_frame all|no-interreflection|
//! no-diffuse|no-noise N` (`valgrind --tool=callgrind target/release/examples/zivid_frame all 2`,
//! less the same with 1, is one frame's instructions).

use glam::Vec3;
use sensor::{SensorSpec, Target, World, look_at, materials, scan};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let usage = "usage: zivid_frame all|no-interreflection|no-diffuse|no-noise N";
    let (variant, frames) = match (a.get(1), a.get(2).and_then(|n| n.parse::<u32>().ok())) {
        (Some(v), Some(n)) => (v.as_str(), n),
        _ => panic!("{usage}"),
    };
    let tris = sensor::shapes::sphere_on_plane(((200_000 / 4) as f64).sqrt() as usize);
    let (ball, table) = tris.split_at(tris.len() / 2);
    let world = World::new(&[
        Target::from_triangles(ball, 1, 1, materials::STAINLESS_STEEL),
        Target::from_triangles(table, 2, 2, materials::MATTE_GREY),
    ]);
    let mut sensor = SensorSpec::preset("zivid-2plus-m130").unwrap();
    match variant {
        "all" => {}
        "no-interreflection" => sensor.noise.interreflection = Default::default(),
        "no-diffuse" => sensor.noise.interreflection.diffuse_reach = 0.0,
        "no-noise" => {
            sensor.noise = Default::default();
            sensor.calibration = Default::default();
        }
        _ => panic!("{usage}"),
    }
    let pose = look_at(
        Vec3::new(0.1, -0.2, 1.28),
        Vec3::new(0.0, 0.0, 0.1),
        Vec3::Y,
    )
    .unwrap();
    for _ in 0..frames {
        let frame = scan(&world, &sensor, &pose, 1);
        let valid = frame
            .pixels
            .iter()
            .filter(|p| p.point.x.is_finite())
            .count();
        println!("{valid} valid pixels");
    }
}
