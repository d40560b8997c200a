//! The disassembly-station work cell of the AgiProbot datasets and the dataset runner that joins
//! `motorgen` and `sensor`: a motor clamped (lying cover up, or standing) in a two-jaw fixture
//! on a table, mask panels, camera rigs, the crop cuboid, the original augmentation levels, and
//! labelled datasets written deterministically, in parallel, resumably and in shards.
//!
//! - [`Config`]: a dataset configuration; [`config::default_table`] is `configs/default.toml`,
//!   which every configuration is laid over ([`overlay`], [`set_key`]), and
//!   [`config::BUILTIN`] the shipped ones.
//! - [`Dataset`]: a configuration planned for a folder: [`Dataset::recipe`] of each sample,
//!   [`Dataset::prepare`] (which claims the folder, [`Claim`]) and [`Dataset::run`] to write it.
//! - [`make`]: one [`Sample`] in memory: the motor, the [`Cell`] it lies in, and per view the
//!   scan's cropped [`sensor::PointCloud`] with the pose and ground truth.
//! - [`coverage`]: how much of a motor's surface a set of views observes.
//! - [`Station`]: the inspection station, one motor clamped and viewed one view at a time, the
//!   coverage so far and the points measured.
//!
//! # Example
//!
//! ```
//! use scene::{Dataset, Shard, make};
//!
//! // sample 3 of the SynMotor configuration, two views, made in memory
//! let mut table = scene::config::builtin_table("synmotor").unwrap();
//! scene::set_key(&mut table, "camera.views", 2.into())?;
//! let dataset = Dataset::new(table, None, None, Shard::ALL, "out/never-written".as_ref())?;
//! let recipe = dataset.recipe(3)?;
//! let sample = make(&recipe, 3)?;
//! assert_eq!(sample.views.len(), 2);
//! let cloud = &sample.views[0].cloud;
//! assert!(cloud.len() > 1000);
//! // class 1 is the cover in SynMotor's labels
//! assert!(cloud.class.contains(&1));
//! # Ok::<(), scene::Error>(())
//! ```

pub mod augment;
pub mod bop;
pub mod cell;
mod claim;
pub mod coco;
pub mod config;
pub mod coverage;
pub mod dataset;
mod error;
mod fixture;
pub mod pass;
pub mod preview;
pub mod recipe;
pub mod record;
mod rendered;
pub mod rig;
pub mod sample;
mod seed;
pub mod silhouette;
pub mod station;
pub mod yolo;

pub use augment::{Level, Split};
pub use cell::{Cell, Object, Variation, compose};
pub use claim::Claim;
pub use config::{Clamping, Config, Span, Variant, overlay, parse_value, set_key};
pub use dataset::{Dataset, Prepared, Row, Shard, Summary, sample_json};
pub use error::{Error, Result};
pub use recipe::Recipe;
pub use record::SampleJson;
pub use sample::{Sample, make};
pub use station::{Capture, Station};

/// The default dataset configuration (`configs/default.toml`), built into the binary.
pub const DEFAULT_CONFIG: &str = include_str!("../configs/default.toml");
