//! Parametric, labelled meshes of small DC gear motors: a re-implementation of the MotorFactory
//! Blender add-on that builds every part as a closed, outward-facing mesh with exact ground truth.
#![warn(missing_docs)]

mod error;
pub mod export;
pub mod kernel;
pub mod labels;
pub mod model;
pub mod params;
mod parts;
pub mod space;

pub use error::{Error, Result};
pub use export::Format;
pub use kernel::Detail;
pub use labels::Scheme;
pub use model::{Attributes, Motor, Part, PartClass, PartKind};
pub use params::MotorParams;
pub use parts::build;
pub use space::{Dist, ParamSpace, derive_seed};
