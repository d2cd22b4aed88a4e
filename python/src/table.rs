//! `strata.Table` (surrogate tables of the asperity law: load, build, save) and
//! `strata.AsperityLaw` (χ, ζ, g, S lookups of one stack from a table).

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use strata_runtime::Solid;
use strata_runtime::law::AsperityLaw;
use strata_runtime::table::{Table, TableLaw};
use strata_tablegen::tablebuild::{Bars, BuildOptions};

use crate::conv;
use crate::errors::{Kind, err, require_file, to_py};
use crate::stack::{PyStack, stack_of};

/// A surrogate table of the second-order asperity law (paper §4) for one material
/// stack or a family of stacks: χ(a), ζ(a), g(a, r) and S(ρ) on log grids.
///
/// Table.load(path) reads a `.strata` file; Table.build(stack) computes one (minutes
/// for a default-resolution table; progress on stderr with progress=True).
#[pyclass(name = "Table", module = "strata", frozen)]
pub struct PyTable {
    pub table: Arc<Table>,
}

/// χ, ζ, g and S of one stack, interpolated from a table ([`Table::law_for`]).
///
/// Units: a, r in m; χ, ζ dimensionless; g in m² (the layers' term of the surface
/// displacement, paper eq. 21); S dimensionless with ρ in 1/m. Lookups outside the table's range of a are
/// refused (strata.TableError).
#[pyclass(name = "AsperityLaw", module = "strata", frozen)]
pub struct PyAsperityLaw {
    pub law: TableLaw,
}

#[pymethods]
impl PyTable {
    /// Reads a table file (`.strata`), checking its format and checksum.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        require_file("Table.load", &path)?;
        Ok(PyTable {
            table: Arc::new(
                Table::load_within(&path, &crate::errors::memory_limit(Kind::Table)?)
                    .map_err(err(Kind::Table))?,
            ),
        })
    }

    /// Builds the table of a layered stack by Fredholm solves (strata-tablegen), with
    /// the resolution of `strata table build` unless nx (a/h₁ nodes), nw (r nodes) or
    /// ns (S nodes) are given; far_max (units of H, the total layer depth; default 2560)
    /// is the farthest join of the tabulated g and its far field, to raise when the build
    /// says so; releases the GIL; progress=True shows progress on stderr.
    #[staticmethod]
    #[pyo3(signature = (stack, progress=false, nx=None, nw=None, ns=None, check_points=200, far_max=None))]
    #[allow(clippy::too_many_arguments)]
    fn build(
        py: Python<'_>,
        stack: &Bound<'_, PyAny>,
        progress: bool,
        nx: Option<usize>,
        nw: Option<usize>,
        ns: Option<usize>,
        check_points: usize,
        far_max: Option<f64>,
    ) -> PyResult<Self> {
        let stack = stack_of(stack, "Table.build: stack")?;
        let build_time = strata_engine::asperity_table::build_time().map_err(err(Kind::Table))?;
        let d = BuildOptions::default();
        let opts = BuildOptions {
            nx: nx.unwrap_or(d.nx),
            nw: nw.unwrap_or(d.nw),
            ns: ns.unwrap_or(d.ns),
            check_points,
            far_max: match far_max {
                None => d.far_max,
                Some(f) if f.is_finite() && f >= 20.0 => f,
                Some(f) => {
                    return Err(to_py(
                        Kind::Table,
                        anyhow::anyhow!(
                            "far_max must be a finite number ≥ 20 (units of H), got {f}"
                        ),
                    ));
                }
            },
            build_time,
            progress,
            bars: Some(Bars(strata_engine::progress::raw_bar)),
            ..d
        };
        let table = crate::progress::call(py, Some(progress), |_| {
            strata_tablegen::tablebuild::build(&stack, &opts)
        })?
        .map_err(err(Kind::Table))?;
        Ok(PyTable {
            table: Arc::new(table),
        })
    }

    /// Writes the table atomically to `path` (`.strata`).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.table.save(&path).map_err(err(Kind::Table))
    }

    /// The stack the table was built for (a family's reference member).
    #[getter]
    fn stack(&self) -> PyStack {
        PyStack {
            stack: self.table.header.bodies(),
        }
    }

    /// Header facts: format and strata versions, build time, tolerance, grids, the
    /// measured interpolation error.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let h = &self.table.header;
        let d = PyDict::new(py);
        d.set_item("format_version", h.format_version)?;
        d.set_item("strata_version", &h.strata_version)?;
        d.set_item("build_time", h.build_time)?;
        d.set_item("tolerance", h.tolerance)?;
        d.set_item("members", self.table.members())?;
        d.set_item("a_over_h1_range", (h.x.lo.exp(), h.x.hi.exp()))?;
        d.set_item("nx", h.x.n)?;
        d.set_item("nw", h.w.n)?;
        d.set_item("rho_h1_range", (h.s.lo.exp(), h.s.hi.exp()))?;
        d.set_item("ns", h.s.n)?;
        if let Some(e) = h.interp_error {
            d.set_item("interp_error", (e.chi, e.zeta, e.g, e.far))?;
        }
        Ok(d)
    }

    /// The asperity law of `stack` (default: the table's own stack); refuses a stack
    /// the table does not serve.
    #[pyo3(signature = (stack=None))]
    fn law(&self, stack: Option<&Bound<'_, PyAny>>) -> PyResult<PyAsperityLaw> {
        let stack = match stack {
            Some(s) => stack_of(s, "Table.law: stack")?,
            None => self.table.header.bodies(),
        };
        Ok(PyAsperityLaw {
            law: self.table.law_for(&stack).map_err(err(Kind::Table))?,
        })
    }

    /// χ(a) of the table's stack (shortcut of `law().chi(a)`).
    fn chi<'py>(&self, py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        self.law(None)?.chi(py, a)
    }

    /// ζ(a) of the table's stack (shortcut of `law().zeta(a)`).
    fn zeta<'py>(&self, py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        self.law(None)?.zeta(py, a)
    }

    /// g(a, r) of the table's stack (shortcut of `law().g(a, r)`).
    fn g<'py>(
        &self,
        py: Python<'py>,
        a: f64,
        r: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.law(None)?.g(py, a, r)
    }

    /// S(ρ) of the table's stack (shortcut of `law().s(rho)`).
    fn s<'py>(&self, py: Python<'py>, rho: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        self.law(None)?.s(py, rho)
    }

    fn __repr__(&self) -> String {
        let h = &self.table.header;
        format!(
            "Table(format {}, {} member(s), a/h1 in [{:e}, {:e}], tolerance {:e})",
            h.format_version,
            self.table.members(),
            h.x.lo.exp(),
            h.x.hi.exp(),
            h.tolerance
        )
    }
}

#[pymethods]
impl PyAsperityLaw {
    /// χ(a): the force factor, P = (4/3) E*₁ χ(a) a³/R (physics.md §4; paper eq. 16).
    fn chi<'py>(&self, py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        conv::map(py, a, "a", Kind::Table, |a| Ok(self.law.try_chi_zeta(a)?.0))
    }

    /// ζ(a): the approach factor, δ = ζ(a) a²/R (physics.md §4; paper eq. 17).
    fn zeta<'py>(&self, py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        conv::map(py, a, "a", Kind::Table, |a| Ok(self.law.try_chi_zeta(a)?.1))
    }

    /// g(a, r) (m²) for r ≥ a: the layers' correction to the half-space displacement
    /// outside an asperity of contact radius a, u(r) = χ(a)/(πR) [(2a² − r²) asin(a/r)
    /// + a√(r² − a²) + g(a, r)] (physics.md §4; paper eq. 21; 0 on a half-space); the
    /// far field beyond the tabulated range.
    fn g<'py>(
        &self,
        py: Python<'py>,
        a: f64,
        r: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        conv::map(py, r, "r", Kind::Table, |r| Ok(self.law.try_g(a, r)?))
    }

    /// S(ρ) from the table (physics.md §2), ρ in 1/m.
    fn s<'py>(&self, py: Python<'py>, rho: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        conv::map(py, rho, "rho", Kind::Table, |r| {
            if !r.is_finite() {
                return Err(anyhow::anyhow!("rho = {r}: not a finite wavenumber (1/m)"));
            }
            Ok(self.law.s(r))
        })
    }

    /// The contact radii (m) the table covers: (a_min, a_max).
    #[getter]
    fn a_range(&self) -> (f64, f64) {
        self.law.a_range()
    }

    /// E*₁ of the stack (Pa).
    #[getter]
    fn e_star1(&self) -> f64 {
        self.law.e_star()
    }

    fn __repr__(&self) -> String {
        let (lo, hi) = self.law.a_range();
        format!(
            "AsperityLaw(a in [{lo:e}, {hi:e}] m, E*1 = {:e} Pa)",
            self.law.e_star()
        )
    }
}

/// The table object behind a `table=` argument: a strata.Table, a path, or None.
pub fn table_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Arc<Table>>> {
    let Some(obj) = obj else { return Ok(None) };
    if obj.is_none() {
        return Ok(None);
    }
    if let Ok(t) = obj.cast::<PyTable>() {
        return Ok(Some(t.get().table.clone()));
    }
    if let Ok(p) = obj.extract::<PathBuf>() {
        require_file("table", &p)?;
        let memory = crate::errors::memory_limit(Kind::Table)?;
        return Ok(Some(Arc::new(
            Table::load_within(&p, &memory).map_err(err(Kind::Table))?,
        )));
    }
    Err(to_py(
        Kind::Table,
        anyhow::anyhow!("table: expected a strata.Table, the path of a .strata file, or None"),
    ))
}
