//! The mesh kernel against analytic solids: exact polygon volumes and closed, oriented shells.

use glam::{Affine3A, Vec2, Vec3};
mod common;

use common::{assert_solid, close};
use motorgen::kernel::*;
use std::f64::consts::PI;

/// Volume of a prism over a regular n-gon inscribed in a circle of radius r.
fn ngon_prism(n: usize, r: f64, h: f64) -> f64 {
    0.5 * n as f64 * (2.0 * PI / n as f64).sin() * r * r * h
}

#[test]
fn revolved_cylinder_has_the_polygon_volume() {
    let n = 32;
    let m = sweep(
        &Section::Circle { segments: n },
        &[
            Vec2::new(0.0, 0.0),
            Vec2::new(0.02, 0.0),
            Vec2::new(0.02, 0.05),
            Vec2::new(0.0, 0.05),
        ],
        &[],
    );
    assert_solid(&m, 1);
    assert!(close(m.signed_volume(), ngon_prism(n, 0.02, 0.05), 1e-5));
    // poles + two rings: 2 + 2n vertices, 4n triangles
    assert_eq!(m.positions.len(), 2 + 2 * n);
    assert_eq!(m.triangle_count(), 4 * n);
}

#[test]
fn profile_direction_does_not_matter() {
    let up = [
        Vec2::new(0.0, 0.0),
        Vec2::new(0.01, 0.0),
        Vec2::new(0.01, 0.02),
        Vec2::new(0.0, 0.02),
    ];
    let mut down = up;
    down.reverse();
    let s = Section::Circle { segments: 16 };
    let (a, b) = (sweep(&s, &up, &[]), sweep(&s, &down, &[]));
    assert_solid(&b, 1);
    assert!(close(a.signed_volume(), b.signed_volume(), 1e-6));
}

#[test]
fn blind_hole_and_pocket_remove_their_volume() {
    let n = 24;
    let s = Section::Circle { segments: n };
    // boss r=5 mm, 12 mm long, with a 2.5 mm hole 5 mm deep from the bottom
    let boss = sweep(
        &s,
        &[
            Vec2::new(0.0, 0.005),
            Vec2::new(0.0025, 0.005),
            Vec2::new(0.0025, 0.0),
            Vec2::new(0.005, 0.0),
            Vec2::new(0.005, 0.012),
            Vec2::new(0.0, 0.012),
        ],
        &[],
    );
    assert_solid(&boss, 1);
    let expect = ngon_prism(n, 0.005, 0.012) - ngon_prism(n, 0.0025, 0.005);
    assert!(
        close(boss.signed_volume(), expect, 1e-5),
        "{} vs {expect}",
        boss.signed_volume()
    );

    // the same hole as a pocket in the top cap
    let pocket = Pocket {
        outline: circle(Vec2::ZERO, 0.0025, n, 0.0),
        depth: 0.005,
    };
    let cup = sweep(
        &s,
        &[
            Vec2::new(0.0, 0.0),
            Vec2::new(0.005, 0.0),
            Vec2::new(0.005, 0.012),
        ],
        &[pocket],
    );
    assert_solid(&cup, 1);
    assert!(close(cup.signed_volume(), expect, 1e-5));
}

#[test]
fn flat_circle_cup_matches_its_area() {
    let s = Section::FlatCircle {
        radius: 0.02,
        half_width: 0.015,
        arc_segments: 200,
    };
    let area = |r: f64, h: f64| {
        // circle of radius r cut at |x| = h: r²(π - 2α) + 2 h sqrt(r²-h²) with α = acos(h/r)
        let a = (h / r).acos();
        r * r * (PI - 2.0 * a) + 2.0 * h * (r * r - h * h).sqrt()
    };
    let inner = s.ring(-0.002);
    let cup = sweep(
        &s,
        &[Vec2::new(0.0, 0.0), Vec2::new(0.0, 0.068)],
        &[Pocket {
            outline: inner,
            depth: 0.066,
        }],
    );
    assert_solid(&cup, 1);
    let expect = area(0.02, 0.015) * 0.068 - area(0.018, 0.013) * 0.066;
    assert!(
        close(cup.signed_volume(), expect, 2e-3),
        "{} vs {expect}",
        cup.signed_volume()
    );
    let b = cup.bounds();
    assert!(
        (b.size() - Vec3::new(0.03, 0.04, 0.068))
            .abs()
            .max_element()
            < 1e-6,
        "{b:?}"
    );
}

#[test]
fn tube_from_a_profile_loop() {
    let s = Section::FlatCircle {
        radius: 0.02,
        half_width: 0.015,
        arc_segments: 16,
    };
    let tube = sweep_loop(
        &s,
        &[
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, 0.01),
            Vec2::new(-0.002, 0.01),
            Vec2::new(-0.002, 0.0),
        ],
    );
    assert_solid(&tube, 1);
    // the ring between the outline at u = 0 and at u = -2 mm, 1 cm tall
    let area = |u: f32| {
        let ring = s.ring(u);
        let n = ring.len();
        (0..n)
            .map(|i| ring[i].perp_dot(ring[(i + 1) % n]) as f64)
            .sum::<f64>()
            / 2.0
    };
    let want = (area(0.0) - area(-0.002)) * 0.01;
    assert!(
        close(tube.signed_volume(), want, 1e-4),
        "{} vs {want}",
        tube.signed_volume()
    );
    let b = tube.bounds();
    assert!(
        (b.max - Vec3::new(0.015, 0.02, 0.01)).abs().max_element() < 1e-6,
        "{b:?}"
    );
}

#[test]
fn extrusion_with_holes() {
    let outer = circle(Vec2::ZERO, 0.01, 40, 0.0);
    let hole = circle(Vec2::new(0.004, 0.0), 0.002, 16, 0.0);
    let m = extrude(&Extrusion {
        outer,
        holes: vec![hole],
        z0: 0.0,
        z1: 0.005,
    });
    assert_solid(&m, 1);
    let expect = ngon_prism(40, 0.01, 0.005) - ngon_prism(16, 0.002, 0.005);
    assert!(close(m.signed_volume(), expect, 1e-5));
}

/// A regular n-gon of radius r about the origin.
fn ring(r: f32, n: usize) -> Vec<Vec2> {
    circle(Vec2::ZERO, r, n, 0.0)
}

/// `outline` held unturned from z0 to z1.
fn stretch(outline: Vec<Vec2>, z0: f32, z1: f32) -> Stretch {
    Stretch {
        outline,
        z0,
        z1,
        turn: [0.0, 0.0],
    }
}

#[test]
fn stacked_wheel_pinion_and_hub() {
    // a wheel (r 10, hole 4) on z 0..2, a pinion (r 5, hole 2) on z 1..6: the wheel gives the
    // outside below 2, the pinion's hole the inside above 1
    let m = stack(
        &[
            stretch(ring(10.0, 48), 0.0, 2.0),
            stretch(ring(5.0, 24), 2.0, 6.0),
        ],
        &[
            stretch(ring(4.0, 20), 0.0, 1.0),
            stretch(ring(2.0, 12), 1.0, 6.0),
        ],
    );
    assert_solid(&m, 1);
    let p = |n, r| ngon_prism(n, r, 1.0);
    let expect = 2.0 * p(48, 10.0) + 4.0 * p(24, 5.0) - p(20, 4.0) - 5.0 * p(12, 2.0);
    assert!(
        close(m.signed_volume(), expect, 1e-5),
        "{}",
        m.signed_volume()
    );
    // turning the outline keeps the shell closed and, for a circle's polygon, its volume
    // within the sliver the triangulated side walls cut off
    let turned = stack(
        &[Stretch {
            turn: [0.0, 0.2],
            ..stretch(ring(10.0, 48), 0.0, 2.0)
        }],
        &[stretch(ring(4.0, 20), 0.0, 2.0)],
    );
    assert_solid(&turned, 1);
    let v = turned.signed_volume();
    let plain = 2.0 * (p(48, 10.0) - p(20, 4.0));
    assert!(v < plain && v > 0.97 * plain, "{v} vs {plain}");
}

#[test]
fn stacked_cup_on_a_boss_with_a_blind_hole() {
    // a boss (r 1) on z 0..1 with a blind hole (r 0.5) 0..0.5, under a cup (r 3) on 1..4 whose
    // cavity (r 2) goes down to 1.5: the hole stops inside the solid
    let m = stack(
        &[
            stretch(ring(1.0, 16), 0.0, 1.0),
            stretch(ring(3.0, 48), 1.0, 4.0),
        ],
        &[
            stretch(ring(0.5, 12), 0.0, 0.5),
            stretch(ring(2.0, 32), 1.5, 4.0),
        ],
    );
    assert_solid(&m, 1);
    let p = |n, r, h| ngon_prism(n, r, h);
    let expect = p(16, 1.0, 1.0) + p(48, 3.0, 3.0) - p(12, 0.5, 0.5) - p(32, 2.0, 2.5);
    assert!(
        close(m.signed_volume(), expect, 1e-5),
        "{}",
        m.signed_volume()
    );
}

#[test]
fn concave_polygons_and_clockwise_input() {
    // an L shape given clockwise
    let l = vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(0.0, 0.02),
        Vec2::new(0.01, 0.02),
        Vec2::new(0.01, 0.01),
        Vec2::new(0.02, 0.01),
        Vec2::new(0.02, 0.0),
    ];
    let m = extrude(&Extrusion {
        outer: l,
        z0: 0.0,
        z1: 0.001,
        ..Default::default()
    });
    assert_solid(&m, 1);
    assert!(close(m.signed_volume(), 3e-4 * 1e-3, 1e-5));
}

#[test]
fn mirroring_keeps_shells_outward() {
    let mut m = cuboid(Vec3::ZERO, Vec3::new(0.01, 0.02, 0.03));
    let v = m.signed_volume();
    m.transform(&Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
    assert_solid(&m, 1);
    assert!(close(m.signed_volume(), v, 1e-6));
}

#[test]
fn inspect_finds_holes_and_flips() {
    let mut m = cuboid(Vec3::ZERO, Vec3::ONE * 0.01);
    let mut open = m.clone();
    open.triangles.pop();
    assert_eq!(inspect(&open).boundary_edges, 3);
    m.triangles[0].swap(1, 2);
    assert!(inspect(&m).misoriented_edges > 0);
    let mut inside_out = cuboid(Vec3::ZERO, Vec3::ONE * 0.01);
    inside_out.flip();
    let rep = inspect(&inside_out);
    assert!(rep.min_shell_volume < 0.0 && !rep.is_valid_solid());
}

#[test]
fn segment_counts_follow_the_tolerance() {
    assert!(Detail::Fine.segments(0.02) > Detail::Normal.segments(0.02));
    assert!(Detail::Normal.segments(0.02) > Detail::Coarse.segments(0.02));
    for d in [Detail::Coarse, Detail::Normal, Detail::Fine] {
        for r in [0.001f32, 0.0035, 0.02, 0.05] {
            let n = d.segments(r);
            assert_eq!(n % 4, 0);
            let sagitta = r * (1.0 - (std::f32::consts::PI / n as f32).cos());
            assert!(
                n == 8 || n == 256 || sagitta <= d.tolerance() * 1.001,
                "{d:?} r={r} n={n}"
            );
        }
    }
}

#[test]
fn csg_union_and_difference_are_closed_with_the_right_volume() {
    let a = cuboid(Vec3::ZERO, Vec3::splat(2.0));
    let b = cuboid(Vec3::splat(1.0), Vec3::splat(3.0));
    let u = csg::union(&[a.clone(), b.clone()]);
    assert_solid(&u, 1);
    assert!(close(u.signed_volume(), 8.0 + 8.0 - 1.0, 1e-9));
    // apart, two shells; a cut through the middle leaves the polygon's volume out
    let far = cuboid(Vec3::splat(5.0), Vec3::splat(6.0));
    assert_solid(&csg::union(&[a.clone(), far]), 2);
    let n = 24;
    let bore = sweep(
        &Section::Circle { segments: n },
        &[
            Vec2::new(0.0, -1.0),
            Vec2::new(0.5, -1.0),
            Vec2::new(0.5, 3.0),
            Vec2::new(0.0, 3.0),
        ],
        &[],
    )
    .transformed(&Affine3A::from_translation(Vec3::new(1.0, 1.0, 0.0)));
    let d = csg::difference(&a, &[bore]);
    assert_solid(&d, 1);
    assert!(close(
        d.signed_volume(),
        8.0 - ngon_prism(n, 0.5, 2.0),
        1e-6
    ));
}
