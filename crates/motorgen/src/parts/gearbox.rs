//! The parts that turn with the gearbox, as the add-on builds them: the gear container's
//! housings, boards and cover-bolt bosses, the cover with its extension, the inner gears, and
//! where the cover bolts go. Built in the gearbox plane frame (u, v, w) in centimetres: v is
//! the motor's z, u the horizontal direction in the cover plane, w the gear axis pointing out
//! of the cover, and the cover plane at w = 0.

use glam::{Affine3A, Vec2, Vec3};

use super::Dims;
use super::body::{BOSS_RADIUS, collar_and_tower_boxes};
use super::shapes::{Tess, gear_outline, plane_frame, rect, strip};
use crate::kernel::{
    Mesh, Plane, Prisms, Shape, Slope, Stretch, Wedge, difference, signed_area2, stack,
};
use crate::model::PartKind;
use crate::params::{Extension, MotorParams, MotorType};

/// Housing wall thickness (the add-on's EXTENSION_THICKNESS).
const WALL: f32 = 0.2;
/// Grid step of the plates' unions (cm): 1 µm.
const GRID: f32 = 1e-4;
/// How far the plates keep from the collar, the tower and the side-bolt bosses (cm): 10 µm.
const CLEAR: f32 = 1e-3;
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

    /// The gearbox's share of the gear container: housings, boards and cover-bolt bosses, one
    /// union clear of the collar, the tower and the side-bolt bosses (`d`'s
    /// [`collar_and_tower_boxes`]).
    pub fn container(&self, t: Tess, p: &MotorParams, d: &Dims) -> Mesh {
        let mut plates = Prisms::new(GRID);
        match p.motor_type {
            MotorType::A => self.container_a(&mut plates, t, d),
            MotorType::B => self.container_b(&mut plates, t, d),
        }
        self.bolt_bosses(&mut plates, t, d);
        let inverse = self.to_motor.inverse();
        for (lo, hi) in collar_and_tower_boxes(d) {
            let corners = (0..8).map(|k| {
                let pick = |bit: u32, a: f32, b: f32| if k & bit == 0 { a } else { b };
                inverse.transform_point3(Vec3::new(
                    pick(1, lo.x, hi.x),
                    pick(2, lo.y, hi.y),
                    pick(4, lo.z, hi.z),
                ))
            });
            let (min, max) = corners.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), c| {
                (a.min(c), b.max(c))
            });
            let (min, max) = (min - CLEAR, max + CLEAR);
            let cut = plates.shape(&rect(min.truncate(), max.truncate()));
            plates.cut(cut, min.z, max.z);
        }
        plates.mesh().transformed(&self.to_motor)
    }

    /// Type A's gearbox share of the gear container as the add-on builds it (its `create_up`
    /// without extension and `create_outer_board`), as plates along the gear axis: the lower
    /// housing, a cup with a boss behind, its wall opened where the upper housing overlaps it; the
    /// upper housing with its inner rings; the gear board (a slanted board from the tower to the
    /// lower housing) and the outer board (a board on the pot's flat, its slanted continuation
    /// to the tower's top, and the web between them).
    fn container_a(&self, p: &mut Prisms, t: Tess, d: &Dims) {
        const LAP: f32 = 0.01;
        let (lower, upper) = (&self.gears[0], &self.gears[1]);
        let (cl, rl, cu, ru) = (lower.centre, lower.radius, upper.centre, upper.radius);
        let l = 1.5 * lower.depth;
        let top = d.top;
        let tower = d.tower_steps()[2];
        let disc = |p: &mut Prisms, c: Vec2, r: f32| p.shape(&t.circle(c, r));
        let lower_out = disc(p, cl, rl);
        let lower_in = disc(p, cl, rl - WALL);
        let upper_out = disc(p, cu, ru);
        let upper_in = disc(p, cu, ru - WALL);
        // boards end 0.5 mm inside the housings' outer walls
        let board_cut_lower = disc(p, cl, rl - 0.05);
        let board_cut_upper = disc(p, cu, ru - 0.05);
        let (floor, mid) = (-2.0 * l / 3.0, -l / 3.0);
        // lower housing: floor, wall, the wall opened by the upper housing, boss behind
        p.plate(&[lower_out], &[], floor, floor + WALL);
        p.plate(&[lower_out], &[lower_in], floor + WALL - LAP, mid + LAP);
        p.plate(&[lower_out], &[lower_in, upper_in], mid, 0.0);
        let boss = disc(p, cl, 0.5);
        p.plate(&[boss], &[], -0.8 * l - 0.5, floor + WALL + LAP);
        // upper housing: floor with its inner ring, wall, the rings behind, outside the lower
        // housing's inside
        let ring_hole = disc(p, cu, 0.65);
        p.plate(&[upper_out], &[ring_hole, lower_in], mid, mid + WALL);
        p.plate(&[upper_out], &[upper_in, lower_in], mid + WALL - LAP, -LAP);
        let ring = disc(p, cu, 0.8);
        p.plate(&[ring], &[ring_hole, lower_in], mid - 1.0, mid + 0.5 * WALL);
        let (ring_out, ring_in) = (disc(p, cu, 1.45), disc(p, cu, 1.25));
        p.plate(
            &[ring_out],
            &[ring_in, lower_in],
            mid - 0.1,
            mid + 0.5 * WALL,
        );
        // gear board
        let board = p.shape(&rect(
            Vec2::new(0.3, top + 1.4 - 0.4 * d.lower_pos),
            Vec2::new(1.2, top + 1.4 + 0.4 * d.lower_pos),
        ));
        p.plate(
            &[board],
            &[board_cut_lower],
            -0.85 - l / 3.0,
            -0.75 - l / 3.0,
        );
        let slant = p.shape(&strip(Vec2::new(0.7, top), cl, 0.05));
        p.plate(
            &[slant],
            &[board_cut_lower],
            -1.875 - l / 3.0,
            0.375 - l / 3.0,
        );
        // the web of the outer board
        let web = p.shape(&[
            Vec2::new(0.0, top),
            Vec2::new(0.0, top + tower),
            Vec2::new(-1.4, top + 2.4),
            Vec2::new(-1.4, top),
        ]);
        p.plate(
            &[web],
            &[board_cut_lower, board_cut_upper],
            -1.05 - l / 3.0,
            -0.95 - l / 3.0,
        );
        // the outer board on the pot's flat and its slanted part, across the pot's width along
        // the gear axis, cut by the housings where they reach it
        let half_width = 0.45 * l;
        let flat = p.shape(&rect(
            Vec2::new(-1.5, top + 1.4),
            Vec2::new(-1.3, top + 2.4),
        ));
        let slope = p.shape(&strip(
            Vec2::new(-1.4, top + 2.4),
            Vec2::new(0.1, top + tower),
            0.1,
        ));
        let outer = p.plate(
            &[flat, slope],
            &[],
            -0.8 - l / 3.0 - half_width,
            -0.8 - l / 3.0 + half_width,
        );
        p.cut_plate(outer, board_cut_lower, -5.0 * l / 6.0, l / 6.0);
        p.cut_plate(outer, board_cut_upper, mid, 1.0);
    }

    /// The holes the cover bolts pass through (Ø7 mm).
    fn bolt_holes(&self, p: &mut Prisms, t: Tess) -> Vec<Shape> {
        self.bolts
            .iter()
            .map(|b| p.shape(&t.circle(*b, 0.35)))
            .collect()
    }

    /// The cover-bolt bosses of the gear container: tubes (Ø8 mm, Ø4 mm hole) from `w0` to
    /// the cover plane, open towards the cover, with a 1 mm deck at the back.
    fn bolt_bosses(&self, p: &mut Prisms, t: Tess, d: &Dims) {
        let (w0, w1) = match d.motor_type {
            MotorType::A => (-1.23, 0.0),
            MotorType::B => (-1.1, 0.15),
        };
        for b in &self.bolts {
            let (outer, hole) = (
                p.shape(&t.circle(*b, BOSS_RADIUS)),
                p.shape(&t.circle(*b, 0.2)),
            );
            p.plate(&[outer], &[], w0, w0 + 0.1);
            p.plate(&[outer], &[hole], w0 + 0.1, w1);
        }
    }

    /// Type B's gearbox share of the gear container as the add-on builds it (its `create_Up1`
    /// and `create_gear_extension`), as plates along the gear axis: the housing (a 1 mm wall on
    /// a 3 mm floor with a Ø15 mm hole, the boss ring behind) and the gear-extension board from
    /// the eye at `type_b_height_1` past the housing to the eye at `type_b_height_2`.
    fn container_b(&self, p: &mut Prisms, t: Tess, d: &Dims) {
        let g = &self.gears[0];
        let (c, r) = (g.centre, g.radius);
        let top = d.top;
        let holes = self.bolt_holes(p, t);
        let (eye_up, eye_low) = (
            Vec2::new(-2.0 * r + 0.3, top + d.h1 - 0.3),
            Vec2::new(2.1, top + d.h2 - 0.3),
        );
        let disc = |p: &mut Prisms, c: Vec2, r: f32| p.shape(&t.circle(c, r));
        let outer = disc(p, c, r);
        let floor_hole = disc(p, c, 0.75);
        let wall_in = disc(p, c, r - 0.1);
        let floor_less: Vec<Shape> = holes.iter().copied().chain([floor_hole]).collect();
        p.plate(&[outer], &floor_less, -1.35, -1.05);
        let wall_less: Vec<Shape> = holes.iter().copied().chain([wall_in]).collect();
        p.plate(&[outer], &wall_less, -1.06, 0.15);
        let (ring_out, ring_in) = (disc(p, c, 0.9), disc(p, c, 0.5));
        p.plate(&[ring_out], &[ring_in], -1.6, -1.2);
        let board = p.shape(&[
            Vec2::new(-2.0 * r, top + d.h1),
            Vec2::new(-2.0 * r, c.y - r + 0.1),
            Vec2::new(1.0, top + 0.8),
            Vec2::new(2.4, top + d.h2),
            Vec2::new(-r + 0.1, c.y + r + 0.8),
        ]);
        let eyes = [disc(p, eye_up, 0.6), disc(p, eye_low, 0.6)];
        let mut board_less = vec![
            disc(p, c, r - 0.05),
            disc(p, eye_up, 0.2),
            disc(p, eye_low, 0.2),
        ];
        board_less.extend(&holes);
        p.plate(&[board, eyes[0], eyes[1]], &board_less, -0.6, 0.15);
    }

    /// The cover, as the add-on builds it for each type.
    pub fn cover(&self, t: Tess, p: &MotorParams) -> Mesh {
        let mut plates = Prisms::new(GRID);
        let mut m = match p.motor_type {
            MotorType::A => self.cover_a(&mut plates, t, p.extension()),
            MotorType::B => {
                self.cover_b(&mut plates, t, p.extension());
                Mesh::default()
            }
        };
        m.append(&plates.mesh());
        m.transformed(&self.to_motor)
    }

    /// Type B's cover as the add-on builds it (its `create_Up2`): a ring over the gear with its
    /// inner ring, a triangular board through three bolts, discs round the bolts and, with
    /// extension 1, the mid board out to the side, 7 mm thick, with the thinner part joining
    /// it to the bolts.
    fn cover_b(&self, p: &mut Prisms, t: Tess, extension: Extension) {
        const THIN: f32 = 0.2;
        const MID: f32 = 0.7;
        let (c, r) = (self.gears[0].centre, self.gears[0].radius);
        let holes = self.bolt_holes(p, t);
        let hub = p.shape(&t.circle(c, 0.75));
        let less: Vec<Shape> = holes.iter().copied().chain([hub]).collect();
        // the add-on's three bolts: the gear's second, the one beside the tower, the gear's first
        let n = self.bolts.len();
        let (b1, b2, b3) = (self.bolts[1], self.bolts[n - 1], self.bolts[0]);
        let (b1, b2, b3) = (
            b1 + Vec2::new(0.0, BOSS_RADIUS),
            b2 + Vec2::new(BOSS_RADIUS, 0.0),
            b3 - Vec2::new(0.0, BOSS_RADIUS),
        );
        let ring = p.shape(&t.circle(c, r));
        p.plate(&[ring], &less, 0.15, 0.15 + MID);
        let (inner, inner_hole) = (p.shape(&t.circle(c, 0.9)), p.shape(&t.circle(c, 0.5)));
        p.plate(&[inner], &[inner_hole], 0.15, 0.15 + MID);
        let board = p.shape(&[b1, b3, b2]);
        p.plate(&[board], &less, 0.15 - 0.01, 0.15 + THIN);
        if extension == Extension::Type1 {
            let p0 = b3 + Vec2::new(BOSS_RADIUS, 0.9);
            let p1 = c + Vec2::new(-3.5, -1.3);
            let p2 = c + Vec2::new(-3.5, 1.0);
            let p3 = c + Vec2::new(-r, 1.0);
            let mid = p.shape(&[p0, p1, p2, p3]);
            p.plate(&[mid], &less, 0.15 - 0.02, 0.15 + MID);
            let thin = p.shape(&[b3, p1, p2, b1]);
            p.plate(&[thin], &less, 0.15 - 0.03, 0.15 + THIN - 0.01);
        }
        for b in &self.bolts {
            let disc = p.shape(&t.circle(*b, BOSS_RADIUS));
            p.plate(&[disc], &[], 0.2, 0.5);
        }
    }

    /// Type A's cover as the add-on builds it (its `create_up` with extension): over the lower
    /// gear a disc with an annular groove in its face and a hub, over the upper gear a ring
    /// with two inner rings, thin rings round the bolts, and for the extensions the wedge
    /// plate between two side boards that deepen towards the eye(s) at its end. Returns the
    /// wedges; the plates go into `p`.
    fn cover_a(&self, p: &mut Prisms, t: Tess, extension: Extension) -> Mesh {
        const LAP: f32 = 0.01;
        let (lower, upper) = (&self.gears[0], &self.gears[1]);
        let (cl, rl, cu, ru) = (lower.centre, lower.radius, upper.centre, upper.radius);
        let disc = |p: &mut Prisms, c: Vec2, r: f32| p.shape(&t.circle(c, r));
        // the plates no higher than the extension's side boards over them
        let mut under = Vec::new();
        let lower_disc = disc(p, cl, rl);
        let (groove_out, groove_in) = (disc(p, cl, rl - 0.5), disc(p, cl, rl - 1.2));
        under.push(p.plate(&[lower_disc], &[], -0.1, 0.05 + LAP));
        under.push(p.plate(&[lower_disc], &[groove_out], 0.05, 0.4));
        under.push(p.plate(&[groove_in], &[], 0.05, 0.4));
        let hub = disc(p, cl, 0.5);
        p.plate(&[hub], &[], 0.15, 1.0);
        let (upper_disc, inner) = (disc(p, cu, ru), disc(p, cu, 0.8));
        under.push(p.plate(&[upper_disc], &[inner], -0.1, 0.4));
        // (the add-on's own booleans leave the inner ring and the bolt rings solid)
        p.plate(&[inner], &[], -0.3, 0.7);
        let (ring_out, ring_in) = (disc(p, cu, 1.45), disc(p, cu, 1.25));
        under.push(p.plate(&[ring_out], &[ring_in], -0.2, 0.4));
        p.plate(&[ring_out], &[], 0.4, 0.7);
        for b in &self.bolts {
            let ring = disc(p, *b, BOSS_RADIUS);
            under.push(p.plate(&[ring], &[], -0.1, 0.2));
        }
        let mut m = Mesh::default();
        if let Some(zone) = ExtensionZone::new(extension, cu, ru) {
            let bottom = p.shape(&zone.bottom_board());
            let bottom_less = disc(p, cl, rl - 0.5);
            under.push(p.plate(&[bottom], &[bottom_less], -0.1, 0.2));
            let eye_length = if zone.two_eyes { 2.6 } else { 1.6 };
            for (centre, r) in zone.eyes() {
                let (eye, hole) = (disc(p, centre, r), disc(p, centre, (r - 0.5).max(0.1)));
                p.plate(&[eye], &[hole], -0.1, eye_length - 0.1);
            }
            // the sloped boards, shells of their own CLEAR apart from the plates: they give way
            // to the plates that stand higher over them (the eyes, the rings round the gears'
            // axes, the hub), the lower plates give way to them
            let grown = |c: Vec2, r: f32| t.circle_grown(c, r, CLEAR);
            let mut higher: Vec<Vec<Vec2>> =
                zone.eyes().iter().map(|&(c, r)| grown(c, r)).collect();
            let eyes = higher.clone();
            higher.extend([grown(cu, 1.45), grown(cu, 0.8), grown(cl, 0.5)]);
            let mut boards = Vec::new();
            for (outline, slopes) in zone.side_boards() {
                let board = Wedge::new(&outline, &higher, slopes);
                boards.extend(board.grown(2.0 * CLEAR));
                for footprint in board.grown(CLEAR) {
                    let cut = p.shape(&footprint);
                    for &plate in &under {
                        p.cut_plate(plate, cut, -0.1 - CLEAR, 1.4 + CLEAR);
                    }
                }
                m.append(&board.mesh());
            }
            let (outline, slopes) = zone.back_plate(CLEAR);
            let back = Wedge::new(&outline, &eyes, slopes);
            m.append(&back.mesh());
            // the cross board, clear of the back plate and cut short of the side boards (the
            // piece between them; its ends beyond them go)
            let pieces = difference(&zone.cross_board(2.0 * CLEAR), &boards);
            if let Some(cross) = pieces
                .iter()
                .max_by(|a, b| signed_area2(a).abs().total_cmp(&signed_area2(b).abs()))
            {
                let cross = p.shape(cross);
                p.plate(&[cross], &[], -0.1, 0.95);
            }
        }
        m
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

    /// The two side boards: each an outline and its two slopes (the board deepens from 5 mm
    /// at its upper end to 11 mm at its bend and 15 mm at its eye end, its back 1 mm less,
    /// its front 1 mm behind the cover plane).
    fn side_boards(&self) -> [(Vec<Vec2>, Vec<Slope>); 2] {
        let [p1, p3, p5, p2, p4, p6, _] = self.p;
        let t = self.across;
        let board = |a: Vec2, bend: Vec2, end: Vec2, t: Vec2| {
            let back = |q: Vec2, depth: f32| q.extend(depth - 0.1);
            (
                vec![a, a - t, bend - t, end - t, end, bend],
                halves(bend, t, a)
                    .into_iter()
                    .zip([
                        Plane::through([back(a, 0.5), back(a - t, 0.5), back(bend, 1.1)]),
                        Plane::through([back(bend, 1.1), back(bend - t, 1.1), back(end, 1.5)]),
                    ])
                    .map(|(part, back)| Slope {
                        part,
                        front: Plane::flat(-0.1),
                        back,
                    })
                    .collect(),
            )
        };
        [board(p1, p3, p5, t), board(p2, p4, p6, -t)]
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

    /// The back plate between the side boards (`gap` clear of them), from p3h and p4 down to
    /// the eye end, 1 mm thick at the boards' back (the add-on leaves it a bare face): its
    /// outline and its two slopes (the halves either side of its diagonal from p3h).
    fn back_plate(&self, gap: f32) -> (Vec<Vec2>, Vec<Slope>) {
        let [_, _, p5, _, p4, p6, p3h] = self.p;
        let t = self.across * (1.0 + gap / self.across.length());
        let q = [p3h - t, p5 - t, p6 + t, p4 + t];
        let back = |k: usize, depth: f32| q[k].extend(depth - 0.1);
        let planes = [
            Plane::through([back(0, 1.1), back(1, 1.5), back(2, 1.5)]),
            Plane::through([back(0, 1.1), back(2, 1.5), back(3, 1.1)]),
        ];
        let slopes = halves(q[0], q[2] - q[0], q[1])
            .into_iter()
            .zip(planes)
            .map(|(part, back)| Slope {
                part,
                front: back.raised(-0.1),
                back,
            })
            .collect();
        (q.to_vec(), slopes)
    }

    /// The cross board from p3h to p4 across the zone (a bare face in the add-on, here 1 mm
    /// thick, on the upper side of that face, `gap` off the back plate), as deep as the back
    /// plate's top, reaching into the side boards (the caller cuts it short of them).
    fn cross_board(&self, gap: f32) -> Vec<Vec2> {
        let [_, _, p5, _, p4, _, p3h] = self.p;
        let (a, b) = (p3h - self.across, p4 + self.across);
        let mut n = (b - a).normalize().perp();
        if n.dot(p5 - a) > 0.0 {
            n = -n;
        }
        let (shift, reach) = (n * (0.05 + gap), (b - a).normalize() * 0.3);
        strip(a + shift - reach, b + shift + reach, 0.05)
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

/// The two halves of the plane either side of the line through `at` along `along`: the one
/// holding `first` first (as large squares).
fn halves(at: Vec2, along: Vec2, first: Vec2) -> [Vec<Vec2>; 2] {
    const FAR: f32 = 100.0;
    let (d, mut n) = (along.normalize(), along.normalize().perp());
    if (first - at).dot(n) < 0.0 {
        n = -n;
    }
    let half = |n: Vec2| {
        vec![
            at - FAR * d,
            at + FAR * d,
            at + FAR * d + FAR * n,
            at - FAR * d + FAR * n,
        ]
    };
    [half(n), half(-n)]
}
