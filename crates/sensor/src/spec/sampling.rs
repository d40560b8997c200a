//! Zivid's pixel sampling: which camera pixels make a point.

use serde::{Deserialize, Serialize};

use crate::Error;

/// Which camera pixels make a point, by Zivid's names (`Settings.Sampling.Pixel`): every pixel;
/// each 2×2 or 4×4 block summed into one (binning: half or a quarter of the resolution, each
/// point with the light of 4 or 16 pixels); or one colour of each 2×2 Bayer block, the
/// projector lighting the scene in that colour alone (half the resolution, each point one
/// pixel's light, a third of a white ambient light). See [`SensorSpec::sampled`](crate::SensorSpec::sampled).
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
}

impl Sampling {
    /// Every sampling, in [`Sampling::NAMES`] order.
    pub const ALL: [Sampling; 5] = [
        Sampling::All,
        Sampling::By2x2,
        Sampling::By4x4,
        Sampling::BlueSubsample2x2,
        Sampling::RedSubsample2x2,
    ];

    /// The names, as Zivid writes them.
    pub const NAMES: [&str; 5] = [
        "all",
        "by2x2",
        "by4x4",
        "blueSubsample2x2",
        "redSubsample2x2",
    ];

    /// The pixels a block has along each side.
    pub fn factor(self) -> u32 {
        match self {
            Sampling::All => 1,
            Sampling::By2x2 | Sampling::BlueSubsample2x2 | Sampling::RedSubsample2x2 => 2,
            Sampling::By4x4 => 4,
        }
    }

    /// Whether one pixel of each block makes the point, rather than the block's sum.
    pub fn subsamples(self) -> bool {
        matches!(self, Sampling::BlueSubsample2x2 | Sampling::RedSubsample2x2)
    }

    /// Where in its block the point's pixel lies, pixels from the block's first along each
    /// axis (Zivid's pixel mapping: the blue pixel first, the red one last, a bin's centre).
    pub fn offset(self) -> f64 {
        match self {
            Sampling::BlueSubsample2x2 => 0.0,
            Sampling::RedSubsample2x2 => 1.0,
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
