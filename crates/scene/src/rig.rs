//! Camera rigs: poses on a spherical cap over the motor, a fixed pose, or a list of poses; one
//! or more views per cell.

use glam::{Affine3A, Mat3, Vec3};
use rand::Rng;

use crate::config::{CameraConfig, Rig};

/// A camera-to-world pose (OpenCV axes: x right, y down, z forward) at `eye` looking at
/// `target`, rolled by `roll` radians from the pose whose image rows follow `across`.
pub fn aim(eye: Vec3, target: Vec3, across: Vec3, roll: f32) -> Option<Affine3A> {
    let z = (target - eye).try_normalize()?;
    let x = (across - z * across.dot(z)).try_normalize()?;
    let (s, c) = roll.sin_cos();
    let x = c * x + s * z.cross(x);
    let y = z.cross(x);
    Some(Affine3A::from_mat3_translation(
        Mat3::from_cols(x, y, z),
        eye,
    ))
}

/// The camera pose on a sphere of radius `distance` about `centre`, looking at it: `tilt` from
/// the vertical, `azimuth` about world z from world x, and `roll` about the view from the pose
/// whose image rows follow world x (world y for a view straight down x), radians.
pub fn on_cap(centre: Vec3, tilt: f32, azimuth: f32, distance: f32, roll: f32) -> Affine3A {
    let dir = Vec3::new(
        tilt.sin() * azimuth.cos(),
        tilt.sin() * azimuth.sin(),
        tilt.cos(),
    );
    let eye = centre + distance * dir;
    aim(eye, centre, Vec3::X, roll)
        .or_else(|| aim(eye, centre, Vec3::Y, roll))
        .expect("a positive distance puts the eye off the centre")
}

/// The camera poses of the cell with index `index` whose motor centre is `centre`.
pub fn camera_poses(
    config: &CameraConfig,
    centre: Vec3,
    index: u64,
    rng: &mut impl Rng,
) -> Vec<Affine3A> {
    let views = u64::from(config.views);
    (0..views)
        .map(|v| {
            let relative = |p: &[f32; 6]| {
                (
                    centre + Vec3::from_slice(&p[..3]),
                    centre + Vec3::from_slice(&p[3..]),
                )
            };
            let (eye, target) = match config.rig {
                Rig::Cap => {
                    let tilt = config.tilt_deg.sample(rng).to_radians();
                    let azimuth = config.azimuth_deg.sample(rng).to_radians();
                    let distance = config.distance.sample(rng);
                    let roll = config.roll_deg.sample(rng).to_radians();
                    return on_cap(centre, tilt, azimuth, distance, roll);
                }
                Rig::Fixed => relative(&config.look_at),
                Rig::List => {
                    let n = config.poses.len() as u64;
                    relative(&config.poses[((index * views + v) % n) as usize])
                }
            };
            let across = (target - eye).cross(Vec3::from(config.up));
            // a view straight along `across` has no defined roll: fall back to world y
            aim(eye, target, across, 0.0)
                .or_else(|| aim(eye, target, Vec3::Y, 0.0))
                .expect("eye and target differ (checked with the config)")
        })
        .collect()
}
