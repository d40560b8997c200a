//! A mesh file read as `scan --mesh FILE.stl` reads it, then built into the ray caster's BVH.
//! Any input may be refused; none may panic.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        if let Ok(targets) = sensor::mesh::parse(data, sensor::mesh::MeshFormat::Stl) {
            sensor::World::new(&targets);
        }
    });
}
