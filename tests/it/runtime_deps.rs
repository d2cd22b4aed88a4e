//! The runtime stays light for an embedder: with its default features,
//! `cargo tree -p strata-runtime -e normal` lists at most 15 distinct crates, the runtime
//! itself included (build-time proc-macros count too); the heavy dependencies (ndarray,
//! rayon, the FFTs, zip) sit behind named features.

use std::collections::BTreeSet;

use crate::support::repo;

/// The distinct crates (`name version`) of `cargo tree -p strata-runtime -e normal`
/// with `extra` arguments, run offline on the lockfile.
fn runtime_tree(extra: &[&str]) -> BTreeSet<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .current_dir(repo())
        .args([
            "tree",
            "-p",
            "strata-runtime",
            "-e",
            "normal",
            "--prefix",
            "none",
        ])
        .args(["--locked", "--offline"])
        .args(extra)
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| !l.trim().is_empty())
        // "name vX.Y.Z (path) (*)" → "name vX.Y.Z": one entry per crate however often
        // it appears.
        .map(|l| l.split_whitespace().take(2).collect::<Vec<_>>().join(" "))
        .collect()
}

#[test]
fn runtime_default_features_are_light() {
    let crates = runtime_tree(&[]);
    assert!(
        crates.len() <= 15,
        "{} crates with the default features (at most 15):\n{}",
        crates.len(),
        crates.iter().cloned().collect::<Vec<_>>().join("\n")
    );
    for heavy in [
        "ndarray", "rayon", "rustfft", "realfft", "zip", "toml", "rand",
    ] {
        assert!(
            !crates.iter().any(|c| c.split(' ').next() == Some(heavy)),
            "{heavy} is a default dependency of the runtime"
        );
    }
    // And the named features still bring them.
    let full = runtime_tree(&["--features", "full"]);
    for heavy in ["ndarray", "rayon", "strata-fft", "zip", "toml"] {
        assert!(
            full.iter().any(|c| c.split(' ').next() == Some(heavy)),
            "feature `full` lacks {heavy}"
        );
    }
}
