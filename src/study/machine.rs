//! The machine a study ran on, as `cargo run -p xtask -- machine FILE` recorded it
//! (`strata study --machine FILE`). The study reads it and does not probe the machine
//! itself: no /proc, no subprocesses in the user's binary.

use std::path::Path;

use anyhow::{Context, Result};

/// What the report's "Machine" section shows from the machine file (the rayon pool, the
/// build profile and strata's version come from the running program).
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Machine {
    /// CPU model name.
    pub cpu: String,
    /// Logical CPUs and how many the process may use.
    pub cores: String,
    /// Total memory.
    pub memory: String,
    /// Operating system.
    pub os: String,
    /// Kernel release.
    pub kernel: String,
    /// The compiler's version.
    pub rustc: String,
    /// The commit of the source tree (and whether it had uncommitted changes).
    pub commit: String,
    /// The 1, 5 and 15 minute load averages when the machine was probed.
    pub load: String,
}

impl Machine {
    /// Reads a machine file (TOML, every key required); errors name the file and the key.
    pub fn from_file(path: &Path) -> Result<Self> {
        let what = format!("--machine {}", path.display());
        let text = strata_runtime::resources::read_text_capped(
            path,
            strata_runtime::resources::TEXT_FILE_CAP,
            "a machine file",
            &strata_runtime::resources::MemoryLimit::of_machine(),
        )
        .with_context(|| what.clone())?;
        toml::from_str(&text).with_context(|| what)
    }

    /// Every row "not recorded", for a study run without `--machine`.
    pub fn not_recorded() -> Self {
        let n = || {
            "not recorded (`cargo run -p xtask -- machine FILE`, then `--machine FILE`)".to_string()
        };
        Machine {
            cpu: n(),
            cores: n(),
            memory: n(),
            os: n(),
            kernel: n(),
            rustc: n(),
            commit: n(),
            load: n(),
        }
    }
}
