//! `strata.ContactLaw`: the sampled contact law p(g), A(g)/A₀, dp/dg of a rough
//! interface (strata_runtime::interface) and its Abaqus/CalculiX table.

use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use strata_engine::contact_law::ContactLaw;
use strata_engine::sampled_law::SampledLaw;

use crate::conv;
use crate::errors::{Kind, err};

/// The contact law of a rough interface, sampled from first contact g₀ = z_M − z̄ down
/// to a smallest separation (Scene.law): p(g) (Pa), A(g)/A₀ and dp/dg (Pa/m) at any
/// separation g (m; scalar or array), by the monotone interpolation of the samples
/// (p = 0 for g ≥ g₀). g is the separation of the mean planes (paper eq. 26).
#[pyclass(name = "ContactLaw", module = "strata", frozen)]
pub struct PyContactLaw {
    pub sampled: SampledLaw,
    /// The scene, for the Abaqus block's comments.
    pub scene: String,
}

impl PyContactLaw {
    /// The law as the engine's [`ContactLaw`] (the one h_c(g), h_c(p) of the CLI, C and
    /// Python); a LawError when its conductance is missing or infinite.
    fn contact(&self) -> PyResult<ContactLaw> {
        self.sampled.contact_law().map_err(err(Kind::Law))
    }
}

#[pymethods]
impl PyContactLaw {
    /// Mean (nominal) pressure p(g) = P/A₀ (Pa).
    fn pressure<'py>(
        &self,
        py: Python<'py>,
        gap: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        conv::map(py, gap, "gap", Kind::Law, |g| {
            Ok(self.sampled.law.pressure(g)?)
        })
    }

    /// Real contact area fraction A(g)/A₀.
    fn area_fraction<'py>(
        &self,
        py: Python<'py>,
        gap: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        conv::map(py, gap, "gap", Kind::Law, |g| {
            Ok(self.sampled.law.area_fraction(g)?)
        })
    }

    /// dp/dg (Pa/m, ≤ 0): minus the interface's normal stiffness per unit area.
    fn dp_dg<'py>(&self, py: Python<'py>, gap: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        conv::map(py, gap, "gap", Kind::Law, |g| {
            Ok(self.sampled.law.dp_dg(g)?)
        })
    }

    /// The samples as arrays: gap (m), overclosure g₀ − g (m), mean_pressure (Pa),
    /// area_fraction, dp_dg (Pa/m), valid (bool: inside the model's validity), in
    /// loading order.
    #[getter]
    fn samples<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let l = &self.sampled.law;
        let g0 = l.first_contact_gap();
        let (mut g, mut p, mut d, mut a) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (gi, pi, di, ai) in l.samples() {
            g.push(gi);
            p.push(pi);
            d.push(di);
            a.push(ai);
        }
        let h: Vec<f64> = g.iter().map(|g| g0 - g).collect();
        let out = PyDict::new(py);
        out.set_item("gap", g.into_pyarray(py))?;
        out.set_item("overclosure", h.into_pyarray(py))?;
        out.set_item("mean_pressure", p.into_pyarray(py))?;
        out.set_item("area_fraction", a.into_pyarray(py))?;
        out.set_item("dp_dg", d.into_pyarray(py))?;
        let valid: Vec<bool> = l.validity().map(|v| v.is_valid()).collect();
        out.set_item("valid", valid.into_pyarray(py))?;
        if let Some((_, h)) = &self.sampled.conductance {
            out.set_item("conductance", h.clone().into_pyarray(py))?;
        }
        if let Some(k) = &self.sampled.tangential_stiffness {
            out.set_item("tangential_stiffness", k.clone().into_pyarray(py))?;
        }
        Ok(out)
    }

    /// g₀ = z_M − z̄, the separation at first contact (m).
    #[getter]
    fn first_contact_gap(&self) -> f64 {
        self.sampled.law.first_contact_gap()
    }

    /// The smallest sampled separation (m).
    #[getter]
    fn min_gap(&self) -> f64 {
        self.sampled.law.min_gap()
    }

    /// The model, in words.
    #[getter]
    fn model(&self) -> String {
        self.sampled.model.clone()
    }

    /// The solid, in words.
    #[getter]
    fn solid(&self) -> String {
        self.sampled.solid.clone()
    }

    /// E*₁ (Pa).
    #[getter]
    fn e_star1(&self) -> f64 {
        self.sampled.e_star
    }

    /// Nominal area A₀ (m²).
    #[getter]
    fn nominal_area(&self) -> f64 {
        self.sampled.nominal_area
    }

    /// Interface conductance h_c(g) (W/(m²·K) thermal, S/m² electrical) at separation
    /// g (m; scalar or array), as the C ABI's `strata_law_conductance`: the solved
    /// values at the samples, a monotone cubic (PCHIP) between them (∝ √δ next to first
    /// contact), 0 at and above first contact; below the smallest sample an error.
    /// Needs `[conductance]` in the scene.
    fn conductance<'py>(
        &self,
        py: Python<'py>,
        gap: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let c = self.contact()?;
        c.conductance_kind()
            .ok_or(strata_engine::contact_law::ContactLawError::NoConductance)
            .map_err(err(Kind::Law))?;
        conv::map(py, gap, "gap", Kind::Law, |g| Ok(c.conductance_at_gap(g)?))
    }

    /// h_c at mean contact pressure p (Pa; scalar or array), as the C ABI's
    /// `strata_law_conductance_at_pressure`: at the largest separation where the law's
    /// p(g) equals p (bisection on the monotone p(g)), h_c(g) there; a sample's own
    /// pressure gives its h_c exactly; above the largest sampled pressure an error.
    fn conductance_at_pressure<'py>(
        &self,
        py: Python<'py>,
        pressure: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let c = self.contact()?;
        c.conductance_kind()
            .ok_or(strata_engine::contact_law::ContactLawError::NoConductance)
            .map_err(err(Kind::Law))?;
        conv::map(py, pressure, "pressure", Kind::Law, |p| {
            Ok(c.conductance_at_pressure(p)?)
        })
    }

    /// The full-stick tangential stiffness K_t of the sample (N/m) at separation g (m;
    /// scalar or array), as the C ABI's `strata_law_tangential_stiffness`: the solved
    /// values at the samples, a monotone cubic between them (∝ √δ next to first
    /// contact), 0 at and above first contact; below the smallest sample an error.
    /// Needs `[friction]` in the scene.
    fn tangential_stiffness<'py>(
        &self,
        py: Python<'py>,
        gap: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let c = self.contact()?;
        if !c.has_tangential_stiffness() {
            return Err(err(Kind::Law)(
                strata_engine::contact_law::ContactLawError::NoTangentialStiffness,
            ));
        }
        conv::map(py, gap, "gap", Kind::Law, |g| {
            Ok(c.tangential_stiffness_at_gap(g)?)
        })
    }

    /// K_t (N/m) at mean contact pressure p (Pa; scalar or array): at the largest
    /// separation where the law's p(g) equals p; a sample's own pressure gives its K_t
    /// exactly. Needs `[friction]` in the scene.
    fn tangential_stiffness_at_pressure<'py>(
        &self,
        py: Python<'py>,
        pressure: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let c = self.contact()?;
        if !c.has_tangential_stiffness() {
            return Err(err(Kind::Law)(
                strata_engine::contact_law::ContactLawError::NoTangentialStiffness,
            ));
        }
        conv::map(py, pressure, "pressure", Kind::Law, |p| {
            Ok(c.tangential_stiffness_at_pressure(p)?)
        })
    }

    /// `"thermal"` (W/(m²·K)), `"electrical"` (S/m²) or None: the conductance the law
    /// carries (the scene's `[conductance]`).
    #[getter]
    fn conductance_kind(&self) -> Option<&'static str> {
        self.sampled.conductance.as_ref().map(|(k, _)| match k {
            strata_runtime::conduction::ConductionKind::Thermal => "thermal",
            strata_runtime::conduction::ConductionKind::Electrical => "electrical",
        })
    }

    /// The samples as CSV text, the columns of `strata law --format csv` (with
    /// `[conductance]` its `conductance` column, with `[plasticity]` its `branch`).
    fn csv(&self) -> String {
        strata_engine::sampled_law::csv(&self.sampled)
    }

    /// The `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR` block for Abaqus and
    /// CalculiX (`strata law --format abaqus`): lines `pressure, overclosure`.
    fn abaqus(&self) -> String {
        self.sampled.abaqus_block(&self.scene)
    }

    /// Writes the Abaqus block to `path` atomically (a reader never sees half a file),
    /// and beside it (`law.inp` → `law_range.inp`) its FE range as the amplitude
    /// `STRATA_LAW_RANGE` (0 to h_max over the step), as `strata law` does.
    fn write_abaqus(&self, path: PathBuf) -> PyResult<()> {
        let (range, name) = strata_engine::sampled_law::range_path(&path);
        strata_runtime::output::write_atomic(&path, self.abaqus().as_bytes())
            .and_then(|()| {
                strata_runtime::output::write_atomic(
                    &range,
                    self.sampled.range_block(&name).as_bytes(),
                )
            })
            .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))
            .map_err(err(Kind::Law))
    }

    /// What CalculiX 2.20 would change in the Abaqus block (more than 200 lines,
    /// overclosure steps below 1e-10 m).
    fn calculix_warnings(&self) -> Vec<String> {
        self.sampled.law.calculix_warnings()
    }

    fn __len__(&self) -> usize {
        self.sampled.law.len()
    }

    fn __repr__(&self) -> String {
        let l = &self.sampled.law;
        format!(
            "ContactLaw({} samples, g from {:e} to {:e} m, {})",
            l.len(),
            l.first_contact_gap(),
            l.min_gap(),
            self.sampled.model
        )
    }
}
