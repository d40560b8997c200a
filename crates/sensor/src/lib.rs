//! Simulated depth sensors on a BVH ray caster built on parry: structured-light cameras with
//! projector shadows, time-of-flight and Kinect-style sensors, and ideal depth, with composable
//! noise models and labelled outputs. Scene-agnostic: it scans any labelled triangle meshes.
#![warn(missing_docs)]

pub mod bvh;

pub use bvh::{Bvh, Hit};
