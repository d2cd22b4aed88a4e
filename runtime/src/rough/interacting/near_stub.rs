//! Without the `spectral` feature there is no FFT: the I model keeps its dense pair
//! sums. These types stand in for the grid sums and are never built.

use super::far_field::{FarModel, Vb};
use crate::resources::ResourceError;
use crate::summits::Summit;

/// Leading coefficients per near pair (as with `spectral`).
pub(crate) const LEAD: usize = 3;

/// Never built without `spectral`.
pub(crate) struct FastSums {
    pub grid: Grid,
    pub modelled_pairs: usize,
}

/// Never built without `spectral`.
pub(crate) struct Grid {
    never: std::convert::Infallible,
    pub r_near: f64,
    pub worst: f64,
}

impl Grid {
    pub fn period(&self) -> (i64, i64, i64) {
        match self.never {}
    }
}

/// Never built without `spectral`.
pub(crate) struct GridWork {
    never: std::convert::Infallible,
}

/// Errors of building the fast sums (never raised without `spectral`).
#[allow(dead_code)]
#[derive(Debug)]
pub(crate) enum FastError {
    Memory(ResourceError),
    Fft(String),
}

impl FastSums {
    /// Always None: the caller sums densely.
    #[allow(clippy::type_complexity)]
    pub fn build(
        _: &[Summit],
        _: &[usize],
        _: (f64, f64),
        _: i64,
        _: &FarModel,
        _: f64,
    ) -> Result<Option<(FastSums, Vec<(usize, usize, f64)>)>, FastError> {
        Ok(None)
    }

    pub fn work(&self) -> GridWork {
        match self.grid.never {}
    }

    pub fn apply(
        &self,
        _: &[Vb],
        _: &[f64],
        _: &mut [f64],
        _: &mut [Vb],
        w: &mut GridWork,
        _: bool,
    ) -> Result<(), String> {
        match w.never {}
    }

    pub fn near_pairs(&self) -> (&[(u32, u32)], &[[f32; LEAD]]) {
        match self.grid.never {}
    }
}
