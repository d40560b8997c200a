//! What the scenes beside the station share: objects added in order, each its own instance, and
//! motors and parts laid down on a surface.

use std::borrow::Cow;

use glam::{Affine3A, Mat3, Vec3};
use motorgen::kernel::{Aabb, Mesh, cuboid};
use motorgen::{Motor, Part, PartKind};
use rand::{Rng, RngExt};
use sensor::Material;

use super::station::orientation;
use super::{Cell, Kind, Object, armature, draw_wear, table_material, transform_box};
use crate::config::{Clamping, TableConfig, WearConfig};
use crate::error::Result;

/// A scene's objects in the order they are added, instance ids from 1 in that order (a whole
/// motor's id among them).
#[derive(Default)]
pub(super) struct Objects {
    pub(super) list: Vec<Object>,
    next: u32,
}

impl Objects {
    /// The next instance id.
    fn id(&mut self) -> u32 {
        self.next += 1;
        self.next
    }

    /// Adds `o`, its instance the next id.
    pub(super) fn push(&mut self, o: Object) {
        let instance = self.id();
        self.list.push(Object { instance, ..o });
    }

    /// Adds an object that is no motor part, its mesh in world coordinates.
    pub(super) fn add(&mut self, name: String, mesh: Mesh, material: Material, kind: Kind) {
        self.add_at(name, mesh, &Affine3A::IDENTITY, material, kind);
    }

    /// Adds an object that is no motor part: `model` moved by `pose`.
    pub(super) fn add_at(
        &mut self,
        name: String,
        model: Mesh,
        pose: &Affine3A,
        material: Material,
        kind: Kind,
    ) {
        self.push(Object {
            name,
            part: None,
            kind,
            instance: 0,
            mesh: model.transformed(pose),
            pose: *pose,
            material,
            wear: None,
        });
    }

    /// Adds part `p` of `motor` (motor frame to world `to_world`) as `kind`, named after the
    /// motor `prefix`, worn as `wear` draws.
    pub(super) fn part(
        &mut self,
        motor: &Motor,
        p: &Part,
        to_world: &Affine3A,
        kind: Kind,
        (prefix, wear): (&str, &WearConfig),
        rng: &mut impl Rng,
    ) {
        // an armature with its surfaces' textures
        let textured = (p.kind == PartKind::Armature)
            .then(|| armature(motor, to_world, kind, 0.0, 0))
            .flatten();
        let mut o = match textured {
            Some(o) => o,
            None => {
                let mut o = Object::part(p, to_world, kind);
                if wear.enabled() {
                    o.wear = draw_wear(p, motor, to_world, wear, &mut o.material, rng);
                }
                o
            }
        };
        o.name = format!("{prefix}{}", o.name);
        self.push(o);
    }

    /// Adds `motor`'s parts but those `hidden` says, assembled (motor frame to world
    /// `to_world`), named `motor_{k}_…`, worn as `wear` draws.
    pub(super) fn motor(
        &mut self,
        k: usize,
        motor: &Motor,
        to_world: &Affine3A,
        hidden: impl Fn(PartKind) -> bool,
        wear: &WearConfig,
        rng: &mut impl Rng,
    ) {
        let whole = self.id();
        let prefix = format!("motor_{k}_");
        for p in motor.parts.iter().filter(|p| !hidden(p.kind)) {
            let kind = Kind::Assembled { motor: whole };
            self.part(motor, p, to_world, kind, (&prefix, wear), rng);
        }
    }

    /// Adds every object of `cell` moved by `pose`, named `{prefix}{name}`, its instance ids
    /// (and its whole motors') after this scene's.
    pub(super) fn merge(&mut self, cell: Cell, pose: &Affine3A, prefix: &str) {
        let offset = self.next;
        for mut o in cell.objects {
            o.name = format!("{prefix}{}", o.name);
            o.mesh = o.mesh.transformed(pose);
            o.pose = *pose * o.pose;
            if let Some(w) = &mut o.wear {
                w.texture *= pose.inverse();
            }
            o.instance += offset;
            self.next = self.next.max(o.instance);
            if let Kind::Assembled { motor } = &mut o.kind {
                *motor += offset;
                self.next = self.next.max(*motor);
            }
            self.list.push(o);
        }
    }

    /// The highest top of the objects but the first (the ground) whose boxes meet a footprint
    /// of `size` centred at `at`; 0 where none does.
    pub(super) fn top(&self, at: Vec3, size: Vec3) -> f32 {
        let (lo, hi) = (at - size / 2.0, at + size / 2.0);
        self.list[1..]
            .iter()
            .map(|o| o.mesh.bounds())
            .filter(|b| b.min.x < hi.x && b.max.x > lo.x && b.min.y < hi.y && b.max.y > lo.y)
            .fold(0.0f32, |top, b| top.max(b.max.z))
    }

    /// `at`, or where `spot` draws next, up to eight times, until a footprint of `size` there
    /// meets nothing ([`Objects::top`]); the last drawn when none does.
    pub(super) fn clear(&self, mut at: Vec3, size: Vec3, mut spot: impl FnMut() -> Vec3) -> Vec3 {
        for _ in 0..8 {
            if self.top(at, size) == 0.0 {
                break;
            }
            at = spot();
        }
        at
    }

    /// The scene as a cell looked at about `centre`, its first motor's pose `motor_to_world`,
    /// the ground (its first object) in a look `table` draws from `rng`, the scene's last draw.
    pub(super) fn cell(
        mut self,
        centre: Vec3,
        motor_to_world: Affine3A,
        table: &TableConfig,
        rng: &mut impl Rng,
    ) -> Cell {
        self.list[0].material = table_material(table, rng);
        Cell {
            objects: self.list,
            motor_to_world,
            motor_centre: centre,
            fixture: Vec::new(),
            clamping: Clamping::GearContainerUp,
        }
    }
}

/// Motor `k` of a scene: `first`, or the one `more` builds.
pub(super) fn motor_k<'a>(
    first: &'a Motor,
    more: &dyn Fn(usize) -> Result<Motor>,
    k: usize,
) -> Result<Cow<'a, Motor>> {
    Ok(if k == 0 {
        Cow::Borrowed(first)
    } else {
        Cow::Owned(more(k)?)
    })
}

/// The parts of a motor lying on its side (cover up) that are hidden: the magnets and the
/// armature inside the pole pot, and the inner gears under the cover (unless it is off).
pub(super) fn inside(kind: PartKind, cover_off: bool) -> bool {
    match kind {
        PartKind::Magnet | PartKind::Armature => true,
        PartKind::Cover | PartKind::CoverBolt => cover_off,
        PartKind::LowerGear | PartKind::UpperGear | PartKind::SingleGear => !cover_off,
        _ => false,
    }
}

/// Motor frame to world for `motor` lying on its side, cover up, turned `yaw` about the
/// vertical, its box's bottom centre at `at`.
pub(super) fn lying(motor: &Motor, yaw: f32, at: Vec3) -> Affine3A {
    let lay = Affine3A::from_rotation_z(yaw)
        * Affine3A::from_mat3(orientation(motor, Clamping::GearContainerUp));
    set_down(&motor.attributes.bounds, lay, at)
}

/// `turn` followed by the shift that puts box `b`'s bottom centre (after `turn`) at `at`.
pub(super) fn set_down(b: &Aabb, turn: Affine3A, at: Vec3) -> Affine3A {
    let laid = transform_box(b, &turn);
    let bottom = Vec3::new(laid.centre().x, laid.centre().y, laid.min.z);
    Affine3A::from_translation(at - bottom) * turn
}

/// A part's rotation lying flat: its box's thinnest side vertical (upside down half the time),
/// turned `yaw` about the vertical.
pub(super) fn flat(p: &Part, yaw: f32, rng: &mut impl Rng) -> Affine3A {
    let size = p.mesh.bounds().size();
    let thin = if size.x <= size.y && size.x <= size.z {
        Vec3::X
    } else if size.y <= size.z {
        Vec3::Y
    } else {
        Vec3::Z
    };
    let up = if rng.random::<bool>() { thin } else { -thin };
    let across = if thin == Vec3::Z { Vec3::X } else { Vec3::Z };
    // motor-frame axes that go to world x, y, z
    let turn = Mat3::from_cols(across, up.cross(across), up).transpose();
    Affine3A::from_rotation_z(yaw) * Affine3A::from_mat3(turn)
}

/// A box of `half` sizes standing on `z`, at (x, y), turned `yaw`.
pub(super) fn block(half: Vec3, at: Vec3, yaw: f32) -> Mesh {
    cuboid(
        Vec3::new(-half.x, -half.y, 0.0),
        Vec3::new(half.x, half.y, 2.0 * half.z),
    )
    .transformed(&(Affine3A::from_translation(at) * Affine3A::from_rotation_z(yaw)))
}

/// A matte plastic of a random colour.
pub(super) fn paint(rng: &mut impl Rng) -> Material {
    let colour = [rng.random(), rng.random(), rng.random()].map(|c: f32| 0.05 + 0.8 * c);
    Material {
        colour,
        reflectivity: 0.2 + 0.5 * colour.iter().sum::<f32>() / 3.0,
        roughness: rng.random_range(0.3..0.9),
        ..sensor::materials::MATTE_GREY
    }
}
