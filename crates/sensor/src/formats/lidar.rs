//! A LiDAR scan's files: Blensor's `.numpy` table and its ideal and noisy PCD pair, as Blensor
//! writes them, and an NPZ with rings and firing times.

use std::io::{Cursor, Result, Write};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::npy::{array, f32s, npz, rgbs, vec3s};
use super::{CloudFormat, write_rows};
use crate::lidar::{LidarFrame, LidarReturn, LidarScan};

/// A LiDAR pass's file format: Blensor's, ours with rings and times, LAS, or a camera's cloud
/// format of the measured points.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LidarFormat {
    /// Blensor's 16-column `.numpy` table ([`write_blensor_numpy`]).
    BlensorNumpy,
    /// Blensor's ideal and noisy ASCII PCD pair ([`write_blensor_pcd`]).
    BlensorPcd,
    /// NPZ with rings, times and echoes ([`write_lidar_npz`]).
    Npz,
    /// LAS 1.4, point format 7 ([`write_las`]).
    Las,
    /// Binary PLY of the measured points.
    Ply,
    /// Binary PCD of the measured points.
    Pcd,
    /// ASCII PCD of the measured points.
    PcdAscii,
    /// NPY `x y z r g b label` of the measured points.
    Npy,
}

impl LidarFormat {
    /// Every format.
    pub const ALL: [LidarFormat; 8] = [
        LidarFormat::BlensorNumpy,
        LidarFormat::BlensorPcd,
        LidarFormat::Npz,
        LidarFormat::Las,
        LidarFormat::Ply,
        LidarFormat::Pcd,
        LidarFormat::PcdAscii,
        LidarFormat::Npy,
    ];

    /// The name used in configs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            LidarFormat::BlensorNumpy => "blensor-numpy",
            LidarFormat::BlensorPcd => "blensor-pcd",
            LidarFormat::Npz => "npz",
            LidarFormat::Las => "las",
            LidarFormat::Ply => CloudFormat::Ply.name(),
            LidarFormat::Pcd => CloudFormat::Pcd.name(),
            LidarFormat::PcdAscii => CloudFormat::PcdAscii.name(),
            LidarFormat::Npy => CloudFormat::Npy.name(),
        }
    }

    /// The camera's cloud format it writes, if it is one.
    pub fn cloud(self) -> Option<CloudFormat> {
        match self {
            LidarFormat::Ply => Some(CloudFormat::Ply),
            LidarFormat::Pcd => Some(CloudFormat::Pcd),
            LidarFormat::PcdAscii => Some(CloudFormat::PcdAscii),
            LidarFormat::Npy => Some(CloudFormat::Npy),
            _ => None,
        }
    }

    /// The names of its files for a pass called `stem` (Blensor's PCD pair: two).
    pub fn file_names(self, stem: &str) -> Vec<String> {
        match self {
            LidarFormat::BlensorNumpy => vec![format!("{stem}.numpy")],
            LidarFormat::BlensorPcd => vec![format!("{stem}.pcd"), format!("{stem}_noisy.pcd")],
            LidarFormat::Npz => vec![format!("{stem}.npz")],
            LidarFormat::Las => vec![format!("{stem}.las")],
            cloud => vec![cloud.cloud().expect("a cloud format").file_name(stem)],
        }
    }

    /// Writes file `k` of [`LidarFormat::file_names`] of `scan`, points in `frame`, lengths
    /// multiplied by `scale`.
    ///
    /// # Errors
    ///
    /// Any error of writing to `w`.
    pub fn write(
        self,
        k: usize,
        w: &mut dyn Write,
        scan: &LidarScan,
        frame: LidarFrame,
        scale: f32,
    ) -> Result<()> {
        match self {
            LidarFormat::BlensorNumpy => write_blensor_numpy(w, scan, frame, scale),
            LidarFormat::BlensorPcd => write_blensor_pcd(w, scan, frame, scale, k == 1),
            LidarFormat::Npz => write_lidar_npz(w, scan, frame, scale),
            LidarFormat::Las => write_las(w, scan, frame, scale),
            cloud => cloud
                .cloud()
                .expect("a cloud format")
                .write(w, &scan.cloud(frame, scale)),
        }
    }
}

/// Appends Python's `%.{digits}e` of `v` to `out`: Rust's `{:e}`, its exponent signed and of
/// at least two digits.
fn python_e(out: &mut Vec<u8>, v: f64, digits: usize) -> Result<()> {
    let start = out.len();
    write!(out, "{v:.digits$e}")?;
    let e = start
        + out[start..]
            .iter()
            .rposition(|&c| c == b'e')
            .expect("{:e} has an exponent");
    let exponent: i32 = std::str::from_utf8(&out[e + 1..])
        .ok()
        .and_then(|x| x.parse().ok())
        .expect("an integer exponent");
    out.truncate(e);
    let sign = if exponent < 0 { '-' } else { '+' };
    write!(out, "e{sign}{:02}", exponent.abs())
}

/// Writes Blensor's `.numpy` table (what `numpy.savetxt` writes, `numpy.loadtxt` reads): a row
/// of 16 columns a return, `timestamp yaw pitch distance distance_noise x y z x_noise y_noise
/// z_noise object_id r g b idx`: seconds, radians, metres, the instance as object id, the
/// colour 0–255 and the ray's index; points in `frame`, lengths multiplied by `scale`.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_blensor_numpy(
    w: &mut dyn Write,
    scan: &LidarScan,
    frame: LidarFrame,
    scale: f32,
) -> Result<()> {
    write_rows(w, &scan.returns, |r, row| {
        let to = scan.to_frame(r, frame, scale);
        let (p, q) = (to.transform_point3(r.point), to.transform_point3(r.noisy));
        let pitch = (r.point.z / r.distance).asin();
        let columns = [
            f64::from(r.time),
            f64::from(r.yaw.to_radians()),
            f64::from(pitch),
            f64::from(r.distance),
            f64::from(r.measured),
            f64::from(p.x),
            f64::from(p.y),
            f64::from(p.z),
            f64::from(q.x),
            f64::from(q.y),
            f64::from(q.z),
            f64::from(r.instance),
            f64::from(r.rgb[0]),
            f64::from(r.rgb[1]),
            f64::from(r.rgb[2]),
            f64::from(r.ray),
        ];
        for (k, &v) in columns.iter().enumerate() {
            if k > 0 {
                row.push(b' ');
            }
            python_e(row, v, 18)?;
        }
        row.push(b'\n');
        Ok(())
    })
}

/// Writes one of Blensor's PCD pair (ASCII v0.7, fields `x y z rgb label`, Blensor's
/// `%f %f %f %.15e %d` rows): the surface points, or with `noisy` the measured ones; `label` is
/// the class. Points in `frame`, lengths multiplied by `scale`.
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_blensor_pcd(
    w: &mut dyn Write,
    scan: &LidarScan,
    frame: LidarFrame,
    scale: f32,
    noisy: bool,
) -> Result<()> {
    let n = scan.returns.len();
    write!(
        w,
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb label\n\
         SIZE 4 4 4 4 4\nTYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH {n}\nHEIGHT 1\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA ascii\n"
    )?;
    write_rows(w, &scan.returns, |r, row| {
        let to = scan.to_frame(r, frame, scale);
        let p = to.transform_point3(if noisy { r.noisy } else { r.point });
        let [red, green, blue] = r.rgb.map(u32::from);
        let rgb = f32::from_bits((red << 16) | (green << 8) | blue);
        write!(
            row,
            "{:.6} {:.6} {:.6} ",
            f64::from(p.x),
            f64::from(p.y),
            f64::from(p.z)
        )?;
        python_e(row, f64::from(rgb), 15)?;
        writeln!(row, " {}", r.class)
    })
}

/// Writes an NPZ of the returns: `xyz` and `xyz_noisy` (N×3 float32, in `frame`, lengths
/// multiplied by `scale`),
/// `distance` and `measured` (N float32, metres), `ring` (N uint16, the laser), `echo` and
/// `echoes` (N uint8: which of its beam's echoes, from 1, of how many), `time` (N float32,
/// seconds from the scan's start), `yaw` (N float32, degrees), `label` (N uint16, the class),
/// `instance` (N uint32), `rgb` (N×3 uint8), `reflectivity` and `intensity` (N float32).
///
/// # Errors
///
/// Any error of writing to `w`.
pub fn write_lidar_npz(
    w: &mut dyn Write,
    scan: &LidarScan,
    frame: LidarFrame,
    scale: f32,
) -> Result<()> {
    let r = &scan.returns;
    let n = r.len();
    let points = |f: fn(&LidarReturn) -> Vec3| -> Vec<Vec3> {
        r.iter()
            .map(|x| scan.to_frame(x, frame, scale).transform_point3(f(x)))
            .collect()
    };
    let floats = |f: fn(&LidarReturn) -> f32| -> Vec<f32> { r.iter().map(f).collect() };
    let (xyz, noisy) = (points(|x| x.point), points(|x| x.noisy));
    let rgb: Vec<[u8; 3]> = r.iter().map(|x| x.rgb).collect();
    npz(
        w,
        n * 12,
        &[
            ("xyz", &|w| vec3s(w, &xyz)),
            ("xyz_noisy", &|w| vec3s(w, &noisy)),
            ("distance", &|w| f32s(w, &floats(|x| x.distance))),
            ("measured", &|w| f32s(w, &floats(|x| x.measured))),
            ("ring", &|w| {
                array(w, "<u2", &[n], r.iter().map(|x| x.laser), u16::to_le_bytes)
            }),
            ("time", &|w| f32s(w, &floats(|x| x.time))),
            ("yaw", &|w| f32s(w, &floats(|x| x.yaw))),
            ("label", &|w| {
                array(w, "<u2", &[n], r.iter().map(|x| x.class), u16::to_le_bytes)
            }),
            ("instance", &|w| {
                array(
                    w,
                    "<u4",
                    &[n],
                    r.iter().map(|x| x.instance),
                    u32::to_le_bytes,
                )
            }),
            ("rgb", &|w| rgbs(w, &rgb)),
            ("echo", &|w| {
                array(w, "|u1", &[n], r.iter().map(|x| x.echo), |v| [v])
            }),
            ("echoes", &|w| {
                array(w, "|u1", &[n], r.iter().map(|x| x.echoes), |v| [v])
            }),
            ("reflectivity", &|w| f32s(w, &floats(|x| x.reflectivity))),
            ("intensity", &|w| f32s(w, &floats(|x| x.intensity))),
        ],
    )
}

/// Writes LAS 1.4, point format 7 (`las` crate), the measured points in `frame` scaled by
/// `scale` to 0.1 mm (in the file's units): `intensity` × 65535, the echo's return number and
/// its beam's number of returns,
/// `gps_time` the seconds from the pass's start, `classification` the class (0–255),
/// `point_source_id` the instance (0–65535), `user_data` the ring, `scan_angle` the laser's
/// elevation in degrees, the colour as 16 bits a channel. No creation date, so the bytes are
/// reproducible.
///
/// # Errors
///
/// Any error of writing to `w`, or of the `las` crate (in words).
pub fn write_las(w: &mut dyn Write, scan: &LidarScan, frame: LidarFrame, scale: f32) -> Result<()> {
    use las::point::Classification;
    let las_error = |e: las::Error| std::io::Error::other(e.to_string());
    let mut builder = las::Builder::from((1, 4));
    builder.date = None;
    builder.generating_software = "motorfactory".into();
    builder.point_format = las::point::Format::new(7).map_err(las_error)?;
    let unit = 1e-4 * f64::from(scale);
    let axis = las::Transform {
        scale: unit,
        offset: 0.0,
    };
    builder.transforms = las::Vector {
        x: axis,
        y: axis,
        z: axis,
    };
    let header = builder.into_header().map_err(las_error)?;
    let mut writer = las::Writer::new(Cursor::new(Vec::new()), header).map_err(las_error)?;
    for r in &scan.returns {
        let p = scan.to_frame(r, frame, scale).transform_point3(r.noisy);
        let class = u8::try_from(r.class).unwrap_or(u8::MAX);
        let colour = |c: u8| u16::from(c) * 257;
        let point = las::Point {
            x: f64::from(p.x),
            y: f64::from(p.y),
            z: f64::from(p.z),
            intensity: (r.intensity.clamp(0.0, 1.0) * 65535.0).round() as u16,
            return_number: r.echo,
            number_of_returns: r.echoes,
            // 12 is the overlap class of LAS 1.3, which the crate refuses; LAS 1.4 has a flag
            classification: Classification::new(class).unwrap_or(Classification::Reserved(class)),
            scan_angle: (r.noisy.z / r.measured.abs().max(f32::MIN_POSITIVE))
                .asin()
                .to_degrees(),
            user_data: u8::try_from(r.laser).unwrap_or(u8::MAX),
            point_source_id: u16::try_from(r.instance).unwrap_or(u16::MAX),
            gps_time: Some(f64::from(r.time)),
            color: Some(las::Color {
                red: colour(r.rgb[0]),
                green: colour(r.rgb[1]),
                blue: colour(r.rgb[2]),
            }),
            ..Default::default()
        };
        writer.write_point(point).map_err(las_error)?;
    }
    let bytes = writer.into_inner().map_err(las_error)?.into_inner();
    w.write_all(&bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_print_as_python_prints_them() {
        let e = |v: f64, digits: usize| {
            let mut out = b"x ".to_vec();
            python_e(&mut out, v, digits).unwrap();
            String::from_utf8(out).unwrap()
        };
        assert_eq!(e(0.0, 18), "x 0.000000000000000000e+00");
        assert_eq!(e(1234.5, 3), "x 1.234e+03");
        assert_eq!(e(-0.000_125, 2), "x -1.25e-04");
        assert_eq!(e(1e-120, 1), "x 1.0e-120");
    }
}
