//! The parts that turn with the gearbox, as the add-on builds them: the gear container's
//! housings, boards and cover-bolt bosses, the cover with its extension, the inner gears, and
//! where the cover bolts go. Built in the gearbox plane frame (u, v, w) in centimetres: v is
//! the motor's z, u the horizontal direction in the cover plane, w the gear axis pointing out
//! of the cover, and the cover plane at w = 0.

use glam::{Affine3A, Vec2, Vec3};

use super::Dims;
use super::body::BOSS_RADIUS;
use super::shapes::{Tess, gear_outline, plane_frame, plate, rect, strip};
use crate::kernel::{Mesh, Region, Stretch, signed_area2, stack};
use crate::model::PartKind;
use crate::params::{Extension, MotorParams, MotorType};

/// Housing wall thickness (the add-on's EXTENSION_THICKNESS).
const WALL: f32 = 0.2;
/// Distance of the cover bolts outside the housing radius.
const BOLT_OFFSET: f32 = 0.36;

/// One gear of the layout.
pub struct Gear {
    /// Which inner gear sits in it.
    pub kind: PartKind,
    /// Centre in (u, v).
    pub centre: Vec2,
    /// Housing outer radius.
    pub radius: f32,
    /// Housing depth behind the cover plane.
    pub depth: f32,
}

/// Where everything of the gearbox goes.
pub struct Layout {
    /// Gearbox frame to motor frame (cm): orientation, mirror and the cover plane's place.
    pub to_motor: Affine3A,
    /// The gears.
    pub gears: Vec<Gear>,
    /// Cover-bolt positions in (u, v), in bolt order.
    pub bolts: Vec<Vec2>,
    /// Height of a Torx cover bolt's drive face above the cover plane (as the add-on places it).
    pub bolt_face: f32,
}

impl Layout {
    /// Lays out the gearbox of `p`.
    pub fn new(p: &MotorParams, d: &Dims) -> Layout {
        let deg = |a: f32| a.to_radians();
        let on_circle = |c: Vec2, r: f32, a: f32| c + (r + BOLT_OFFSET) * Vec2::from_angle(deg(a));
        let quarter_turns = p.gearbox_orientation_deg / 90;
        let rotation = Affine3A::from_rotation_z(-deg(p.gearbox_orientation_deg as f32));
        let mirror = Affine3A::from_scale(Vec3::new(if p.mirror { -1.0 } else { 1.0 }, 1.0, 1.0));
        match p.motor_type {
            MotorType::A => {
                // gearbox depth along the gear axis = the pot's extent in that direction
                let l = if quarter_turns.is_multiple_of(2) {
                    4.0
                } else {
                    3.0
                };
                let (rl, ru) = (d.lower_dia / 2.0, d.upper_dia / 2.0);
                let cl = Vec2::new(rl, d.top + d.lower_pos);
                let cu = Vec2::new(rl - 0.8, d.top + d.lower_pos + ru + 0.2);
                let cover_plane = -1.0 - l / 3.0;
                let frame =
                    plane_frame(Vec3::X, Vec3::Z, -Vec3::Y, Vec3::new(0.0, cover_plane, 0.0));
                let mut bolts = vec![
                    on_circle(cl, rl, p.lower_bolt_1_deg),
                    on_circle(cl, rl, p.lower_bolt_2_deg),
                ];
                bolts.extend(
                    p.upper_bolt_angles_deg()
                        .into_iter()
                        .map(|a| on_circle(cu, ru, a)),
                );
                Layout {
                    to_motor: rotation * frame * mirror,
                    gears: vec![
                        Gear {
                            kind: PartKind::LowerGear,
                            centre: cl,
                            radius: rl,
                            depth: 2.0 * l / 3.0,
                        },
                        Gear {
                            kind: PartKind::UpperGear,
                            centre: cu,
                            radius: ru,
                            depth: l / 3.0,
                        },
                    ],
                    bolts,
                    bolt_face: 0.5005,
                }
            }
            MotorType::B => {
                let r = d.lower_dia / 2.0;
                let c = Vec2::new(-r, d.top + d.lower_pos);
                let frame = plane_frame(Vec3::Y, Vec3::Z, Vec3::X, Vec3::new(0.6, 0.0, 0.0));
                let mut bolts: Vec<Vec2> = p
                    .b_bolt_angles_deg()
                    .into_iter()
                    .map(|a| on_circle(c, r, a))
                    .collect();
                bolts.push(Vec2::new(1.1, d.top + d.right_bolt));
                Layout {
                    to_motor: rotation * frame * mirror,
                    gears: vec![Gear {
                        kind: PartKind::SingleGear,
                        centre: c,
                        radius: r,
                        depth: 1.5,
                    }],
                    bolts,
                    bolt_face: 0.6305,
                }
            }
        }
    }

    /// The gearbox's share of the gear container: housings, boards and cover-bolt bosses.
    pub fn container(&self, t: Tess, p: &MotorParams, d: &Dims) -> Mesh {
        match p.motor_type {
            MotorType::A => self.container_a(t, d),
            MotorType::B => self.container_b(t, d),
        }
    }

    /// Type A's gearbox share of the gear container as the add-on builds it (its `create_up`
    /// without extension and `create_outer_board`), as plates along the gear axis: the lower
    /// housing, a cup with a boss behind, its wall opened where the upper housing overlaps it; the
    /// upper housing with its inner rings; the cover-bolt bosses; the gear board (a slanted board
    /// from the tower to the lower housing) and the outer board (a board on the pot's flat, its
    /// slanted continuation to the tower's top, and the web between them). What lies inside the
    /// collar or the tower is cut away. Plates that meet overlap by 0.1 mm, so that no two share
    /// an edge.
    fn container_a(&self, t: Tess, d: &Dims) -> Mesh {
        const LAP: f32 = 0.01;
        let (lower, upper) = (&self.gears[0], &self.gears[1]);
        let (cl, rl, cu, ru) = (lower.centre, lower.radius, upper.centre, upper.radius);
        let l = 1.5 * lower.depth;
        let top = d.top;
        let tower = d.tower_steps()[2];
        let rect = |u0: f32, v0: f32, u1: f32, v1: f32| {
            Region::polygon(&rect(Vec2::new(u0, v0), Vec2::new(u1, v1)))
        };
        // boards end 0.5 mm inside the housings' outer walls; upper parts reach into the lower
        // housing's wall
        let board_cut_lower = t.disc(cl, rl - 0.05);
        let board_cut_upper = t.disc(cu, ru - 0.05);
        let inside_lower = t.disc(cl, rl - WALL);
        let (floor, mid) = (-2.0 * l / 3.0, -l / 3.0);
        let mut plates: Vec<(Region, f32, f32)> = vec![
            // lower housing: floor, wall, the wall opened by the upper housing, boss behind
            (t.disc(cl, rl), floor, floor + WALL),
            (t.annulus(cl, rl, rl - WALL), floor + WALL - LAP, mid + LAP),
            (
                t.annulus(cl, rl, rl - WALL)
                    .difference(&t.disc(cu, ru - WALL)),
                mid,
                0.0,
            ),
            (t.disc(cl, 0.5), -0.8 * l - 0.5, floor + WALL + LAP),
            // upper housing: floor with its inner ring, wall, the rings behind, outside the
            // lower housing's inside
            (
                t.annulus(cu, ru, 0.65).difference(&inside_lower),
                mid,
                mid + WALL,
            ),
            (
                t.annulus(cu, ru, ru - WALL).difference(&inside_lower),
                mid + WALL - LAP,
                0.0 - LAP,
            ),
            (
                t.annulus(cu, 0.8, 0.65).difference(&inside_lower),
                mid - 1.0,
                mid + 0.5 * WALL,
            ),
            (
                t.annulus(cu, 1.45, 1.25).difference(&inside_lower),
                mid - 0.1,
                mid + 0.5 * WALL,
            ),
            // gear board
            (
                rect(
                    0.3,
                    top + 1.4 - 0.4 * d.lower_pos,
                    1.2,
                    top + 1.4 + 0.4 * d.lower_pos,
                )
                .difference(&board_cut_lower),
                -0.85 - l / 3.0,
                -0.75 - l / 3.0,
            ),
            (
                Region::polygon(&strip(Vec2::new(0.7, top), cl, 0.05)).difference(&board_cut_lower),
                -1.875 - l / 3.0,
                0.375 - l / 3.0,
            ),
            // the web of the outer board
            (
                Region::polygon(&[
                    Vec2::new(0.0, top),
                    Vec2::new(0.0, top + tower),
                    Vec2::new(-1.4, top + 2.4),
                    Vec2::new(-1.4, top),
                ])
                .difference(&board_cut_lower)
                .difference(&board_cut_upper),
                -1.05 - l / 3.0,
                -0.95 - l / 3.0,
            ),
        ];
        // the outer board on the pot's flat and its slanted part, across the pot's width along
        // the gear axis, cut by the housings where they reach it
        let half_width = 0.45 * l;
        let outer = rect(-1.5, top + 1.4, -1.3, top + 2.4).union(&Region::polygon(&strip(
            Vec2::new(-1.4, top + 2.4),
            Vec2::new(0.1, top + tower),
            0.1,
        )));
        let housing_cuts = [
            (board_cut_lower.clone(), -5.0 * l / 6.0, l / 6.0),
            (board_cut_upper.clone(), mid, 1.0),
        ];
        plates.extend(pieces(
            &outer,
            -0.8 - l / 3.0 - half_width,
            -0.8 - l / 3.0 + half_width,
            &housing_cuts,
        ));
        // cut away: the collar (and the pot below it), the brush tower
        let axis = -1.0 - l / 3.0;
        let across = 3.5 - 0.5 * l;
        let cuts = [
            (
                rect(-across, top - 0.1, across, top + 1.5),
                axis - 0.5 * l,
                axis + 0.5 * l,
            ),
            (
                rect(-0.71, top, 0.71, top + d.tower_height() + 0.01),
                axis - 0.71,
                axis + 0.71,
            ),
        ];
        let mut m = Mesh::default();
        for (region, w0, w1) in plates {
            for (piece, p0, p1) in pieces(&region, w0, w1, &cuts) {
                m.append(&piece.extrude(p0, p1));
            }
        }
        m.append(&self.bolt_bosses(t, -1.23, 0.0));
        m.transformed(&self.to_motor)
    }

    /// The holes the cover bolts pass through (Ø7 mm).
    fn bolt_holes(&self, t: Tess) -> Region {
        self.bolts.iter().fold(t.disc(self.bolts[0], 0.35), |h, b| {
            h.union(&t.disc(*b, 0.35))
        })
    }

    /// The cover-bolt bosses of the gear container: tubes (Ø8 mm, Ø4 mm hole) from `w0` to
    /// `w1`, open towards the cover, with a 1 mm deck at the back.
    fn bolt_bosses(&self, t: Tess, w0: f32, w1: f32) -> Mesh {
        let mut m = Mesh::default();
        for b in &self.bolts {
            let boss = t.revolve(
                &[
                    Vec2::new(0.0, w0),
                    Vec2::new(BOSS_RADIUS, w0),
                    Vec2::new(BOSS_RADIUS, w1),
                    Vec2::new(0.2, w1),
                    Vec2::new(0.2, w0 + 0.1),
                    Vec2::new(0.0, w0 + 0.1),
                ],
                &[],
            );
            m.append(&boss.transformed(&Affine3A::from_translation(b.extend(0.0))));
        }
        m
    }

    /// Type B's gearbox share of the gear container as the add-on builds it (its `create_Up1`
    /// and `create_gear_extension`), as plates along the gear axis: the housing (a 1 mm wall on
    /// a 3 mm floor with a Ø15 mm hole, the boss ring behind), the gear-extension board from
    /// the eye at `type_b_height_1` past the housing to the eye at `type_b_height_2`, and the
    /// cover-bolt bosses. Plates that meet overlap, so that no two share an edge.
    fn container_b(&self, t: Tess, d: &Dims) -> Mesh {
        let g = &self.gears[0];
        let (c, r) = (g.centre, g.radius);
        let top = d.top;
        let bolt_holes = self.bolt_holes(t);
        let (eye_up, eye_low) = (
            Vec2::new(-2.0 * r + 0.3, top + d.h1 - 0.3),
            Vec2::new(2.1, top + d.h2 - 0.3),
        );
        let board = Region::polygon(&[
            Vec2::new(-2.0 * r, top + d.h1),
            Vec2::new(-2.0 * r, c.y - r + 0.1),
            Vec2::new(1.0, top + 0.8),
            Vec2::new(2.4, top + d.h2),
            Vec2::new(-r + 0.1, c.y + r + 0.8),
        ])
        .union(&t.disc(eye_up, 0.6))
        .union(&t.disc(eye_low, 0.6))
        .difference(&t.disc(c, r - 0.05))
        .difference(&t.disc(eye_up, 0.2))
        .difference(&t.disc(eye_low, 0.2))
        .difference(&bolt_holes);
        let plates = [
            (t.annulus(c, r, 0.75).difference(&bolt_holes), -1.35, -1.05),
            (
                t.annulus(c, r, r - 0.1).difference(&bolt_holes),
                -1.06,
                0.15,
            ),
            (t.annulus(c, 0.9, 0.5), -1.6, -1.2),
            (board, -0.6, 0.15),
        ];
        let mut m = Mesh::default();
        for (region, w0, w1) in plates {
            m.append(&region.extrude(w0, w1));
        }
        m.append(&self.bolt_bosses(t, -1.1, 0.15));
        m.transformed(&self.to_motor)
    }

    /// The cover, as the add-on builds it for each type.
    pub fn cover(&self, t: Tess, p: &MotorParams) -> Mesh {
        match p.motor_type {
            MotorType::A => self.cover_a(t, p.extension()),
            MotorType::B => self.cover_b(t, p.extension()),
        }
    }

    /// Type B's cover as the add-on builds it (its `create_Up2`): a ring over the gear with its
    /// inner ring, a triangular board through three bolts, discs round the bolts and, with
    /// extension 1, the mid board out to the side, 7 mm thick, with the thinner part joining
    /// it to the bolts.
    fn cover_b(&self, t: Tess, extension: Extension) -> Mesh {
        const THIN: f32 = 0.2;
        const MID: f32 = 0.7;
        let (c, r) = (self.gears[0].centre, self.gears[0].radius);
        let holes = self.bolt_holes(t);
        // the add-on's three bolts: the gear's second, the one beside the tower, the gear's first
        let n = self.bolts.len();
        let (b1, b2, b3) = (self.bolts[1], self.bolts[n - 1], self.bolts[0]);
        let (b1, b2, b3) = (
            b1 + Vec2::new(0.0, BOSS_RADIUS),
            b2 + Vec2::new(BOSS_RADIUS, 0.0),
            b3 - Vec2::new(0.0, BOSS_RADIUS),
        );
        let mut plates = vec![
            (t.annulus(c, r, 0.75).difference(&holes), 0.15, 0.15 + MID),
            (t.annulus(c, 0.9, 0.5), 0.15, 0.15 + MID),
            (
                Region::polygon(&[b1, b3, b2])
                    .difference(&t.disc(c, 0.75))
                    .difference(&holes),
                0.15 - 0.01,
                0.15 + THIN,
            ),
        ];
        if extension == Extension::Type1 {
            let p0 = b3 + Vec2::new(BOSS_RADIUS, 0.9);
            let p1 = c + Vec2::new(-3.5, -1.3);
            let p2 = c + Vec2::new(-3.5, 1.0);
            let p3 = c + Vec2::new(-r, 1.0);
            plates.push((
                Region::polygon(&[p0, p1, p2, p3])
                    .difference(&t.disc(c, 0.75))
                    .difference(&holes),
                0.15 - 0.02,
                0.15 + MID,
            ));
            plates.push((
                Region::polygon(&[b3, p1, p2, b1])
                    .difference(&t.disc(c, 0.75))
                    .difference(&holes),
                0.15 - 0.03,
                0.15 + THIN - 0.01,
            ));
        }
        for b in &self.bolts {
            plates.push((t.disc(*b, BOSS_RADIUS), 0.2, 0.5));
        }
        let mut m = Mesh::default();
        for (region, w0, w1) in plates {
            m.append(&region.extrude(w0, w1));
        }
        m.transformed(&self.to_motor)
    }

    /// Type A's cover as the add-on builds it (its `create_up` with extension): over the lower
    /// gear a disc with an annular groove in its face and a hub, over the upper gear a ring
    /// with two inner rings, thin rings round the bolts, and for the extensions the wedge
    /// plate between two side boards that deepen towards the eye(s) at its end.
    fn cover_a(&self, t: Tess, extension: Extension) -> Mesh {
        const LAP: f32 = 0.01;
        let (lower, upper) = (&self.gears[0], &self.gears[1]);
        let (cl, rl, cu, ru) = (lower.centre, lower.radius, upper.centre, upper.radius);
        let groove = t.annulus(cl, rl - 0.5, rl - 1.2);
        let mut plates = vec![
            (t.disc(cl, rl), -0.1, 0.05 + LAP),
            (t.disc(cl, rl).difference(&groove), 0.05, 0.4),
            (t.disc(cl, 0.5), 0.15, 1.0),
            (t.annulus(cu, ru, 0.8), -0.1, 0.4),
            // (the add-on's own booleans leave the inner ring and the bolt rings solid)
            (t.disc(cu, 0.8), -0.3, 0.7),
            (t.annulus(cu, 1.45, 1.25), -0.2, 0.4 + LAP),
            (t.disc(cu, 1.45), 0.4, 0.7),
        ];
        for b in &self.bolts {
            plates.push((t.disc(*b, BOSS_RADIUS), -0.1, 0.2));
        }
        let mut m = Mesh::default();
        if let Some(zone) = ExtensionZone::new(extension, cu, ru) {
            plates.push((
                Region::polygon(&zone.bottom_board()).difference(&t.disc(cl, rl - 0.5)),
                -0.1,
                0.2,
            ));
            let eye_length = if zone.two_eyes { 2.6 } else { 1.6 };
            for (centre, r) in zone.eyes() {
                plates.push((
                    t.annulus(centre, r, (r - 0.5).max(0.1)),
                    -0.1,
                    eye_length - 0.1,
                ));
            }
            for (outline, depth) in zone.side_boards() {
                let back: Vec<f32> = depth.iter().map(|d| d - 0.1).collect();
                m.append(&wedge(&outline, &vec![-0.1; outline.len()], &back));
            }
            let (outline, depth) = zone.back_plate();
            let front: Vec<f32> = depth.iter().map(|d| d - 0.2).collect();
            let back: Vec<f32> = depth.iter().map(|d| d - 0.1).collect();
            m.append(&wedge(&outline, &front, &back));
            plates.push((Region::polygon(&zone.cross_board()), -0.1, 0.95));
        }
        for (region, w0, w1) in plates {
            m.append(&region.extrude(w0, w1));
        }
        m.transformed(&self.to_motor)
    }

    /// The inner gear of housing `g` as the add-on builds it: a toothed wheel with its pinion
    /// (lower gear) or hub (upper and type B gears) on one axis, the teeth turned by the teeth
    /// inclination. Returns the mesh (motor frame) and the gear's tip diameter.
    pub fn inner_gear(&self, t: Tess, p: &MotorParams, g: &Gear) -> (Mesh, f32) {
        let incline = p.teeth_inclination_deg.to_radians().tan();
        // a toothed body: the add-on's gear of `teeth` scaled by `scale`, its ring `thickness`
        // (unscaled) thick, from w0 to w1
        let wheel = |teeth: usize, scale: f32, thickness: f32, w0: f32, w1: f32| {
            let (outline, tip) = gear_outline(t, teeth, scale);
            // the add-on shifts each tooth's far face sideways by tan(inclination) of the unscaled
            // height; turned about the axis that is this angle at mid-tooth
            let mid_tooth = 0.5 * (1.0 + tip / scale);
            let body = Body {
                outline,
                hole: (1.1 - thickness) * scale,
                w: [w0, w1],
                twist: incline / mid_tooth,
            };
            (body, 2.0 * tip)
        };
        let round = |radius: f32, hole: f32, w0: f32, w1: f32| Body {
            outline: t.circle(Vec2::ZERO, radius),
            hole,
            w: [w0, w1],
            twist: 0.0,
        };
        let (r, depth) = (g.radius, g.depth);
        let (bodies, tip) = match g.kind {
            PartKind::LowerGear => {
                let (gear, tip) = wheel(40, 0.6 * r, 0.7, -0.85 * depth, -0.45 * depth);
                let (pinion, _) = wheel(10, 0.2 * r, 0.3, -0.725 * depth, 0.025 * depth);
                (vec![gear, pinion], tip)
            }
            PartKind::UpperGear => {
                let (gear, tip) = wheel(30, 0.7 * r, 0.8, -0.6 * depth, 0.2 * depth);
                let hub = round(
                    0.25 * r,
                    0.25 * r - 0.2,
                    -1.2 * depth - 0.65,
                    0.65 - 0.2 * depth,
                );
                (vec![gear, hub], tip)
            }
            _ => {
                // the add-on turns this gear onto its axis about another axis than type A's:
                // seen along w its teeth stand a quarter pitch on
                let (mut gear, tip) = wheel(30, 0.75 * r, 0.8, -0.975, 0.075);
                let quarter_pitch = Vec2::from_angle(std::f32::consts::PI / 60.0);
                for q in &mut gear.outline {
                    *q = quarter_pitch.rotate(*q);
                }
                (vec![gear, round(0.75, 0.4, -1.425, 0.525)], tip)
            }
        };
        let mut m = coaxial(t, &bodies);
        m.transform(&(self.to_motor * Affine3A::from_translation(g.centre.extend(0.0))));
        (m, tip)
    }

    /// The motor-frame point of a gearbox-frame (u, v, w) point.
    pub fn point(&self, uv: Vec2, w: f32) -> Vec3 {
        self.to_motor.transform_point3(uv.extend(w))
    }

    /// The motor-frame direction of the gear axis (out of the cover).
    pub fn axis(&self) -> Vec3 {
        self.to_motor.transform_vector3(Vec3::Z).normalize()
    }
}

/// One body of an inner gear on the gear axis: an outline with a round hole from `w[0]` to
/// `w[1]`, turning by `twist` radians from the one end to the other.
struct Body {
    outline: Vec<Vec2>,
    hole: f32,
    w: [f32; 2],
    twist: f32,
}

impl Body {
    /// The turn at `w`: none at the far end (the add-on's unshifted tooth face), `-twist` at
    /// the near one.
    fn turn(&self, w: f32) -> f32 {
        self.twist * (w - self.w[1]) / (self.w[1] - self.w[0])
    }
}

/// The union of coaxial bodies that together fill one span of the axis, whose outlines nest
/// (a wider body's outline holds a narrower one's) and whose holes nest: along the axis, the
/// widest body present gives the outside and the smallest hole the inside.
fn coaxial(t: Tess, bodies: &[Body]) -> Mesh {
    let mut cuts: Vec<f32> = bodies.iter().flat_map(|b| b.w).collect();
    cuts.sort_by(f32::total_cmp);
    cuts.dedup();
    let size = |b: &Body| signed_area2(&b.outline).abs();
    // stretches with the body each comes from
    let mut outer: Vec<(usize, Stretch)> = vec![];
    let mut hole: Vec<(usize, Stretch)> = vec![];
    for span in cuts.windows(2) {
        let [w0, w1] = [span[0], span[1]];
        let present = || {
            bodies
                .iter()
                .enumerate()
                .filter(|(_, b)| b.w[0] <= w0 && b.w[1] >= w1)
        };
        let (wide, widest) = present()
            .max_by(|a, b| size(a.1).total_cmp(&size(b.1)))
            .expect("the bodies fill the span");
        let (narrow, _) = present()
            .min_by(|a, b| a.1.hole.total_cmp(&b.1.hole))
            .expect("the bodies fill the span");
        extend(
            &mut outer,
            wide,
            w0,
            w1,
            || widest.outline.clone(),
            |w| widest.turn(w),
        );
        // holes within 0.2 mm of each other are taken as one: no hairline step between them
        let narrow = match hole.last() {
            Some(&(last, _)) if (bodies[last].hole - bodies[narrow].hole).abs() < 0.02 => last,
            _ => narrow,
        };
        let r = bodies[narrow].hole;
        extend(
            &mut hole,
            narrow,
            w0,
            w1,
            || t.circle(Vec2::ZERO, r),
            |_| 0.0,
        );
    }
    let strip = |v: Vec<(usize, Stretch)>| v.into_iter().map(|(_, s)| s).collect::<Vec<_>>();
    stack(&strip(outer), &strip(hole))
}

/// Lengthens the last stretch when it belongs to body `id`, or starts a new one.
fn extend(
    stretches: &mut Vec<(usize, Stretch)>,
    id: usize,
    w0: f32,
    w1: f32,
    outline: impl FnOnce() -> Vec<Vec2>,
    turn: impl Fn(f32) -> f32,
) {
    match stretches.last_mut() {
        Some((last, s)) if *last == id => {
            s.z1 = w1;
            s.turn[1] = turn(w1);
        }
        _ => stretches.push((
            id,
            Stretch {
                outline: outline(),
                z0: w0,
                z1: w1,
                turn: [turn(w0), turn(w1)],
            },
        )),
    }
}

/// A plate of `region` from `w0` to `w1`, split where `cuts` (a region over a range of w) that
/// take something from it begin or end, each piece less the cuts over it. Neighbouring pieces
/// overlap by 0.1 mm.
fn pieces(
    region: &Region,
    w0: f32,
    w1: f32,
    cuts: &[(Region, f32, f32)],
) -> Vec<(Region, f32, f32)> {
    const LAP: f32 = 0.01;
    let area = region.area();
    let cuts: Vec<&(Region, f32, f32)> = cuts
        .iter()
        .filter(|c| {
            c.1 < w1 && c.2 > w0 && region.may_meet(&c.0) && region.difference(&c.0).area() < area
        })
        .collect();
    // cut ends within 1 µm of the plate's ends or of each other count as one
    let mut edges = vec![w0, w1];
    edges.extend(
        cuts.iter()
            .flat_map(|c| [c.1, c.2])
            .filter(|w| *w > w0 + 1e-4 && *w < w1 - 1e-4),
    );
    edges.sort_by(f32::total_cmp);
    edges.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
    edges
        .windows(2)
        .map(|span| {
            let piece = cuts
                .iter()
                .filter(|c| c.1 <= span[0] + 1e-4 && c.2 >= span[1] - 1e-4)
                .fold(region.clone(), |r, c| r.difference(&c.0));
            let lap = |w: f32| if w == w0 || w == w1 { 0.0 } else { LAP };
            (piece, span[0] - lap(span[0]), span[1] + lap(span[1]))
        })
        .filter(|(piece, _, _)| piece.area() > 0.0)
        .collect()
}

/// The add-on's extension zone of a type A cover (its `create_extension_zone`), in the gearbox
/// plane: the polylines of its two side boards from beside the upper gear down to the eye(s).
struct ExtensionZone {
    /// Side board 1: p1, p3, p5; side board 2: p2, p4, p6; where the back plate begins on
    /// board 1 (p3h).
    p: [Vec2; 7],
    /// The boards' thickness across, pointing from side board 2 towards side board 1 (turned
    /// with the zone where the add-on mirrors it).
    across: Vec2,
    /// The upper gear's radius (the bottom board's top edge follows it).
    ru: f32,
    /// Two eyes (extension 2) or one.
    two_eyes: bool,
}

impl ExtensionZone {
    fn new(extension: Extension, cu: Vec2, ru: f32) -> Option<ExtensionZone> {
        // angles (degrees) and lengths of the add-on's construction
        let (a1, a11, a4, a5, s2, s5, two_eyes) = match extension {
            Extension::Type1 => (30.0f32, 30.0f32, 25.0f32, 25.0f32, 5.5, 5.0, false),
            Extension::Type2 => (20.0, 30.0, 0.0, 5.0, 4.5, 4.5, true),
            Extension::None => return None,
        };
        let (s1, s4, s6) = (1.45, 4.5, 3.0);
        let dir = |deg: f32| Vec2::from_angle(deg.to_radians());
        let down = |deg: f32| {
            let (s, c) = deg.to_radians().sin_cos();
            Vec2::new(s, -c)
        };
        let p1 = cu + s1 * dir(a1);
        let p2 = cu - s1 * dir(a11);
        let p3 = p1 + s2 * down(a1);
        let p4 = p2 + s4 * down(a5);
        let p5 = p3 + s5 * Vec2::new(-a4.to_radians().sin(), -a4.to_radians().cos());
        let p6 = p4 - Vec2::new(0.0, s6);
        let p3h = if two_eyes {
            p3 - Vec2::new(0.0, 1.5)
        } else {
            p3 - 1.5 * Vec2::new(25f32.to_radians().sin(), 25f32.to_radians().cos())
        };
        let mut p = [p1, p3, p5, p2, p4, p6, p3h];
        let mut across = Vec2::new(35f32.to_radians().cos() * 0.2, 0.0);
        if two_eyes {
            across = -across;
            // the add-on mirrors this zone across u = 0 and moves it 2.32 cm along u
            for q in &mut p {
                q.x = 2.32 - q.x;
            }
        }
        Some(ExtensionZone {
            p,
            across,
            ru,
            two_eyes,
        })
    }

    /// The two side boards: outline and each corner's depth along the gear axis.
    fn side_boards(&self) -> [(Vec<Vec2>, Vec<f32>); 2] {
        let [p1, p3, p5, p2, p4, p6, _] = self.p;
        let t = self.across;
        let depth = vec![0.5, 0.5, 1.1, 1.5, 1.5, 1.1];
        [
            (vec![p1, p1 - t, p3 - t, p5 - t, p5, p3], depth.clone()),
            (vec![p2, p2 + t, p4 + t, p6 + t, p6, p4], depth),
        ]
    }

    /// The bottom board between the side boards (reaching half into them).
    fn bottom_board(&self) -> Vec<Vec2> {
        let [p1, p3, p5, p2, p4, p6, _] = self.p;
        let t = self.across;
        let a1 = (p3 - p1).normalize();
        vec![
            p1 + t - Vec2::new(0.0, 0.4 * self.ru * a1.x.abs()),
            p3 - 0.5 * t,
            p5 - 0.5 * t,
            p6 + 0.5 * t,
            p4 + 0.5 * t,
            p2 - Vec2::new(0.0, self.ru / 3.0),
        ]
    }

    /// The back plate between the side boards, from p3h and p4 down to the eye end, 1 mm thick
    /// at the boards' back (the add-on leaves it a bare face): outline and each corner's depth.
    fn back_plate(&self) -> (Vec<Vec2>, Vec<f32>) {
        let [_, _, p5, _, p4, p6, p3h] = self.p;
        let t = self.across;
        // reaching half into the side boards, as the bottom board does
        (
            vec![p3h - 0.5 * t, p5 - 0.5 * t, p6 + 0.5 * t, p4 + 0.5 * t],
            vec![1.1, 1.5, 1.5, 1.1],
        )
    }

    /// The cross board from p3h to p4 across the zone (a bare face in the add-on, here 1 mm
    /// thick), as deep as the back plate's top.
    fn cross_board(&self) -> Vec<Vec2> {
        let [_, _, _, _, p4, _, p3h] = self.p;
        strip(p3h - self.across, p4, 0.05)
    }

    /// The eyes: centre and outer radius.
    fn eyes(&self) -> Vec<(Vec2, f32)> {
        let [_, _, p5, _, _, p6, _] = self.p;
        let span = p5.distance(p6);
        if self.two_eyes {
            vec![
                (p5 + (p6 - p5) * (5.0 / 6.0), span / 6.0),
                (p5 + (p6 - p5) / 6.0, span / 6.0),
            ]
        } else {
            vec![(0.5 * (p5 + p6), 0.5 * span)]
        }
    }
}

/// A plate whose depth varies: each corner of `outline` from `front` to `back` along w, front
/// and back made of the same triangles (so they may bend). One closed shell.
fn wedge(outline: &[Vec2], front: &[f32], back: &[f32]) -> Mesh {
    // an extrusion from 0 to 1 whose corners then move to their depths (it keeps the corners,
    // perhaps in reverse order)
    let mut m = plate(outline.to_vec(), vec![], 0.0, 1.0);
    for p in &mut m.positions {
        let k = outline
            .iter()
            .position(|q| q.distance(p.truncate()) < 1e-6)
            .expect("every corner is an outline corner");
        p.z = if p.z > 0.5 { back[k] } else { front[k] };
    }
    m
}
