//! What a rough-contact solve is asked for and returns: the image convention, the
//! model, the results of one load step and where they leave the models' validity.

use super::params::Diagnostics;

/// How interactions treat the sample boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Images {
    /// Interactions stop at the sample edge (plain distances).
    Isolated,
    /// The sample is one cell of a periodic pattern; sources are repeated on the
    /// (2m+1)×(2m+1) block of cells around it (m = 2: the 5×5 sum).
    Periodic(usize),
}

/// Which model a solve uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    /// N model: independent asperities.
    Independent,
    /// I model: interacting asperities with the given image convention.
    Interacting(Images),
}

/// Results of one load step.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct Step {
    /// Approach δ (m).
    pub delta: f64,
    /// Separation g_n = (z_M − z̄) − δ (m).
    pub gap: f64,
    /// Total load P (N).
    pub load: f64,
    /// Mean pressure p_n = P/A₀ (Pa).
    pub mean_pressure: f64,
    /// p_n/E*₁ (-).
    pub pressure_ratio: f64,
    /// Real contact area fraction A/A₀ (-).
    pub area_fraction: f64,
    /// Number of asperities in contact.
    pub contacts: usize,
    /// Normal stiffness dP/dδ of the sample (N/m).
    pub stiffness: f64,
    /// I model only: KKT residual relative to the largest interference.
    pub kkt_residual: Option<f64>,
    /// Newton iterations (I model only; 0 otherwise).
    pub iterations: usize,
    /// Contact radius of every summit (m), 0 when out of contact.
    pub radii: Vec<f64>,
    /// What the solve did (I model; default for the N model).
    pub diagnostics: Diagnostics,
    /// Where the step leaves the models' validity (logged by the engine, recorded in
    /// curve.json).
    pub validity: Validity,
}

/// Where a step leaves the validity of the asperity models (physics.md §5): recorded,
/// never refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Validity {
    /// The flat is below the mean plane (g_n < 0).
    pub below_mean_plane: bool,
    /// The approach exceeds the peak-to-valley height z_M − z_min: every summit loaded.
    pub beyond_deepest_valley: bool,
    /// The summed contact areas exceed the nominal area (A/A₀ > 1).
    pub area_above_nominal: bool,
    /// I model: pairs of contacts whose circles overlap (r_kl < a_k + a_l) among the
    /// pairs summed exactly (the paper's model assumes separate circular contacts).
    pub overlapping_contacts: usize,
}

impl Validity {
    /// True when every check holds.
    pub fn is_valid(&self) -> bool {
        *self == Validity::default()
    }

    /// One line naming what does not hold (empty when valid).
    pub fn describe(&self) -> String {
        let mut out = Vec::new();
        if self.below_mean_plane {
            out.push("the flat is below the mean plane (g_n < 0)".to_string());
        }
        if self.beyond_deepest_valley {
            out.push("the approach exceeds z_M − z_min (every summit loaded)".to_string());
        }
        if self.area_above_nominal {
            out.push("the contact areas sum to more than the nominal area".to_string());
        }
        if self.overlapping_contacts > 0 {
            out.push(format!(
                "{} pairs of contact circles overlap",
                self.overlapping_contacts
            ));
        }
        out.join("; ")
    }
}
