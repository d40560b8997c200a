//! Scans a mesh file (OBJ, STL or PLY) with a sensor preset from a camera position, and writes
//! the valid points as a PLY cloud in the camera frame (OpenCV's: x right, y down, z forward), in
//! metres.
//!
//! Usage: `cargo run --release --example scan_mesh -- MESH PRESET EX,EY,EZ OUT.ply`
//! (the camera at EX,EY,EZ looks at the mesh's centre; `motorfactory motor --format stl` writes
//! a mesh to try, and `zivid-2plus-m130` is a preset).

use glam::Vec3;
use sensor::formats::CloudFormat;
use sensor::{Frame, SensorSpec, Units, World, look_at, scan};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [mesh, preset, eye, out] = args.as_slice() else {
        return Err("usage: scan_mesh MESH PRESET EX,EY,EZ OUT.ply".into());
    };
    // one target of class 1 (a PLY written by `motorfactory motor` keeps its parts' labels)
    let targets = sensor::mesh::read(mesh.as_ref())?;
    let (lo, hi) = targets
        .iter()
        .flat_map(|t| &t.positions)
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let world = World::new(&targets);
    let sensor = SensorSpec::preset(preset)?;
    let eye: Vec<f32> = eye.split(',').map(str::parse).collect::<Result<_, _>>()?;
    let eye = Vec3::from_slice(&eye);
    let pose = look_at(eye, (lo + hi) / 2.0, Vec3::Z).ok_or("the camera looks along Z")?;
    let scan = scan(&world, &sensor, &pose, 0);
    let cloud = scan.cloud(false, Frame::Camera, Units::Metres);
    let mut file = std::io::BufWriter::new(std::fs::File::create(out)?);
    CloudFormat::Ply.write(&mut file, &cloud)?;
    println!(
        "{} points of {} triangles seen by {preset}, written to {out}",
        cloud.len(),
        world.triangle_count()
    );
    Ok(())
}
