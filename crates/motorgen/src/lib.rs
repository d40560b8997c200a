//! Parametric, labelled meshes of small DC gear motors: a re-implementation of the MotorFactory
//! Blender add-on that builds every part as a closed, outward-facing mesh with exact ground truth.
//!
//! - [`MotorParams`]: every parameter of the add-on, with its default ([`params::PARAMS`]
//!   lists them with ranges and meanings); [`ParamSpace`] draws them from distributions,
//!   [`ParamSpace::addon`] as the add-on's random mode did.
//! - [`build`]: the [`Motor`] of a set of parameters: its [`Part`]s (pole pot, gearbox, cover,
//!   bolts, ...) in metres, each with a kind, a class and an instance, and its [`Attributes`]
//!   (gear centres and axes, bolt head centres and drive rotations, part boxes).
//! - [`export`]: OBJ, STL, PLY (with per-face labels) and glTF binary, per part and whole;
//!   [`Scheme`] maps part kinds to the label sets of the original datasets.
//!
//! Units are metres and degrees. The motor frame is the add-on's: z along the motor axis, z = 0
//! at the free end of the shaft boss.
//!
//! # Example
//!
//! ```
//! use motorgen::{Detail, Format, MotorParams, ParamSpace, build, export::write_motor};
//!
//! // the add-on's default motor: type A with one cover eye
//! let motor = build(&MotorParams::default(), Detail::Normal);
//! assert_eq!(motor.attributes.variant, "A1");
//! assert!(motor.parts.iter().any(|p| p.name == "cover"));
//!
//! // a motor from the add-on's random generator, written as glTF with its ground truth
//! let params = ParamSpace::addon().sample(7)?;
//! let dir = std::env::temp_dir().join("motorgen-doc-example");
//! let files = write_motor(&build(&params, Detail::Coarse), &dir, &[Format::Glb], false)?;
//! assert!(files.iter().any(|f| f.ends_with("motor.glb")));
//! assert!(files.iter().any(|f| f.ends_with("attributes.json")));
//! # Ok::<(), motorgen::Error>(())
//! ```

mod error;
pub mod export;
pub mod kernel;
pub mod labels;
pub mod model;
pub mod params;
mod parts;
pub mod space;

pub use error::{Error, Result, cut, did_you_mean, shown};
pub use export::Format;
pub use kernel::Detail;
pub use labels::Scheme;
pub use model::{Attributes, Motor, Part, PartClass, PartKind};
pub use params::MotorParams;
pub use parts::{ArmatureLayout, armature_layout, build};
pub use space::{Dist, ParamSpace, derive_seed};
