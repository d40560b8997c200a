//! `motorfactory.Station`: the inspection station, one motor clamped and viewed one view at a
//! time, the surface covered so far and the points measured; the core of
//! `motorfactory.gym.ViewPlanningEnv`.

use std::f32::consts::FRAC_PI_2;

use glam::{Affine3A, Vec3};
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use scene::coverage::Rule;
use scene::rig::on_cap;
use scene::{Clamping, Dataset, Shard};

use crate::generator::config_table;
use crate::{cloud_dict, scene_error, table_dict, vectors, work};

/// One motor of a dataset configuration clamped at the inspection station.
#[pyclass(module = "motorfactory")]
pub(crate) struct Station {
    station: scene::Station,
    /// What it was made from: its configuration (every key), the motor's sample index, the
    /// clamping, the surface's density and the coverage rule.
    made: (toml::Table, u64, Clamping, f32, Rule),
    /// The views taken since it was made or restarted: azimuth, elevation, distance and roll.
    taken: Vec<[f32; 4]>,
}

impl Station {
    /// The camera pose at `distance` (m) from the motor's centre, `azimuth` about world z from
    /// world x, `elevation` above the horizontal and `roll` about the view, radians.
    fn pose(&self, azimuth: f32, elevation: f32, distance: f32, roll: f32) -> PyResult<Affine3A> {
        let s = self.station.sensor();
        if !(s.min_range..=s.max_range).contains(&distance) {
            return Err(PyValueError::new_err(format!(
                "distance = {distance} m is not allowed: the sensor's working range is {} to {} m",
                s.min_range, s.max_range
            )));
        }
        if !(0.0..=FRAC_PI_2).contains(&elevation) || !azimuth.is_finite() || !roll.is_finite() {
            return Err(PyValueError::new_err(format!(
                "elevation = {elevation} is not allowed: 0 to pi/2 (azimuth and roll finite)"
            )));
        }
        Ok(on_cap(
            self.station.cell.motor_centre,
            FRAC_PI_2 - elevation,
            azimuth,
            distance,
            roll,
        ))
    }
}

#[pymethods]
impl Station {
    /// Sample `index`'s motor of the configuration (`config` and `overrides` as for
    /// `Generator`) clamped as `clamping` (`gear-container-up` or `pole-pot-up`), its surface
    /// sampled at `density` per m² (10³ to 10⁷); a view observes a sample when a measured point
    /// lies within `radius` (m, 0.1 to 50 mm) and the sample faces the camera and the projector
    /// within `max_angle` degrees (1 to 90).
    #[new]
    #[pyo3(signature = (config = None, index = 0, clamping = "gear-container-up", overrides = None, density = 2e5, radius = 0.002, max_angle = 75.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        config: Option<&Bound<'_, PyAny>>,
        index: u64,
        clamping: &str,
        overrides: Option<&Bound<'_, PyDict>>,
        density: f32,
        radius: f32,
        max_angle: f32,
    ) -> PyResult<Station> {
        let clamping = Clamping::ALL
            .into_iter()
            .find(|c| c.name() == clamping)
            .ok_or_else(|| {
                PyValueError::new_err(format!(
                    "clamping = \"{}\" is not allowed: \"gear-container-up\" or \"pole-pot-up\"",
                    motorgen::shown(clamping)
                ))
            })?;
        let table = config_table(config, overrides)?;
        let dataset =
            Dataset::new(table, None, None, Shard::ALL, "".as_ref()).map_err(scene_error)?;
        let rule = Rule {
            radius,
            max_angle_deg: max_angle,
        };
        let station = work(py, || {
            let recipe = dataset.recipe(index)?;
            scene::Station::new(&recipe, index, clamping, density, rule)
        })
        .map_err(scene_error)?;
        Ok(Station {
            station,
            made: (dataset.table().clone(), index, clamping, density, rule),
            taken: Vec::new(),
        })
    }

    /// The motor's centre, world, m: the point views look at.
    #[getter]
    fn centre(&self) -> (f32, f32, f32) {
        self.station.cell.motor_centre.into()
    }

    /// The sensor's working range (nearest and farthest depth), m.
    #[getter]
    fn working_range(&self) -> (f32, f32) {
        let s = self.station.sensor();
        (s.min_range, s.max_range)
    }

    /// How many views were taken.
    #[getter]
    fn views(&self) -> u32 {
        self.station.taken()
    }

    /// Forgets every view taken: the station as new (the same views give the same scans), its
    /// motor, cell and surface samples kept rather than made again.
    fn restart(&mut self) {
        self.station.restart();
        self.taken.clear();
    }

    /// Pickles as what it was made from and the views taken since: a copy in another process
    /// takes them again and is the same station.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Bound<'py, PyAny>,
            u64,
            &'static str,
            Option<()>,
            f32,
            f32,
            f32,
        ),
        Vec<[f32; 4]>,
    )> {
        let this = slf.borrow();
        let (table, index, clamping, density, rule) = &this.made;
        let made = (
            table_dict(py, table)?,
            *index,
            clamping.name(),
            None,
            *density,
            rule.radius,
            rule.max_angle_deg,
        );
        Ok((slf.get_type().into_any(), made, this.taken.clone()))
    }

    /// Takes the views of a pickled station again (see `__reduce__`).
    fn __setstate__(&mut self, py: Python<'_>, taken: Vec<[f32; 4]>) -> PyResult<()> {
        let poses = taken
            .iter()
            .map(|&[azimuth, elevation, distance, roll]| {
                self.pose(azimuth, elevation, distance, roll)
            })
            .collect::<PyResult<Vec<_>>>()?;
        let station = &mut self.station;
        work(py, || {
            for pose in &poses {
                station.capture(pose);
            }
        });
        self.taken.extend(taken);
        Ok(())
    }

    /// The camera-to-world pose (4×4, OpenCV axes) of the view at `azimuth`, `elevation`,
    /// `distance`, `roll` (see `capture`).
    #[pyo3(signature = (azimuth, elevation, distance, roll = 0.0))]
    fn camera_pose(
        &self,
        azimuth: f32,
        elevation: f32,
        distance: f32,
        roll: f32,
    ) -> PyResult<[[f32; 4]; 4]> {
        Ok(scene::sample::matrix(
            &self.pose(azimuth, elevation, distance, roll)?,
        ))
    }

    /// Takes a view from `distance` (m, within the working range) of the motor's centre,
    /// `azimuth` about world z from world x, `elevation` above the horizontal (0 to pi/2) and
    /// `roll` about the view, radians; returns the share of the surface it observed first
    /// (`gain`) and the points it measured near the motor, world, with the arrays of a sample's
    /// view (`xyz`, `normal`, `intensity`, `snr`, `rgb`, `label`, `instance`).
    #[pyo3(signature = (azimuth, elevation, distance, roll = 0.0))]
    fn capture<'py>(
        &mut self,
        py: Python<'py>,
        azimuth: f32,
        elevation: f32,
        distance: f32,
        roll: f32,
    ) -> PyResult<Bound<'py, PyDict>> {
        let pose = self.pose(azimuth, elevation, distance, roll)?;
        self.taken.push([azimuth, elevation, distance, roll]);
        let station = &mut self.station;
        let (gain, cloud) = work(py, || {
            let got = station.capture(&pose);
            (got.gain, station.clouds.last().cloned().unwrap_or_default())
        });
        let d = cloud_dict(py, cloud)?;
        d.set_item("gain", gain)?;
        Ok(d)
    }

    /// The share of the surface not yet observed that an ideal sensor would observe from the
    /// view (arguments as `capture`): in its image and working range, facing the camera and the
    /// projector, with free lines of sight to both.
    #[pyo3(signature = (azimuth, elevation, distance, roll = 0.0))]
    fn predict(
        &self,
        py: Python<'_>,
        azimuth: f32,
        elevation: f32,
        distance: f32,
        roll: f32,
    ) -> PyResult<f32> {
        let pose = self.pose(azimuth, elevation, distance, roll)?;
        Ok(work(py, || self.station.predict(&pose)))
    }

    /// Which surface samples were observed so far (bool, in the order of `surface()`'s).
    #[getter]
    fn seen<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_slice(py, &self.station.seen)
    }

    /// The share of the surface observed so far, and per part (by name).
    fn coverage(&self) -> (f32, Vec<(&'static str, f32)>) {
        let (total, parts) = self.station.coverage();
        (
            total,
            parts.into_iter().map(|(k, c)| (k.name(), c)).collect(),
        )
    }

    /// The surface samples: `xyz` and `normal` (N×3 float32, world), `instance` (uint32),
    /// `part` (names, by sample) and `seen` (bool, observed so far); each stands for `area` m².
    fn surface<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.station.surface;
        let d = PyDict::new(py);
        d.set_item("xyz", vectors(py, s.points.clone())?)?;
        d.set_item("normal", vectors(py, s.normals.clone())?)?;
        d.set_item("instance", PyArray1::from_slice(py, &s.instances))?;
        d.set_item("part", s.parts.iter().map(|k| k.name()).collect::<Vec<_>>())?;
        d.set_item("seen", self.seen(py))?;
        d.set_item("area", s.area)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let v: Vec3 = self.station.cell.motor_centre;
        format!(
            "Station({} surface samples, {} views, coverage {:.3}, centre {v})",
            self.station.surface.len(),
            self.station.taken(),
            self.station.coverage().0
        )
    }
}
