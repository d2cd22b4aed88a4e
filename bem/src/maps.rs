//! The solution of one load, its maps, and grid utilities (contact patches, spectral
//! resampling, .npy input).

use std::path::Path;

use ndarray::Array2;
use strata_runtime::fft::{RealFft2, signed_index};

use crate::{BemError, BemLoad};

/// The result of one load.
#[derive(Debug, Clone)]
pub struct BemSolution {
    /// The load that was imposed.
    pub load: BemLoad,
    /// Mean pressure p̄ = P/A₀ (Pa), A₀ = Lx·Ly.
    pub mean_pressure: f64,
    /// p̄/E*₁.
    pub pressure_ratio: f64,
    /// Real contact area fraction A/A₀ (grid points with p > 0 over ny·nx).
    pub area_fraction: f64,
    /// Grid points in contact.
    pub contact_points: usize,
    /// Contact patches: connected components of the contact set (4-connected; wrapped
    /// around on a periodic cell).
    pub patches: usize,
    /// Mean gap ḡ (m).
    pub mean_gap: f64,
    /// Approach δ of the flat from first touch (m): z_M − z̄ − ḡ + w̄ on a periodic cell,
    /// z_M − c (the flat at c) on a non-periodic sample.
    pub approach: f64,
    /// Nominal separation g_n = (z_M − z̄) − δ (m), as in the asperity models.
    pub separation: f64,
    /// Total load P = p̄ Lx Ly (N).
    pub total_load: f64,
    /// Mean surface deflection w̄ (m): C₀p̄ on a periodic cell on a rigid base, 0 on an
    /// elastic base (zero-mean convention), the free solid's mean deflection when
    /// non-periodic.
    pub mean_deflection: f64,
    /// Conjugate-gradient iterations used.
    pub iterations: usize,
    /// Applications of the influence operator (one FFT convolution each) the solve
    /// spent: one per iteration (two preconditioned), one more on each iteration whose
    /// contact set changed at more than a few points (fewer are corrected in real
    /// space), and the exact gap refreshes (see the `cg` module).
    pub products: usize,
    /// Final error ε (see the crate docs).
    pub error: f64,
    /// Pressure map p (Pa), ny×nx, same orientation as the heights.
    pub pressure: Array2<f64>,
    /// Gap map g (m), ny×nx (0×0 from [`BemSolver::solve_pressure_only`] until
    /// [`BemSolver::complete_maps`]).
    ///
    /// [`BemSolver::solve_pressure_only`]: crate::BemSolver::solve_pressure_only
    /// [`BemSolver::complete_maps`]: crate::BemSolver::complete_maps
    pub gap: Array2<f64>,
    /// Surface deflection map w (m), ny×nx: the elastic displacement of the surface
    /// into the solid under `pressure`, so that g = w − z + c with z the heights (the
    /// flattened heights under plasticity) and c the flat's position. On a periodic cell
    /// its mean is [`Self::mean_deflection`] (C₀p̄ on a rigid base, 0 on an elastic base
    /// or the half-space); on an isolated sample it is the free solid's absolute
    /// deflection. 0×0 like [`Self::gap`] from a pressure-only solve.
    pub displacement: Array2<f64>,
    /// Plastic depth map u_pl (m), ny×nx, of a capped solve (`None` for an elastic one):
    /// the overlap flattened so far along the path, so that with the undeformed heights
    /// z the gap is g = w − (z − u_pl) + c.
    pub plastic_depth: Option<Array2<f64>>,
    /// Sides of the sample (m): along x (columns) and along y (rows).
    pub sides: [f64; 2],
    /// Whether the sample is one cell of a periodic pattern.
    pub periodic: bool,
    /// The flat's offset c (m) in g = w − z + c (the Lagrange multiplier of the mean
    /// pressure under force control).
    pub offset: f64,
}

impl BemSolution {
    /// Writes the plastic depth map (a capped solve's) as an f64 .npy file, atomically;
    /// nothing for an elastic solve.
    pub fn write_plastic_depth(&self, path: &Path) -> Result<(), BemError> {
        let Some(map) = &self.plastic_depth else {
            return Ok(());
        };
        strata_runtime::output::write_atomic_with(path, |tmp| {
            ndarray_npy::write_npy(tmp, map).map_err(std::io::Error::other)
        })
        .map_err(|e| BemError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Writes the pressure and gap maps as f64 .npy files, each atomically
    /// ([`strata_runtime::output::write_atomic_with`]).
    pub fn write_maps(&self, pressure_path: &Path, gap_path: &Path) -> Result<(), BemError> {
        for (path, map) in [(pressure_path, &self.pressure), (gap_path, &self.gap)] {
            strata_runtime::output::write_atomic_with(path, |tmp| {
                ndarray_npy::write_npy(tmp, map).map_err(std::io::Error::other)
            })
            .map_err(|e| BemError::Write {
                path: path.display().to_string(),
                message: e.to_string(),
            })?;
        }
        Ok(())
    }
}

/// The deflection w = g + z − c of a solve (`gap` g, heights `z`, the flat at `c`), moved
/// on a periodic cell so that its mean is `mean` (the operator's uniform mode is a
/// convention there, see the crate docs); `None`: left as it is.
pub(crate) fn deflection(gap: &[f64], z: &[f64], c: f64, mean: Option<f64>) -> Vec<f64> {
    let mut w: Vec<f64> = gap.iter().zip(z).map(|(g, z)| g + z - c).collect();
    if let Some(mean) = mean.filter(|m| m.is_finite()) {
        let shift = mean - w.iter().sum::<f64>() / w.len().max(1) as f64;
        w.iter_mut().for_each(|v| *v += shift);
    }
    w
}

/// Reads a height map (m, f64) from a .npy file.
pub fn read_heights_npy(path: &Path) -> Result<Array2<f64>, BemError> {
    ndarray_npy::read_npy(path).map_err(|e: ndarray_npy::ReadNpyError| BemError::Read {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// Number of connected components of `mask` (ny×nx, row-major), 4-connected, with
/// wrap-around when `periodic`.
pub fn count_patches(mask: &[bool], ny: usize, nx: usize, periodic: bool) -> usize {
    patch_sizes(mask, ny, nx, periodic).len()
}

/// The sizes (pixels) of the contact patches of `mask` (ny × nx, row-major): the
/// connected components of [`count_patches`], in no particular order.
pub fn patch_sizes(mask: &[bool], ny: usize, nx: usize, periodic: bool) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..mask.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for i in 0..ny {
        for j in 0..nx {
            let a = i * nx + j;
            if !mask[a] {
                continue;
            }
            let right = (j + 1 < nx || periodic).then(|| i * nx + (j + 1) % nx);
            let down = (i + 1 < ny || periodic).then(|| ((i + 1) % ny) * nx + j);
            for b in [right, down].into_iter().flatten() {
                if mask[b] {
                    let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                    if ra != rb {
                        parent[ra] = rb;
                    }
                }
            }
        }
    }
    let mut size = vec![0usize; mask.len()];
    for a in 0..mask.len() {
        if mask[a] {
            let r = find(&mut parent, a);
            size[r] += 1;
        }
    }
    size.into_iter().filter(|&n| n > 0).collect()
}

/// The median of patch sizes (pixels): the middle one, the mean of the two middle ones
/// for an even count; `None` without patches.
pub fn median_patch_size(sizes: &[usize]) -> Option<f64> {
    let mut s = sizes.to_vec();
    s.sort_unstable();
    let n = s.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(s[n / 2] as f64),
        _ => Some((s[n / 2 - 1] + s[n / 2]) as f64 / 2.0),
    }
}

/// Spectral (Fourier) resampling of a periodic n×n field to m×m (m even ≥ 4): the
/// Fourier coefficients with |fx|, |fy| < min(n, m)/2 are kept, the rest (including
/// the Nyquist lines) set to zero. Exact for band-limited surfaces.
pub fn resample_spectral(field: &Array2<f64>, m: usize) -> Result<Array2<f64>, BemError> {
    let (rows, cols) = field.dim();
    if rows != cols || rows < 4 || !rows.is_multiple_of(2) {
        return Err(BemError::Grid { rows, cols });
    }
    if m < 4 || !m.is_multiple_of(2) {
        return Err(BemError::Resample(m));
    }
    resample_rect(field, m, m)
}

/// [`resample_spectral`] on rectangles: ny×nx → my×mx, keeping |fy| < min(ny, my)/2 and
/// |fx| < min(nx, mx)/2.
pub fn resample_rect(field: &Array2<f64>, my: usize, mx: usize) -> Result<Array2<f64>, BemError> {
    let a = field.as_standard_layout();
    let out = resample_flat(a.as_slice().unwrap_or_default(), field.dim(), my, mx)?;
    Array2::from_shape_vec((my, mx), out).map_err(|_| BemError::Resample(my))
}

/// [`resample_rect`] of the row-major ny × nx field `a` (no copy of it).
pub(crate) fn resample_flat(
    a: &[f64],
    (ny, nx): (usize, usize),
    my: usize,
    mx: usize,
) -> Result<Vec<f64>, BemError> {
    if my < 4 || mx < 4 || !my.is_multiple_of(2) || !mx.is_multiple_of(2) {
        return Err(BemError::Resample(my.min(mx)));
    }
    let from = RealFft2::new(ny, nx)?;
    let mut wf = from.work();
    from.forward(a, &mut wf)?;
    let to = RealFft2::new(my, mx)?;
    let mut wt = to.work();
    wt.spec.fill(Default::default());
    let (ky_keep, kx_keep) = (ny.min(my) / 2, nx.min(mx) / 2);
    for kx in 0..kx_keep {
        for fy in -(ky_keep as i64) + 1..ky_keep as i64 {
            let src = fy.rem_euclid(ny as i64) as usize;
            let dst = fy.rem_euclid(my as i64) as usize;
            debug_assert_eq!(signed_index(src, ny), fy);
            wt.spec[kx * my + dst] = wf.spec[kx * ny + src];
        }
    }
    drop(wf);
    let mut out = vec![0.0; my * mx];
    to.inverse(&mut out, &mut wt)?;
    let norm = 1.0 / (ny * nx) as f64;
    out.iter_mut().for_each(|v| *v *= norm);
    Ok(out)
}
