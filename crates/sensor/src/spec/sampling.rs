//! Zivid's pixel sampling: which camera pixels make a point.

use serde::{Deserialize, Serialize};

use crate::Error;

/// Which camera pixels make a point, by Zivid's names (`Settings.Sampling.Pixel`): every pixel;
/// each 2×2 or 4×4 block summed into one (binning: half or a quarter of the resolution, each
/// point with the light of 4 or 16 pixels; the Zivid 2+ R line's monochrome imager); or one
/// colour of the Bayer grid, the projector lighting the scene in that colour alone: that
/// colour's pixel of each 2×2 block (half the resolution, each point one pixel's light), or
/// that colour's four pixels of each 4×4 block summed (a quarter of the resolution, four
/// pixels' light), each with a third of a white ambient light. Each camera offers its own
/// ([`SensorSpec::samplings`](crate::SensorSpec::samplings)); see
/// [`SensorSpec::sampled`](crate::SensorSpec::sampled).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Sampling {
    /// Every pixel.
    #[default]
    #[serde(rename = "all")]
    All,
    /// 2×2 blocks.
    #[serde(rename = "by2x2")]
    By2x2,
    /// 4×4 blocks.
    #[serde(rename = "by4x4")]
    By4x4,
    /// The blue pixel of each 2×2 block, under blue light.
    #[serde(rename = "blueSubsample2x2")]
    BlueSubsample2x2,
    /// The red pixel of each 2×2 block, under red light.
    #[serde(rename = "redSubsample2x2")]
    RedSubsample2x2,
    /// The four blue pixels of each 4×4 block, summed, under blue light.
    #[serde(rename = "blueSubsample4x4")]
    BlueSubsample4x4,
    /// The four red pixels of each 4×4 block, summed, under red light.
    #[serde(rename = "redSubsample4x4")]
    RedSubsample4x4,
}

impl Sampling {
    /// Every sampling, in [`Sampling::NAMES`] order.
    pub const ALL: [Sampling; 7] = [
        Sampling::All,
        Sampling::By2x2,
        Sampling::By4x4,
        Sampling::BlueSubsample2x2,
        Sampling::RedSubsample2x2,
        Sampling::BlueSubsample4x4,
        Sampling::RedSubsample4x4,
    ];

    /// The names, as Zivid writes them.
    pub const NAMES: [&str; 7] = [
        "all",
        "by2x2",
        "by4x4",
        "blueSubsample2x2",
        "redSubsample2x2",
        "blueSubsample4x4",
        "redSubsample4x4",
    ];

    /// The pixels a block has along each side.
    pub fn factor(self) -> u32 {
        match self {
            Sampling::All => 1,
            Sampling::By2x2 | Sampling::BlueSubsample2x2 | Sampling::RedSubsample2x2 => 2,
            Sampling::By4x4 | Sampling::BlueSubsample4x4 | Sampling::RedSubsample4x4 => 4,
        }
    }

    /// Whether one colour's pixels of each block make the point, rather than the whole block.
    pub fn subsamples(self) -> bool {
        !matches!(self, Sampling::All | Sampling::By2x2 | Sampling::By4x4)
    }

    /// Where in its block the point's light comes from, pixels from the block's first along
    /// each axis (Zivid's pixel mapping: the blue pixel of a 2×2 block first, the red one
    /// last, a bin's centre; a 4×4 block's blue pixels, at 0 and 2, about 1, its red ones
    /// about 2).
    pub fn offset(self) -> f64 {
        match self {
            Sampling::BlueSubsample2x2 => 0.0,
            Sampling::RedSubsample2x2 | Sampling::BlueSubsample4x4 => 1.0,
            Sampling::RedSubsample4x4 => 2.0,
            _ => (f64::from(self.factor()) - 1.0) / 2.0,
        }
    }
}

impl std::fmt::Display for Sampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let i = Sampling::ALL.iter().position(|s| s == self).unwrap_or(0);
        f.write_str(Sampling::NAMES[i])
    }
}

impl std::str::FromStr for Sampling {
    type Err = Error;

    /// A sampling by its name.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] for a name that is not one of [`Sampling::NAMES`].
    fn from_str(name: &str) -> Result<Sampling, Error> {
        Sampling::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Sampling::ALL[i])
            .ok_or_else(|| Error::Invalid {
                key: "sampling".into(),
                value: format!("\"{name}\""),
                allowed: format!("one of {}", Sampling::NAMES.join(", ")),
            })
    }
}
