//! Dense LU factorisation with partial pivoting: the direct solve of the I model's
//! Newton and stiffness systems J x = b where the Jacobian is held densely (a leaf:
//! it imports nothing of the crate).

/// Dense LU solve with partial pivoting (row-major m×m); None when singular.
pub(crate) fn lu_solve(a: &mut [f64], b: &mut [f64], m: usize) -> Option<Vec<f64>> {
    for k in 0..m {
        let piv = (k..m).max_by(|&i, &j| {
            a[i * m + k]
                .abs()
                .partial_cmp(&a[j * m + k].abs())
                .unwrap_or(std::cmp::Ordering::Equal)
        })?;
        if a[piv * m + k].is_nan() || a[piv * m + k] == 0.0 {
            return None;
        }
        if piv != k {
            for c in 0..m {
                a.swap(k * m + c, piv * m + c);
            }
            b.swap(k, piv);
        }
        let d = a[k * m + k];
        for i in k + 1..m {
            let f = a[i * m + k] / d;
            if f != 0.0 {
                for c in k..m {
                    a[i * m + c] -= f * a[k * m + c];
                }
                b[i] -= f * b[k];
            }
        }
    }
    let mut x = vec![0.0; m];
    for i in (0..m).rev() {
        let mut s = b[i];
        for c in i + 1..m {
            s -= a[i * m + c] * x[c];
        }
        x[i] = s / a[i * m + i];
    }
    if x.iter().all(|v| v.is_finite()) {
        Some(x)
    } else {
        None
    }
}
