//! The table cache: one place for the surrogate tables strata builds on demand (a
//! layered stack without `stack.table` in `solve`, `law`, `compare`, `sweep`, and
//! `asperity --model approx` without `--table`). A table is named after the stack's
//! nondimensional fingerprint (`stack-<hex>.strata`), so every scene and command with
//! the same stack shares it. Beside them: the ψ tables of conducting stacks
//! (`psi-<hex>.strata`) and the capped asperity's response tables of `[plasticity]`
//! scenes with the N and I models (`capped-<hex>.strata`, [`capped_response`]), and the
//! disc-stiffness tables of `[friction]` scenes (`kt-<hex>.strata`, [`disc_stiffness`]).
//!
//! Location, first that applies:
//! 1. `--cache-dir DIR` of the command;
//! 2. the environment variable `STRATA_CACHE_DIR`;
//! 3. `$XDG_CACHE_HOME/strata`;
//! 4. `$HOME/.cache/strata`;
//! 5. `strata-cache` in the system's temporary directory.
//!
//! The directory is checked for writing before a table is built (a build takes
//! seconds to minutes), so a read-only cache fails at once.

use std::path::{Path, PathBuf};

use strata_runtime::rough::plastic::PlasticResponse;
use strata_runtime::rough::plastic::asperity::{
    PlasticAsperityError, ResponseCacheUse, cached_response,
};
use thiserror::Error;

/// A cache directory that cannot take a table.
#[derive(Debug, Error)]
#[error(
    "table cache {path} ({origin}) is not writable: {error}; point --cache-dir or STRATA_CACHE_DIR to a writable directory"
)]
pub struct CacheError {
    pub path: String,
    pub origin: &'static str,
    pub error: std::io::Error,
}

/// The cache directory and where its location comes from (see the module docs).
pub fn dir(flag: Option<&Path>) -> (PathBuf, &'static str) {
    if let Some(d) = flag {
        return (d.to_path_buf(), "--cache-dir");
    }
    let env = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
    if let Some(d) = env("STRATA_CACHE_DIR") {
        (PathBuf::from(d), "STRATA_CACHE_DIR")
    } else if let Some(d) = env("XDG_CACHE_HOME") {
        (PathBuf::from(d).join("strata"), "$XDG_CACHE_HOME/strata")
    } else if let Some(h) = env("HOME") {
        (
            PathBuf::from(h).join(".cache/strata"),
            "$HOME/.cache/strata",
        )
    } else {
        (
            std::env::temp_dir().join("strata-cache"),
            "the temporary directory",
        )
    }
}

/// Creates `dir` if needed and checks that a file can be written there.
pub fn ensure_writable(dir: &Path, origin: &'static str) -> Result<(), CacheError> {
    let fail = |error| CacheError {
        path: dir.display().to_string(),
        origin,
        error,
    };
    std::fs::create_dir_all(dir).map_err(fail)?;
    let probe = dir.join(format!(".strata-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(fail)?;
    std::fs::remove_file(&probe).map_err(fail)
}

/// The capped asperity's response table of `stack` at `hardness` (Pa; physics.md §9,
/// `[plasticity]` with the N and I models) from the table cache `dir` (file
/// `capped-<hex>.strata`, `strata_runtime::rough::plastic::asperity::cached_response`): read
/// when held, else built by ring solves (13–18 CPU-s on a layered stack) and kept
/// there. One log line says which; a cache that cannot be written is a warning, not an
/// error (the table built is used and solved again next time). The same table, bit
/// for bit, as a build in memory.
pub fn capped_response<S: strata_runtime::Solid + ?Sized>(
    stack: &S,
    hardness: f64,
    dir: &Path,
    quiet: bool,
) -> Result<PlasticResponse, PlasticAsperityError> {
    let t0 = std::time::Instant::now();
    let (resp, used) = cached_response(stack, hardness, dir)?;
    let s = t0.elapsed().as_secs_f64();
    let line = match used {
        ResponseCacheUse::Read(p) => format!(
            "plasticity: the capped asperity's response table read from the table cache {}",
            p.display()
        ),
        ResponseCacheUse::Written(p) => format!(
            "plasticity: the capped asperity's response table built (ring solves, {s:.1} s) into the table cache {}",
            p.display()
        ),
        ResponseCacheUse::NotWritten(why) => {
            crate::progress::warn(format_args!(
                "plasticity: the capped asperity's response table could not be kept in the table cache ({why}); it is built again next time"
            ));
            return Ok(resp);
        }
    };
    if !quiet {
        crate::progress::log(line);
    }
    Ok(resp)
}

/// The disc-stiffness table of `stack` (K_n and K_t of a contact disc against a/h₁,
/// `strata_runtime::disc_stiffness`) covering the radii `lo` ≤ `hi` (m) from the table
/// cache `dir` (file `kt-<hex>.strata`, `strata_tablegen::stiffness_table::cached`):
/// read when it covers them, else built (or extended) by Fredholm solves (16 a decade
/// of a/h₁) and kept there; homogeneous bodies need none (ψ ≡ 1). One log line says which; a cache
/// that cannot be written is a warning (the table built is used). The same values,
/// bit for bit, as a build in memory.
pub fn disc_stiffness<S: strata_runtime::Solid + ?Sized>(
    stack: &S,
    lo: f64,
    hi: f64,
    dir: &Path,
    quiet: bool,
) -> Result<
    strata_runtime::disc_stiffness::StiffnessTable,
    strata_tablegen::stiffness_table::StiffnessTableError,
> {
    use strata_tablegen::stiffness_table::{CacheUse, cached};
    if stack.is_homogeneous() {
        // ψ ≡ 1 on homogeneous bodies (S_LL = S_TT = 1): no table, no solve
        let tc = strata_runtime::compliance::tangential::TangentialCompliance::new(stack);
        return Ok(strata_runtime::disc_stiffness::StiffnessTable::half_space(
            tc.plane_strain_modulus(),
            tc.shear_modulus(),
        ));
    }
    let t0 = std::time::Instant::now();
    let solver = strata_tablegen::stiffness::Stiffness::new(stack);
    let (table, used) = cached(&solver, lo, hi, dir)?;
    let s = t0.elapsed().as_secs_f64();
    let line = match used {
        CacheUse::HalfSpace => return Ok(table),
        CacheUse::Read(p) => format!(
            "friction: the disc-stiffness table read from the table cache {}",
            p.display()
        ),
        CacheUse::Written { path, decades } => format!(
            "friction: the disc-stiffness table solved for a/h1 = 1e{} … 1e{} (16 Fredholm solves a decade, {s:.1} s) into the table cache {}",
            decades.0,
            decades.1,
            path.display()
        ),
        CacheUse::NotWritten(why) => {
            crate::progress::warn(format_args!(
                "friction: the disc-stiffness table could not be kept in the table cache ({why}); it is solved again next time"
            ));
            return Ok(table);
        }
    };
    if !quiet {
        crate::progress::log(line);
    }
    Ok(table)
}

// passed on by the engine with `?` (engine/src/error.rs)
crate::error::passed_on!(CacheError);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flag_wins_and_unwritable_fails() {
        let d = std::env::temp_dir().join(format!("strata-cache-test-{}", std::process::id()));
        assert_eq!(dir(Some(&d)), (d.clone(), "--cache-dir"));
        ensure_writable(&d, "--cache-dir").unwrap();
        let file = d.join("plain-file");
        std::fs::write(&file, "x").unwrap();
        let e = ensure_writable(&file.join("sub"), "--cache-dir").unwrap_err();
        assert!(e.to_string().contains("not writable"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
