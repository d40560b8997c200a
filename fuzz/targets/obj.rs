//! A mesh file read as `scan --mesh FILE.obj` reads it, then built into the ray caster's BVH.
//! Any input may be refused; none may panic.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        if let Ok(targets) = sensor::mesh::parse(data, sensor::mesh::MeshFormat::Obj) {
            sensor::World::new(&targets);
        }
    });
}
