//! Cooperative cancellation of a long solve: a [`Cancel`] token the caller keeps and
//! hands to the solvers (the BEM iteration, the I model's load steps and Newton steps),
//! which check it between iterations and stop with a `Cancelled` error, leaving no
//! partial result. The Python package cancels on Ctrl-C (`KeyboardInterrupt`); a token
//! is per call, never global: two solves in one process are cancelled independently.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A cancellation token: clones share one flag. The default token can never be
/// cancelled (no allocation, a `None` check per iteration).
#[derive(Debug, Clone, Default)]
pub struct Cancel(Option<Arc<AtomicBool>>);

/// The solve was cancelled through its [`Cancel`] token.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("cancelled (interrupted by the caller)")]
pub struct Cancelled;

impl Cancel {
    /// A token that [`cancel`](Self::cancel) can trip.
    pub fn new() -> Self {
        Cancel(Some(Arc::new(AtomicBool::new(false))))
    }

    /// Asks every solve holding a clone of this token to stop at its next check.
    pub fn cancel(&self) {
        if let Some(f) = &self.0 {
            f.store(true, Ordering::Relaxed);
        }
    }

    /// Whether [`cancel`](Self::cancel) was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// `Err(Cancelled)` once cancelled: the solvers' check between iterations.
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

/// Tokens carry no physics: every two compare equal (so that the parameter structs
/// holding one keep their `PartialEq`).
impl PartialEq for Cancel {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_flag_and_the_default_never_trips() {
        let c = Cancel::new();
        let d = c.clone();
        assert!(c.check().is_ok());
        d.cancel();
        assert_eq!(c.check(), Err(Cancelled));
        let never = Cancel::default();
        never.cancel();
        assert!(never.check().is_ok() && !never.is_cancelled());
        // an independent token is untouched
        assert!(!Cancel::new().is_cancelled());
    }
}
