//! Every export read back by an independent reader crate, and byte-identical output for the
//! same parameters.

use std::collections::BTreeMap;
use std::path::Path;

use glam::Vec3;
use motorgen::export::{csv_header, csv_row, write_motor};
use motorgen::kernel::Aabb;
use motorgen::params::Value;
use motorgen::{Detail, Format, Motor, MotorParams, ParamSpace, Scheme, build};

fn motor(pairs: &[(&str, &str)]) -> Motor {
    let map: BTreeMap<String, Value> = pairs
        .iter()
        .map(|(k, v)| (k.to_string(), Value::Text(v.to_string())))
        .collect();
    build(&MotorParams::from_values(&map).unwrap(), Detail::Coarse)
}

fn bounds_of(points: impl Iterator<Item = Vec3>) -> Aabb {
    points.fold(Aabb::EMPTY, |b, p| Aabb {
        min: b.min.min(p),
        max: b.max.max(p),
    })
}

fn same_box(a: Aabb, b: Aabb) {
    assert!(
        (a.min - b.min).abs().max_element() < 1e-7 && (a.max - b.max).abs().max_element() < 1e-7,
        "{a:?} vs {b:?}"
    );
}

fn written(m: &Motor, formats: &[Format]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    write_motor(m, dir.path(), formats, true).unwrap();
    dir
}

#[test]
fn obj_reads_back_with_tobj() {
    let m = motor(&[("type", "A"), ("extension_a", "type2")]);
    let dir = written(&m, &[Format::Obj]);
    let (models, materials) =
        tobj::load_obj(dir.path().join("motor.obj"), &tobj::LoadOptions::default()).unwrap();
    let materials = materials.unwrap();
    assert_eq!(models.len(), m.parts.len());
    for (model, part) in models.iter().zip(&m.parts) {
        assert_eq!(model.name, part.name);
        assert_eq!(model.mesh.positions.len(), 3 * part.mesh.positions.len());
        assert_eq!(model.mesh.indices.len(), 3 * part.mesh.triangle_count());
        let mat = &materials[model.mesh.material_id.unwrap()];
        assert_eq!(mat.name, part.kind.material().name);
        assert_eq!(
            mat.diffuse.unwrap(),
            <[f32; 3]>::try_from(&part.kind.material().base_color[..3]).unwrap()
        );
        let b = bounds_of(model.mesh.positions.chunks(3).map(Vec3::from_slice));
        same_box(b, part.mesh.bounds());
    }
    // per-part files hold one object each
    let (single, _) = tobj::load_obj(
        dir.path().join("cover_bolt_1.obj"),
        &tobj::LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(single.len(), 1);
}

#[test]
fn stl_reads_back_with_stl_io() {
    let m = motor(&[("type", "B")]);
    let dir = written(&m, &[Format::Stl]);
    for part in m.parts.iter().take(4) {
        let mut f = std::fs::File::open(dir.path().join(format!("{}.stl", part.name))).unwrap();
        let stl = stl_io::read_stl(&mut f).unwrap();
        assert_eq!(stl.faces.len(), part.mesh.triangle_count());
        assert_eq!(
            stl.vertices.len(),
            part.mesh.positions.len(),
            "{}: every vertex distinct",
            part.name
        );
        // stl_io calls a face degenerate below an absolute f32::EPSILON of area: check the
        // closedness in millimetres, where a 1 mm² face is not mistaken for a point
        let mut mm = stl.clone();
        for v in &mut mm.vertices {
            *v = stl_io::Vertex::new([v[0] * 1e3, v[1] * 1e3, v[2] * 1e3]);
        }
        mm.validate()
            .unwrap_or_else(|e| panic!("{}: {e}", part.name));
        same_box(
            bounds_of(stl.vertices.iter().map(|v| Vec3::new(v[0], v[1], v[2]))),
            part.mesh.bounds(),
        );
    }
    let mut f = std::fs::File::open(dir.path().join("motor.stl")).unwrap();
    let whole = stl_io::read_stl(&mut f).unwrap();
    assert_eq!(
        whole.faces.len(),
        m.parts
            .iter()
            .map(|p| p.mesh.triangle_count())
            .sum::<usize>()
    );
}

#[test]
fn ply_reads_back_with_ply_rs_and_carries_labels() {
    use ply_rs_bw::{
        parser::Parser,
        ply::{DefaultElement, Property},
    };
    let m = motor(&[("type", "A")]);
    let dir = written(&m, &[Format::Ply]);
    let mut f = std::fs::File::open(dir.path().join("motor.ply")).unwrap();
    let ply = Parser::<DefaultElement>::new().read_ply(&mut f).unwrap();
    let verts = &ply.payload["vertex"];
    let faces = &ply.payload["face"];
    assert_eq!(
        verts.len(),
        m.parts
            .iter()
            .map(|p| p.mesh.positions.len())
            .sum::<usize>()
    );
    assert_eq!(
        faces.len(),
        m.parts
            .iter()
            .map(|p| p.mesh.triangle_count())
            .sum::<usize>()
    );
    let float = |e: &DefaultElement, k: &str| match e[k] {
        Property::Float(x) => x,
        ref other => panic!("{k}: {other:?}"),
    };
    let b = bounds_of(
        verts
            .iter()
            .map(|v| Vec3::new(float(v, "x"), float(v, "y"), float(v, "z"))),
    );
    same_box(b, m.attributes.bounds);
    let mut next = 0;
    for part in &m.parts {
        for face in &faces[next..next + part.mesh.triangle_count()] {
            assert_eq!(
                face["class"],
                Property::UChar(Scheme::SynMotor.id(part.kind))
            );
            assert_eq!(face["part_class"], Property::UChar(part.kind as u8));
            assert_eq!(face["instance"], Property::Int(part.instance as i32));
            assert!(matches!(&face["vertex_indices"], Property::ListInt(l) if l.len() == 3));
        }
        next += part.mesh.triangle_count();
    }
}

#[test]
fn glb_reads_back_with_gltf() {
    let m = motor(&[("type", "A"), ("extension_a", "type1")]);
    let dir = written(&m, &[Format::Glb]);
    let (doc, buffers, _) = gltf::import(dir.path().join("motor.glb")).unwrap();
    // one root, turning the motor's Z-up frame into glTF's Y-up: the motor axis (+z) is +y
    let roots: Vec<_> = doc.default_scene().unwrap().nodes().collect();
    assert_eq!(roots.len(), 1);
    let turn = glam::Quat::from_array(roots[0].transform().decomposed().1);
    assert!(turn.mul_vec3(Vec3::Z).distance(Vec3::Y) < 1e-6);
    assert!(turn.mul_vec3(Vec3::X).distance(Vec3::X) < 1e-6);
    let nodes: Vec<_> = roots[0].children().collect();
    assert_eq!(nodes.len(), m.parts.len());
    for (node, part) in nodes.iter().zip(&m.parts) {
        assert_eq!(node.name(), Some(part.name.as_str()));
        let prim = node.mesh().unwrap().primitives().next().unwrap();
        let reader = prim.reader(|b| Some(&buffers[b.index()]));
        let positions: Vec<Vec3> = reader.read_positions().unwrap().map(Vec3::from).collect();
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(positions.len(), part.mesh.positions.len());
        assert_eq!(indices.len(), 3 * part.mesh.triangle_count());
        same_box(bounds_of(positions.into_iter()), part.mesh.bounds());
        assert_eq!(prim.material().name(), Some(part.kind.material().name));
    }
}

fn tree_bytes(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let space = ParamSpace::addon();
    let files = |seed| {
        let m = build(&space.sample(seed).unwrap(), Detail::Normal);
        tree_bytes(written(&m, &Format::ALL).path())
    };
    let (a, b, c) = (files(11), files(11), files(12));
    assert_eq!(a, b);
    assert_ne!(a, c);
    assert!(
        a.keys().any(|k| k.ends_with(".glb"))
            && a.contains_key("attributes.json")
            && a.contains_key("materials.mtl")
    );
    assert!(!a.keys().any(|k| k.ends_with(".tmp")));
}

#[test]
fn attributes_json_and_csv_hold_the_ground_truth() {
    let m = motor(&[("type", "A")]);
    let dir = written(&m, &[]);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("attributes.json")).unwrap())
            .unwrap();
    assert_eq!(json["params"]["type"], "A");
    assert_eq!(json["attributes"]["variant"], "A1");
    assert_eq!(
        json["attributes"]["bolts"].as_array().unwrap().len(),
        m.attributes.bolts.len()
    );
    let c = m.attributes.gears[1].centre;
    let g = &json["attributes"]["gears"][1]["center"];
    assert_eq!(
        [
            g[0].as_f64().unwrap() as f32,
            g[1].as_f64().unwrap() as f32,
            g[2].as_f64().unwrap() as f32
        ],
        c.to_array()
    );

    let header: Vec<String> = csv_header().split(',').map(String::from).collect();
    let row: Vec<String> = csv_row("m0", &m).split(',').map(String::from).collect();
    assert_eq!(header.len(), row.len());
    let cell = |name: &str| row[header.iter().position(|h| h == name).unwrap()].clone();
    assert_eq!(cell("bolt_num"), "4");
    assert_eq!(cell("gear2_z").parse::<f32>().unwrap(), c.z);
    assert_eq!(cell("bolt5_x"), "");
}

#[test]
fn label_schemes_cover_every_part_kind() {
    use motorgen::PartKind;
    for (i, kind) in PartKind::ALL.iter().enumerate() {
        // the PLY's part_class byte and the scheme tables index kinds in this order
        assert_eq!(*kind as usize, i);
        for scheme in Scheme::ALL {
            let id = scheme.id(*kind);
            assert!(
                scheme.classes().iter().any(|c| c.id == id),
                "{scheme:?} has no class {id} for {kind:?}"
            );
            // the armature's surfaces are labelled apart from the parts
            let surfaces_only = scheme == Scheme::Armature;
            assert_eq!(
                id == 0,
                surfaces_only,
                "{kind:?} background under {scheme:?}"
            );
        }
    }
    // the schemes as the original datasets define them
    assert_eq!(Scheme::SynMotor.id(PartKind::SideBolt), 5);
    assert_eq!(Scheme::SynMotor.id(PartKind::CoverBolt), 6);
    assert_eq!(
        Scheme::Wacv.id(PartKind::SideBolt),
        Scheme::Wacv.id(PartKind::CoverBolt)
    );
    assert_eq!(Scheme::InnerParts.id(PartKind::SingleGear), 9);
    assert_eq!(Scheme::SynMotor.classes().len(), 7);
    assert_eq!(Scheme::Wacv.classes().len(), 6);
    assert_eq!(Scheme::InnerParts.classes().len(), 10);
    // whole objects: an assembled motor is one motor, a part taken off is its kind
    assert_eq!(Scheme::Objects.assembled(PartKind::Cover), 1);
    assert_eq!(Scheme::Objects.id(PartKind::Cover), 3);
    assert_eq!(Scheme::Objects.carrier(), 2);
    assert_eq!(Scheme::SynMotor.carrier(), 0);
    for (k, name) in ["shaft", "lamination_stack", "windings", "commutator"]
        .iter()
        .enumerate()
    {
        let id = Scheme::Armature.armature_surface(k);
        assert_eq!(Scheme::Armature.classes()[id as usize].name, *name);
    }
    for scheme in Scheme::ALL {
        for (i, c) in scheme.classes().iter().enumerate() {
            assert_eq!(c.id as usize, i, "{scheme:?}");
        }
    }
}
