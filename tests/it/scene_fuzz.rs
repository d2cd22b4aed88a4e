//! Property tests of the scene reader: mutated scenes — values replaced by
//! random numbers and strings, lines deleted or duplicated, characters inserted or
//! deleted, arbitrary text — never panic. Every accepted scene satisfies the
//! documented invariants and its load and surface can be built; every rejection is a
//! one-line message.
//!
//! Bounded for CI: fixed case counts and a fixed seed (~2 s in the test profile).
//! Longer run: `PROPTEST_CASES=100000 cargo test -p strata-runtime --test scene_fuzz`
//! (`PROPTEST_RNG_SEED=N` changes the seed).

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use strata::scene::{LoadSpec, Scene, SurfaceSource};

/// Fixed case count and seed unless PROPTEST_CASES / PROPTEST_RNG_SEED say otherwise.
fn config(cases: u32) -> ProptestConfig {
    crate::support::fuzz_config(cases, 0x5ce4e)
}

/// A directory with a small surface file and a stack file the scenes can point to,
/// written once per process (tests run in parallel threads and must not see a file
/// being rewritten).
fn fixture_dir() -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(write_fixture).clone()
}

fn write_fixture() -> PathBuf {
    let d = crate::support::scratch().join("scene-fuzz");
    std::fs::create_dir_all(&d).expect("temp dir");
    let mut text = String::new();
    for i in 0..8 {
        let row: Vec<String> = (0..8)
            .map(|j| format!("{:e}", 1e-6 * ((i * 7 + j * 3) % 11) as f64))
            .collect();
        text += &row.join(" ");
        text.push('\n');
    }
    std::fs::write(d.join("s.txt"), text).expect("surface");
    std::fs::write(
        d.join("stack.toml"),
        "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"\n",
    )
    .expect("stack");
    d
}

const GENERATED: &str = r#"[stack]
[[stack.layer]]
thickness = 1e-4
young = 4e9
poisson = 0.15
[stack.base]
kind = "elastic"
young = 2e10
poisson = 0.3
[surface]
size = 1e-3
periodic = true
[surface.generate]
grid = 16
fractal_dimension = 2.4
k_min = 2
k_max = 6
rms = 3.4e-6
seed = 1
[model]
kind = "interacting"
images = "periodic"
image_cells = 2
[load]
approach = { from = 1e-6, to = 9e-6, steps = 5 }
"#;

const FROM_FILE: &str = r#"[stack]
file = "stack.toml"
[surface]
file = "s.txt"
size = 1e-3
periodic = false
[model]
kind = "independent"
[load]
separations = [9e-6, 8e-6]
"#;

/// Replacement values: numbers of every kind, wrong types, broken syntax.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|x| format!("{x:e}")),
        any::<i64>().prop_map(|i| i.to_string()),
        (-20i64..20).prop_map(|i| i.to_string()),
        (1e-9f64..1e-2).prop_map(|x| format!("{x:e}")),
        Just("nan".to_string()),
        Just("-inf".to_string()),
        Just("0".to_string()),
        Just("-0.0".to_string()),
        Just("1e400".to_string()),
        Just("\"text\"".to_string()),
        Just("\"bem\"".to_string()),
        Just("\"isolated\"".to_string()),
        Just("[]".to_string()),
        Just("[1e-6, nan]".to_string()),
        Just("{ from = 0, to = 0, steps = 1 }".to_string()),
        Just("true".to_string()),
        Just("".to_string()),
        Just("= =".to_string()),
        "[ -~]{0,12}",
    ]
}

#[derive(Debug, Clone)]
enum Edit {
    /// Replace the value of the line (index mod lines) after its `=`.
    Value(usize, String),
    Delete(usize),
    Duplicate(usize),
    /// Insert text at a char position (mod length).
    Insert(usize, String),
    /// Remove one char at a position (mod length).
    Remove(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        4 => (any::<usize>(), value()).prop_map(|(i, v)| Edit::Value(i, v)),
        1 => any::<usize>().prop_map(Edit::Delete),
        1 => any::<usize>().prop_map(Edit::Duplicate),
        1 => (any::<usize>(), "[\\[\\]=\"\n{},.a-z0-9 -]{1,4}").prop_map(|(i, s)| Edit::Insert(i, s)),
        1 => any::<usize>().prop_map(Edit::Remove),
    ]
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for e in edits {
        if lines.is_empty() {
            break;
        }
        let n = lines.len();
        match e {
            Edit::Value(i, v) => {
                let l = &mut lines[i % n];
                if let Some(eq) = l.find('=') {
                    *l = format!("{}= {v}", &l[..eq]);
                }
            }
            Edit::Delete(i) => {
                lines.remove(i % n);
            }
            Edit::Duplicate(i) => {
                let l = lines[i % n].clone();
                lines.insert(i % n, l);
            }
            Edit::Insert(i, s) => {
                let mut all = lines.join("\n");
                let chars: Vec<char> = all.chars().collect();
                let at = i % (chars.len() + 1);
                let byte = chars[..at].iter().map(|c| c.len_utf8()).sum();
                all.insert_str(byte, s);
                lines = all.lines().map(String::from).collect();
            }
            Edit::Remove(i) => {
                let all: Vec<char> = lines.join("\n").chars().collect();
                if all.is_empty() {
                    break;
                }
                let at = i % all.len();
                let s: String = all
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != at)
                    .map(|(_, c)| *c)
                    .collect();
                lines = s.lines().map(String::from).collect();
            }
        }
    }
    lines.join("\n") + "\n"
}

/// Parses `text`; checks the invariants of an accepted scene or the shape of the error.
fn check(text: &str, dir: &Path) {
    match Scene::from_str_in(text, dir) {
        Ok(s) => {
            if let Some(sp) = s.surface.read.spacing {
                let (dx, dy) = sp.pixel(64, 48).expect("accepted spacing");
                assert!(dx > 0.0 && dy > 0.0 && dx.is_finite() && dy.is_finite());
            }
            for l in s.bodies.first.layers() {
                assert!(l.thickness > 0.0 && l.young > 0.0 && l.poisson <= 0.5);
            }
            match &s.load {
                LoadSpec::Separations(g) => assert!(!g.is_empty()),
                LoadSpec::MeanPressures(p) => {
                    assert!(!p.is_empty() && p.iter().all(|x| x.is_finite() && *x > 0.0))
                }
                LoadSpec::Approach { from, to, steps } => {
                    assert!(*from >= 0.0 && *to >= 0.0 && (1..=100_000).contains(steps))
                }
            }
            // Loads against any admissible range: values or an error naming the field.
            for (top, max) in [(1e-5, 2e-5), (0.0, 0.0), (1.0, 1e-9)] {
                match s.load.approaches(top, max) {
                    Ok(Some(d)) => assert!(d.iter().all(|x| x.is_finite() && *x >= 0.0)),
                    Ok(None) => assert!(matches!(s.load, LoadSpec::MeanPressures(_))),
                    Err(e) => assert!(e.to_string().contains("load"), "{e}"),
                }
            }
            // Building the surface: only small grids (a mutated grid may ask for 16384²).
            let small = match &s.surface.source {
                SurfaceSource::Generate(g) => g.grid <= 64,
                SurfaceSource::File(_) => true,
            };
            if small {
                match s.load_surface(&strata_runtime::resources::MemoryLimit::default()) {
                    Ok(sf) => assert!(sf.heights().iter().all(|z| z.is_finite())),
                    Err(e) => {
                        let m = e.to_string();
                        assert!(m.contains("surface"), "{m}");
                        assert!(!m.contains('\n'), "{m}");
                    }
                }
            }
        }
        Err(e) => {
            let m = e.to_string();
            // Scene::from_str_in names the field (from_file adds the scene file); toml's
            // syntax errors are multi-line excerpts; our own messages are one line.
            assert!(!m.is_empty(), "{m}");
            if !m.starts_with("not valid TOML") {
                assert!(!m.contains('\n'), "{m}");
            }
        }
    }
}

#[test]
fn unmutated_scenes_are_accepted() {
    let dir = fixture_dir();
    for t in [GENERATED, FROM_FILE] {
        let s = Scene::from_str_in(t, &dir).expect("valid scene");
        assert!(
            s.load_surface(&strata_runtime::resources::MemoryLimit::default())
                .is_ok()
        );
    }
}

proptest! {
    #![proptest_config(config(600))]

    #[test]
    fn mutated_generated_scenes_never_panic(edits in proptest::collection::vec(edit(), 1..5)) {
        let dir = fixture_dir();
        check(&apply(GENERATED, &edits), &dir);
    }

    #[test]
    fn mutated_file_scenes_never_panic(edits in proptest::collection::vec(edit(), 1..5)) {
        let dir = fixture_dir();
        check(&apply(FROM_FILE, &edits), &dir);
    }
}

proptest! {
    #![proptest_config(config(300))]

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,300}") {
        let dir = fixture_dir();
        check(&text, &dir);
    }
}
