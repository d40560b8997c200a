//! The seeds of a sample's random draws, one stream per draw.

use motorgen::derive_seed;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// What a sample draws at random, each from a seed of its own derived from the sample's seed,
/// so that changing one setting leaves the others' draws alone. (The sensor's per-pixel draws
/// are keyed by the scan's seed, `Seed::Scan`, and streams of their own: `sensor::noise::stream`.)
#[derive(Clone, Copy)]
pub(crate) enum Seed {
    Motor,
    Cell,
    Camera,
    Crop,
    NoiseScale,
    Cover,
    /// The inspection station's surface samples.
    Surface,
    /// The cell of the other clamping (`cell.reclamp`).
    Reclamp,
    /// View `k`'s scan.
    Scan(u64),
    /// View `k`'s jitter after cropping.
    Jitter(u64),
    /// The lights of the sample's rendered colour images.
    Lighting,
    /// View `k`'s rendered colour image: its exposure, motion and paths.
    Render(u64),
    /// The scene's `k`-th motor besides the sample's own (k from 1).
    Extra(u64),
    /// The camera the sample is taken with: its calibration error (`sensor.cameras`).
    Calibration,
    /// How the hall's robot drives: its speed, start and offset.
    Drive,
}

impl Seed {
    /// The seed of this draw in the sample with seed `sample`.
    pub(crate) fn of(self, sample: u64) -> u64 {
        let stream = match self {
            Seed::Motor => 0,
            Seed::Cell => 1,
            Seed::Camera => 2,
            Seed::Crop => 3,
            Seed::NoiseScale => 4,
            Seed::Cover => 5,
            Seed::Surface => 6,
            Seed::Reclamp => 7,
            Seed::Lighting => 8,
            Seed::Calibration => 9,
            Seed::Drive => 10,
            Seed::Scan(k) => 100 + k,
            Seed::Jitter(k) => 200 + k,
            Seed::Render(k) => 300 + k,
            Seed::Extra(k) => 1000 + k,
        };
        derive_seed(sample, stream)
    }

    /// A generator for this draw in the sample with seed `sample`.
    pub(crate) fn rng(self, sample: u64) -> ChaCha8Rng {
        ChaCha8Rng::seed_from_u64(self.of(sample))
    }
}
