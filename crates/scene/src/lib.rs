//! The disassembly-station work cell of the AgiProbot datasets and the dataset runner that joins
//! `motorgen` and `sensor`: a motor clamped cover up in a two-jaw fixture on a table, mask panels,
//! camera rigs, the crop cuboid, the original augmentation levels, and labelled datasets written
//! deterministically, in parallel, resumably and in shards.
#![warn(missing_docs)]

pub mod augment;
pub mod cell;
pub mod config;
pub mod dataset;
mod error;
mod fixture;
pub mod preview;
pub mod rig;
pub mod sample;

pub use augment::{Level, Split};
pub use cell::{Cell, Object, Variation, compose};
pub use config::{Config, Span, Variant, overlay, parse_value, set_key};
pub use dataset::{Dataset, Row, Shard, Summary};
pub use error::{Error, Result};
pub use sample::{Recipe, Sample, make};

/// The default dataset configuration (`configs/default.toml`), built into the binary.
pub const DEFAULT_CONFIG: &str = include_str!("../../../configs/default.toml");
