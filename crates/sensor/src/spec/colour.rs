//! The camera's colour image: what a capture records beside the points, and the settings of
//! its exposure, light and white balance.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::camera::Intrinsics;

/// What a capture records in its colour image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ColourCapture {
    /// A 2D+3D capture: the imager's own colour (or grey) image, pixel for pixel with the
    /// points.
    #[default]
    #[serde(rename = "2d+3d")]
    TwoDThreeD,
    /// A 3D-only capture: no 2D image; every pixel is Zivid's pink, RGB (200, 50, 200).
    #[serde(rename = "3d")]
    ThreeD,
    /// Each pixel its surface's base colour, unlit and without noise, as Blensor's scanners
    /// record a material's colour.
    #[serde(rename = "flat")]
    Flat,
}

/// Zivid's colour of a 3D-only capture.
pub const PINK: [u8; 3] = [200, 50, 200];

/// The camera's colour image, every pixel's colour and each point's rgb: the surface a pixel's
/// centre ray meets, with its material's surface model (the colour renderer's), lit by the
/// projector's white flash (the camera's own light on sensors without a projector) with its
/// shadows and highlights, and by a uniform ambient light; then the camera's gain, white
/// balance and noise, encoded as 8-bit sRGB (a monochrome camera records grey).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ColourCamera {
    /// What the capture records: `"2d+3d"` (the 2D image) or `"3d"` (Zivid's pink).
    pub capture: ColourCapture,
    /// The imager records grey (the Zivid 2+ R line's monochrome 2D).
    pub monochrome: bool,
    /// Linear value of a white Lambertian surface facing the flash at the reference range, in
    /// the flash alone (exposure time, aperture and the projector's brightness together).
    pub exposure: f32,
    /// Linear value of a white Lambertian surface in the ambient light alone.
    pub ambient: f32,
    /// Correlated colour temperature of the ambient light, kelvin (1667 to 25000).
    pub ambient_kelvin: f32,
    /// Analogue gain, 1 to 16: multiplies the signal and its noise.
    pub gain: f32,
    /// Gains of the red and the blue channel against green, 0.25 to 8 (Zivid's red and blue
    /// balance; 1 and 1 keep the flash white).
    pub white_balance: [f32; 2],
    /// Standard deviation of the noise on each channel before the gain, linear units.
    pub noise: f32,
    /// The colour camera's centre in the depth camera's frame, m: 0 for the same imager (a
    /// Zivid's), the RGB camera beside the infrared one for a Kinect. Each pixel takes the
    /// colour its surface point shows that camera, black where the camera cannot see it (a
    /// registered colour image's holes).
    pub offset: [f32; 3],
    /// Whether the sensor's own light (the projector's flash) lights the colour image: not an
    /// infrared projector's.
    pub flash: bool,
    /// Share of the light the lens loses at the image's corners (vignetting), 0 to 0.9: a
    /// pixel loses this times the square of its distance from the principal point over the
    /// farthest corner's.
    pub vignetting: f32,
    /// The lens's f-number, 0 for a pinhole (everything sharp): with `focus` and `pixel_um`
    /// it sets a rendered image's depth of field.
    pub f_number: f32,
    /// Distance the lens is focused at, along the camera's axis, m.
    pub focus: f32,
    /// The imager's pixel pitch, µm: the lens's focal length is the focal length in pixels
    /// times this.
    pub pixel_um: f32,
}

impl Default for ColourCamera {
    fn default() -> ColourCamera {
        ColourCamera {
            capture: ColourCapture::TwoDThreeD,
            monochrome: false,
            exposure: 0.7,
            ambient: 0.15,
            ambient_kelvin: 5000.0,
            gain: 1.0,
            white_balance: [1.0, 1.0],
            noise: 0.01,
            offset: [0.0; 3],
            flash: true,
            vignetting: 0.0,
            f_number: 0.0,
            focus: 1.0,
            pixel_um: 3.45,
        }
    }
}

impl ColourCamera {
    /// Checks the ranges.
    ///
    /// # Errors
    ///
    /// [`Error::Invalid`] naming the first key out of its range.
    pub fn validate(&self) -> Result<(), Error> {
        let [red, blue] = self.white_balance;
        let checks = [
            ("colour.exposure", self.exposure, 0.0..=100.0, "0 to 100"),
            ("colour.ambient", self.ambient, 0.0..=100.0, "0 to 100"),
            (
                "colour.ambient_kelvin",
                self.ambient_kelvin,
                1667.0..=25000.0,
                "1667 to 25000 kelvin",
            ),
            ("colour.gain", self.gain, 1.0..=16.0, "1 to 16"),
            (
                "colour.white_balance",
                red,
                0.25..=8.0,
                "two gains of 0.25 to 8",
            ),
            (
                "colour.white_balance",
                blue,
                0.25..=8.0,
                "two gains of 0.25 to 8",
            ),
            ("colour.noise", self.noise, 0.0..=1.0, "0 to 1"),
            ("colour.vignetting", self.vignetting, 0.0..=0.9, "0 to 0.9"),
            (
                "colour.f_number",
                self.f_number,
                0.0..=64.0,
                "0 (a pinhole) to 64",
            ),
            ("colour.focus", self.focus, 0.01..=1000.0, "0.01 to 1000 m"),
            (
                "colour.pixel_um",
                self.pixel_um,
                0.1..=100.0,
                "0.1 to 100 µm",
            ),
            (
                "colour.offset",
                self.offset[0],
                -0.5..=0.5,
                "-0.5 to 0.5 m per axis",
            ),
            (
                "colour.offset",
                self.offset[1],
                -0.5..=0.5,
                "-0.5 to 0.5 m per axis",
            ),
            (
                "colour.offset",
                self.offset[2],
                -0.5..=0.5,
                "-0.5 to 0.5 m per axis",
            ),
        ];
        super::within(checks)
    }

    /// The ambient light's linear sRGB colour at luminance 1.
    pub fn ambient_colour(&self) -> Vec3 {
        blackbody(self.ambient_kelvin)
    }

    /// The radius of the lens's aperture, m, on a camera of `intrinsics`: half the focal length
    /// (`fx` × `pixel_um`) over the f-number; 0 for a pinhole.
    pub fn aperture_radius(&self, intrinsics: &Intrinsics) -> f32 {
        if self.f_number == 0.0 {
            return 0.0;
        }
        let focal = intrinsics.fx as f32 * self.pixel_um * 1e-6;
        focal / self.f_number / 2.0
    }
}

/// The linear sRGB colour of a black body at `kelvin` (1667 to 25000 K), luminance 1: the
/// Planckian locus's chromaticity by Kim et al.'s cubic fits (US patent 7024034), to XYZ, to
/// linear sRGB (negative channels, below about 1900 K, clipped).
pub fn blackbody(kelvin: f32) -> Vec3 {
    let t = f64::from(kelvin.clamp(1667.0, 25000.0));
    let (t2, t3) = (t * t, t * t * t);
    let x = if t <= 4000.0 {
        -0.266_123_9e9 / t3 - 0.234_358_9e6 / t2 + 0.877_695_6e3 / t + 0.179_910
    } else {
        -3.025_846_9e9 / t3 + 2.107_037_9e6 / t2 + 0.222_634_7e3 / t + 0.240_390
    };
    let (x2, x3) = (x * x, x * x * x);
    let y = if t <= 2222.0 {
        -1.106_381_4 * x3 - 1.348_110_20 * x2 + 2.185_558_32 * x - 0.202_196_83
    } else if t <= 4000.0 {
        -0.954_947_6 * x3 - 1.374_185_93 * x2 + 2.091_370_15 * x - 0.167_488_67
    } else {
        3.081_758_0 * x3 - 5.873_386_70 * x2 + 3.751_129_97 * x - 0.370_014_83
    };
    let (big_x, big_z) = (x / y, (1.0 - x - y) / y);
    let r = 3.240_454_2 * big_x - 1.537_138_5 - 0.498_531_4 * big_z;
    let g = -0.969_266_0 * big_x + 1.876_010_8 + 0.041_556_0 * big_z;
    let b = 0.055_643_4 * big_x - 0.204_025_9 + 1.057_225_2 * big_z;
    Vec3::new(r as f32, g as f32, b as f32).max(Vec3::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_out_of_range_are_refused_by_key() {
        assert!(ColourCamera::default().validate().is_ok());
        for (camera, key) in [
            (
                ColourCamera {
                    gain: 0.5,
                    ..ColourCamera::default()
                },
                "colour.gain",
            ),
            (
                ColourCamera {
                    white_balance: [1.0, 9.0],
                    ..ColourCamera::default()
                },
                "colour.white_balance",
            ),
            (
                ColourCamera {
                    ambient_kelvin: f32::NAN,
                    ..ColourCamera::default()
                },
                "colour.ambient_kelvin",
            ),
            (
                ColourCamera {
                    exposure: -1.0,
                    ..ColourCamera::default()
                },
                "colour.exposure",
            ),
        ] {
            let message = camera.validate().unwrap_err().to_string();
            assert!(message.contains(key), "{message}");
        }
    }

    #[test]
    fn a_black_body_is_warm_below_daylight_and_white_at_d65() {
        let d65 = blackbody(6504.0);
        // the Planckian locus passes near D65's white point, not through it
        assert!(
            (d65 / d65.y - Vec3::ONE).abs().max_element() < 0.06,
            "{d65}"
        );
        let warm = blackbody(3000.0);
        assert!(warm.x > warm.y && warm.y > warm.z, "{warm}");
        let cool = blackbody(12000.0);
        assert!(cool.z > cool.y && cool.y > cool.x, "{cool}");
        for k in [1667.0, 2500.0, 4000.0, 6500.0, 25000.0] {
            let c = blackbody(k);
            let luminance = c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
            assert!((luminance - 1.0).abs() < 0.05 || k < 1900.0, "{k} K: {c}");
        }
    }
}
