//! Reading OBJ, STL and PLY meshes into labelled scan targets.

use std::path::Path;

use glam::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};
use sensor::{Classes, Material, Target};

use crate::error::{CliError, CliResult};

/// Reads a mesh as targets: one with instance 1 and class 1, or, for a PLY with per-face
/// `class` and `instance` properties (as `motorfactory motor` writes them), one per instance with
/// the file's labels.
pub fn read_targets(path: &Path) -> CliResult<Vec<Target>> {
    let bad = |why: String| CliError::Usage(format!("cannot read mesh {}: {why}", path.display()));
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let targets = match ext.as_str() {
        "obj" => {
            let options = tobj::LoadOptions {
                triangulate: true,
                single_index: true,
                ..Default::default()
            };
            let (models, _) = tobj::load_obj(path, &options).map_err(|e| bad(e.to_string()))?;
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
        "stl" => {
            let mut f = std::fs::File::open(path).map_err(|e| bad(e.to_string()))?;
            let stl = stl_io::read_stl(&mut f).map_err(|e| bad(e.to_string()))?;
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
        "ply" => read_ply(path).map_err(bad)?,
        _ => {
            return Err(bad(format!(
                "unknown extension \"{ext}\": expected obj, stl or ply"
            )));
        }
    };
    if targets.iter().all(|t| t.triangles.is_empty()) {
        return Err(bad("it holds no triangles".into()));
    }
    for t in &targets {
        if t.triangles
            .iter()
            .flatten()
            .any(|&i| i as usize >= t.positions.len())
            || t.positions.iter().any(|p| !p.is_finite())
        {
            return Err(bad(
                "it has out-of-range vertex indices or non-finite coordinates".into(),
            ));
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

/// A PLY mesh; with per-face `instance`, one target per instance.
fn read_ply(path: &Path) -> Result<Vec<Target>, String> {
    let mut f = std::io::BufReader::new(std::fs::File::open(path).map_err(|e| e.to_string())?);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut f)
        .map_err(|e| e.to_string())?;
    let vertices = ply.payload.get("vertex").ok_or("no vertex element")?;
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
    let faces = ply.payload.get("face").ok_or("no face element")?;
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
    // each instance keeps only the vertices its triangles use
    Ok(groups
        .into_iter()
        .map(|(inst, (triangles, classes))| {
            let mut remap = vec![u32::MAX; positions.len()];
            let mut used = Vec::new();
            let triangles = triangles
                .into_iter()
                .map(|t| {
                    t.map(|i| {
                        let slot = &mut remap[i as usize];
                        if *slot == u32::MAX {
                            *slot = used.len() as u32;
                            used.push(positions[i as usize]);
                        }
                        *slot
                    })
                })
                .collect();
            target(used, triangles, Classes::PerTriangle(classes), inst)
        })
        .collect())
}
