//! A solution's maps as one NetCDF-3 file in contact.engineering's layout (its
//! per-step `results.nc`), readable by xarray, netCDF4, scipy or ncdump without any C
//! library on strata's side (pure-Rust `netcdf3` writer).
//!
//! # Layout
//! NetCDF-3 with 64-bit offsets (CDF-2, `NETCDF3_64BIT`, the format contact.engineering
//! writes), dimensions `x` and `y` with x the first axis of the input heights, as in
//! contact.engineering, SurfaceTopography and strata's surface inputs (`surface info`'s
//! Lx): `x` has the maps' first-index points (the rows of strata's `.npy` maps, which
//! keep the input's orientation) and spans that axis' side, `y` the second index.
//! `pressure[i, j]` is the value at x = i·Lx/n₀, y = j·Ly/n₁, i.e. strata's `.npy` map
//! element for element. (The BEM names its grid the other way round internally —
//! [`BemSolution::sides`] is (columns, rows) — which is why the sides are swapped here.)
//!
//! | variable | dims | type | units |
//! |---|---|---|---|
//! | `pressure` | (x, y) | double | Pa |
//! | `contacting_points` | (x, y) | byte, `dtype = "bool"` (xarray reads a bool array) | 1 where p > 0 |
//! | `gap` | (x, y) | double | m |
//! | `displacement` | (x, y) | double | m (the surface's deflection w) |
//! | `plastic_depth` | (x, y) | double | m (capped solves only: u_pl, g = w − z + u_pl + c) |
//! | `x`, `y` | (x), (y) | double | m (grid positions, coordinates for xarray) |
//!
//! Global attributes: contact.engineering's `mean_pressure` (here in Pa, not in units of
//! E*), `total_contact_area` (A/A₀), `type` (`"periodic"` or `"nonperiodic"`) and
//! `hardness` (Pa, plastic solves only), then strata's summary of the step: `step`,
//! `pressure_ratio` (p̄/E*₁, contact.engineering's dimensionless pressure), `approach`,
//! `separation`, `mean_gap`, `mean_deflection`, `total_load`, `contact_points`,
//! `contact_patches`, `iterations`, `error`, `physical_sizes` (Lx, Ly); each dimensional
//! one with a `<name>_units` attribute.

use std::path::Path;

use netcdf3::{DataSet, FileWriter, Version};

use crate::BemError;
use crate::maps::BemSolution;

/// The variables holding maps, in the file's order (`contacting_points` is derived).
pub const NETCDF_MAP_VARIABLES: [&str; 4] =
    ["pressure", "contacting_points", "gap", "displacement"];

impl BemSolution {
    /// Writes the maps and the summary of this solution as a NetCDF-3 file (see the
    /// [module docs](crate::netcdf)), atomically. `step`: the load step's index;
    /// `hardness` (Pa): the plastic solve's, if any.
    pub fn write_netcdf(
        &self,
        path: &Path,
        step: usize,
        hardness: Option<f64>,
    ) -> Result<(), BemError> {
        let err = |message: String| BemError::Write {
            path: path.display().to_string(),
            message,
        };
        let set = self
            .netcdf_definition(step, hardness)
            .map_err(|e| err(e.to_string()))?;
        // x = the input's first axis = the maps' rows: element (i, j) of a variable is
        // the map's (row i, column j), the map in its own (row-major) order.
        let (n0, n1) = self.pressure.dim();
        let [lx, ly] = self.physical_sizes();
        let flat = |m: &ndarray::Array2<f64>| -> Vec<f64> { m.iter().copied().collect() };
        let contact: Vec<i8> = self.pressure.iter().map(|&p| i8::from(p > 0.0)).collect();
        let coords = |n: usize, side: f64| -> Vec<f64> {
            (0..n).map(|i| i as f64 * side / n as f64).collect()
        };
        strata_runtime::output::write_atomic_with(path, |tmp| {
            let io = |e: netcdf3::WriteError| std::io::Error::other(format!("{e:?}"));
            let mut w = FileWriter::open(tmp).map_err(io)?;
            w.set_def(&set, Version::Offset64Bit, 0).map_err(io)?;
            w.write_var_f64("x", &coords(n0, lx)).map_err(io)?;
            w.write_var_f64("y", &coords(n1, ly)).map_err(io)?;
            w.write_var_f64("pressure", &flat(&self.pressure))
                .map_err(io)?;
            w.write_var_i8("contacting_points", &contact).map_err(io)?;
            w.write_var_f64("gap", &flat(&self.gap)).map_err(io)?;
            w.write_var_f64("displacement", &flat(&self.displacement))
                .map_err(io)?;
            if let Some(u) = &self.plastic_depth {
                w.write_var_f64("plastic_depth", &flat(u)).map_err(io)?;
            }
            w.close().map_err(io)
        })
        .map_err(|e| err(e.to_string()))
    }

    /// The physical sizes (Lx, Ly) (m) in the NetCDF's (and the input's) axes: Lx along
    /// the maps' first index (rows), Ly along the second.
    pub fn physical_sizes(&self) -> [f64; 2] {
        [self.sides[1], self.sides[0]]
    }

    /// The header: dimensions, variables and attributes.
    fn netcdf_definition(
        &self,
        step: usize,
        hardness: Option<f64>,
    ) -> Result<DataSet, netcdf3::InvalidDataSet> {
        let (n0, n1) = self.pressure.dim();
        let mut d = DataSet::new();
        d.add_fixed_dim("x", n0)?;
        d.add_fixed_dim("y", n1)?;
        for (name, long) in [
            (
                "x",
                "position along x, the input's first axis (the rows of strata's .npy maps)",
            ),
            (
                "y",
                "position along y, the input's second axis (the columns of strata's .npy maps)",
            ),
        ] {
            d.add_var_f64(name, &[name])?;
            d.add_var_attr_string(name, "units", "m")?;
            d.add_var_attr_string(name, "long_name", long)?;
        }
        let xy = ["x", "y"];
        d.add_var_f64("pressure", &xy)?;
        d.add_var_attr_string("pressure", "units", "Pa")?;
        d.add_var_attr_string("pressure", "long_name", "contact pressure")?;
        d.add_var_i8("contacting_points", &xy)?;
        // xarray's encoding of a bool array: decoded back to bool on opening.
        d.add_var_attr_string("contacting_points", "dtype", "bool")?;
        d.add_var_attr_string("contacting_points", "units", "1")?;
        d.add_var_attr_string(
            "contacting_points",
            "long_name",
            "contact mask: 1 where the pressure is positive",
        )?;
        d.add_var_f64("gap", &xy)?;
        d.add_var_attr_string("gap", "units", "m")?;
        d.add_var_attr_string(
            "gap",
            "long_name",
            "gap between the flat and the deformed surface",
        )?;
        d.add_var_f64("displacement", &xy)?;
        d.add_var_attr_string("displacement", "units", "m")?;
        d.add_var_attr_string(
            "displacement",
            "long_name",
            "surface deflection into the solid (gap = displacement - heights + plastic_depth + flat position)",
        )?;
        if self.plastic_depth.is_some() {
            d.add_var_f64("plastic_depth", &xy)?;
            d.add_var_attr_string("plastic_depth", "units", "m")?;
            d.add_var_attr_string(
                "plastic_depth",
                "long_name",
                "plastic depth: the overlap flattened so far (gap = displacement - heights + plastic_depth + flat position)",
            )?;
        }
        // contact.engineering's attributes first, then strata's summary of the step.
        d.add_global_attr_f64("mean_pressure", vec![self.mean_pressure])?;
        d.add_global_attr_string("mean_pressure_units", "Pa")?;
        d.add_global_attr_f64("total_contact_area", vec![self.area_fraction])?;
        d.add_global_attr_string("total_contact_area_units", "1")?;
        d.add_global_attr_string(
            "type",
            if self.periodic {
                "periodic"
            } else {
                "nonperiodic"
            },
        )?;
        if let Some(h) = hardness {
            d.add_global_attr_f64("hardness", vec![h])?;
            d.add_global_attr_string("hardness_units", "Pa")?;
        }
        d.add_global_attr_i32("step", vec![i32::try_from(step).unwrap_or(i32::MAX)])?;
        d.add_global_attr_f64("pressure_ratio", vec![self.pressure_ratio])?;
        d.add_global_attr_string("pressure_ratio_units", "1 (mean pressure / E*1)")?;
        for (name, v, unit) in [
            ("approach", self.approach, "m"),
            ("separation", self.separation, "m"),
            ("mean_gap", self.mean_gap, "m"),
            ("mean_deflection", self.mean_deflection, "m"),
            ("total_load", self.total_load, "N"),
        ] {
            d.add_global_attr_f64(name, vec![v])?;
            d.add_global_attr_string(&format!("{name}_units"), unit)?;
        }
        let int = |n: usize| i32::try_from(n).unwrap_or(i32::MAX);
        d.add_global_attr_i32("contact_points", vec![int(self.contact_points)])?;
        d.add_global_attr_i32("contact_patches", vec![int(self.patches)])?;
        d.add_global_attr_i32("iterations", vec![int(self.iterations)])?;
        d.add_global_attr_f64("error", vec![self.error])?;
        d.add_global_attr_f64("physical_sizes", self.physical_sizes().to_vec())?;
        d.add_global_attr_string("physical_sizes_units", "m")?;
        d.add_global_attr_string(
            "source",
            concat!("strata ", env!("CARGO_PKG_VERSION"), " (boundary elements)"),
        )?;
        Ok(d)
    }
}
