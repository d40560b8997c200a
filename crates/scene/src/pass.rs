//! A LiDAR pass of the hall (`cell.scene = "hall"`): one revolution of the head on the mobile
//! robot as it drives along the aisle. Samples k·n to k·n + n − 1 (n = `lidar.revolutions`)
//! are the consecutive passes of hall k, whose layout, motors, speed and start are drawn from
//! the seed of its first sample; each pass is a pure function of (configuration, index).

use std::collections::BTreeMap;

use glam::{Affine3A, Vec3};
use motorgen::Scheme;
use rand::RngExt;
use sensor::lidar::{LidarFrame, Motion};
use sensor::{Lidar, LidarScan, Units, World, head_pose, scan_lidar};
use serde::{Deserialize, Serialize};

use crate::augment::{Level, Split};
use crate::cell::{AISLE, Cell, hall};
use crate::error::{Error, Result};
use crate::recipe::Recipe;
use crate::record::{Matrix, ObjectJson};
use crate::sample::matrix;
use crate::seed::Seed;

/// Clearance between the robot's path and the hall's end walls, m.
const END_CLEARANCE: f32 = 1.5;

/// A hall ready to scan: its objects, their ray-casting world and how the robot drives.
pub struct Hall {
    /// Its number: samples `number · revolutions …` are its passes.
    pub number: u64,
    /// Its objects.
    pub cell: Cell,
    /// The objects' world.
    pub world: World,
    /// The robot's speed, m/s.
    pub speed: f32,
    /// Where along its path the robot is when the hall's first pass begins, m.
    pub start: f32,
    /// The path's offset from the aisle's middle (world y), m.
    pub offset: f32,
    /// The path's length: along the aisle from end to end, m.
    pub length: f32,
}

/// Builds hall `number` of `recipe`: drawn from the seed of its first sample.
///
/// # Errors
///
/// [`Error::Config`] when a motor's parameters drawn do not form a valid motor.
pub fn make_hall(recipe: &Recipe, number: u64) -> Result<Hall> {
    let config = &recipe.config;
    let first = number * u64::from(config.lidar.revolutions);
    let (seed, motor) = recipe.motor(first)?;
    let more = |k: usize| recipe.extra_motor(first, k);
    let cell = hall(&motor, &more, &config.cell, &mut Seed::Cell.rng(seed))?;
    let world = World::new(&cell.targets(config.output.scheme));
    let length = (config.cell.hall.size[0] - 2.0 * END_CLEARANCE).max(0.0);
    let drive = &mut Seed::Drive.rng(seed);
    let speed = config.lidar.speed.sample(drive);
    let start = drive.random_range(0.0..=2.0 * length);
    let offset = drive.random_range(-0.25..=0.25) * (AISLE / 2.0);
    Ok(Hall {
        number,
        cell,
        world,
        speed,
        start,
        offset,
        length,
    })
}

/// One pass in memory.
pub struct Pass {
    /// Index in the dataset.
    pub index: u64,
    /// Seed derived from the global seed and the index.
    pub seed: u64,
    /// The hall's number.
    pub hall: u64,
    /// Which of the hall's passes, from 0.
    pub revolution: u32,
    /// Augmentation level (its noise scale).
    pub level: Level,
    /// Split.
    pub split: Split,
    /// The LiDAR as used (noise scaled).
    pub lidar: Lidar,
    /// Factor applied to the LiDAR's distance noise σ.
    pub noise_scale: f32,
    /// The head's pose when the pass begins.
    pub pose: Affine3A,
    /// How the head moves during the pass.
    pub motion: Motion,
    /// The returns.
    pub scan: LidarScan,
}

/// Makes pass `index` of `recipe` in `hall` (its hall: [`hall_of`]).
pub fn make_pass(recipe: &Recipe, index: u64, hall: &Hall) -> Pass {
    let config = &recipe.config;
    let revolutions = u64::from(config.lidar.revolutions);
    debug_assert_eq!(index / revolutions, hall.number);
    let revolution = (index % revolutions) as u32;
    let seed = motorgen::derive_seed(config.seed, index);
    let (_, level, split) = recipe.placement(index);
    let lc = level.config(&config.augment);
    let noise_scale = lc.noise_scale.sample(&mut Seed::NoiseScale.rng(seed));
    let mut lidar = recipe.lidar().clone();
    lidar.noise.sigma *= noise_scale;
    for row in &mut lidar.noise.table {
        row[2] *= noise_scale;
    }
    // back and forth along the aisle: s in [0, 2·length) out, back beyond length
    let period = 1.0 / lidar.rotation;
    let travelled = hall.start + hall.speed * period * revolution as f32;
    let lap = 2.0 * hall.length;
    let s = if lap > 0.0 { travelled % lap } else { 0.0 };
    let (along, heading) = if s <= hall.length {
        (s, 1.0)
    } else {
        (lap - s, -1.0)
    };
    let position = Vec3::new(-hall.length / 2.0 + along, hall.offset, config.lidar.height);
    let pose = head_pose(position, position + Vec3::X * heading, Vec3::Z)
        .expect("a level heading is off the vertical axis");
    let motion = Motion {
        velocity: Vec3::new(heading * hall.speed, 0.0, 0.0),
        turn: 0.0,
    };
    let scan = scan_lidar(&hall.world, &lidar, &pose, &motion, Seed::Scan(0).of(seed));
    Pass {
        index,
        seed,
        hall: hall.number,
        revolution,
        level,
        split,
        lidar,
        noise_scale,
        pose,
        motion,
        scan,
    }
}

/// The hall of sample `index`.
pub fn hall_of(recipe: &Recipe, index: u64) -> u64 {
    index / u64::from(recipe.config.lidar.revolutions)
}

/// A pass's ground truth and provenance (`{stem}.json` beside its files).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PassJson {
    /// Index in the dataset.
    pub index: u64,
    /// The dataset's global seed.
    pub seed: u64,
    /// The hall's number.
    pub hall: u64,
    /// Which of the hall's passes, from 0.
    pub revolution: u32,
    /// Augmentation level.
    pub level: Level,
    /// Split.
    pub split: Split,
    /// The swept keys' values of this sample (dotted key → value).
    pub sweep: BTreeMap<String, toml::Value>,
    /// The LiDAR as used.
    pub lidar: Lidar,
    /// Factor on the LiDAR's distance noise σ.
    pub noise_scale: f32,
    /// The head's pose when the pass begins (x its yaw 0, z its axis).
    pub head_to_world: Matrix,
    /// How the head moves during the pass.
    pub motion: Motion,
    /// Rays fired.
    pub rays: usize,
    /// Returns written.
    pub returns: usize,
    /// Frame of the written points.
    pub frame: LidarFrame,
    /// Units of the written points.
    pub units: Units,
    /// Label scheme.
    pub scheme: Scheme,
    /// Every object of the hall.
    pub objects: Vec<ObjectJson>,
    /// The pass's files.
    pub files: Vec<String>,
}

impl Pass {
    /// Its file names' stem: `{index}_hall_{level}`.
    pub fn stem(&self) -> String {
        format!("{:06}_hall_{}", self.index, self.level.name())
    }

    /// Ground truth and provenance as its JSON, `files` its files.
    pub fn json(&self, recipe: &Recipe, hall: &Hall, files: Vec<String>) -> PassJson {
        let out = &recipe.config.output;
        PassJson {
            index: self.index,
            seed: recipe.config.seed,
            hall: self.hall,
            revolution: self.revolution,
            level: self.level,
            split: self.split,
            sweep: recipe.sweep.iter().cloned().collect(),
            lidar: self.lidar.clone(),
            noise_scale: self.noise_scale,
            head_to_world: matrix(&self.pose),
            motion: self.motion,
            rays: self.scan.rays,
            returns: self.scan.returns.len(),
            frame: recipe.config.lidar.frame,
            units: out.units,
            scheme: out.scheme,
            objects: hall
                .cell
                .objects
                .iter()
                .map(|o| ObjectJson::of(o, out.scheme))
                .collect(),
            files,
        }
    }
}

/// Why a hall's first pass holds no return.
pub(crate) fn why_empty(recipe: &Recipe, pass: &Pass) -> Error {
    Error::Config(format!(
        "sample {} holds no return: the LiDAR ({}) at {} m over the floor sees no surface \
         within {} m; check lidar.height and cell.hall.size",
        pass.index, pass.lidar.name, recipe.config.lidar.height, pass.lidar.max_range
    ))
}
