//! Reading OBJ, STL and PLY meshes into labelled scan targets, with bounds: only regular files
//! (a FIFO or a device would block or never end), an OBJ's material library never followed, a
//! binary STL exactly as long as its triangle count says, and errors in words.

use std::path::Path;

use glam::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use crate::error::Error;
use crate::world::{Classes, Material, Target};

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ.
    Obj,
    /// STL, binary or ASCII.
    Stl,
    /// PLY, ASCII or binary.
    Ply,
}

impl MeshFormat {
    /// The format a file name's extension names (any case).
    pub fn of(path: &Path) -> Option<MeshFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(MeshFormat::Obj),
            "stl" => Some(MeshFormat::Stl),
            "ply" => Some(MeshFormat::Ply),
            _ => None,
        }
    }
}

/// Reads a mesh file as targets: one with instance 1 and class 1, or, for a PLY with per-face
/// `class` and `instance` properties (as `motorfactory motor` writes them), one per instance with
/// the file's labels.
///
/// # Example
///
/// ```
/// let path = std::env::temp_dir().join("mesh-doc-example.obj");
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// let targets = sensor::mesh::read(&path)?;
/// assert_eq!(targets[0].triangles, [[0, 1, 2]]);
/// # Ok::<(), sensor::Error>(())
/// ```
///
/// # Errors
///
/// [`Error::Mesh`] naming the file and what is wrong: an unknown extension, a file that is
/// missing, not a regular file or not valid in its format, out-of-range vertex indices,
/// non-finite coordinates, or no triangles.
pub fn read(path: &Path) -> Result<Vec<Target>, Error> {
    let bad = |why: String| Error::Mesh {
        path: path.display().to_string(),
        why,
    };
    let format = MeshFormat::of(path).ok_or_else(|| {
        bad(format!(
            "unknown extension \"{}\": expected obj, stl or ply",
            path.extension().unwrap_or_default().to_string_lossy()
        ))
    })?;
    let unreadable = |e: std::io::Error| {
        bad(match e.kind() {
            std::io::ErrorKind::NotFound => "no such file".into(),
            std::io::ErrorKind::PermissionDenied => "permission denied".into(),
            _ => e.to_string(),
        })
    };
    let bytes = crate::files::read(path, u64::MAX).map_err(unreadable)?;
    parse(&bytes, format).map_err(bad)
}

/// Parses a mesh held in memory as [`read`] does a file.
///
/// # Errors
///
/// What is wrong with the bytes, in words.
pub fn parse(bytes: &[u8], format: MeshFormat) -> Result<Vec<Target>, String> {
    let targets = match format {
        MeshFormat::Obj => {
            let options = tobj::LoadOptions {
                triangulate: true,
                single_index: true,
                ..Default::default()
            };
            // only vertices, faces and object names are read: texture coordinates, normals
            // and materials are not used (an `mtllib` line is never followed, and tobj's
            // arithmetic on texture and normal indices overflows on hostile ones)
            let geometry: Vec<u8> = bytes
                .split(|&b| b == b'\n')
                .filter(|line| {
                    let word = line
                        .trim_ascii_start()
                        .split(u8::is_ascii_whitespace)
                        .next();
                    matches!(word, Some(b"v" | b"f" | b"o" | b"g"))
                })
                .flat_map(|line| line.iter().copied().chain([b'\n']))
                .collect();
            let (models, _) = tobj::load_obj_buf(&mut &geometry[..], &options, |_| {
                Ok((Vec::new(), Default::default()))
            })
            .map_err(|e| format!("not a valid OBJ file: {}", obj_error(&e)))?;
            let mut positions = Vec::new();
            let mut triangles = Vec::new();
            for m in models {
                let base = positions.len() as u32;
                positions.extend(m.mesh.positions.chunks_exact(3).map(Vec3::from_slice));
                triangles.extend(
                    m.mesh
                        .indices
                        .chunks_exact(3)
                        .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
                );
            }
            vec![target(positions, triangles, Classes::Uniform(1), 1)]
        }
        MeshFormat::Stl => {
            check_stl_size(bytes)?;
            let stl = stl_io::read_stl(&mut std::io::Cursor::new(bytes))
                .map_err(|e| format!("not a valid STL file: {}", io_error(&e)))?;
            let positions = stl
                .vertices
                .iter()
                .map(|v| Vec3::new(v[0], v[1], v[2]))
                .collect();
            let triangles = stl
                .faces
                .iter()
                .map(|f| f.vertices.map(|i| i as u32))
                .collect();
            vec![target(positions, triangles, Classes::Uniform(1), 1)]
        }
        MeshFormat::Ply => read_ply(bytes).map_err(|e| format!("not a valid PLY file: {e}"))?,
    };
    if targets.iter().all(|t| t.triangles.is_empty()) {
        return Err("it holds no triangles".into());
    }
    for t in &targets {
        if t.triangles
            .iter()
            .flatten()
            .any(|&i| i as usize >= t.positions.len())
            || t.positions.iter().any(|p| !p.is_finite())
        {
            return Err("it has out-of-range vertex indices or non-finite coordinates".into());
        }
    }
    Ok(targets)
}

fn target(
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    classes: Classes,
    instance: u32,
) -> Target {
    Target {
        positions,
        triangles,
        classes,
        instance,
        material: Material::default(),
        wear: None,
    }
}

/// A numeric PLY property as f64.
pub fn number(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Float(x) => x as f64,
        Property::Double(x) => x,
        Property::Char(x) => x as f64,
        Property::UChar(x) => x as f64,
        Property::Short(x) => x as f64,
        Property::UShort(x) => x as f64,
        Property::Int(x) => x as f64,
        Property::UInt(x) => x as f64,
        _ => return None,
    })
}

/// An OBJ reader's error in words.
fn obj_error(e: &tobj::LoadError) -> &'static str {
    use tobj::LoadError as E;
    match e {
        E::OpenFileFailed | E::ReadError => "the file cannot be read as text",
        E::UnrecognizedCharacter => "it holds a character OBJ does not allow",
        E::PositionParseError | E::NormalParseError | E::TexcoordParseError => {
            "a vertex line does not hold numbers"
        }
        E::ScalingByZeroError => "a vertex has w = 0",
        E::ColorParseError => "a vertex colour has too many or too few numbers",
        E::FaceParseError | E::InvalidPolygon => "a face line is not a polygon of vertex indices",
        E::FaceVertexOutOfBounds
        | E::FaceTexCoordOutOfBounds
        | E::FaceNormalOutOfBounds
        | E::FaceColorOutOfBounds => "a face refers to a vertex that does not exist",
        _ => "its text is not OBJ",
    }
}

/// A mesh reader's I/O error in words.
fn io_error(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::UnexpectedEof => "the file ends early".into(),
        std::io::ErrorKind::InvalidData => "its text is not valid UTF-8 or not STL".into(),
        kind => kind.to_string(),
    }
}

/// A binary STL's size must be what its triangle count says; an ASCII one starts with `solid`.
fn check_stl_size(bytes: &[u8]) -> Result<(), String> {
    let Some(count) = bytes.get(80..84) else {
        return Err(format!("{} bytes, too short for STL", bytes.len()));
    };
    let count = u32::from_le_bytes(count.try_into().expect("4 bytes")) as u64;
    let expected = 84 + 50 * count;
    if expected == bytes.len() as u64 || bytes.starts_with(b"solid") {
        Ok(())
    } else {
        Err(format!(
            "a binary STL of {count} triangles has {expected} bytes, but the file has {}",
            bytes.len()
        ))
    }
}

/// A PLY mesh; with per-face `instance`, one target per instance.
fn read_ply(bytes: &[u8]) -> Result<Vec<Target>, String> {
    let in_words = |e: ply_rs_bw::parser::ParseError| match e.kind() {
        std::io::ErrorKind::UnexpectedEof => "the file ends early".to_string(),
        // its first line: the rest quotes the line and the parser's error as Rust writes it
        _ => e.to_string().lines().next().unwrap_or_default().to_string(),
    };
    let parser = Parser::<DefaultElement>::new();
    // every element takes at least a byte, so a header may not promise more elements than the
    // file has bytes (an element without properties would take none, and be read forever)
    let mut reader = ply_rs_bw::parser::Reader::new(bytes);
    let header = parser.read_header(&mut reader).map_err(in_words)?;
    let mut promised = 0usize;
    for (name, element) in &header.elements {
        if element.count > 0 && element.properties.is_empty() {
            return Err(format!("element {name} has no properties"));
        }
        promised = promised.saturating_add(element.count);
    }
    if promised > bytes.len() {
        return Err(format!(
            "its header promises {promised} elements, more than its {} bytes can hold",
            bytes.len()
        ));
    }
    let payload = parser
        .read_payload(&mut reader, &header)
        .map_err(in_words)?;
    let vertices = payload.get("vertex").ok_or("no vertex element")?;
    let positions: Vec<Vec3> = vertices
        .iter()
        .map(|v| {
            let c = |k: &str| {
                v.get(k)
                    .and_then(number)
                    .map(|x| x as f32)
                    .ok_or(format!("vertex without {k}"))
            };
            Ok(Vec3::new(c("x")?, c("y")?, c("z")?))
        })
        .collect::<Result<_, String>>()?;
    let faces = payload.get("face").ok_or("no face element")?;
    // per instance: triangles and their classes
    let mut groups: std::collections::BTreeMap<u32, (Vec<[u32; 3]>, Vec<u16>)> = Default::default();
    for face in faces {
        let list: Vec<u32> = match face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
        {
            Some(Property::ListInt(l)) => l.iter().map(|&i| i as u32).collect(),
            Some(Property::ListUInt(l)) => l.clone(),
            Some(Property::ListUChar(l)) => l.iter().map(|&i| i as u32).collect(),
            Some(Property::ListUShort(l)) => l.iter().map(|&i| i as u32).collect(),
            _ => return Err("faces without vertex_indices".into()),
        };
        if let Some(bad) = list.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(format!(
                "a face uses vertex {bad}, but there are {} vertices",
                positions.len()
            ));
        }
        let class = face.get("class").and_then(number).map_or(1, |c| c as u16);
        let inst = face
            .get("instance")
            .and_then(number)
            .map_or(1, |i| i as u32);
        let group = groups.entry(inst).or_default();
        for k in 1..list.len().saturating_sub(1) {
            group.0.push([list[0], list[k], list[k + 1]]);
            group.1.push(class);
        }
    }
    // each instance keeps only the vertices its triangles use: a vertex's slot in the instance
    // that used it last, so that many instances cost no more than one
    let mut owner = vec![usize::MAX; positions.len()];
    let mut slot = vec![0u32; positions.len()];
    Ok(groups
        .into_iter()
        .enumerate()
        .map(|(g, (inst, (triangles, classes)))| {
            let mut used = Vec::new();
            let triangles = triangles
                .into_iter()
                .map(|t| {
                    t.map(|i| {
                        let i = i as usize;
                        if owner[i] != g {
                            owner[i] = g;
                            slot[i] = used.len() as u32;
                            used.push(positions[i]);
                        }
                        slot[i]
                    })
                })
                .collect();
            target(used, triangles, Classes::PerTriangle(classes), inst)
        })
        .collect())
}
