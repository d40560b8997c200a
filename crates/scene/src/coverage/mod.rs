//! Surface coverage: the motor's surface sampled evenly by area, each sample tagged with its
//! part and instance, and which samples a set of views observes (a measured point near it, and
//! the sample facing both the camera and the projector).

use crate::cell::Object;
use glam::{Affine3A, Vec3};
use motorgen::PartKind;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use sensor::{Classes, Scan, SensorSpec, Target, World};

mod exposure;

pub use exposure::{exposed, exposed_each};

/// Points spread evenly by area over surfaces, with their normals and what they belong to.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surface {
    /// Each sample's position, in the objects' frame.
    pub points: Vec<Vec3>,
    /// Each sample's outward surface normal.
    pub normals: Vec<Vec3>,
    /// Each sample's part instance.
    pub instances: Vec<u32>,
    /// Each sample's part kind.
    pub parts: Vec<PartKind>,
    /// The area each sample stands for, m².
    pub area: f32,
}

impl Surface {
    /// The surface of the motor's parts among `objects` (background objects left out), about
    /// `density` samples per square metre, drawn from `seed`, less the hidden ones (see
    /// [`exposed`]): the same objects, density and seed give the same samples.
    pub fn sample(objects: &[Object], density: f32, seed: u64) -> Surface {
        let all = Surface::sample_all(objects, density, seed);
        let motor = motor_world(objects);
        let shown = exposed_each(&motor, &all.points, &all.normals);
        fn keep<T: Copy>(v: &[T], shown: &[bool]) -> Vec<T> {
            v.iter()
                .zip(shown)
                .filter(|(_, s)| **s)
                .map(|(x, _)| *x)
                .collect()
        }
        Surface {
            points: keep(&all.points, &shown),
            normals: keep(&all.normals, &shown),
            instances: keep(&all.instances, &shown),
            parts: keep(&all.parts, &shown),
            area: all.area,
        }
    }

    /// [`Surface::sample`] with the hidden samples kept.
    pub fn sample_all(objects: &[Object], density: f32, seed: u64) -> Surface {
        // every triangle of every part, with its cumulative area
        let mut tris: Vec<(usize, [Vec3; 3])> = Vec::new();
        let mut cumulative: Vec<f64> = Vec::new();
        let mut total = 0.0f64;
        for (k, o) in objects.iter().enumerate() {
            if o.part.is_none() {
                continue;
            }
            for t in &o.mesh.triangles {
                let [a, b, c] = t.map(|i| o.mesh.positions[i as usize]);
                let area = 0.5 * (b - a).cross(c - a).length() as f64;
                if area > 0.0 {
                    total += area;
                    tris.push((k, [a, b, c]));
                    cumulative.push(total);
                }
            }
        }
        let n = (total * f64::from(density)).round() as usize;
        let mut out = Surface {
            area: if n > 0 {
                (total / n as f64) as f32
            } else {
                0.0
            },
            ..Surface::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let drawn: Vec<(usize, Vec3, Vec3)> = (0..n)
            .map(|_| {
                let at = rng.random::<f64>() * total;
                let i = cumulative.partition_point(|&c| c <= at).min(tris.len() - 1);
                let (k, [a, b, c]) = tris[i];
                // uniform on the triangle: the unit square folded onto it
                let (mut u, mut v): (f32, f32) = (rng.random(), rng.random());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                (
                    k,
                    a + u * (b - a) + v * (c - a),
                    (b - a).cross(c - a).normalize(),
                )
            })
            .collect();
        for (k, p, normal) in drawn {
            let object = &objects[k];
            out.points.push(p);
            out.normals.push(normal);
            out.instances.push(object.instance);
            out.parts.push(object.part.expect("a motor part"));
        }
        out
    }

    /// How many samples there are.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// The motor's parts among `objects`, to cast rays at.
fn motor_world(objects: &[Object]) -> World {
    let targets: Vec<Target> = objects
        .iter()
        .filter(|o| o.part.is_some())
        .map(|o| Target {
            positions: o.mesh.positions.clone(),
            triangles: o.mesh.triangles.clone(),
            classes: Classes::Uniform(0),
            instance: o.instance,
            material: o.material,
            wear: o.wear,
        })
        .collect();
    World::new(&targets)
}

/// When a view observes a surface sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rule {
    /// A measured point lies within this distance of the sample, m.
    pub radius: f32,
    /// The sample's normal lies within this angle of the directions to the camera and to the
    /// projector, degrees.
    pub max_angle_deg: f32,
}

/// Marks in `seen` the samples of `surface` that `scan` (taken by `sensor`) observes under
/// `rule`; `seen` only gains samples. Returns how many it gained.
pub fn observe(
    surface: &Surface,
    scan: &Scan,
    sensor: &SensorSpec,
    rule: Rule,
    seen: &mut [bool],
) -> usize {
    let pose: Affine3A = scan.pose;
    let camera = Vec3::from(pose.translation);
    let projector = sensor
        .projector()
        .map(|p| pose.transform_point3(p.centre()));
    // the measured points that can lie near a sample
    let (lo, hi) = surface
        .points
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let (lo, hi) = (lo - rule.radius, hi + rule.radius);
    let points: Vec<Vec3> = scan
        .window_rows()
        .flat_map_iter(|row| row.iter().filter(|p| p.is_valid()))
        .map(|p| pose.transform_point3(p.point))
        .filter(|w| w.cmpge(lo).all() && w.cmple(hi).all())
        .collect();
    let grid = Grid::new(&points, rule.radius);
    let cos = rule.max_angle_deg.to_radians().cos();
    seen.par_iter_mut()
        .enumerate()
        .filter(|(_, s)| !**s)
        .map(|(i, s)| {
            let (p, n) = (surface.points[i], surface.normals[i]);
            *s = faces(p, n, camera, cos)
                && projector.is_none_or(|l| faces(p, n, l, cos))
                && grid.any_within(&points, p, rule.radius);
            usize::from(*s)
        })
        .sum()
}

/// Whether the surface at `p` with normal `n` faces `eye` within the angle whose cosine is `cos`.
pub(crate) fn faces(p: Vec3, n: Vec3, eye: Vec3, cos: f32) -> bool {
    n.dot((eye - p).normalize()) >= cos
}

/// The overlap of views: for views A and B (each a list of exact surface points, world), the
/// share of A's points on the motor (those with a sample of `surface` within `radius`) with a
/// sample within `radius` that lies within `radius` of one of B's points. `out[a][b]`; 1 on the
/// diagonal (for a view with motor points), 0 for views that share no surface.
pub fn overlap(surface: &Surface, views: &[Vec<Vec3>], radius: f32) -> Vec<Vec<f32>> {
    let samples = Grid::new(&surface.points, radius);
    // per view, the samples it measured near
    let measured: Vec<Vec<bool>> = views
        .iter()
        .map(|points| {
            let grid = Grid::new(points, radius);
            surface
                .points
                .par_iter()
                .map(|&s| grid.any_within(points, s, radius))
                .collect()
        })
        .collect();
    let has_sample = |p: Vec3, seen: Option<&[bool]>| {
        samples
            .within(&surface.points, p, radius)
            .any(|i| seen.is_none_or(|seen| seen[i as usize]))
    };
    views
        .iter()
        .map(|points| {
            // the motor's points: those with a sample near
            let motor = points.par_iter().filter(|&&p| has_sample(p, None)).count();
            measured
                .iter()
                .map(|seen| {
                    let shared = points
                        .par_iter()
                        .filter(|&&p| has_sample(p, Some(seen)))
                        .count();
                    shared as f32 / motor.max(1) as f32
                })
                .collect()
        })
        .collect()
}

/// Points binned by cells of a given size, for finding those near a point: each cell's
/// points under a hash of the cell, the buckets in one array (a counting sort, linear in the
/// points).
struct Grid {
    size: f32,
    /// log2 of the number of buckets.
    bits: u32,
    /// Bucket b's items are `items[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    /// (cell key, point index).
    items: Vec<(u64, u32)>,
}

impl Grid {
    fn new(points: &[Vec3], size: f32) -> Grid {
        let keys: Vec<u64> = points.iter().map(|&p| key(cell(p, size))).collect();
        // about two buckets per point
        let bits = (2 * points.len())
            .max(2)
            .next_power_of_two()
            .trailing_zeros();
        let mut start = vec![0u32; (1 << bits) + 1];
        for &k in &keys {
            start[bucket(k, bits) + 1] += 1;
        }
        for b in 1..start.len() {
            start[b] += start[b - 1];
        }
        let mut fill = start.clone();
        let mut items = vec![(0, 0); points.len()];
        for (i, &k) in keys.iter().enumerate() {
            let b = bucket(k, bits);
            items[fill[b] as usize] = (k, i as u32);
            fill[b] += 1;
        }
        Grid {
            size,
            bits,
            start,
            items,
        }
    }

    /// The indices of the points of `points` within `radius` (at most the cell size) of `p`.
    fn within<'a>(
        &'a self,
        points: &'a [Vec3],
        p: Vec3,
        radius: f32,
    ) -> impl Iterator<Item = u32> + 'a {
        let c = cell(p, self.size);
        (0..27).flat_map(move |n| {
            let k = key(c + glam::IVec3::new(n % 3 - 1, n / 3 % 3 - 1, n / 9 - 1));
            let b = bucket(k, self.bits);
            self.items[self.start[b] as usize..self.start[b + 1] as usize]
                .iter()
                .filter(move |e| {
                    e.0 == k && points[e.1 as usize].distance_squared(p) <= radius * radius
                })
                .map(|e| e.1)
        })
    }

    /// Whether a point of `points` lies within `radius` (at most the cell size) of `p`.
    fn any_within(&self, points: &[Vec3], p: Vec3, radius: f32) -> bool {
        self.within(points, p, radius).next().is_some()
    }
}

/// The cell holding `p`: each coordinate over `size`, rounded down.
fn cell(p: Vec3, size: f32) -> glam::IVec3 {
    // a cast rounds towards zero (no call to floor on baseline x86-64): one less below zero
    let floor = |x: f32| {
        let i = x as i32;
        i.saturating_sub(i32::from(x < i as f32))
    };
    let q = p / size;
    glam::IVec3::new(floor(q.x), floor(q.y), floor(q.z))
}

/// A cell's key: its coordinates offset into 21 bits each.
fn key(c: glam::IVec3) -> u64 {
    let k = |x: i32| ((x + (1 << 20)) as u64) & 0x1f_ffff;
    k(c.x) | k(c.y) << 21 | k(c.z) << 42
}

/// The bucket of the cell with key `k` among 2^`bits`, `bits` ≥ 1 (Fibonacci hashing).
fn bucket(k: u64, bits: u32) -> usize {
    (k.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> (64 - bits)) as usize
}

/// The share of the samples seen: in total, and per part kind present (in `PartKind` order).
pub fn coverage(surface: &Surface, seen: &[bool]) -> (f32, Vec<(PartKind, f32)>) {
    let total = seen.iter().filter(|&&s| s).count() as f32 / surface.len().max(1) as f32;
    let mut per: std::collections::BTreeMap<PartKind, (usize, usize)> = Default::default();
    for (part, &s) in surface.parts.iter().zip(seen) {
        let e = per.entry(*part).or_default();
        e.0 += usize::from(s);
        e.1 += 1;
    }
    (
        total,
        per.into_iter()
            .map(|(k, (s, n))| (k, s as f32 / n as f32))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{Cell, Kind};
    use motorgen::Scheme;
    use motorgen::kernel::Mesh;
    use sensor::{Intrinsics, Model, Projector, World, look_at, materials};

    /// A cube of side 0.1 m at the origin, one part.
    fn cube() -> Object {
        let h = 0.05;
        let positions: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    h * [-1.0, 1.0][i & 1],
                    h * [-1.0, 1.0][i >> 1 & 1],
                    h * [-1.0, 1.0][i >> 2],
                )
            })
            .collect();
        // two outward triangles per face
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        Object {
            name: "cube".into(),
            part: Some(PartKind::Cover),
            kind: Kind::Assembled { motor: 2 },
            instance: 1,
            mesh: Mesh {
                positions,
                triangles,
            },
            pose: Affine3A::IDENTITY,
            material: materials::MATTE_GREY,
            wear: None,
        }
    }

    /// The ideal camera, 300×300, looking at the origin from 0.6 m along `dir`.
    fn view(objects: &[Object], dir: Vec3) -> (Scan, SensorSpec) {
        let mut sensor = SensorSpec::preset("ideal").unwrap();
        sensor.intrinsics = Intrinsics::from_fov(300, 300, 30.0, 30.0);
        view_with(objects, dir, sensor)
    }

    /// `sensor` looking at the origin from 0.6 m along `dir`.
    fn view_with(objects: &[Object], dir: Vec3, sensor: SensorSpec) -> (Scan, SensorSpec) {
        let cell = Cell {
            objects: objects.to_vec(),
            motor_to_world: Affine3A::IDENTITY,
            motor_centre: Vec3::ZERO,
            fixture: Vec::new(),
            clamping: crate::Clamping::default(),
        };
        let world = World::new(&cell.targets(Scheme::SynMotor));
        let up = if dir.y.abs() > 0.9 { Vec3::Z } else { Vec3::Y };
        let pose = look_at(0.6 * dir, Vec3::ZERO, up).unwrap();
        (sensor::scan(&world, &sensor, &pose, 1), sensor)
    }

    const RULE: Rule = Rule {
        radius: 0.003,
        max_angle_deg: 80.0,
    };

    #[test]
    fn a_cube_is_covered_a_sixth_from_one_face_and_wholly_from_six() {
        let objects = [cube()];
        let surface = Surface::sample(&objects, 2e5, 7);
        assert_eq!(surface.len(), 12_000);
        let mut seen = vec![false; surface.len()];
        let mut last = 0.0;
        for (k, dir) in [
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
        ]
        .into_iter()
        .enumerate()
        {
            let (scan, sensor) = view(&objects, dir);
            observe(&surface, &scan, &sensor, RULE, &mut seen);
            let (total, parts) = coverage(&surface, &seen);
            eprintln!("{} views: {total}", k + 1);
            assert!(total >= last, "coverage fell");
            assert!(
                (total - (k + 1) as f32 / 6.0).abs() < 0.02,
                "{} views: {total}",
                k + 1
            );
            assert_eq!(parts.len(), 1);
            last = total;
        }
    }

    #[test]
    fn a_face_in_the_projectors_shadow_is_not_covered() {
        let objects = [cube()];
        let surface = Surface::sample(&objects, 2e5, 3);
        // a camera that sees the top (+z) and the -x face at 45°
        let dir = Vec3::new(-1.0, 0.0, 1.0).normalize();
        let mut ideal = SensorSpec::preset("ideal").unwrap();
        ideal.intrinsics = Intrinsics::from_fov(300, 300, 30.0, 30.0);
        // the same camera with a projector 1 m along its x axis (in the x-z plane): it lights
        // one of the two faces only
        let structured = SensorSpec {
            model: Model::StructuredLight {
                projector: Projector {
                    baseline: 1.0,
                    convergence: 0.6,
                    hfov_deg: 90.0,
                    vfov_deg: 90.0,
                },
            },
            ..ideal.clone()
        };
        let covered = |sensor: SensorSpec| {
            let (scan, sensor) = view_with(&objects, dir, sensor);
            let mut seen = vec![false; surface.len()];
            observe(&surface, &scan, &sensor, RULE, &mut seen);
            coverage(&surface, &seen).0
        };
        let (both, one) = (covered(ideal), covered(structured));
        eprintln!("camera alone {both}, with the projector's shadow {one}");
        assert!((both - 2.0 / 6.0).abs() < 0.02, "{both}");
        assert!((one - 1.0 / 6.0).abs() < 0.02, "{one}");
    }

    #[test]
    fn a_hidden_part_is_not_covered() {
        // a second cube 0.3 m behind the first as the camera sees them: hidden
        let mut behind = cube();
        behind.part = Some(PartKind::GearContainer);
        behind.instance = 2;
        for p in &mut behind.mesh.positions {
            p.z -= 0.3;
        }
        let objects = [cube(), behind];
        let surface = Surface::sample(&objects, 2e5, 5);
        let (scan, sensor) = view(&objects, Vec3::Z);
        let mut seen = vec![false; surface.len()];
        observe(&surface, &scan, &sensor, RULE, &mut seen);
        let (total, parts) = coverage(&surface, &seen);
        eprintln!("{total} {parts:?}");
        assert!((total - 1.0 / 12.0).abs() < 0.01, "{total}");
        assert_eq!(parts[0], (PartKind::GearContainer, 0.0));
        assert_eq!(parts[1].0, PartKind::Cover);
        assert!((parts[1].1 - 1.0 / 6.0).abs() < 0.02, "{parts:?}");
    }

    /// The exact points of a scan, world.
    fn exact(scan: &Scan) -> Vec<Vec3> {
        scan.pixels
            .iter()
            .filter(|p| !p.clean.x.is_nan())
            .map(|p| scan.pose.transform_point3(p.clean))
            .collect()
    }

    #[test]
    fn a_view_overlaps_itself_wholly_the_opposite_view_not_at_all() {
        let objects = [cube()];
        let surface = Surface::sample_all(&objects, 4e5, 2);
        let view_from = |dir: Vec3| exact(&view(&objects, dir.normalize()).0);
        let views = [
            view_from(Vec3::Z),
            view_from(Vec3::NEG_Z),
            view_from(Vec3::new(1.0, 0.0, 1.0)),
            view_from(Vec3::Z),
        ];
        let o = overlap(&surface, &views, 0.0025);
        eprintln!("{o:?}");
        for (a, row) in o.iter().enumerate() {
            assert_eq!(row[a], 1.0);
            assert!(row.iter().all(|x| (0.0..=1.0).contains(x)));
        }
        // top and bottom share nothing; the same view again shares everything
        assert_eq!((o[0][1], o[1][0]), (0.0, 0.0));
        assert_eq!((o[0][3], o[3][0]), (1.0, 1.0));
        // at 45° the camera sees the top and the +x face equally: half its points are the top's,
        // and all of the top view's points are seen from there
        assert!((o[2][0] - 0.5).abs() < 0.05, "{}", o[2][0]);
        assert!(o[0][2] > 0.95, "{}", o[0][2]);
    }

    /// A motor's parts as cell objects, in the motor's frame.
    fn motor(seed: u64) -> Vec<Object> {
        let params = motorgen::ParamSpace::addon().sample(seed).unwrap();
        motorgen::build(&params, motorgen::Detail::Normal)
            .parts
            .iter()
            .map(|p| Object::part(p, &Affine3A::IDENTITY, Kind::Assembled { motor: 0 }))
            .collect()
    }

    #[test]
    fn a_motors_hidden_parts_are_left_out_and_coverage_only_grows() {
        for seed in [1, 2] {
            let objects = motor(seed);
            let surface = Surface::sample(&objects, 2e5, seed);
            assert_eq!(surface, Surface::sample(&objects, 2e5, seed));
            let kinds: std::collections::BTreeSet<PartKind> =
                surface.parts.iter().copied().collect();
            let count = |k: PartKind| surface.parts.iter().filter(|&&p| p == k).count();
            eprintln!(
                "{} samples: {:?}",
                surface.len(),
                kinds.iter().map(|&k| (k, count(k))).collect::<Vec<_>>()
            );
            // the magnets lie inside the pole pot; of the armature and the gears only what
            // the shaft's hole and the container's openings show
            assert_eq!(count(PartKind::Magnet), 0);
            let inner = count(PartKind::Armature)
                + count(PartKind::LowerGear)
                + count(PartKind::UpperGear)
                + count(PartKind::SingleGear);
            assert!(inner * 20 < surface.len(), "{inner} of {}", surface.len());
            for shown in [
                PartKind::PolePot,
                PartKind::GearContainer,
                PartKind::Cover,
                PartKind::CoverBolt,
            ] {
                assert!(count(shown) > 0, "{shown:?}");
            }
            let mut seen = vec![false; surface.len()];
            let mut last = (0.0, vec![]);
            for dir in [
                Vec3::Z,
                Vec3::X,
                Vec3::NEG_Y,
                Vec3::new(1.0, 1.0, -1.0).normalize(),
                Vec3::NEG_X,
                Vec3::NEG_Z,
            ] {
                let centre: Vec3 =
                    surface.points.iter().copied().sum::<Vec3>() / surface.len() as f32;
                let moved: Vec<Object> = objects
                    .iter()
                    .cloned()
                    .map(|mut o| {
                        o.mesh.positions.iter_mut().for_each(|p| *p -= centre);
                        o
                    })
                    .collect();
                let shifted = Surface {
                    points: surface.points.iter().map(|p| *p - centre).collect(),
                    ..surface.clone()
                };
                let (scan, sensor) = view(&moved, dir);
                observe(&shifted, &scan, &sensor, RULE, &mut seen);
                let now = coverage(&surface, &seen);
                assert!(now.0 >= last.0);
                for ((k, c), (_, before)) in now.1.iter().zip(
                    last.1
                        .iter()
                        .chain(std::iter::repeat(&(PartKind::Cover, 0.0))),
                ) {
                    assert!(*c <= 1.0 && c >= before, "{k:?}: {c} after {before}");
                }
                last = now;
            }
            eprintln!("six views: {:?}", last);
            assert!(last.0 > 0.5, "{last:?}");
        }
    }
}
