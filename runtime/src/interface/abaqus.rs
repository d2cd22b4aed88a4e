//! The law as an Abaqus/CalculiX `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR`
//! block, and what the two FE codes do with such a table.
//!
//! **Fields.** Abaqus ("floating point numbers can occupy a maximum of 20 spaces",
//! input syntax rules) and CalculiX (`read(textpart(i)(1:20),'(f20.0)')`) read a
//! number from at most 20 characters; CalculiX cuts a longer field silently, so a
//! 21-character `8.335791983246352E+02` reads as `8.335791983246352E+0` (11 orders of
//! magnitude lost per exponent digit). [`abaqus_real`] writes the most significant
//! digits that fit in 20 characters; [`read_f20`] reads a field back as CalculiX does.
//!
//! **What each code does with the table** (CalculiX 2.20 measured with `ccx` by the
//! tests in `tests/it/calculix.rs`; Abaqus from its Keywords Reference, `*SURFACE
//! BEHAVIOR`):
//!
//! | | Abaqus | CalculiX 2.20 |
//! |---|---|---|
//! | between lines | linear | linear |
//! | beyond the last line | continues the last slope | holds the last pressure (zero stiffness) |
//! | more than 200 lines | uses every line | resamples onto [`CALCULIX_MAX_LINES`] evenly spaced overclosures, linear between the given lines |
//! | overclosure steps < 1e-10 (model length unit) | – | moves the points [`CALCULIX_MIN_OVERCLOSURE_STEP`] apart (stretches the law) |
//! | contact formulation | any | `NODE TO SURFACE`; `SURFACE TO SURFACE` with a TABULAR law crashes (segmentation fault) |

use super::{InterfaceLaw, InvalidRange};

/// Characters Abaqus and CalculiX read for one number of a data line.
pub const FIELD_WIDTH: usize = 20;

/// Table lines CalculiX 2.20 uses as given: a longer `PRESSURE-OVERCLOSURE=TABULAR`
/// table is resampled onto this many evenly spaced overclosures.
pub const CALCULIX_MAX_LINES: usize = 200;

/// Smallest step between table overclosures CalculiX 2.20 keeps (in the model's length
/// unit): closer points are moved this far apart when the deck is read.
pub const CALCULIX_MIN_OVERCLOSURE_STEP: f64 = 1e-10;

/// `v` in Fortran E notation with `digits` digits after the point and an exponent of
/// at least two digits (`d.ddd…E±xx`, `E±xxx` when |exponent| ≥ 100).
fn e_notation(v: f64, digits: usize) -> String {
    let s = format!("{v:.digits$E}");
    match s.split_once('E') {
        Some((mant, exp)) => {
            let e: i32 = exp.parse().unwrap_or(0);
            format!("{mant}E{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
        }
        None => s,
    }
}

/// Formats a number for an Abaqus/CalculiX data field: `0.` for zero, else
/// `d.ddd…E±xx` with as many significant digits as fit in [`FIELD_WIDTH`] (20)
/// characters: 15 for a positive value with a two-digit exponent (relative rounding
/// error ≤ 5e-15), 14 for a positive value with a three-digit exponent or a negative
/// value with a two-digit one (≤ 5e-14), 13 for a negative value with a three-digit
/// exponent (≤ 5e-13). Full precision belongs in CSV/JSON.
pub fn abaqus_real(v: f64) -> String {
    if v == 0.0 {
        return "0.".into();
    }
    (0..=14)
        .rev()
        .map(|d| e_notation(v, d))
        .find(|s| s.len() <= FIELD_WIDTH)
        .unwrap_or_else(|| e_notation(v, 0))
}

/// Reads a data field as CalculiX does (`read(field(1:20), '(f20.0)')`): only the first
/// [`FIELD_WIDTH`] characters count, blanks are ignored, an empty field is 0; the
/// number is `[sign] digits [. digits] [exponent]`, the exponent `E`, `D` or `Q` with
/// an optionally signed integer, or a signed integer alone; without a decimal point
/// the digits are an integer (d = 0). `None` if the field is not a Fortran real.
pub fn read_f20(field: &str) -> Option<f64> {
    let s: String = field
        .chars()
        .take(FIELD_WIDTH)
        .filter(|c| *c != ' ')
        .collect();
    if s.is_empty() {
        return Some(0.0);
    }
    let b = s.as_bytes();
    let mut i = 0;
    let mut out = String::new();
    if matches!(b[0], b'+' | b'-') {
        if b[0] == b'-' {
            out.push('-');
        }
        i = 1;
    }
    let (mut digits, mut point) = (0, false);
    while i < b.len() {
        match b[i] {
            c @ b'0'..=b'9' => {
                digits += 1;
                out.push(c as char);
            }
            b'.' if !point => {
                point = true;
                out.push('.');
            }
            _ => break,
        }
        i += 1;
    }
    if digits == 0 {
        return None;
    }
    if i < b.len() {
        if matches!(b[i], b'E' | b'e' | b'D' | b'd' | b'Q' | b'q') {
            i += 1;
        } else if !matches!(b[i], b'+' | b'-') {
            return None;
        }
        let exp = &s[i..];
        let unsigned = exp.strip_prefix(['+', '-']).unwrap_or(exp);
        if unsigned.is_empty() || !unsigned.bytes().all(|c| c.is_ascii_digit()) {
            return None;
        }
        out.push('E');
        out.push_str(exp);
    }
    out.parse().ok()
}

/// `text` as `** `-comment lines of at most `width` characters after the prefix,
/// continuation lines indented; non-ASCII characters replaced (`−` by `-`), since the
/// FE readers expect ASCII.
fn comment_lines(first: &str, text: &str, width: usize) -> String {
    let ascii: String = text
        .chars()
        .map(|c| match c {
            '−' => '-',
            c if c.is_ascii() => c,
            _ => '?',
        })
        .collect();
    let mut out = String::new();
    let mut line = String::from(first);
    // Whether `line` holds only its prefix.
    let mut fresh = true;
    for word in ascii.split_whitespace() {
        if !fresh && line.len() + 1 + word.len() > width {
            out.push_str(&line);
            out.push('\n');
            line = String::from("**  ");
        }
        line.push(' ');
        line.push_str(word);
        fresh = false;
    }
    out.push_str(&line);
    out.push('\n');
    out
}

impl InvalidRange {
    /// One sentence: where (g and overclosure h = g₀ − g, m) the model `model` is
    /// outside its validity and why; `g0` the first-contact separation (m).
    pub fn describe(&self, model: &str, g0: f64) -> String {
        let range = if self.to_end {
            format!(
                "for g <= {:.6e} m (overclosure h >= {:.6e} m; the last {} samples)",
                self.from_gap,
                g0 - self.from_gap,
                self.samples
            )
        } else {
            format!(
                "for {:.6e} m >= g >= {:.6e} m (overclosure {:.6e} m <= h <= {:.6e} m; {} samples)",
                self.from_gap,
                self.to_gap,
                g0 - self.from_gap,
                g0 - self.to_gap,
                self.samples
            )
        };
        format!(
            "the {model} is outside its validity {range} ({}); the law there is an extrapolation of the model",
            self.validity.describe()
        )
    }
}

impl InterfaceLaw {
    /// Where the model is outside its validity ([`InterfaceLaw::invalid_ranges`]), one
    /// sentence per run of samples; empty when the whole law is valid. The Abaqus block
    /// carries them as `** WARNING:` comments.
    pub fn validity_warnings(&self) -> Vec<String> {
        let g0 = self.first_contact_gap();
        self.invalid_ranges()
            .iter()
            .map(|r| r.describe(self.model_name(), g0))
            .collect()
    }

    /// What CalculiX 2.20 would change in this law's table: more than
    /// [`CALCULIX_MAX_LINES`] lines, or overclosure steps below
    /// [`CALCULIX_MIN_OVERCLOSURE_STEP`] m (SI: the table's unit). One sentence each;
    /// empty when CalculiX uses the table as written.
    pub fn calculix_warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        let n = self.len();
        if n > CALCULIX_MAX_LINES {
            w.push(format!(
                "{n} table lines: CalculiX 2.20 resamples a table of more than \
                 {CALCULIX_MAX_LINES} lines onto {CALCULIX_MAX_LINES} evenly spaced \
                 overclosures (Abaqus uses every line); sample {CALCULIX_MAX_LINES} or \
                 fewer for CalculiX"
            ));
        }
        let step = self
            .x
            .windows(2)
            .map(|p| p[1] - p[0])
            .fold(f64::INFINITY, f64::min);
        if step < CALCULIX_MIN_OVERCLOSURE_STEP {
            w.push(format!(
                "overclosure step {} m: CalculiX 2.20 moves table points closer than \
                 {CALCULIX_MIN_OVERCLOSURE_STEP:e} (model length unit) that far apart, \
                 stretching the law; sample fewer points or model in a smaller length unit",
                abaqus_real(step)
            ));
        }
        w
    }

    /// The law as an Abaqus `*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR` block:
    /// `**` comment lines (the convention, `comments` first), the keyword line, then one
    /// data line `pressure, overclosure` per sample with overclosure h = g₀ − g ≥ 0
    /// (m), first line `0., 0.` (first contact), h strictly increasing, p
    /// non-decreasing ≥ 0 (Pa), every number in at most 20 characters
    /// ([`abaqus_real`]). The comments state what Abaqus and CalculiX do beyond the
    /// last line and with long tables, [`InterfaceLaw::calculix_warnings`] and, as
    /// `** WARNING:` lines right after `comments`, where the model is outside its
    /// validity ([`InterfaceLaw::validity_warnings`]). Every line is ASCII.
    pub fn abaqus_block(&self, comments: &[String]) -> String {
        let g0 = self.first_contact_gap();
        let dev = self.linear_table_deviation();
        let mut s = String::new();
        for c in comments {
            for line in c.lines() {
                s.push_str("** ");
                s.push_str(line);
                s.push('\n');
            }
        }
        for w in self.validity_warnings() {
            s.push_str(&comment_lines("** WARNING:", &w, 90));
        }
        s.push_str(&format!(
            "** Convention: overclosure h = g0 - g (m), g = separation of the mean planes (P26),\n\
             **   g0 = z_M - zbar = {} m = separation at first contact (z_M: highest summit in\n\
             **   the N and I models, highest grid point in the BEM; g means the same in both).\n\
             **   h = 0 is first contact; place the FE surfaces so that zero FE overclosure means\n\
             **   mean planes g0 apart. pressure = mean (nominal) contact pressure p = P/A0 (Pa).\n\
             ** Units: SI (Pa, m). Use a consistent unit system (scale both columns otherwise).\n\
             ** Samples: {}, from h = 0 to h = {} m (g = {} m).\n\
             ** Numbers: at most 20 characters a field (Abaqus and CalculiX read no more),\n\
             **   14-15 significant digits; full precision in strata's CSV and JSON output.\n\
             ** Between lines Abaqus and CalculiX interpolate linearly. Linear vs interpolated\n\
             **   law at interval midpoints: {:.1e} of the largest pressure, {:.1e} of the local\n\
             **   pressure where p >= 1% of the largest.\n\
             ** Beyond the last line Abaqus continues the last slope; CalculiX 2.20 holds the last\n\
             **   pressure (zero stiffness: the surfaces then interpenetrate freely). Sample to a\n\
             **   separation below any the model reaches (strata law --min-gap).\n\
             ** More than {CALCULIX_MAX_LINES} lines: Abaqus uses every line; CalculiX 2.20 resamples the table\n\
             **   onto {CALCULIX_MAX_LINES} evenly spaced overclosures. Overclosure steps below 1e-10 (model\n\
             **   length unit): CalculiX 2.20 moves the points 1e-10 apart (stretching the law).\n\
             ** CalculiX: use *CONTACT PAIR, TYPE=NODE TO SURFACE (TYPE=SURFACE TO SURFACE with a\n\
             **   TABULAR law crashes CalculiX 2.20); a tested deck is in strata's examples/calculix.\n",
            abaqus_real(g0),
            self.len(),
            abaqus_real(g0 - self.min_gap()),
            abaqus_real(self.min_gap()),
            dev.of_max,
            dev.local,
        ));
        for w in self.calculix_warnings() {
            s.push_str("** WARNING: ");
            s.push_str(&w);
            s.push('\n');
        }
        s.push_str("** Place this block under your *SURFACE INTERACTION (or *INCLUDE it there).\n");
        s.push_str("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR\n");
        for (i, (g, p, _, _)) in self.samples().enumerate() {
            let h = if i == 0 { 0.0 } else { g0 - g };
            s.push_str(&format!("{}, {}\n", abaqus_real(p), abaqus_real(h)));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative difference, exact 0 for equal values.
    fn rel(a: f64, b: f64) -> f64 {
        if a == b { 0.0 } else { (a - b).abs() / b.abs() }
    }

    /// Every finite value fits the field and reads back (as CalculiX reads it) to the
    /// documented number of significant digits; values spanning all exponents,
    /// subnormals and both signs.
    #[test]
    fn every_number_fits_twenty_characters_and_reads_back() {
        let mut values = vec![
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            1e-310,
            9.999999999999999e99,
            9.999999999999999e-100,
            1e100,
            1e-100,
            1.0 / 3.0,
            8.335791983246352e2,
            4.92462311557795e-8,
            123456789012345680.0,
        ];
        let mut x = 1.2345e-320_f64;
        while x < 1e308 {
            values.push(x);
            x *= 7.38905609893065;
        }
        let mut worst = [0.0f64; 3];
        for v in values.iter().flat_map(|&v| [v, -v]) {
            let s = abaqus_real(v);
            assert!(
                s.len() <= FIELD_WIDTH,
                "{v:e}: `{s}` has {} characters",
                s.len()
            );
            let back = read_f20(&s).unwrap_or_else(|| panic!("`{s}` does not read back"));
            let e = rel(back, v);
            let three = v.abs() >= 1e100 || v.abs() < 1e-99;
            let class = match (v < 0.0, three) {
                (false, false) => 0,
                (true, true) => 2,
                _ => 1,
            };
            worst[class] = worst[class].max(e);
        }
        eprintln!(
            "worst relative round trip: 15 digits {:.1e}, 14 {:.1e}, 13 {:.1e}",
            worst[0], worst[1], worst[2]
        );
        assert!(worst[0] <= 5e-15, "{worst:?}");
        assert!(worst[1] <= 5e-14, "{worst:?}");
        assert!(worst[2] <= 5e-13, "{worst:?}");
        assert_eq!(abaqus_real(0.0), "0.");
        assert_eq!(abaqus_real(-0.0), "0.");
        assert_eq!(abaqus_real(1.5e-6), "1.50000000000000E-06");
        assert_eq!(abaqus_real(2.5e7), "2.50000000000000E+07");
        assert_eq!(abaqus_real(-2.5e7), "-2.5000000000000E+07");
        assert_eq!(abaqus_real(1e-300), "1.0000000000000E-300");
        assert_eq!(abaqus_real(-1e-300), "-1.000000000000E-300");
        // Rounding up into a three-digit exponent still fits.
        assert_eq!(abaqus_real(9.999999999999999e99), "1.0000000000000E+100");
    }

    /// The reader follows Fortran's F editing on a 20-character field, including the
    /// silent cut that made 21-character fields lose their last exponent digit.
    #[test]
    fn reads_fields_as_calculix_does() {
        let cases: [(&str, Option<f64>); 14] = [
            ("0.", Some(0.0)),
            ("", Some(0.0)),
            ("  ", Some(0.0)),
            ("1.5E-06", Some(1.5e-6)),
            ("1.5d-06", Some(1.5e-6)),
            (" 1.5 E- 06", Some(1.5e-6)),
            ("-1.5-6", Some(-1.5e-6)),
            ("15E2", Some(1500.0)),
            (".5", Some(0.5)),
            ("+7", Some(7.0)),
            ("8.335791983246352E+02", Some(8.335791983246352)),
            ("4.924623115577950E-08", Some(4.92462311557795)),
            ("1.0E", None),
            ("abc", None),
        ];
        for (field, want) in cases {
            assert_eq!(read_f20(field), want, "`{field}`");
        }
        assert_eq!(read_f20("-"), None);
        assert_eq!(read_f20("1.2.3"), None);
    }

    /// CalculiX warnings: none for a 200-line table with µm steps; both past the limits.
    #[test]
    fn calculix_limits_are_reported() {
        let law = |n: usize, span: f64| {
            let g: Vec<f64> = (0..n).map(|i| -span * i as f64 / (n - 1) as f64).collect();
            let p: Vec<f64> = (0..n).map(|i| i as f64).collect();
            let k = vec![0.0; n];
            let a = vec![0.0; n];
            InterfaceLaw::from_samples(&g, &p, &k, &a).expect("law")
        };
        assert!(law(200, 1e-5).calculix_warnings().is_empty());
        let w = law(201, 1e-5).calculix_warnings();
        assert_eq!(w.len(), 1);
        assert!(w[0].contains("201") && w[0].contains("200"), "{w:?}");
        let w = law(200, 1e-8).calculix_warnings();
        assert_eq!(w.len(), 1);
        assert!(w[0].contains("1e-10"), "{w:?}");
        let block = law(300, 1e-8).abaqus_block(&[]);
        assert_eq!(block.matches("** WARNING: ").count(), 2, "{block}");
        for line in block.lines() {
            assert!(line.len() <= 256 && line.is_ascii(), "{line}");
        }
    }
}
