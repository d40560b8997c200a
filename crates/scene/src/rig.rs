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
            let (eye, target, roll) = match config.rig {
                Rig::Cap => {
                    let tilt = config.tilt_deg.sample(rng).to_radians();
                    let azimuth = config.azimuth_deg.sample(rng).to_radians();
                    let distance = config.distance.sample(rng);
                    let roll = config.roll_deg.sample(rng).to_radians();
                    let dir = Vec3::new(
                        tilt.sin() * azimuth.cos(),
                        tilt.sin() * azimuth.sin(),
                        tilt.cos(),
                    );
                    (centre + distance * dir, centre, roll)
                }
                Rig::Fixed => {
                    let (e, t) = relative(&config.look_at);
                    (e, t, 0.0)
                }
                Rig::List => {
                    let n = config.poses.len() as u64;
                    let (e, t) = relative(&config.poses[((index * views + v) % n) as usize]);
                    (e, t, 0.0)
                }
            };
            let across = match config.rig {
                Rig::Cap => Vec3::X,
                _ => (target - eye).cross(Vec3::from(config.up)),
            };
            // a view straight along `across` has no defined roll: fall back to world y
            aim(eye, target, across, roll)
                .or_else(|| aim(eye, target, Vec3::Y, roll))
                .expect("eye and target differ (checked with the config)")
        })
        .collect()
}
