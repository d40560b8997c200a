//! A checked configuration, ready to make samples: its motor parameter spaces, its sensor (or
//! the hall's LiDAR), each sample's placement and motors.

use std::borrow::Cow;

use motorgen::{Motor, ParamSpace, build, derive_seed};
use sensor::{Lidar, PointCloud, SensorSpec};

use crate::augment::{Level, Place, Split, place};
use crate::config::{Colouring, Config, SceneKind, Variant};
use crate::error::Result;
use crate::seed::Seed;

/// A checked configuration, ready to make samples.
#[derive(Clone, Debug)]
pub struct Recipe {
    /// The configuration.
    pub config: Config,
    /// The sweep values that made it from the base configuration.
    pub sweep: Vec<(String, toml::Value)>,
    /// The motor parameter space of each variant (one space when no variants are listed).
    spaces: Vec<ParamSpace>,
    /// The sensor, its sampling applied.
    sensor: SensorSpec,
    /// The hall's LiDAR (`cell.scene = "hall"`).
    lidar: Option<Lidar>,
}

impl Recipe {
    /// Checks `config` and prepares its parameter spaces and sensor.
    ///
    /// # Errors
    ///
    /// The errors of [`Config::check`](crate::Config::check), and
    /// [`Error::Config`](crate::Error::Config) for a sensor that does not resolve.
    pub fn new(config: Config, sweep: Vec<(String, toml::Value)>) -> Result<Recipe> {
        config.check()?;
        let spaces = config.param_spaces()?;
        let sensor = config.sensor.resolve()?;
        let lidar = (config.cell.scene == SceneKind::Hall)
            .then(|| config.lidar.resolve())
            .transpose()?;
        Ok(Recipe {
            config,
            sweep,
            spaces,
            sensor,
            lidar,
        })
    }

    /// Sample `index`'s motor variant, augmentation level and split ([`place`]).
    pub fn placement(&self, index: u64) -> (Option<Variant>, Level, Split) {
        let p = self.place(index);
        let variant = self.config.motor.variants.get(p.slot as usize).copied();
        (variant, p.level, p.split)
    }

    fn place(&self, index: u64) -> Place {
        let slots = u32::try_from(self.spaces.len()).unwrap_or(u32::MAX);
        place(index, slots, &self.config.augment)
    }

    /// Sample `index`'s seed and motor.
    ///
    /// # Errors
    ///
    /// [`Error::Config`](crate::Error::Config) when the motor's parameters drawn for this sample
    /// do not form a valid motor.
    pub fn motor(&self, index: u64) -> Result<(u64, Motor)> {
        let seed = derive_seed(self.config.seed, index);
        let space = &self.spaces[self.place(index).slot as usize];
        let motor = build(
            &space.sample(Seed::Motor.of(seed))?,
            self.config.motor.detail,
        );
        Ok((seed, motor))
    }

    /// Sample `index`'s `k`-th motor besides its own (k from 1: the transfer unit's and the
    /// handling table's): its own draw of the parameters, of the next variant in turn.
    ///
    /// # Errors
    ///
    /// [`Error::Config`](crate::Error::Config) when the motor's parameters drawn do not form a valid motor.
    pub fn extra_motor(&self, index: u64, k: usize) -> Result<Motor> {
        let seed = derive_seed(self.config.seed, index);
        let slot = (self.place(index).slot as usize + k) % self.spaces.len();
        let params = self.spaces[slot].sample(Seed::Extra(k as u64).of(seed))?;
        Ok(build(&params, self.config.motor.detail))
    }

    /// The sensor, its sampling applied.
    pub fn sensor(&self) -> &SensorSpec {
        &self.sensor
    }

    /// The hall's LiDAR, if the scene is the hall.
    pub fn hall_lidar(&self) -> Option<&Lidar> {
        self.lidar.as_ref()
    }

    /// The hall's LiDAR.
    ///
    /// # Panics
    ///
    /// Unless the scene is the hall.
    pub(crate) fn lidar(&self) -> &Lidar {
        self.lidar
            .as_ref()
            .expect("the hall's recipe has its LiDAR")
    }

    /// `cloud` with the rgb `output.colour` asks for: the camera's, or the class colours of the
    /// label scheme (grey beyond it).
    pub fn coloured<'a>(&self, cloud: &'a PointCloud) -> Cow<'a, PointCloud> {
        match self.config.output.colour {
            Colouring::Camera => Cow::Borrowed(cloud),
            Colouring::Class => {
                let classes = self.config.output.scheme.classes();
                Cow::Owned(PointCloud {
                    rgb: cloud
                        .class
                        .iter()
                        .map(|&c| classes.get(c as usize).map_or([128; 3], |c| c.color))
                        .collect(),
                    ..cloud.clone()
                })
            }
        }
    }
}
