//! Parsing and checks of CLI arguments shared by several subcommands: list-valued
//! arguments, and the one-counterface rule of `--counterface`.

use anyhow::{Result, bail};

fn parse_number(flag: &str, s: &str) -> Result<f64> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| anyhow::anyhow!("{flag}: `{s}` is not a number"))?;
    if !v.is_finite() {
        bail!("{flag}: `{s}` is not a finite number");
    }
    Ok(v)
}

/// The one spelling of value lists on the command line (`--delta`, `--rho-h`):
/// `a,b,c` (the values), `LO:HI:N` (N values evenly spaced from LO to HI, linear) or
/// `LO:HI:N:log` (N values geometrically spaced, LO, HI > 0). N ≥ 1; N = 1 gives LO;
/// the end points are exact.
pub const LIST_HELP: &str =
    "a list `a,b,c`, or `LO:HI:N` (N linearly spaced values) or `LO:HI:N:log` (log-spaced)";

/// Parses a value list (see [`LIST_HELP`]).
pub fn parse_list(flag: &str, s: &str) -> Result<Vec<f64>> {
    let s = s.trim();
    if s.is_empty() {
        bail!("{flag}: empty list");
    }
    if s.contains(':') {
        let mut parts: Vec<&str> = s.split(':').map(str::trim).collect();
        let log = match parts.len() {
            3 => false,
            4 if parts[3].eq_ignore_ascii_case("log") => true,
            4 if parts[3].eq_ignore_ascii_case("lin") => false,
            _ => bail!("{flag}: range `{s}` must be LO:HI:N (linear) or LO:HI:N:log"),
        };
        parts.truncate(3);
        let lo = parse_number(flag, parts[0])?;
        let hi = parse_number(flag, parts[1])?;
        let n: usize = parts[2]
            .parse()
            .map_err(|_| anyhow::anyhow!("{flag}: N in `{s}` must be a positive integer"))?;
        if n == 0 {
            bail!("{flag}: N in `{s}` must be at least 1");
        }
        if n > 10_000_000 {
            bail!("{flag}: N in `{s}` is too large (at most 10000000)");
        }
        if log && (lo <= 0.0 || hi <= 0.0) {
            bail!("{flag}: a log-spaced range needs LO > 0 and HI > 0, got `{s}`");
        }
        let f = |i: usize| {
            if n == 1 {
                return lo;
            }
            let u = i as f64 / (n - 1) as f64;
            if log {
                (lo.ln() + (hi.ln() - lo.ln()) * u).exp()
            } else {
                lo + (hi - lo) * u
            }
        };
        let mut v: Vec<f64> = (0..n).map(f).collect();
        // Exact end points despite exp/ln round-off.
        v[0] = lo;
        if n > 1 {
            v[n - 1] = hi;
        }
        return Ok(v);
    }
    s.split(',').map(|p| parse_number(flag, p)).collect()
}

/// True for a linear range `LO:HI:N` whose ends differ by 100× or more (a hint that
/// `:log` may have been meant).
pub fn wide_linear_range(s: &str) -> bool {
    let parts: Vec<&str> = s.trim().split(':').map(str::trim).collect();
    if parts.len() != 3 {
        return false;
    }
    match (parts[0].parse::<f64>(), parts[1].parse::<f64>()) {
        (Ok(lo), Ok(hi)) => lo > 0.0 && hi > 0.0 && (hi / lo >= 100.0 || lo / hi >= 100.0),
        _ => false,
    }
}

/// `--counterface` on a stack file that has its own `[counterface]`: refused (the
/// stack file's would be replaced silently); one counterface, given in one place.
pub fn refuse_two_counterfaces(
    stack: &strata_runtime::Bodies,
    stack_path: &std::path::Path,
    counterface: &std::path::Path,
) -> Result<()> {
    if stack.counterface.stack().is_some() {
        bail!(
            "--counterface {}: the stack file {} has its own [counterface]; give the counterface in one place (remove --counterface, or the stack file's [counterface])",
            counterface.display(),
            stack_path.display()
        );
    }
    Ok(())
}

/// The bodies of a command's `STACK [--counterface FILE]`: the stack file (with the
/// `[counterface]` it may name) against `--counterface` when given (one counterface, in
/// one place: [`refuse_two_counterfaces`]).
pub fn bodies(
    stack_path: &std::path::Path,
    counterface: Option<&std::path::Path>,
) -> Result<strata_runtime::Bodies> {
    use anyhow::Context;
    let stack = strata_runtime::Bodies::from_toml_file(stack_path)?;
    let Some(c) = counterface else {
        return Ok(stack);
    };
    refuse_two_counterfaces(&stack, stack_path, c)?;
    Ok(stack
        .first
        .against(strata_runtime::Stack::from_toml_file(c).context("--counterface")?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_and_ranges() {
        assert_eq!(
            parse_list("--x", "1,2.5,3e-3").unwrap(),
            vec![1.0, 2.5, 3e-3]
        );
        let v = parse_list("--x", "0.01:100:5:log").unwrap();
        assert_eq!(v.len(), 5);
        assert_eq!(v[0], 0.01);
        assert_eq!(v[4], 100.0);
        assert!((v[2] - 1.0).abs() < 1e-14);
        let v = parse_list("--x", "0:1:3").unwrap();
        assert_eq!(v, vec![0.0, 0.5, 1.0]);
        assert_eq!(parse_list("--x", "0:1:3:lin").unwrap(), v);
        let v = parse_list("--x", "0.01:100:3").unwrap();
        assert_eq!(v, vec![0.01, 0.01 + (100.0 - 0.01) * 0.5, 100.0]);
        for bad in [
            "",
            "a",
            "1,,2",
            "1:2",
            "0:1:3x",
            "1:2:0",
            "nan",
            "inf,1",
            "1:2:3:cubic",
            "0:1:3:log",
        ] {
            assert!(parse_list("--x", bad).is_err(), "{bad}");
        }
        assert!(wide_linear_range("0.01:100:5") && !wide_linear_range("0.01:100:5:log"));
        assert!(!wide_linear_range("1:2:5") && !wide_linear_range("0:1:5"));
    }
}
