//! The distributed solve under MPI (feature `mpi`; needs `mpirun` on PATH): the load
//! curves of `bem-mpi` on 1, 2 and 4 ranks agree to 1e-12 relative (a 512² periodic cell
//! on a layered stack, a 256 × 384 isolated sample). Ranks are oversubscribed: 4 run on a
//! 2-core machine.
#![cfg(feature = "mpi")]

use std::path::Path;
use std::process::Command;

/// Runs `bem-mpi SCENE NY NX` on `np` ranks; returns the curve's rows as numbers.
fn curve(np: usize, scene: &str, ny: usize, nx: usize, dir: &Path) -> Vec<Vec<f64>> {
    let out = dir.join(format!("{scene}-{np}"));
    let status = Command::new("mpirun")
        .args(["--allow-run-as-root", "--oversubscribe", "-np"])
        .arg(np.to_string())
        .arg(env!("CARGO_BIN_EXE_bem-mpi"))
        .args([scene, &ny.to_string(), &nx.to_string()])
        .arg(&out)
        // One FFT thread per rank: the ranks share the cores.
        .env("RAYON_NUM_THREADS", "1")
        .status()
        .expect("mpirun runs (OpenMPI's openmpi-bin)");
    assert!(
        status.success(),
        "mpirun -np {np} bem-mpi {scene}: {status}"
    );
    let text = std::fs::read_to_string(out.join("curve.csv")).expect("rank 0 wrote curve.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(strata_bem::SlabStep::CSV_HEADER));
    lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse::<f64>().expect("a number"))
                .collect()
        })
        .collect()
}

/// Largest relative difference of the physical columns (all but `iterations`, `error`).
fn worst(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut w = 0.0f64;
    for (ra, rb) in a.iter().zip(b) {
        for k in 0..6 {
            let scale = ra[k].abs().max(1e-300);
            w = w.max((ra[k] - rb[k]).abs() / scale);
        }
    }
    w
}

fn agree(scene: &str, ny: usize, nx: usize) {
    // A directory per test: the two run at once.
    let dir = std::env::temp_dir().join(format!("strata-mpi-{}-{scene}", std::process::id()));
    let serial = curve(1, scene, ny, nx, &dir);
    assert!(serial.len() == 3 && serial.iter().all(|r| r[2] > 0.0 && r[4] > 0.0));
    for np in [2, 4] {
        let d = worst(&serial, &curve(np, scene, ny, nx, &dir));
        println!("{scene} {ny}×{nx}: np {np} against np 1: {d:.2e} relative");
        assert!(d <= 1e-12, "{scene}: np {np} differs from np 1 by {d:e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn periodic_layered_512_same_curve_on_1_2_4_ranks() {
    agree("periodic", 512, 512);
}

#[test]
fn non_periodic_256_by_384_same_curve_on_1_2_4_ranks() {
    agree("free", 256, 384);
}
