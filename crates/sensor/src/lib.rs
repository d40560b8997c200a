//! Simulated depth sensors on a BVH ray caster: structured-light cameras with
//! projector shadows, time-of-flight and Kinect-style sensors, and ideal depth, with composable
//! noise models and labelled outputs. Scene-agnostic: it scans any labelled triangle meshes.
//!
//! - [`Target`]: a triangle mesh with a class (per mesh or per triangle), an instance and a
//!   [`Material`]; a [`World`] holds the targets in one BVH; [`mesh::read`] reads OBJ, STL and
//!   PLY files as targets.
//! - [`SensorSpec`]: camera [`Intrinsics`], sensor [`Model`], [`Noise`] and working range;
//!   [`SensorSpec::preset`] gives the Zivid, Blensor, Kinect and ideal presets.
//! - [`scan()`] (and [`scan_within`] a region, [`scan_reusing`] an earlier scan's buffer): one
//!   organized [`Scan`] of [`Pixel`]s in the camera frame, the same bytes for any thread count.
//! - [`Scan::cloud`]: the valid points as a [`PointCloud`] in a [`Frame`] and [`Units`];
//!   [`formats`] writes clouds (PLY, PCD, NPY, NPZ) and images (PNG, NPY).
//!
//! # Example
//!
//! ```
//! use glam::Vec3;
//! use sensor::{Frame, Material, SensorSpec, Target, Units, World, look_at, scan};
//!
//! // a user's mesh: a 1 m square, class 3, instance 1, facing a camera 1 m above it
//! let corners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]];
//! let target = Target {
//!     positions: corners.iter().map(|&[x, y]| Vec3::new(x, y, 0.0)).collect(),
//!     triangles: vec![[0, 1, 2], [0, 2, 3]],
//!     classes: sensor::Classes::Uniform(3),
//!     instance: 1,
//!     material: Material::default(),
//!     wear: None,
//! };
//! let world = World::new(&[target]);
//! let mut zivid = SensorSpec::preset("zivid-2plus-mr130")?.binned(4); // Zivid's by4x4
//! zivid.min_range = 0.5; // the preset's working range starts at 0.8 m
//! let pose = look_at(Vec3::new(0.0, 0.0, 1.0), Vec3::ZERO, Vec3::Y).unwrap();
//! let cloud = scan(&world, &zivid, &pose, 0).cloud(false, Frame::World, Units::Metres);
//! assert!(cloud.len() > 10_000);
//! assert!(cloud.class.iter().all(|&c| c == 3));
//! assert!(cloud.xyz.iter().all(|p| p.z.abs() < 0.005)); // on the square, within the noise
//! # Ok::<(), sensor::Error>(())
//! ```

pub mod bvh;
pub mod camera;
pub mod cloud;
mod epipolar;
mod error;
pub mod files;
pub mod formats;
pub mod lidar;
pub mod materials;
pub mod mesh;
pub mod noise;
mod pages;
pub mod render;
pub mod scan;
pub mod shapes;
pub mod spec;
pub mod wear;
pub mod world;

pub use bvh::{Bvh, Hit};
pub use camera::{Distortion, Intrinsics, look_at};
pub use cloud::{Frame, PointCloud, Units};
pub use error::Error;
pub use lidar::{LIDAR_PRESETS, Lidar, LidarScan, head_pose, scan_lidar};
pub use materials::MATERIALS;
pub use noise::Noise;
pub use scan::{Pixel, Region, Scan, Window, nearest_surface, scan, scan_reusing, scan_within};
pub use spec::{
    Calibration, CalibrationError, ColourCamera, ColourCapture, Model, PRESETS, Processing,
    Projector, Removal, Sampling, SensorSpec,
};
pub use world::{Classes, Material, Target, World};
