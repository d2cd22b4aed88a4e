//! `strata.Surface`: a height map on a regular grid, from a numpy array, generated
//! (self-affine, physics.md §5) or read from `.npy`, `.x3p` or text files.

use std::path::PathBuf;

use pyo3::prelude::*;
use strata_runtime::surface::{
    Detrend, GenerateParams, HeightUnit, ReadOptions, Repair, Spacing, Surface,
};

use crate::conv;
use crate::errors::{Kind, err, require_file, to_py};

/// A height map z (m) on an n0 × n1 grid (first axis x), pixels dx × dy (m), periodic
/// or not. Heights are positive towards the rigid flat.
///
/// Surface(heights, size=None, pixel_size=None, periodic=False, repair="none")
///
/// heights: 2-D float array (m); size: the length of the first axis (m, square
/// pixels) or (Lx, Ly); pixel_size: (dx, dy) (m). Exactly one of size and pixel_size.
/// Non-finite heights and spikes are refused (strata.SurfaceError naming the row and
/// column) unless repair="median" (or "harmonic") fills them, clusters included, by
/// harmonic interpolation from the valid points around them.
#[pyclass(name = "Surface", module = "strata", frozen)]
pub struct PySurface {
    pub surface: Surface,
}

fn spacing(
    size: Option<&Bound<'_, PyAny>>,
    pixel: Option<(f64, f64)>,
) -> PyResult<Option<Spacing>> {
    match (size, pixel) {
        (Some(_), Some(_)) => Err(to_py(
            Kind::Surface,
            anyhow::anyhow!("give either size or pixel_size, not both"),
        )),
        (None, Some((dx, dy))) => Ok(Some(Spacing::Pixel(dx, dy))),
        (Some(s), None) => {
            if s.is_instance_of::<pyo3::types::PyBool>() {
                // True would be taken as 1 m
                return Err(to_py(
                    Kind::Surface,
                    anyhow::anyhow!("size: expected a length L (m) or (Lx, Ly), got a bool"),
                ));
            }
            if let Ok(l) = s.extract::<f64>() {
                Ok(Some(Spacing::Size(l)))
            } else if let Ok((lx, ly)) = s.extract::<(f64, f64)>() {
                Ok(Some(Spacing::Extent(lx, ly)))
            } else {
                Err(to_py(
                    Kind::Surface,
                    anyhow::anyhow!("size: expected a length L (m) or (Lx, Ly)"),
                ))
            }
        }
        (None, None) => Ok(None),
    }
}

fn repair_of(s: &str) -> PyResult<Repair> {
    match s {
        "none" | "refuse" => Ok(Repair::Refuse),
        "median" | "harmonic" => Ok(Repair::Median),
        other => Err(to_py(
            Kind::Surface,
            anyhow::anyhow!("repair: `{other}` is not one of \"none\", \"median\", \"harmonic\""),
        )),
    }
}

#[pymethods]
impl PySurface {
    #[new]
    #[pyo3(signature = (heights, size=None, pixel_size=None, periodic=false, repair="none"))]
    fn new(
        heights: &Bound<'_, PyAny>,
        size: Option<&Bound<'_, PyAny>>,
        pixel_size: Option<(f64, f64)>,
        periodic: bool,
        repair: &str,
    ) -> PyResult<Self> {
        let (z, n0, n1) = conv::heights(heights)?;
        let sp = spacing(size, pixel_size)?.ok_or_else(|| {
            to_py(
                Kind::Surface,
                anyhow::anyhow!("the lateral size is missing: give size=L, size=(Lx, Ly) or pixel_size=(dx, dy) (m)"),
            )
        })?;
        let memory = crate::errors::memory_limit(Kind::Surface)?;
        let surface = Surface::measured_with(z, n0, n1, sp, periodic, repair_of(repair)?, &memory)
            .map_err(err(Kind::Surface))?;
        Ok(PySurface { surface })
    }

    /// A self-affine random surface (physics.md §5; the paper's §5): side `size` (m),
    /// `grid` points per side, fractal dimension D_f in [2, 3), wavenumbers k_min…k_max
    /// in units of 2π/L, RMS height `rms` (m), `seed` of the generator (default 1). Periodic.
    /// A bool or a negative `grid` or `seed` is refused naming it.
    #[staticmethod]
    #[pyo3(signature = (size, grid, fractal_dimension, k_min, k_max, rms, seed=None))]
    #[allow(clippy::too_many_arguments)]
    fn generate(
        py: Python<'_>,
        size: f64,
        grid: &Bound<'_, PyAny>,
        fractal_dimension: f64,
        k_min: f64,
        k_max: f64,
        rms: f64,
        seed: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let grid =
            usize::try_from(crate::conv::count(grid, "grid", Kind::Surface)?).unwrap_or(usize::MAX);
        let seed = match seed {
            Some(s) => crate::conv::count(s, "seed", Kind::Surface)?,
            None => 1,
        };
        let p = GenerateParams {
            size,
            grid,
            fractal_dimension,
            k_min,
            k_max,
            rms,
            seed,
        };
        let memory = crate::errors::memory_limit(Kind::Surface)?;
        strata_engine::engine::check_generate_memory(&p, &memory).map_err(err(Kind::Surface))?;
        let surface = py
            .detach(|| Surface::generate_within(&p, &memory))
            .map_err(err(Kind::Surface))?;
        Ok(PySurface { surface })
    }

    /// Reads a height map by extension: `.x3p` (sizes and units from the file: give
    /// neither size nor pixel_size), SurfaceTopography's `.nc` (sizes, unit and periodic
    /// flag from the file when it has them), `.npy` (2-D float64) or a text matrix (both need
    /// size or pixel_size, heights in `height_unit`: "m" (default), "mm", "um", "nm").
    /// detrend: "none", "plane" or "curvature"; repair: "none" or "median". A
    /// contact.engineering container (`.zip` with meta.yml): `topography` picks one by
    /// its number (from 0, default 0) or its name, read with the metadata's sizes, unit
    /// and periodic flag; `topography` on another file is a ValueError.
    #[staticmethod]
    #[pyo3(signature = (path, size=None, pixel_size=None, periodic=false, height_unit=None, detrend="none", repair="none", topography=None))]
    #[allow(clippy::too_many_arguments)]
    fn read(
        path: PathBuf,
        size: Option<&Bound<'_, PyAny>>,
        pixel_size: Option<(f64, f64)>,
        periodic: bool,
        height_unit: Option<&str>,
        detrend: &str,
        repair: &str,
        topography: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        require_file("Surface.read", &path)?;
        let height_unit = height_unit
            .map(|u| {
                HeightUnit::parse(u).ok_or_else(|| {
                    to_py(
                        Kind::Surface,
                        anyhow::anyhow!(
                            "height_unit: `{u}` is not one of \"m\", \"mm\", \"um\", \"nm\""
                        ),
                    )
                })
            })
            .transpose()?;
        let detrend = Detrend::parse(detrend).ok_or_else(|| {
            to_py(
                Kind::Surface,
                anyhow::anyhow!(
                    "detrend: `{detrend}` is not one of \"none\", \"plane\", \"curvature\""
                ),
            )
        })?;
        let opts = ReadOptions {
            spacing: spacing(size, pixel_size)?,
            periodic,
            repair: repair_of(repair)?,
            height_unit,
            detrend,
            memory: crate::errors::memory_limit(Kind::Surface)?,
        };
        let pick = match topography {
            None => None,
            Some(t) => Some(if let Ok(name) = t.extract::<String>() {
                strata_runtime::surface::container::Pick::Name(name)
            } else if let Ok(i) = t.extract::<usize>() {
                strata_runtime::surface::container::Pick::Index(i)
            } else {
                return Err(pyo3::exceptions::PyValueError::new_err(
                    "topography: a number (from 0) or a name",
                ));
            }),
        };
        let is_zip = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("zip"));
        let surface = match (pick, is_zip) {
            (Some(pick), true) => {
                strata_runtime::surface::container::read_container(&path, &pick, &opts)
            }
            (Some(_), false) => {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "topography: {} is not a container (.zip); give topography only for one",
                    path.display()
                )));
            }
            (None, _) => Surface::read(&path, &opts),
        }
        .map_err(err(Kind::Surface))?;
        Ok(PySurface { surface })
    }

    /// Writes the heights (m) as a 2-D float64 `.npy` file, atomically.
    fn write_npy(&self, path: PathBuf) -> PyResult<()> {
        self.surface.write_npy(&path).map_err(err(Kind::Surface))
    }

    /// The heights (m) as a new n0 × n1 float64 array (first axis x).
    #[getter]
    fn heights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let (n0, n1) = self.surface.shape();
        conv::array(py, self.surface.heights().to_vec(), &[n0, n1])
    }

    /// (n0, n1) grid points.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        self.surface.shape()
    }

    /// (dx, dy) pixel sizes (m).
    #[getter]
    fn pixel_size(&self) -> (f64, f64) {
        self.surface.pixel_size()
    }

    /// (Lx, Ly) sides of the sample (m).
    #[getter]
    fn extent(&self) -> (f64, f64) {
        self.surface.extent()
    }

    /// Whether the sample is one cell of a periodic pattern.
    #[getter]
    fn periodic(&self) -> bool {
        self.surface.is_periodic()
    }

    /// Mean height (m).
    #[getter]
    fn mean(&self) -> f64 {
        self.surface.mean()
    }

    /// RMS height about the mean (m).
    #[getter]
    fn rms(&self) -> f64 {
        self.surface.rms()
    }

    /// Statistics, repairs and the reader's log as a dict (what `strata surface info
    /// --json` prints), SI units.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::conv::json_to_py(
            py,
            &serde_json::to_value(strata_engine::solution::SurfaceReport::of(&self.surface))
                .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?,
        )
    }

    /// Warnings of the reader and of the statistics' plausibility checks.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        strata_engine::engine::surface_warnings(&self.surface)
    }

    fn __repr__(&self) -> String {
        let (n0, n1) = self.surface.shape();
        let (lx, ly) = self.surface.extent();
        format!(
            "Surface({n0}×{n1}, {lx:e} × {ly:e} m, rms {:e} m, {})",
            self.surface.rms(),
            if self.surface.is_periodic() {
                "periodic"
            } else {
                "non-periodic"
            }
        )
    }
}
