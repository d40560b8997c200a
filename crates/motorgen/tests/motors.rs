//! Built motors against their parameters: every part a valid solid, dimensions as asked, ground
//! truth where the mesh is. The gearbox frame is recomputed here from the parameters alone.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};
use motorgen::kernel::{Mesh, inspect, shell_ids};
use motorgen::params::{MotorType, Value};
use motorgen::{Detail, Motor, MotorParams, ParamSpace, PartKind, build};
use proptest::prelude::*;

/// Length tolerance for measured dimensions: f32 coordinates and the cm→m scaling.
const TOL: f32 = 2e-6;

/// How far apart the shells of a part must stay (metres): a quarter of the plates' 1 µm grid,
/// within which they would be one.
const APART: f64 = 2.5e-7;

/// Whether the segment `p q` meets the triangle `t` (Möller and Trumbore; touching counts).
fn segment_meets(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> bool {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], q - p);
    let h = d.cross(e2);
    let a = e1.dot(h);
    if a.abs() < 1e-18 {
        return false;
    }
    let s = (p - t[0]) / a;
    let u = s.dot(h);
    let qv = s.cross(e1);
    let v = d.dot(qv);
    let w = e2.dot(qv);
    (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&w)
}

/// Distance from `p` to the triangle `t`.
fn point_triangle_distance(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    let off = (p - t[0]).dot(n);
    let q = p - off * n;
    let inside = (0..3).all(|k| (t[(k + 1) % 3] - t[k]).cross(q - t[k]).dot(n) >= 0.0);
    if inside {
        return off.abs();
    }
    (0..3)
        .map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let s = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + s * (b - a))
        })
        .fold(f64::INFINITY, f64::min)
}

/// The shells of `mesh` neither meet nor come within `gap` of each other (metres): no edge of
/// one passes through a triangle of another, no corner of one lies within `gap` of another.
fn shells_apart(mesh: &Mesh, gap: f64) -> Result<(), String> {
    let shell = shell_ids(mesh);
    if shell.iter().all(|&s| s == 0) {
        return Ok(());
    }
    let tris: Vec<[DVec3; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| mesh.positions[i as usize].as_dvec3()))
        .collect();
    let bounds: Vec<(DVec3, DVec3)> = tris
        .iter()
        .map(|t| {
            (
                t[0].min(t[1]).min(t[2]) - gap,
                t[0].max(t[1]).max(t[2]) + gap,
            )
        })
        .collect();
    let mut order: Vec<usize> = (0..tris.len()).collect();
    order.sort_by(|&a, &b| bounds[a].0.x.total_cmp(&bounds[b].0.x));
    let mut active: Vec<usize> = Vec::new();
    for &i in &order {
        active.retain(|&j| bounds[j].1.x >= bounds[i].0.x);
        for &j in &active {
            let (a, b) = (&bounds[i], &bounds[j]);
            if shell[i] == shell[j] || a.0.cmpgt(b.1).any() || b.0.cmpgt(a.1).any() {
                continue;
            }
            let (s, t) = (&tris[i], &tris[j]);
            let edges_meet = |s: &[DVec3; 3], t: &[DVec3; 3]| {
                (0..3).any(|k| segment_meets(s[k], s[(k + 1) % 3], t))
            };
            let near = |s: &[DVec3; 3], t: &[DVec3; 3]| {
                s.iter().any(|&p| point_triangle_distance(p, t) < gap)
            };
            if edges_meet(s, t) || edges_meet(t, s) || near(s, t) || near(t, s) {
                return Err(format!(
                    "shells {} and {} meet at {:?} / {:?}",
                    shell[i], shell[j], s, t
                ));
            }
        }
        active.push(i);
    }
    Ok(())
}

fn params(pairs: &[(&str, Value)]) -> MotorParams {
    let map: BTreeMap<String, Value> = pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    MotorParams::from_values(&map).unwrap()
}

/// The gearbox's in-plane horizontal direction u (v is the motor axis), from the parameters.
fn gearbox_u(p: &MotorParams) -> Vec3 {
    let base = match p.motor_type {
        MotorType::A => Vec3::X,
        MotorType::B => Vec3::Y,
    };
    let mirrored = if p.mirror { -base } else { base };
    glam::Quat::from_rotation_z(-(p.gearbox_orientation_deg as f32).to_radians()) * mirrored
}

fn parts(m: &Motor, kind: PartKind) -> Vec<&motorgen::Part> {
    m.parts.iter().filter(|p| p.kind == kind).collect()
}

fn check_motor(p: &MotorParams, detail: Detail) -> Result<(), TestCaseError> {
    let m = build(p, detail);
    // every part a closed, oriented, non-degenerate solid, its shells apart; instances unique
    // from 1
    for (i, part) in m.parts.iter().enumerate() {
        let rep = inspect(&part.mesh);
        prop_assert!(rep.is_valid_solid(), "{} of {:?}: {:?}", part.name, p, rep);
        if let Err(e) = shells_apart(&part.mesh, APART) {
            prop_assert!(false, "{} of {:?}: {}", part.name, p, e);
        }
        prop_assert_eq!(part.instance as usize, i + 1);
    }

    // pole pot: shaft boss + pot length along z, 3 x 4 cm across
    let pot = parts(&m, PartKind::PolePot)[0].mesh.bounds();
    prop_assert!(
        (pot.size().z - (p.pole_pot_length + p.shaft_boss_length)).abs() < TOL,
        "{pot:?}"
    );
    prop_assert!(
        (pot.size().x - 0.03).abs() < TOL && (pot.size().y - 0.04).abs() < TOL,
        "{pot:?}"
    );
    prop_assert!(pot.min.z.abs() < TOL);

    // bolt counts
    let (side, cover) = (
        parts(&m, PartKind::SideBolt),
        parts(&m, PartKind::CoverBolt),
    );
    prop_assert_eq!(side.len(), 2);
    let expect_cover = match p.motor_type {
        MotorType::A => 2 + p.upper_bolt_count as usize,
        MotorType::B => p.b_bolt_count as usize + 1,
    };
    prop_assert_eq!(cover.len(), expect_cover);
    prop_assert_eq!(m.attributes.bolts.len(), 2 + expect_cover);

    // each bolt's drive face: no vertex beyond it, and the head centred on it
    for (b, part) in m.attributes.bolts.iter().zip(side.iter().chain(&cover)) {
        prop_assert_eq!(&b.name, &part.name);
        let heights: Vec<f32> = part
            .mesh
            .positions
            .iter()
            .map(|v| (*v - b.head_centre).dot(-b.axis))
            .collect();
        prop_assert!(heights.iter().all(|h| *h < TOL));
        prop_assert!(heights.iter().any(|h| h.abs() < TOL));
        let off_axis = part.mesh.bounds().centre() - b.head_centre;
        prop_assert!(
            (off_axis - off_axis.dot(b.axis) * b.axis).length() < 1e-4,
            "{} off axis {off_axis}",
            b.name
        );
    }

    // gears and cover bolts in the gearbox plane: housing circles where the ground truth says,
    // bolts at the parameter angles on radius R + 3.6 mm
    let (u, v) = (gearbox_u(p), Vec3::Z);
    let container = &parts(&m, PartKind::GearContainer)[0].mesh;
    let expected_gears: Vec<(PartKind, f32)> = match p.motor_type {
        MotorType::A => vec![
            (PartKind::LowerGear, p.lower_gear_diameter),
            (PartKind::UpperGear, p.upper_gear_diameter),
        ],
        MotorType::B => vec![(PartKind::SingleGear, p.lower_gear_diameter)],
    };
    prop_assert_eq!(m.attributes.gears.len(), expected_gears.len());
    for (g, (kind, dia)) in m.attributes.gears.iter().zip(&expected_gears) {
        prop_assert_eq!(g.kind, *kind);
        prop_assert!(
            g.axis.dot(u).abs() < 1e-6 && g.axis.dot(v).abs() < 1e-6,
            "axis {} not normal to the cover plane",
            g.axis
        );
        let on_rim = container
            .positions
            .iter()
            .filter(|q| {
                let d = **q - g.centre;
                let radial = (d - d.dot(g.axis) * g.axis).length();
                (radial - dia / 2.0).abs() < TOL && d.dot(g.axis) < TOL
            })
            .count();
        prop_assert!(
            on_rim >= 16,
            "{:?}: only {on_rim} container vertices on the housing circle",
            kind
        );
        let inner = parts(&m, *kind)[0].mesh.bounds();
        prop_assert!(g.gear_diameter < *dia && (inner.centre() - g.centre).dot(u).abs() < 1e-4);
    }
    let angle_of = |centre: Vec3, point: Vec3| {
        let d = point - centre;
        (d.dot(v).atan2(d.dot(u)).to_degrees() + 360.0) % 360.0
    };
    let on_gear = |k: usize,
                   dia: f32,
                   angles: Vec<f32>,
                   bolts: &[&motorgen::model::BoltAttr]|
     -> Result<(), TestCaseError> {
        let g = &m.attributes.gears[k];
        for (a, b) in angles.iter().zip(bolts) {
            let d = b.head_centre - g.centre;
            let radial = (d - d.dot(g.axis) * g.axis).length();
            prop_assert!(
                (radial - (dia / 2.0 + 0.0036)).abs() < 2e-5,
                "{} at radius {radial}",
                b.name
            );
            prop_assert!(
                ((angle_of(g.centre, b.head_centre) - a + 540.0) % 360.0 - 180.0).abs() < 0.01,
                "{} angle",
                b.name
            );
            prop_assert!(
                b.axis.dot(g.axis) < -0.9999,
                "{} screws into the cover",
                b.name
            );
        }
        Ok(())
    };
    let cover_bolts: Vec<_> = m
        .attributes
        .bolts
        .iter()
        .filter(|b| b.kind == PartKind::CoverBolt)
        .collect();
    match p.motor_type {
        MotorType::A => {
            on_gear(
                0,
                p.lower_gear_diameter,
                vec![p.lower_bolt_1_deg, p.lower_bolt_2_deg],
                &cover_bolts[..2],
            )?;
            on_gear(
                1,
                p.upper_gear_diameter,
                p.upper_bolt_angles_deg(),
                &cover_bolts[2..],
            )?;
        }
        MotorType::B => {
            on_gear(
                0,
                p.lower_gear_diameter,
                p.b_bolt_angles_deg(),
                &cover_bolts,
            )?;
            let right = cover_bolts.last().unwrap().head_centre;
            prop_assert!(
                (right.z - (m.attributes.pole_pot_top + p.type_b_right_bolt_height)).abs() < TOL
            );
        }
    }
    // the attribute summary matches the meshes
    for (a, part) in m.attributes.parts.iter().zip(&m.parts) {
        prop_assert_eq!(a.triangles, part.mesh.triangle_count());
        prop_assert!(a.volume > 0.0);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1200, ..ProptestConfig::default() })]

    /// Random motors from the add-on's generator (every type, extension, orientation, mirror,
    /// drive and bolt layout).
    #[test]
    fn random_motors_are_valid_and_measure_right(seed in any::<u64>()) {
        let p = ParamSpace::addon().sample(seed).unwrap();
        check_motor(&p, Detail::Coarse)?;
    }
}

/// The add-on's random motors (by seed) whose gear containers and covers once showed a flaw
/// of the plates' union while it was made: pinches, touching solids, needles, slivers, crossed
/// routes, sloped boards too close to the plates.
#[test]
fn motors_that_tested_the_plates_union() {
    let space = ParamSpace::addon();
    let coarse: [u64; 20] = [
        900586915709452871,
        5148544111132648116,
        17488846536187842370,
        6734745621718541239,
        14171233490469838811,
        4452193541862435671,
        14652289558169344231,
        7686799985273589625,
        15670530889359354521,
        4451650061075893894,
        4661635746485828676,
        11646013959916852983,
        17867868702486864219,
        3167776657858206400,
        12753219024174179482,
        14171226733099132959,
        14160854169065685607,
        13624345296644575854,
        11059746506436274086,
        3741150891907036989,
    ];
    let normal: [u64; 15] = [
        7919, 71271, 87109, 95028, 285084, 332598, 688953, 855252, 934442, 958199, 1346230,
        1354149, 1575881, 10769840, 14167091,
    ];
    for (seeds, detail) in [(&coarse[..], Detail::Coarse), (&normal[..], Detail::Normal)] {
        for &seed in seeds {
            check_motor(&space.sample(seed).unwrap(), detail).unwrap();
        }
    }
}

#[test]
fn every_variant_at_every_detail() {
    for (ty, ext) in [
        ("A", "type1"),
        ("A", "type2"),
        ("A", "none"),
        ("B", "type1"),
        ("B", "none"),
    ] {
        let key = if ty == "A" {
            "extension_a"
        } else {
            "extension_b"
        };
        let p = params(&[
            ("type", Value::Text(ty.into())),
            (key, Value::Text(ext.into())),
        ]);
        for detail in [Detail::Coarse, Detail::Normal, Detail::Fine] {
            check_motor(&p, detail).unwrap();
        }
    }
}

#[test]
fn parts_of_several_shells_keep_them_apart() {
    // every variant, and random motors of the add-on's generator: the gear container's collar
    // and tower apart from its plates, the cover's pieces apart from each other
    let space = ParamSpace::addon();
    let variants = [
        ("A", "type1"),
        ("A", "type2"),
        ("A", "none"),
        ("B", "type1"),
        ("B", "none"),
    ]
    .map(|(ty, ext)| {
        let key = if ty == "A" {
            "extension_a"
        } else {
            "extension_b"
        };
        params(&[
            ("type", Value::Text(ty.into())),
            (key, Value::Text(ext.into())),
        ])
    });
    let random = (1..=10).map(|seed| space.sample(seed).unwrap());
    for p in variants.into_iter().chain(random) {
        let m = build(&p, Detail::Coarse);
        for part in &m.parts {
            if let Err(e) = shells_apart(&part.mesh, APART) {
                panic!("{} of {p:?}: {e}", part.name);
            }
        }
    }
}

#[test]
fn extension_shapes_differ_and_change_only_the_cover() {
    let cover_of = |ext: &str| {
        let m = build(
            &params(&[("extension_a", Value::Text(ext.into()))]),
            Detail::Coarse,
        );
        (
            m.parts
                .iter()
                .find(|p| p.kind == PartKind::Cover)
                .unwrap()
                .mesh
                .clone(),
            m,
        )
    };
    let (one, m1) = cover_of("type1");
    let (two, _) = cover_of("type2");
    let (none, m0) = cover_of("none");
    assert!(one.bounds() != two.bounds() && one.bounds() != none.bounds());
    assert!(
        none.triangle_count() < one.triangle_count() && one.triangle_count() < two.triangle_count()
    );
    for (a, b) in m1.parts.iter().zip(&m0.parts) {
        if a.kind != PartKind::Cover {
            assert_eq!(a.mesh, b.mesh, "{} changed with the cover shape", a.name);
        }
    }
}

#[test]
fn orientation_turns_the_gearbox_but_not_the_body() {
    let at = |deg: f64| {
        build(
            &params(&[("gearbox_orientation_deg", Value::Num(deg))]),
            Detail::Coarse,
        )
    };
    let (r0, r90) = (at(0.0), at(90.0));
    for (a, b) in r0.parts.iter().zip(&r90.parts) {
        let fixed = matches!(
            a.kind,
            PartKind::PolePot
                | PartKind::Magnet
                | PartKind::Armature
                | PartKind::ElectricConnection
                | PartKind::SideBolt
        );
        assert_eq!(fixed, a.mesh == b.mesh, "{}", a.name);
    }
    // r0 gear axis is -y (cover towards the connector side), r90 turns it by -90° about z
    assert!((r0.attributes.gears[0].axis - Vec3::NEG_Y).length() < 1e-6);
    assert!((r90.attributes.gears[0].axis - Vec3::NEG_X).length() < 1e-6);
}

#[test]
fn mirror_reflects_the_gearbox() {
    let m = build(&params(&[("mirror", Value::Bool(true))]), Detail::Coarse);
    let plain = build(&MotorParams::default(), Detail::Coarse);
    let (a, b) = (
        m.attributes.gears[0].centre,
        plain.attributes.gears[0].centre,
    );
    assert!((a - Vec3::new(-b.x, b.y, b.z)).length() < 1e-6);
}

#[test]
fn teeth_inclination_shears_the_teeth() {
    let gear = |deg: f64| {
        let m = build(
            &params(&[("teeth_inclination_deg", Value::Num(deg))]),
            Detail::Coarse,
        );
        m.parts
            .iter()
            .find(|p| p.kind == PartKind::UpperGear)
            .unwrap()
            .mesh
            .clone()
    };
    let (flat, left, right) = (gear(0.0), gear(-15.0), gear(15.0));
    assert_ne!(flat, left);
    assert_ne!(left, right);
    // same tooth profile, only the top face turned: same vertex count, nearly the same volume
    assert_eq!(flat.positions.len(), left.positions.len());
    assert!((left.signed_volume() / flat.signed_volume() - 1.0).abs() < 0.05);
}

#[test]
fn bolt_rotations_same_and_random() {
    let same = build(
        &params(&[("bolt_rotation_deg", Value::Num(75.0))]),
        Detail::Coarse,
    );
    assert!(
        same.attributes
            .bolts
            .iter()
            .all(|b| b.rotation_deg == 75.0 && b.rotation_mod_deg == 15.0)
    );
    let random = build(
        &params(&[
            ("bolt_orientation", Value::Text("random".into())),
            ("bolt_seed", Value::Num(3.0)),
        ]),
        Detail::Coarse,
    );
    let angles: Vec<f32> = random
        .attributes
        .bolts
        .iter()
        .map(|b| b.rotation_deg)
        .collect();
    assert!(
        angles
            .iter()
            .all(|a| a.fract() == 0.0 && (0.0..360.0).contains(a))
    );
    assert!(angles.windows(2).any(|w| w[0] != w[1]), "{angles:?}");
    // the recess turns with the angle: meshes differ, vertex counts do not
    let turned = build(
        &params(&[("bolt_rotation_deg", Value::Num(20.0))]),
        Detail::Coarse,
    );
    let (a, b) = (
        &same
            .parts
            .iter()
            .find(|p| p.kind == PartKind::CoverBolt)
            .unwrap()
            .mesh,
        &turned
            .parts
            .iter()
            .find(|p| p.kind == PartKind::CoverBolt)
            .unwrap()
            .mesh,
    );
    assert_ne!(a, b);
    assert_eq!(a.positions.len(), b.positions.len());
}

#[test]
fn a_slots_recess_lies_at_its_bolts_angle() {
    // the direction of the slot across each bolt's drive face, counter-clockwise about the
    // bolt's outward normal (-axis) from a fixed direction in the face: the principal axis of
    // the face's vertices (the rim, a regular polygon, adds the same in every direction)
    let slot_angles = |deg: f32| -> Vec<f64> {
        let m = build(
            &params(&[
                ("bolt_drive", Value::Text("slot".into())),
                ("bolt_rotation_deg", Value::Num(deg as f64)),
            ]),
            Detail::Normal,
        );
        m.attributes
            .bolts
            .iter()
            .map(|b| {
                let mesh = &m.parts.iter().find(|p| p.name == b.name).unwrap().mesh;
                let n = -b.axis.as_dvec3();
                let e1 = n.any_orthonormal_vector();
                let e2 = n.cross(e1);
                let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
                for p in &mesh.positions {
                    let d = (*p - b.head_centre).as_dvec3();
                    if d.dot(n).abs() < 1e-7 {
                        let (x, y) = (d.dot(e1), d.dot(e2));
                        (sxx, syy, sxy) = (sxx + x * x, syy + y * y, sxy + x * y);
                    }
                }
                0.5 * (2.0 * sxy).atan2(sxx - syy)
            })
            .collect()
    };
    let (straight, turned) = (slot_angles(0.0), slot_angles(30.0));
    assert!(straight.len() >= 4 && straight.len() == turned.len());
    for (a, b) in straight.iter().zip(&turned) {
        let turn = (b - a).to_degrees().rem_euclid(180.0);
        assert!((turn - 30.0).abs() < 0.5, "the slot turned {turn}° for 30°");
    }
}

#[test]
fn every_drive_builds_a_distinct_recess() {
    let meshes: Vec<_> = ["torx", "slot", "cross", "allen"]
        .iter()
        .map(|d| {
            let m = build(
                &params(&[("bolt_drive", Value::Text(d.to_string()))]),
                Detail::Normal,
            );
            m.parts
                .iter()
                .find(|p| p.kind == PartKind::SideBolt)
                .unwrap()
                .mesh
                .clone()
        })
        .collect();
    for i in 0..4 {
        assert!(inspect(&meshes[i]).is_valid_solid());
        for j in i + 1..4 {
            assert_ne!(meshes[i].signed_volume(), meshes[j].signed_volume());
        }
    }
}

#[test]
fn exploded_view_moves_parts_apart() {
    // summed volume of the pairwise overlaps of the parts' boxes
    let overlap = |m: &Motor| {
        let boxes: Vec<_> = m.parts.iter().map(|p| p.mesh.bounds()).collect();
        let mut sum = 0.0;
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[i + 1..] {
                let e = (a.max.min(b.max) - a.min.max(b.min)).max(Vec3::ZERO);
                sum += e.x * e.y * e.z;
            }
        }
        sum
    };
    for params in [
        MotorParams::default(),
        params(&[("type", Value::Text("B".into()))]),
    ] {
        let m = build(&params, Detail::Coarse);
        assert_eq!(m.exploded(0.0).parts, m.parts);
        // each part moves by its own offset, in proportion to the factor
        for f in [0.5, 1.0] {
            for (a, b) in m.parts.iter().zip(&m.exploded(f).parts) {
                let shift = b.mesh.bounds().min - a.mesh.bounds().min;
                assert!(
                    (shift - a.explode * f).abs().max_element() < 1e-6,
                    "{}",
                    a.name
                );
                assert_eq!(a.mesh.triangles, b.mesh.triangles);
            }
        }
        // every part but the gear container, which the others leave, moves out by a centimetre
        // or more, and the parts' boxes overlap far less than assembled
        let still: Vec<&str> = m
            .parts
            .iter()
            .filter(|p| p.explode.length() < 0.01)
            .map(|p| p.name.as_str())
            .collect();
        assert_eq!(still, ["gear_container"]);
        assert!(overlap(&m.exploded(1.0)) < 0.25 * overlap(&m));
    }
    // the cover moves out along its gear axis (-y at orientation 0)
    let m = build(&MotorParams::default(), Detail::Coarse);
    let cover = |m: &Motor| {
        let p = m.parts.iter().find(|p| p.kind == PartKind::Cover).unwrap();
        p.mesh.bounds().centre()
    };
    assert!((cover(&m.exploded(1.0)) - cover(&m)).dot(Vec3::NEG_Y) > 0.04);
}

#[test]
fn unused_parameters_do_not_change_the_motor() {
    let b = |extra: &[(&str, Value)]| {
        let mut pairs = vec![("type", Value::Text("B".into()))];
        pairs.extend_from_slice(extra);
        build(&params(&pairs), Detail::Coarse).parts
    };
    assert_eq!(
        b(&[]),
        b(&[
            ("upper_gear_diameter", Value::Num(0.06)),
            ("upper_bolt_count", Value::Num(3.0))
        ])
    );
}

#[test]
fn covers_span_the_addons_depth_along_the_gear_axis() {
    // type A covers reach 3 mm behind the cover plane (the upper gear's inner ring) and out to
    // the lower gear's hub (10 mm), the eye of extension 1 (15 mm) or the eyes of extension 2
    // (25 mm), as the add-on's
    for (ext, reach) in [("none", 0.010), ("type1", 0.015), ("type2", 0.025)] {
        let m = build(
            &params(&[("extension_a", Value::Text(ext.into()))]),
            Detail::Coarse,
        );
        let gear = &m.attributes.gears[0];
        let cover = &m
            .parts
            .iter()
            .find(|p| p.kind == PartKind::Cover)
            .unwrap()
            .mesh;
        let along: Vec<f32> = cover
            .positions
            .iter()
            .map(|v| (*v - gear.centre).dot(gear.axis))
            .collect();
        let (lo, hi) = along
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), a| (lo.min(*a), hi.max(*a)));
        assert!((lo + 0.003).abs() < 1e-5, "{ext}: {lo}");
        assert!((hi - reach).abs() < 1e-5, "{ext}: {hi}");
        assert!(inspect(cover).is_valid_solid(), "{ext}");
    }
}
