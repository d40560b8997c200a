//! `sensor::mesh`: each format read into targets, and the inputs fuzzing found refused or read
//! cleanly.

use glam::Vec3;
use sensor::Classes;
use sensor::mesh::{MeshFormat, parse};

const SEEDS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/seeds");

fn seed(path: &str) -> Vec<u8> {
    std::fs::read(format!("{SEEDS}/{path}")).unwrap()
}

#[test]
fn each_format_reads_its_triangles_and_labels() {
    // a quad, triangulated; texture and normal indices ignored
    let obj = parse(&seed("obj/quad.obj"), MeshFormat::Obj).unwrap();
    assert_eq!(obj.len(), 1);
    assert_eq!(
        obj[0].triangles.len(),
        3,
        "the quad's two triangles and one more face"
    );
    for stl in ["stl/ascii.stl", "stl/binary.stl"] {
        let t = parse(&seed(stl), MeshFormat::Stl).unwrap();
        assert!(!t[0].triangles.is_empty(), "{stl}");
        assert!(t[0].positions.iter().all(|p| p.z == 0.0));
    }
    // a PLY with per-face class and instance: one target per instance, with its class
    let ply = parse(&seed("ply/binary.ply"), MeshFormat::Ply).unwrap();
    assert_eq!(ply.len(), 2);
    assert_eq!(ply[1].instance, 2);
    assert!(matches!(&ply[1].classes, Classes::PerTriangle(c) if c == &[2]));
    assert_eq!(
        ply[0].positions,
        [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)]
    );
}

#[test]
fn inputs_found_by_fuzzing_are_read_or_refused_in_words() {
    // a texture index of −2·10^15 (tobj's index arithmetic overflows on it): texture
    // coordinates are never read, so the faces are, each within the vertices
    let obj = parse(&seed("obj/negative-texture-index.obj"), MeshFormat::Obj).unwrap();
    let t = &obj[0];
    assert!(!t.triangles.is_empty());
    assert!(
        t.triangles
            .iter()
            .flatten()
            .all(|&i| (i as usize) < t.positions.len())
    );
    // an element without properties and 11,111,111,111 entries: refused, not read forever
    let ply = b"ply\nformat binary_little_endian 1.0\nelement vfthdz\t11111111111\nend_header\n";
    assert_eq!(
        parse(ply, MeshFormat::Ply).unwrap_err(),
        "not a valid PLY file: element vfthdz has no properties"
    );
}
