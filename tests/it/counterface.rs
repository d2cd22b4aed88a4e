//! Two deformable bodies (physics.md §6.1): an elastic counterface in place
//! of the rigid flat. Frictionless normal displacements add, so
//! * the pair's kernel is the sum of both bodies' (checked against a direct evaluation
//!   of both S(k), and a BEM built from that sum by another route);
//! * two homogeneous half-spaces are one half-space of the composite E* (BEM periodic
//!   and not, full asperity, N and I models);
//! * two identical layered bodies are one body with E*/2 (same S): the asperity's
//!   radius is unchanged and its force halves;
//! * swapping the bodies changes nothing (bit for bit);
//! * a rough counterface is the summed heights on one body (bit for bit);
//! * a pair table is built within its tolerance and refused for anything else.
//!
//! Measured (tolerances ~10× these, docs/validation.md): pair S vs the sum of both S
//! 4.9e-16 (of max(S, 1)); identical layered bodies 4.0e-16; pair BEM vs the summed
//! kernel through `BemSolver::with_compliance` 6.7e-16; homogeneous pair vs composite
//! half-space 0 (the same operations: the required bounds 1e-12 BEM, 1e-10 the rest are
//! asserted).

use std::path::{Path, PathBuf};

use ndarray::Array2;
use strata_bem::{BemLoad, BemOptions, BemSolver, Geometry};
use strata_runtime::surface::Surface;
use strata_runtime::{Compliance, Solid, Stack};
use strata_tablegen::asperity::{Asperity, Options};

use crate::support::{fresh_dir, repo, strata_in};

fn stack_file(name: &str) -> PathBuf {
    repo().join("tables/stacks").join(name)
}

fn stack(name: &str) -> Stack {
    Stack::from_toml_file(&stack_file(name)).expect("stack")
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

use crate::support::paper_like_surface as surface;

fn heights(s: &Surface) -> Array2<f64> {
    let (n0, n1) = s.shape();
    Array2::from_shape_vec((n0, n1), s.heights().to_vec()).unwrap()
}

/// C(ρ) = 2S/(E*ρ) of the pair equals C_A + C_B from each body's own S.
#[test]
fn pair_kernel_is_the_sum_of_both_bodies() {
    let pairs = [
        ("paper-two-layer.toml", "half-space-steel.toml"),
        ("paper-two-layer.toml", "paper-two-layer-E2E1-0.2.toml"),
        ("coating-on-steel.toml", "paper-two-layer.toml"),
    ];
    let mut worst: f64 = 0.0;
    for (a, b) in pairs {
        let (sa, sb) = (stack(a), stack(b));
        let pair = sa.clone().against(sb.clone());
        let (ca, cb, cp) = (
            Compliance::new(&sa),
            Compliance::new(&sb),
            Compliance::new(&pair),
        );
        let (ea, eb, ep) = (
            sa.top_plane_strain_modulus(),
            sb.top_plane_strain_modulus(),
            pair.contact_modulus(),
        );
        assert!(
            rel(1.0 / ep, 1.0 / ea + 1.0 / eb) < 1e-15,
            "{a} + {b}: E* {:e}",
            rel(1.0 / ep, 1.0 / ea + 1.0 / eb)
        );
        for i in 0..=80 {
            let rho = 10f64.powf(-1.0 + 0.1 * i as f64) / 1e-4; // ρh₁ 0.1 … 1e7
            // S = E*(S_A/E*_A + S_B/E*_B), error in units of max(S, 1): a small S
            // (a rigid base at ρ → 0) is 1 + k_z with k_z near −1, exact to ε absolute.
            let direct = ep * (ca.s(rho) / ea + cb.s(rho) / eb);
            let e = (cp.s(rho) - direct).abs() / direct.max(1.0);
            worst = worst.max(e);
        }
        assert_eq!(cp.s(f64::INFINITY), 1.0, "{a} + {b}: S(∞)");
        let s0 = ep * (ca.s_at_zero() / ea + cb.s_at_zero() / eb);
        let e0 = (cp.s_at_zero() - s0).abs() / s0.max(1.0);
        assert!(
            e0 < 1e-15,
            "{a} + {b}: S(0) {} vs {s0} ({e0:e})",
            cp.s_at_zero()
        );
        worst = worst.max(e0);
    }
    eprintln!("pair S vs the sum of both: worst {worst:.1e}");
    assert!(worst < 5e-15, "worst {worst:e}");
}

/// The periodic BEM of a layered pair (both on rigid bases: the uniform modes add)
/// against a BEM given the summed kernel S_A + (E*_A/E*_B) S_B directly, normalised
/// by E*_A instead of the pair's E*.
#[test]
fn layered_pair_bem_equals_the_summed_kernel() {
    let (sa, sb) = (
        stack("paper-two-layer.toml"),
        stack("paper-two-layer-E2E1-0.2.toml"),
    );
    let pair = sa.clone().against(sb.clone());
    let s = surface(64, 11);
    let h = heights(&s);
    let (ca, cb) = (Compliance::new(&sa), Compliance::new(&sb));
    let (ea, eb) = (sa.top_plane_strain_modulus(), sb.top_plane_strain_modulus());
    let c0 =
        strata_bem::uniform_compliance(&sa).unwrap() + strata_bem::uniform_compliance(&sb).unwrap();
    let direct = BemSolver::with_compliance(
        &h,
        1e-3,
        ea,
        Some(c0),
        |k| ca.s(k) + ea / eb * cb.s(k),
        BemOptions::default(),
    )
    .unwrap();
    let solver =
        BemSolver::with_geometry(&h, Geometry::square(1e-3), &pair, BemOptions::default()).unwrap();
    let mut worst: f64 = 0.0;
    for d in [1e-6, 3e-6, 6e-6, 9e-6] {
        let (x, y) = (
            solver.solve(BemLoad::Approach(d)).unwrap(),
            direct.solve(BemLoad::Approach(d)).unwrap(),
        );
        worst = worst.max(rel(x.mean_pressure, y.mean_pressure));
        assert_eq!(x.area_fraction, y.area_fraction, "δ = {d}");
    }
    eprintln!("pair BEM vs summed kernel: worst {worst:.1e}");
    assert!(worst < 1e-14, "worst {worst:e}");
}

/// Two homogeneous half-spaces (steel on aluminium) against one half-space of the
/// composite E* (ν = 0, E = E*): BEM periodic and not, and the full asperity.
#[test]
fn homogeneous_pair_is_the_composite_half_space_bem_and_asperity() {
    let steel = Stack::half_space(210e9, 0.3).unwrap();
    let alu = Stack::half_space(70e9, 0.33).unwrap();
    let pair = steel.clone().against(alu);
    assert!(pair.is_homogeneous());
    let composite = Stack::half_space(pair.contact_modulus(), 0.0).unwrap();
    let s = surface(64, 3);
    let h = heights(&s);
    let mut worst: f64 = 0.0;
    for periodic in [true, false] {
        let g = Geometry {
            lx: 1e-3,
            ly: 1e-3,
            periodic,
        };
        let a = BemSolver::with_geometry(&h, g, &pair, BemOptions::default()).unwrap();
        let b = BemSolver::with_geometry(&h, g, &composite, BemOptions::default()).unwrap();
        for d in [1e-6, 4e-6, 8e-6] {
            let (x, y) = (
                a.solve(BemLoad::Approach(d)).unwrap(),
                b.solve(BemLoad::Approach(d)).unwrap(),
            );
            worst = worst.max(rel(x.mean_pressure, y.mean_pressure));
        }
    }
    eprintln!("homogeneous pair BEM: worst {worst:.1e}");
    assert!(worst < 1e-12, "BEM worst {worst:e}");
    let (ap, ac) = (
        Asperity::new(&pair, Options::default()).unwrap(),
        Asperity::new(&composite, Options::default()).unwrap(),
    );
    for d in [1e-8, 1e-6, 1e-4] {
        let (x, y) = (
            ap.paraboloid_at_delta(d, 1e-4).unwrap(),
            ac.paraboloid_at_delta(d, 1e-4).unwrap(),
        );
        assert!(
            rel(x.force, y.force) < 1e-10,
            "δ {d}: {} vs {}",
            x.force,
            y.force
        );
        assert!(rel(x.a, y.a) < 1e-10, "δ {d}: a");
    }
}

/// Two identical layered bodies: S of the pair is each body's, E* halves, so the
/// asperity's contact radius is the same and its force half (full Fredholm solution).
#[test]
fn identical_layered_bodies_halve_the_asperity_force() {
    let st = stack("paper-two-layer.toml");
    let pair = st.clone().against(st.clone());
    let (one, two) = (
        Asperity::new(&st, Options::default()).unwrap(),
        Asperity::new(&pair, Options::default()).unwrap(),
    );
    let mut worst: f64 = 0.0;
    for d in [1e-8, 1e-7, 1e-6, 1e-5, 1e-4] {
        let (x, y) = (
            one.paraboloid_at_delta(d, 1e-4).unwrap(),
            two.paraboloid_at_delta(d, 1e-4).unwrap(),
        );
        worst = worst.max(rel(x.a, y.a)).max(rel(x.force, 2.0 * y.force));
    }
    eprintln!("identical pair asperity: worst {worst:.1e}");
    assert!(worst < 5e-15, "worst {worst:e}");
}

fn write(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
}

const GEN: &str = "[surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 64\n\
                   fractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 5\n";

fn solve(cache: &Path, scene: &Path, out: &Path) -> String {
    let o = strata_in(cache)
        .args(["solve", "-q", "--no-plots", "--force"])
        .arg(scene)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{}: {}",
        scene.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    std::fs::read_to_string(out.join("curve.csv")).unwrap()
}

use crate::support::csv_rows as curve;

/// The three models on a steel/aluminium pair against the composite half-space, through
/// scenes: every column within 1e-10 (the BEM 1e-12).
#[test]
fn homogeneous_pair_scenes_equal_the_composite_half_space() {
    let d = fresh_dir("counterface", "homogeneous");
    let pair = Stack::half_space(210e9, 0.3)
        .unwrap()
        .against(Stack::half_space(70e9, 0.33).unwrap());
    let e = pair.contact_modulus();
    for (model, load, tol) in [
        ("independent", "mean_pressures = [1e6, 1e7, 1e8]", 1e-10),
        ("interacting", "mean_pressures = [1e6, 1e7, 1e8]", 1e-10),
        (
            "bem",
            "approach = { from = 1e-6, to = 8e-6, steps = 3 }",
            1e-12,
        ),
    ] {
        let a = d.join(format!("{model}-pair.toml"));
        let b = d.join(format!("{model}-composite.toml"));
        write(
            &a,
            &format!(
                "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 210e9\npoisson = 0.3\n\
                 [counterface]\n[counterface.base]\nkind = \"elastic\"\nyoung = 70e9\npoisson = 0.33\n\
                 {GEN}[model]\nkind = \"{model}\"\n[load]\n{load}\n"
            ),
        );
        write(
            &b,
            &format!(
                "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = {e:e}\npoisson = 0\n\
                 {GEN}[model]\nkind = \"{model}\"\n[load]\n{load}\n"
            ),
        );
        let (x, y) = (
            curve(&solve(&d, &a, &d.join(format!("{model}-a")))),
            curve(&solve(&d, &b, &d.join(format!("{model}-b")))),
        );
        assert_eq!(x.len(), y.len());
        let mut worst: f64 = 0.0;
        for (rx, ry) in x.iter().zip(&y) {
            for (u, v) in rx.iter().zip(ry) {
                worst = worst.max(rel(*u, *v));
            }
        }
        eprintln!("{model}: homogeneous pair vs composite, worst column {worst:.1e}");
        assert!(worst < tol, "{model}: worst {worst:e}");
    }
}

/// A layered pair and its swap: the same curve.csv, byte for byte (the N model on the
/// pair's table, one table serving both orders; and the BEM). The cache's side of it, a
/// pair and its swap naming one cached table, is tablegen's
/// `tablebuild::tests::a_pair_and_its_swap_share_a_cache_name`; the table here is built
/// without its random-point check (`--check-points 0`), which would be 80 % of its cost.
#[test]
fn swapping_the_bodies_changes_nothing() {
    let d = fresh_dir("counterface", "swap");
    let (p, s) = (
        stack_file("paper-two-layer.toml"),
        stack_file("coating-on-steel.toml"),
    );
    let table = d.join("pair.strata");
    let o = strata_in(&d)
        .args(["table", "build", "--check-points", "0", "-q"])
        .arg(&p)
        .arg("--counterface")
        .arg(&s)
        .arg("--out")
        .arg(&table)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (model, load) in [
        ("independent", "mean_pressures = [1e6, 1e7]"),
        ("bem", "approach = { from = 2e-6, to = 6e-6, steps = 2 }"),
    ] {
        let mut curves = Vec::new();
        for (i, (x, y)) in [(&p, &s), (&s, &p)].into_iter().enumerate() {
            let scene = d.join(format!("{model}-{i}.toml"));
            write(
                &scene,
                &format!(
                    "[stack]\nfile = {:?}\n[counterface]\nfile = {:?}\ntable = {:?}\n{GEN}[model]\nkind = \"{model}\"\n[load]\n{load}\n",
                    x.display(),
                    y.display(),
                    table.display()
                ),
            );
            curves.push(solve(&d, &scene, &d.join(format!("{model}-out-{i}"))));
        }
        assert_eq!(curves[0], curves[1], "{model}");
    }
}

/// `[counterface.surface]`: the composite surface h_A + h_B, equal bit for bit to the
/// summed heights given as one body's file against a smooth counterface (BEM, N model).
#[test]
fn rough_counterface_is_the_summed_heights() {
    let d = fresh_dir("counterface", "rough");
    let (a, b) = (surface(64, 5), surface(64, 6));
    let sum: Vec<f64> = a
        .heights()
        .iter()
        .zip(b.heights())
        .map(|(x, y)| x + y)
        .collect();
    let npy = d.join("sum.npy");
    Surface::new(sum, 64, 64, 1e-3, true)
        .unwrap()
        .write_npy(&npy)
        .unwrap();
    let body = "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 210e9\npoisson = 0.3\n\
                [counterface]\n[counterface.base]\nkind = \"elastic\"\nyoung = 70e9\npoisson = 0.33\n";
    for (model, load) in [
        ("bem", "approach = { from = 2e-6, to = 1e-5, steps = 3 }"),
        ("independent", "mean_pressures = [1e6, 1e7]"),
    ] {
        let rough = d.join(format!("{model}-rough.toml"));
        write(
            &rough,
            &format!(
                "{body}[counterface.surface]\nperiodic = true\n[counterface.surface.generate]\nsize = 1e-3\n\
                 grid = 64\nfractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 6\n\
                 {GEN}[model]\nkind = \"{model}\"\n[load]\n{load}\n"
            ),
        );
        let summed = d.join(format!("{model}-summed.toml"));
        write(
            &summed,
            &format!(
                "{body}[surface]\nfile = \"sum.npy\"\nsize = 1e-3\nperiodic = true\n[model]\nkind = \"{model}\"\n[load]\n{load}\n"
            ),
        );
        let (x, y) = (
            solve(&d, &rough, &d.join(format!("{model}-r"))),
            solve(&d, &summed, &d.join(format!("{model}-s"))),
        );
        assert_eq!(x, y, "{model}");
    }
}

/// A pair table: `table check` passes (200 random points against direct quadrature;
/// the build's own 1 000-point check is left to the second pair below), it serves the
/// pair and its swap but neither body alone nor another pair; `table info` names both
/// bodies. A second pair (the coating against itself) is built within its stated
/// tolerance as measured by the builder's 1 000 points.
#[test]
fn pair_table_serves_the_pair_only() {
    let d = fresh_dir("counterface", "table");
    let (p, s) = (
        stack_file("paper-two-layer.toml"),
        stack_file("paper-two-layer-E2E1-0.2.toml"),
    );
    let out = d.join("pair.strata");
    let o = strata_in(&d)
        .args(["table", "build"])
        .arg(&p)
        .arg("--counterface")
        .arg(&s)
        .args(["--check-points", "0"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = strata_in(&d)
        .args(["table", "check", "--points", "200"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = strata_in(&d)
        .args(["table", "info"])
        .arg(&out)
        .output()
        .unwrap();
    let info = String::from_utf8_lossy(&o.stdout);
    assert!(
        info.contains("counterface: paper two-layer, E2/E1 = 0.2"),
        "{info}"
    );
    assert!(info.contains("[[counterface.layer]]"), "{info}");
    let t = strata_runtime::table::Table::load(&out).unwrap();
    let (sp, ss) = (
        stack("paper-two-layer.toml"),
        stack("paper-two-layer-E2E1-0.2.toml"),
    );
    assert!(t.law_for(&sp.clone().against(ss.clone())).is_ok());
    assert!(t.law_for(&ss.clone().against(sp.clone())).is_ok());
    let alone = t.law_for(&sp).unwrap_err().to_string();
    assert!(alone.contains("counterface"), "{alone}");
    let other = t
        .law_for(&sp.clone().against(sp.clone()))
        .unwrap_err()
        .to_string();
    // the part that differs is named: the counterface's layer 2 (its modulus)
    assert!(
        other.contains("the counterface's layer 2") && !other.contains("first body"),
        "{other}"
    );
    // The paper's coating against the same coating: built within the
    // table tolerance (the builder checks 1 000 points and refuses a table above it).
    let same = d.join("same.strata");
    let o = strata_in(&d)
        .args(["table", "build"])
        .arg(&p)
        .arg("--counterface")
        .arg(&p)
        .arg("--out")
        .arg(&same)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let t2 = strata_runtime::table::Table::load(&same).unwrap();
    let err = t2.header.interp_error.expect("measured at build");
    assert!(
        err.chi <= 1e-4 && err.zeta <= 1e-4 && err.g <= 1e-4,
        "{err:?}"
    );
    // The single-stack family table refuses the pair.
    let fam =
        strata_runtime::table::Table::load(&repo().join("tables/paper-two-layer.strata")).unwrap();
    let e = fam.law_for(&sp.against(ss)).unwrap_err().to_string();
    assert!(e.contains("build a table for the pair"), "{e}");
}

/// `strata asperity --counterface`: the pair of identical bodies halves the force at the
/// same radius; swapping the files prints the same rows.
#[test]
fn asperity_cli_counterface() {
    let d = fresh_dir("counterface", "asperity");
    let (p, s) = (
        stack_file("paper-two-layer.toml"),
        stack_file("half-space-steel.toml"),
    );
    let run = |x: &Path, y: Option<&Path>| {
        let mut c = strata_in(&d);
        c.arg("asperity")
            .arg(x)
            .args(["--radius", "1e-4", "--delta", "1e-7,1e-6,1e-5"]);
        if let Some(y) = y {
            c.arg("--counterface").arg(y);
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        curve(&String::from_utf8_lossy(&o.stdout))
    };
    let (one, two) = (run(&p, None), run(&p, Some(&p)));
    for (x, y) in one.iter().zip(&two) {
        assert_eq!(x[1], y[1], "radius");
        assert!(rel(x[2], 2.0 * y[2]) < 1e-12, "{} vs 2 × {}", x[2], y[2]);
    }
    assert_eq!(run(&p, Some(&s)), run(&s, Some(&p)));
}

/// Scene errors name the `[counterface]` field.
#[test]
fn counterface_scene_errors_name_the_field() {
    let d = fresh_dir("counterface", "errors");
    let steel = stack_file("half-space-steel.toml");
    let head = format!("[stack]\nfile = \"{}\"\n", steel.display());
    let tail = format!("{GEN}[model]\nkind = \"bem\"\n[load]\nmean_pressures = [1e6]\n");
    let cases = [
        (
            "[counterface]\nkind = \"soft\"\n".to_string(),
            "counterface.kind",
        ),
        (
            format!(
                "[counterface]\nkind = \"rigid\"\nfile = \"{}\"\n",
                steel.display()
            ),
            "counterface.file",
        ),
        (
            "[counterface]\nkind = \"elastic\"\n".to_string(),
            "counterface.file",
        ),
        (
            "[counterface]\nfile = \"nope.toml\"\n".to_string(),
            "counterface.file",
        ),
        (
            "[counterface]\nbogus = 1\n".to_string(),
            "counterface.bogus",
        ),
        (
            "[counterface]\n[counterface.base]\nkind = \"elastic\"\nyoung = -1\npoisson = 0.3\n"
                .to_string(),
            "young",
        ),
        (
            format!(
                "[counterface]\nfile = \"{}\"\n[counterface.surface]\nperiodic = true\n\
                 [counterface.surface.generate]\nsize = 1e-3\ngrid = 32\nfractal_dimension = 2.4\n\
                 k_min = 2\nk_max = 10\nrms = 1e-6\nseed = 9\n",
                steel.display()
            ),
            "its grid (32×32) differs from the first body's (64×64)",
        ),
        (
            format!(
                "[counterface]\nfile = \"{}\"\n[counterface.surface]\nwrong = 1\n",
                steel.display()
            ),
            "counterface.surface.wrong",
        ),
    ];
    for (i, (cf, want)) in cases.iter().enumerate() {
        let scene = d.join(format!("bad-{i}.toml"));
        write(&scene, &format!("{head}{cf}{tail}"));
        let o = strata_in(&d)
            .args(["solve", "-q", "--no-plots", "--out"])
            .arg(d.join(format!("out-{i}")))
            .arg(&scene)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "case {i} ran");
        assert!(err.contains(want), "case {i}: want `{want}` in: {err}");
    }
    // `stack.table` (a single-stack table) with an elastic counterface.
    let scene = d.join("table.toml");
    write(
        &scene,
        &format!(
            "[stack]\nfile = \"{}\"\ntable = \"{}\"\n[counterface]\nfile = \"{}\"\n{tail}",
            stack_file("paper-two-layer.toml").display(),
            repo().join("tables/paper-two-layer.strata").display(),
            steel.display()
        ),
    );
    let o = strata_in(&d)
        .args(["solve", "-q", "--no-plots", "--out"])
        .arg(d.join("out-table"))
        .arg(&scene)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("stack.table") && err.contains("counterface.table"),
        "{err}"
    );
}

/// `counterface.*` sweep axes: each case equals `strata solve` of the scene with that
/// counterface (here the counterface's base modulus, 70 and 210 GPa), and a counterface
/// axis on a scene without an elastic counterface is refused by name.
#[test]
fn sweep_counterface_axes() {
    let d = fresh_dir("counterface", "sweep");
    let scene = |young: &str| {
        format!(
            "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 210e9\npoisson = 0.3\n\
             [counterface]\n[counterface.base]\nkind = \"elastic\"\nyoung = {young}\npoisson = 0.33\n\
             {GEN}[model]\nkind = \"independent\"\n[load]\nmean_pressures = [1e6, 1e7]\n"
        )
    };
    let prefixed = |text: &str| {
        text.replace("[stack", "[scene.stack")
            .replace("[counterface", "[scene.counterface")
            .replace("[surface", "[scene.surface")
            .replace("[model", "[scene.model")
            .replace("[load", "[scene.load")
    };
    let sweep = d.join("sweep.toml");
    write(
        &sweep,
        &format!(
            "{}[sweep]\ncounterface.base.young = [70e9, 210e9]\n",
            prefixed(&scene("1e9"))
        ),
    );
    let out = d.join("out");
    let o = strata_in(&d)
        .args(["sweep", "-q", "--no-plots"])
        .arg(&sweep)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    for (case, young) in [(0, "70e9"), (1, "210e9")] {
        let one = d.join(format!("case{case}.toml"));
        write(&one, &scene(young));
        let single = solve(&d, &one, &d.join(format!("case{case}")));
        let singles: Vec<&str> = single.lines().skip(1).collect();
        for (k, line) in singles.iter().enumerate() {
            let row = &rows[case * 2 + k];
            // case, counterface.base.young, model, step, then the curve.csv columns
            assert_eq!(row[4..].join(","), *line, "case {case} step {k}");
        }
    }
    let bad = d.join("bad.toml");
    write(
        &bad,
        &format!(
            "{}[sweep]\ncounterface.base.young = [70e9]\n",
            prefixed(&homogeneous_scene_text())
        ),
    );
    let o = strata_in(&d)
        .args(["sweep", "-q", "--no-plots"])
        .arg(&bad)
        .arg("--out")
        .arg(d.join("bad-out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("sweep.counterface.base.young") && err.contains("no elastic counterface"),
        "{err}"
    );
}

fn homogeneous_scene_text() -> String {
    format!(
        "[stack]\n[stack.base]\nkind = \"elastic\"\nyoung = 210e9\npoisson = 0.3\n{GEN}[model]\nkind = \"independent\"\n[load]\nmean_pressures = [1e6]\n"
    )
}

/// The approximate asperity (χ, ζ, g of the second-order approximation) of two
/// homogeneous half-spaces is the composite half-space's: χ = ζ = 1, g = 0.
#[test]
fn homogeneous_pair_approximate_asperity_is_hertz() {
    let pair = Stack::half_space(210e9, 0.3)
        .unwrap()
        .against(Stack::half_space(70e9, 0.33).unwrap());
    let ap = strata_tablegen::approx::Approx::new(&pair);
    for a in [1e-7, 1e-5, 1e-3] {
        let (chi, zeta) = ap.chi_zeta(a).unwrap();
        assert!(
            (chi - 1.0).abs() < 1e-10 && (zeta - 1.0).abs() < 1e-10,
            "a {a}: {chi} {zeta}"
        );
        assert!(ap.g(a, 3.0 * a).unwrap().abs() < 1e-10 * a * a, "a {a}: g");
    }
}

/// `[counterface] kind = "rigid"` names the default: the same curve as no counterface.
#[test]
fn rigid_counterface_is_the_default() {
    let d = fresh_dir("counterface", "rigid");
    let body = format!(
        "[stack]\nfile = \"{}\"\n{GEN}[model]\nkind = \"bem\"\n[load]\nmean_pressures = [1e6, 1e7]\n",
        stack_file("paper-two-layer.toml").display()
    );
    let (a, b) = (d.join("none.toml"), d.join("rigid.toml"));
    write(&a, &body);
    write(&b, &format!("{body}[counterface]\nkind = \"rigid\"\n"));
    assert_eq!(
        solve(&d, &a, &d.join("none")),
        solve(&d, &b, &d.join("rigid"))
    );
}

/// Hard cases: the paper's stack against half-spaces 1e-4 and 1e4 times its top modulus
/// and a ν = 0.5 layer on a ν = 0.5 base: the pair's S finite and positive for ρh₁ from
/// 1e-4 to 1e4 with S(∞) = 1, the contact modulus between 0 and the softer body's, and
/// the full asperity finite with its force below the rigid-flat one.
#[test]
fn extreme_pairs_stay_finite() {
    let paper = stack("paper-two-layer.toml");
    let incompressible = Stack::new(
        vec![strata_runtime::Layer {
            thickness: 1e-5,
            young: 1e6,
            poisson: 0.5,
        }],
        strata_runtime::Base::Elastic {
            young: 1e9,
            poisson: 0.5,
        },
    )
    .unwrap();
    let rigid = Asperity::new(&paper, Options::default())
        .unwrap()
        .paraboloid_at_delta(1e-6, 1e-4)
        .unwrap();
    for c in [
        Stack::half_space(4e5, 0.5).unwrap(),
        Stack::half_space(4e13, 0.3).unwrap(),
        incompressible,
    ] {
        let pair = paper.clone().against(c.clone());
        let e = pair.contact_modulus();
        let softer = paper
            .top_plane_strain_modulus()
            .min(c.top_plane_strain_modulus());
        assert!(e > 0.0 && e <= softer, "{e} vs {softer}");
        let comp = Compliance::new(&pair);
        for i in 0..=80 {
            let rho = 10f64.powf(-4.0 + 0.1 * i as f64) / 1e-4;
            let s = comp.s(rho);
            assert!(s.is_finite() && s > 0.0, "{c:?}: S({rho}) = {s}");
        }
        assert_eq!(comp.s(f64::INFINITY), 1.0);
        let a = Asperity::new(&pair, Options::default())
            .unwrap()
            .paraboloid_at_delta(1e-6, 1e-4)
            .unwrap();
        assert!(
            a.force.is_finite() && a.force > 0.0 && a.force <= rigid.force * (1.0 + 1e-9),
            "{c:?}: {} vs rigid {}",
            a.force,
            rigid.force
        );
    }
}

/// A stack file with its own `[counterface]` is neither replaced silently by a scene's
/// elastic `[counterface]` or `--counterface`, nor overridden by a scene's explicit rigid
/// flat: each ambiguity is refused naming the field and the stack file (the stack
/// file's was replaced, or used, without a word); alone it is used.
#[test]
fn a_stack_files_own_counterface_is_not_replaced_silently() {
    let d = fresh_dir("counterface", "two-counterfaces");
    let own = d.join("paired.toml");
    std::fs::write(
        &own,
        "[[layer]]\nthickness = 1e-4\nyoung = 4e9\npoisson = 0.3\n\
         [base]\nkind = \"elastic\"\nyoung = 210e9\npoisson = 0.3\n\
         [counterface]\n[counterface.base]\nkind = \"elastic\"\nyoung = 70e9\npoisson = 0.3\n",
    )
    .unwrap();
    let steel = stack_file("half-space-steel.toml");
    let surface = "[surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 32\n\
                   fractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 1e-6\nseed = 1\n\
                   [model]\nkind = \"bem\"\n[load]\nseparations = [2e-6]\n";
    let scene =
        |counterface: &str| format!("[stack]\nfile = \"paired.toml\"\n{counterface}{surface}");
    for (cf, what) in [
        (
            format!("[counterface]\nfile = {:?}\n", steel.display().to_string()),
            "an elastic [counterface] too",
        ),
        (
            "[counterface]\nkind = \"rigid\"\n".to_string(),
            "kind = \"rigid\"",
        ),
    ] {
        let e = strata::scene::Scene::from_str_in(&scene(&cf), &d)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("counterface") && e.contains("paired.toml") && e.contains(what),
            "{e}"
        );
    }
    // alone, the stack file's counterface is the one used
    let s = strata::scene::Scene::from_str_in(&scene(""), &d).unwrap();
    assert!(s.bodies.counterface.stack().is_some());
    // the command line: --counterface on such a stack
    let o = strata_in(&d)
        .args([
            "asperity",
            own.to_str().unwrap(),
            "--radius",
            "1e-4",
            "--delta",
            "1e-7",
        ])
        .arg("--counterface")
        .arg(&steel)
        .output()
        .unwrap();
    let e = crate::support::stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("--counterface") && e.contains("paired.toml") && e.contains("one place"),
        "{e}"
    );
}

/// A pair scene whose `counterface.table` is a table of the stack alone: the error
/// names `counterface.table` (it named `stack.table`, which the scene does not have).
#[test]
fn a_wrong_pair_table_names_counterface_table() {
    let d = fresh_dir("counterface", "wrong-pair-table");
    let table = repo().join("tables/paper-two-layer.strata");
    let scene = d.join("s.toml");
    std::fs::write(
        &scene,
        format!(
            "[stack]\nfile = {:?}\n[counterface]\nfile = {:?}\ntable = {:?}\n\
             [surface]\nperiodic = true\n[surface.generate]\nsize = 1e-3\ngrid = 32\n\
             fractal_dimension = 2.4\nk_min = 2\nk_max = 8\nrms = 1e-6\nseed = 1\n\
             [model]\nkind = \"independent\"\n[load]\nseparations = [2e-6]\n",
            stack_file("paper-two-layer.toml").display().to_string(),
            stack_file("half-space-steel.toml").display().to_string(),
            table.display().to_string(),
        ),
    )
    .unwrap();
    let o = strata_in(&d)
        .args(["solve", scene.to_str().unwrap(), "--no-plots", "--out"])
        .arg(d.join("out"))
        .output()
        .unwrap();
    let e = crate::support::stderr_of(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(
        e.contains("counterface.table")
            && e.contains("paper-two-layer.strata")
            && !e.contains("stack.table"),
        "{e}"
    );
}
