//! Simulated depth sensors on a BVH ray caster built on parry: structured-light cameras with
//! projector shadows, time-of-flight and Kinect-style sensors, and ideal depth, with composable
//! noise models and labelled outputs. Scene-agnostic: it scans any labelled triangle meshes.
#![warn(missing_docs)]

pub mod bvh;
pub mod camera;
pub mod cloud;
mod epipolar;
mod error;
pub mod formats;
pub mod noise;
pub mod scan;
pub mod scene;
pub mod sensor;

pub use bvh::{Bvh, Hit};
pub use camera::{Distortion, Intrinsics, look_at};
pub use cloud::{Frame, PointCloud, Units};
pub use error::Error;
pub use noise::Noise;
pub use scan::{Pixel, Region, Scan, scan, scan_reusing, scan_within};
pub use scene::{Classes, Material, Scene, Target};
pub use sensor::{Model, PRESETS, Projector, SensorSpec};
