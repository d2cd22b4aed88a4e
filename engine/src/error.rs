//! The engine's error: what failed, where in the scene or the load path, and why.
//!
//! Every fallible engine function returns [`Result`]. An error is a chain: the outer
//! [`EngineError::At`] names the place (a scene field such as `load.mean_pressures[3]`,
//! a load step, an effect such as `[conductance]`) and keeps the library error that
//! caused it as its `source`, so front ends print the whole chain (`{:#}` through
//! `anyhow`: `load step 4: plasticity: …`) and the C ABI and Python find the cause's
//! type in it (`downcast_ref` on each link). [`Context`] attaches a place to any
//! library error, as `anyhow::Context` would, while the type stays the engine's.

use std::error::Error as StdError;

use thiserror::Error;

/// A fallible engine result.
pub type Result<T, E = EngineError> = std::result::Result<T, E>;

/// Why the engine could not serve a scene, a law or a query.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum EngineError {
    /// An input (a scene field or an option) that cannot be served; the message names it.
    #[error("{0}")]
    Input(String),
    /// A failure at a named place (a scene field, a load step, an effect), caused by
    /// `source` (a library error: scene, stack, table, surface, BEM, memory budget, …).
    #[error("{at}")]
    At {
        /// Where: a dotted scene field, a load step, an effect.
        at: String,
        /// What went wrong there.
        #[source]
        source: Box<dyn StdError + Send + Sync + 'static>,
    },
    /// A library error passed on as it is: its message is the whole story (no place to
    /// add), its type found by `downcast_ref` as any link of the chain.
    #[error(transparent)]
    Source(Box<dyn StdError + Send + Sync + 'static>),
    /// A failure described by its message alone (e.g. a missing value at a named place).
    #[error("{0}")]
    Failed(String),
    /// A broken internal invariant: a defect of strata, never of the input.
    #[error("{0}: internal error")]
    Internal(&'static str),
}

impl EngineError {
    /// `source` at the place `at`.
    pub fn at(at: impl Into<String>, source: impl StdError + Send + Sync + 'static) -> Self {
        EngineError::At {
            at: at.into(),
            source: Box::new(source),
        }
    }
}

impl EngineError {
    /// Every link of the chain, outermost first, with the library error inside each
    /// [`EngineError::Source`] as a link of its own (a transparent link forwards its
    /// `source()` past the error it holds): where a front end looks for a cause's type.
    pub fn causes(&self) -> Vec<&(dyn StdError + 'static)> {
        let mut out: Vec<&(dyn StdError + 'static)> = vec![];
        let mut next: Option<&(dyn StdError + 'static)> = Some(self);
        while let Some(e) = next {
            out.push(e);
            next = match e.downcast_ref::<EngineError>() {
                Some(EngineError::Source(inner)) => Some(&**inner),
                _ => e.source(),
            };
        }
        out
    }
}

/// A library error the engine passes on with `?` (as [`EngineError::Source`]).
macro_rules! passed_on {
    ($($t:ty),* $(,)?) => {$(
        impl From<$t> for $crate::error::EngineError {
            fn from(e: $t) -> Self {
                $crate::error::EngineError::Source(Box::new(e))
            }
        }
    )*};
}

// the engine's own modules' errors pass on from where they are defined (scene, cache,
// spots), so that this module imports none of them
pub(crate) use passed_on;
passed_on!(
    strata_runtime::cancel::Cancelled,
    strata_runtime::resources::ResourceError,
    strata_runtime::rough::RoughError,
    strata_runtime::surface::SurfaceError,
    strata_runtime::table::TableError,
    strata_bem::BemError,
    strata_tablegen::psi_table::PsiError,
    strata_tablegen::spot::SpotError,
    strata_tablegen::spot_pair::SpotPairError,
    strata_tablegen::stiffness_table::StiffnessTableError,
);

/// Attaches a place to an error (or to a missing value), as `anyhow::Context` does.
pub trait Context<T> {
    /// The error (or `None`) at the place `at`.
    fn context(self, at: impl Into<String>) -> Result<T>;
    /// As [`Context::context`], the place built only on failure.
    fn with_context<S: Into<String>>(self, at: impl FnOnce() -> S) -> Result<T>;
}

impl<T, E: StdError + Send + Sync + 'static> Context<T> for std::result::Result<T, E> {
    fn context(self, at: impl Into<String>) -> Result<T> {
        self.map_err(|e| EngineError::at(at, e))
    }
    fn with_context<S: Into<String>>(self, at: impl FnOnce() -> S) -> Result<T> {
        self.map_err(|e| EngineError::at(at(), e))
    }
}

impl<T> Context<T> for Option<T> {
    fn context(self, at: impl Into<String>) -> Result<T> {
        self.ok_or_else(|| EngineError::Failed(at.into()))
    }
    fn with_context<S: Into<String>>(self, at: impl FnOnce() -> S) -> Result<T> {
        self.ok_or_else(|| EngineError::Failed(at().into()))
    }
}

/// Returns `Err(EngineError::Input(format!(…)))`: an input the engine cannot serve.
macro_rules! bail_input {
    ($($arg:tt)*) => {
        return Err($crate::error::EngineError::Input(format!($($arg)*)))
    };
}
pub(crate) use bail_input;

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Error)]
    #[error("the cause")]
    struct Cause;

    /// The chain prints as anyhow prints it (`at: cause`) and the cause's type is
    /// found in it (what the C ABI and Python rely on).
    #[test]
    fn chain_and_downcast() {
        let e: Result<()> = Err(Cause).context("load step 3");
        let e = anyhow::Error::from(e.unwrap_err().at_outer("[conductance]"));
        assert_eq!(format!("{e:#}"), "[conductance]: load step 3: the cause");
        assert!(e.chain().any(|c| c.downcast_ref::<Cause>().is_some()));
        // a cause passed on as it is: one message, its type among the causes
        let passed = EngineError::Source(Box::new(Cause));
        assert_eq!(
            format!("{:#}", anyhow::Error::from(EngineError::at("x", passed))),
            "x: the cause"
        );
        let passed = EngineError::at("x", EngineError::Source(Box::new(Cause)));
        assert!(
            passed
                .causes()
                .iter()
                .any(|c| c.downcast_ref::<Cause>().is_some())
        );
        let none: Result<u8> = None.context("no step");
        assert_eq!(none.unwrap_err().to_string(), "no step");
        assert_eq!(
            EngineError::Internal("load").to_string(),
            "load: internal error"
        );
    }

    impl EngineError {
        fn at_outer(self, at: &str) -> EngineError {
            EngineError::at(at, self)
        }
    }
}
