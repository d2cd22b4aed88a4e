//! The 2-D FFT helper against direct sums: the DFT, linear (padded) convolution, the fused
//! row passes of the boundary-element solver.

use strata_fft::{Complex, Fft2Work, Fields, RealFft2, RowPasses, signed_index};

/// Direct O(n⁴) DFT of a real ny×nx field at (kx, ky).
fn dft(z: &[f64], ny: usize, nx: usize, kx: usize, ky: usize) -> Complex<f64> {
    let mut acc = Complex::new(0.0, 0.0);
    for i in 0..ny {
        for j in 0..nx {
            let ph = -std::f64::consts::TAU
                * (ky as f64 * i as f64 / ny as f64 + kx as f64 * j as f64 / nx as f64);
            acc += Complex::from_polar(z[i * nx + j], ph);
        }
    }
    acc
}

fn field(ny: usize, nx: usize) -> Vec<f64> {
    (0..ny * nx)
        .map(|i| ((i * 37 % 11) as f64) - 3.0 + 0.1 * (i as f64).sin())
        .collect()
}

/// A test kernel (1/(1 + i) over the spectrum), the plain convolution of `z` with it
/// (mean term `dc`), and the work buffers.
fn plain_convolution(plan: &RealFft2, z: &[f64], dc: f64) -> (Vec<f64>, Vec<f64>, Fft2Work) {
    let kernel: Vec<f64> = (0..plan.spectrum_len())
        .map(|i| 1.0 / (1.0 + i as f64))
        .collect();
    let mut w = plan.work();
    let mut plain = vec![0.0; z.len()];
    plan.convolve(z, &mut plain, &kernel, dc, &mut w).unwrap();
    (kernel, plain, w)
}

#[test]
fn forward_matches_direct_dft_on_rectangles() {
    for (ny, nx) in [(6, 10), (8, 4), (12, 12), (5, 7), (9, 6)] {
        let z = field(ny, nx);
        let plan = RealFft2::new(ny, nx).unwrap();
        let mut w = plan.work();
        plan.forward(&z, &mut w).unwrap();
        for kx in 0..=nx / 2 {
            for ky in 0..ny {
                let d = dft(&z, ny, nx, kx, ky);
                let s = w.spec[kx * ny + ky];
                assert!(
                    (s - d).norm() < 1e-11,
                    "({ny},{nx}) k=({kx},{ky}): {s} vs {d}"
                );
            }
        }
        // Round trip.
        let mut back = vec![0.0; ny * nx];
        plan.inverse(&mut back, &mut w).unwrap();
        for (a, b) in back.iter().zip(&z) {
            assert!((a / (ny * nx) as f64 - b).abs() < 1e-12);
        }
    }
}

#[test]
fn padded_convolution_is_the_linear_convolution() {
    // Zero padding to 2ny × 2nx turns the circular convolution into the linear one.
    let (ny, nx) = (5, 7);
    let (gy, gx) = (10, 14);
    let z = field(ny, nx);
    // A real, even kernel in real space: g(di, dj), |di| < ny, |dj| < nx.
    let g = |di: i64, dj: i64| 1.0 / (1.0 + (di * di) as f64 + 0.5 * (dj * dj) as f64);
    let mut gr = vec![0.0; gy * gx];
    for i in 0..gy {
        for j in 0..gx {
            gr[i * gx + j] = g(signed_index(i, gy), signed_index(j, gx));
        }
    }
    let full = RealFft2::new(gy, gx).unwrap();
    let mut w = full.work();
    full.forward(&gr, &mut w).unwrap();
    let norm = 1.0 / (gy * gx) as f64;
    let kernel: Vec<f64> = w.spec.iter().map(|c| c.re * norm).collect();
    assert!(w.spec.iter().all(|c| c.im.abs() < 1e-12));
    let plan = RealFft2::padded((gy, gx), (ny, nx)).unwrap();
    let mut w = plan.work();
    let mut out = vec![0.0; ny * nx];
    plan.convolve(&z, &mut out, &kernel, kernel[0], &mut w)
        .unwrap();
    for i in 0..ny {
        for j in 0..nx {
            let mut acc = 0.0;
            for a in 0..ny {
                for b in 0..nx {
                    acc += g(i as i64 - a as i64, j as i64 - b as i64) * z[a * nx + b];
                }
            }
            assert!((out[i * nx + j] - acc).abs() < 1e-11, "({i},{j})");
        }
    }
}

#[test]
fn fused_convolution_equals_plain_with_row_sums() {
    // Periodic and zero-padded plans, one and several lanes' worth of rows.
    for (grid, data) in [
        ((6, 10), (6, 10)),
        ((10, 14), (5, 7)),
        ((130, 128), (130, 128)),
    ] {
        let plan = RealFft2::padded(grid, data).unwrap();
        let (ny, nx) = data;
        let z = field(ny, nx);
        let (kernel, plain, mut w) = plain_convolution(&plan, &z, 0.5);
        // fill doubles the data in place and feeds it; drain writes the result.
        let mut d = z.clone();
        let mut out = vec![0.0; ny * nx];
        let rows = RowPasses {
            data: &mut d,
            out: &mut out,
            kernel: (&kernel).into(),
            dc: 0.5,
        };
        let (a, b) = plan
            .convolve_with(
                rows,
                &mut w,
                |_, row, input| {
                    row.iter_mut().for_each(|v| *v *= 2.0);
                    input.copy_from_slice(row);
                    row.iter().sum::<f64>()
                },
                |i, row, result, o| {
                    o.copy_from_slice(result);
                    [1.0, i as f64, row.iter().sum::<f64>()]
                },
            )
            .unwrap();
        let total: f64 = z.iter().sum();
        assert!((a - 2.0 * total).abs() < 1e-9 * total.abs().max(1.0));
        assert_eq!(b[0], ny as f64);
        assert_eq!(b[1], (ny * (ny - 1) / 2) as f64);
        assert!((b[2] - 2.0 * total).abs() < 1e-9 * total.abs().max(1.0));
        for (x, y) in out.iter().zip(&plain) {
            assert!((x - 2.0 * y).abs() < 1e-12 * (1.0 + y.abs()));
        }
    }
}

#[test]
fn gated_fields_convolution_stops_or_hands_its_value_to_the_drain() {
    let (ny, nx) = (130, 128);
    let plan = RealFft2::new(ny, nx).unwrap();
    let z = field(ny, nx);
    let (kernel, plain, mut w) = plain_convolution(&plan, &z, 0.0);
    for go in [false, true] {
        // Three fields: the source (scaled by 3 in place), an output, a row counter.
        let (mut a, mut b, mut c) = (z.clone(), vec![0.0; ny * nx], vec![0.0; ny * nx]);
        let fields = Fields {
            fields: [&mut a, &mut b, &mut c],
            kernel: (&kernel).into(),
            dc: 0.0,
        };
        let (sum, drained) = plan
            .convolve_fields(
                fields,
                &mut w,
                |_, [a, _, c], input| {
                    a.iter_mut().for_each(|v| *v *= 3.0);
                    input.copy_from_slice(a);
                    c.fill(1.0);
                    a.iter().sum::<f64>()
                },
                |s: &f64| go.then_some(*s),
                |&s, i, [_, b, c], result| {
                    b.copy_from_slice(result);
                    c.iter_mut().for_each(|v| *v += 1.0);
                    [s, i as f64]
                },
            )
            .unwrap();
        let total: f64 = z.iter().sum();
        assert!((sum - 3.0 * total).abs() < 1e-9 * total.abs().max(1.0));
        assert!(a.iter().zip(&z).all(|(x, y)| *x == 3.0 * y));
        match drained {
            None => {
                assert!(!go);
                assert!(b.iter().all(|&v| v == 0.0) && c.iter().all(|&v| v == 1.0));
            }
            Some(d) => {
                assert!(go);
                assert!((d[0] - ny as f64 * sum).abs() < 1e-9 * (ny as f64 * sum).abs());
                assert_eq!(d[1], (ny * (ny - 1) / 2) as f64);
                assert!(c.iter().all(|&v| v == 2.0));
                for (x, y) in b.iter().zip(&plain) {
                    assert!((x - 3.0 * y).abs() < 1e-10 * (1.0 + y.abs()), "{x} {y}");
                }
            }
        }
    }
}

#[test]
fn folded_multiplier_equals_its_expanded_half_kernel_and_its_inverse() {
    // A kernel even in ky held once per |ky| (the BEM's periodic kernel and its inverse,
    // the preconditioner) gives the same bits as the kernel written out on the half
    // spectrum, with the buffers of convolution_work (no transposed spectrum).
    for (ny, nx) in [(6, 10), (9, 6), (130, 128)] {
        let plan = RealFft2::new(ny, nx).unwrap();
        let (h, hy) = (nx / 2 + 1, ny / 2 + 1);
        let scale = 1.0 / (ny * nx) as f64;
        let table: Vec<f64> = (0..h * hy)
            .map(|i| if i == 3 { 0.0 } else { 1.0 / (1.0 + i as f64) })
            .collect();
        let z = field(ny, nx);
        for inverse in [false, true] {
            let value = |t: f64| {
                let k = t * scale;
                if !inverse {
                    k
                } else if k > 0.0 {
                    scale * scale / k
                } else {
                    0.0
                }
            };
            let half: Vec<f64> = (0..h * ny)
                .map(|i| {
                    let (kx, ky) = (i / ny, i % ny);
                    let fy = if ky <= ny / 2 { ky } else { ny - ky };
                    value(table[kx * hy + fy])
                })
                .collect();
            let mut want = vec![0.0; ny * nx];
            plan.convolve(&z, &mut want, &half, half[0], &mut plan.work())
                .unwrap();
            let mut w = plan.convolution_work();
            assert!(w.spec.is_empty());
            let (mut a, mut out) = (z.clone(), vec![0.0; ny * nx]);
            let f = Fields {
                fields: [&mut a, &mut out],
                kernel: strata_fft::Multiplier::Folded {
                    table: &table,
                    scale,
                    inverse,
                },
                dc: half[0],
            };
            plan.convolve_fields(
                f,
                &mut w,
                |_, [a, _], input| input.copy_from_slice(a),
                |_| Some(()),
                |_, _, [_, o], result| o.copy_from_slice(result),
            )
            .unwrap();
            assert_eq!(out, want, "{ny}×{nx}, inverse {inverse}");
            // The transforms need the spectrum: an error, not a panic.
            assert!(plan.forward(&z, &mut w).is_err());
        }
    }
}
