//! A view's colour image path-traced under the sample's lights (`render.enabled`), through the
//! colour camera's lens, exposed and developed by the camera, in place of the scan's own.

use rand::{Rng, RngExt};
use sensor::render::{Lighting, Settings, render};
use sensor::{Scan, SensorSpec, World};

use crate::config::RenderConfig;
use crate::error::{Error, Result};

/// The mean luminance an automatic exposure brings a frame to.
const MID_GREY: f32 = 0.18;

/// Replaces `scan`'s colour image by one path-traced of `world` under `lighting` (the scan's
/// intrinsics and pose, the lens of the sensor's colour camera), exposed and moved as `config`
/// draws from `rng`, developed by the sensor's colour camera.
pub(crate) fn colour(
    scan: &mut Scan,
    world: &World,
    sensor: &SensorSpec,
    lighting: &Lighting,
    config: &RenderConfig,
    rng: &mut impl Rng,
) -> Result<()> {
    let k = &sensor.intrinsics;
    let travel = config.motion.sample(rng);
    let angle = rng.random_range(0.0..std::f32::consts::TAU);
    let mut exposure = config.exposure.sample(rng).exp2();
    let settings = Settings {
        samples: config.samples,
        bounces: config.bounces,
        seed: rng.random(),
        aperture: sensor.colour.aperture_radius(k),
        focus: sensor.colour.focus,
        motion: [travel * angle.cos(), travel * angle.sin(), 0.0],
        denoise: config.denoise,
        light_block: config.light_block,
    };
    let mut frame = render(world, k, &scan.pose, lighting, &settings)
        .map_err(|e| Error::Config(e.to_string()))?;
    if config.auto_exposure {
        let mean = frame.mean_luminance();
        if mean > 0.0 {
            exposure *= MID_GREY / mean;
        }
    }
    for p in &mut frame.pixels {
        *p = p.map(|c| c * exposure);
    }
    let rgb = sensor.colour.develop(k, &frame, rng.random());
    for (p, c) in scan.pixels.iter_mut().zip(rgb) {
        p.rgb = c;
    }
    Ok(())
}
