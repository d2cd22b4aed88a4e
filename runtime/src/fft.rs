//! The one 2-D FFT helper of the workspace (feature `spectral`): unnormalised complex
//! transforms of n×n row-major arrays, rows then columns (rustfft).

use rustfft::{FftPlanner, num_complex::Complex};

/// In-place unnormalised 2-D inverse FFT of an n×n row-major array (rows, then columns).
pub fn ifft2(a: &mut [Complex<f64>], n: usize) {
    fft2(a, n, true);
}

/// In-place unnormalised 2-D FFT (forward or inverse) of an n×n row-major array.
pub fn fft2(a: &mut [Complex<f64>], n: usize, inverse: bool) {
    let mut planner = FftPlanner::new();
    let fft = if inverse {
        planner.plan_fft_inverse(n)
    } else {
        planner.plan_fft_forward(n)
    };
    for row in a.chunks_mut(n) {
        fft.process(row);
    }
    let mut col = vec![Complex::new(0.0, 0.0); n];
    for j in 0..n {
        for i in 0..n {
            col[i] = a[i * n + j];
        }
        fft.process(&mut col);
        for i in 0..n {
            a[i * n + j] = col[i];
        }
    }
}
