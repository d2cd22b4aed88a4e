//! Progress of table building and checking: a bar on the terminal, or one a caller's
//! factory makes ([`Bars`]), or none. Reporting never changes a table.

use indicatif::{ProgressBar, ProgressStyle};

/// A progress-bar factory: `(steps, description) -> bar`. Progress reporting never
/// changes a table, so all factories compare equal.
#[derive(Clone, Copy)]
pub struct Bars(pub fn(u64, &'static str) -> ProgressBar);

impl PartialEq for Bars {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for Bars {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Bars(..)")
    }
}

/// The bar of a pass over `n` items: hidden unless `show`; from `bars` if given.
pub(crate) fn bar(n: usize, show: bool, bars: Option<Bars>, msg: &'static str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    if let Some(Bars(make)) = bars {
        return make(n as u64, msg);
    }
    let pb = ProgressBar::new(n as u64);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})")
    {
        pb.set_style(style);
    }
    pb.set_message(msg);
    pb
}
