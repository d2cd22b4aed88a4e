//! Export of a table's arrays as NumPy `.npy` files (ndarray-npy), for Python users.
//!
//! Files written into the target directory (all float64):
//! `chi.npy`, `zeta.npy` [member, x]; `g_r_over_a3.npy` [member, x, w];
//! `s.npy` `[member, s]`; `k0.npy` `[member]`; the coordinate axes `ln_x.npy` = ln(a/h₁),
//! `w.npy`, `ln_rho_h1.npy` and, for a family, `ln_ratio.npy` = ln(E_v/E₁).

use std::path::{Path, PathBuf};

use ndarray::{Array1, ArrayD, IxDyn};

use super::{Table, TableError};

/// Writes the arrays of `table` into `dir` (created if missing); returns the files.
pub fn export_npy(table: &Table, dir: &Path) -> Result<Vec<PathBuf>, TableError> {
    let io = |p: &Path, m: String| TableError::Io {
        path: p.display().to_string(),
        message: m,
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e.to_string()))?;
    let h = &table.header;
    let m = table.members();
    let mut files = Vec::new();
    let mut put = |name: &str, shape: &[usize], data: &[f64]| -> Result<(), TableError> {
        let p = dir.join(name);
        let arr = ArrayD::from_shape_vec(IxDyn(shape), data.to_vec())
            .map_err(|e| io(&p, e.to_string()))?;
        // Atomic (temporary file + rename): an interrupted export leaves no partial .npy.
        crate::output::write_atomic_with(&p, |tmp| {
            ndarray_npy::write_npy(tmp, &arr).map_err(std::io::Error::other)
        })
        .map_err(|e| io(&p, e.to_string()))?;
        files.push(p);
        Ok(())
    };
    put("chi.npy", &[m, h.x.n], &table.chi)?;
    put("zeta.npy", &[m, h.x.n], &table.zeta)?;
    put("g_r_over_a3.npy", &[m, h.x.n, h.w.n], &table.g)?;
    put("s.npy", &[m, h.s.n], &table.s)?;
    put("k0.npy", &[m], &table.k0)?;
    let axis = |a: &super::Axis| Array1::from(a.nodes()).to_vec();
    put("ln_x.npy", &[h.x.n], &axis(&h.x))?;
    put("w.npy", &[h.w.n], &axis(&h.w))?;
    put("ln_rho_h1.npy", &[h.s.n], &axis(&h.s))?;
    if let Some(f) = h.family {
        put("ln_ratio.npy", &[f.ratio.n], &axis(&f.ratio))?;
    }
    Ok(files)
}
