//! The interface conductance of the BEM's contact sets (physics.md §6.2):
//! `[conductance]` scenes through `strata solve`, and one spot on a layered stack against
//! the Fredholm spot solver of `strata conductance` (an independent method: dual
//! integral equations in Hankel space against CG on a pixel set in Fourier space).

use strata_bem::{ConductanceOptions, ConductanceSolver, Conductor, Geometry};
use strata_runtime::Stack;
use strata_runtime::conduction::{ConductionCompliance, ConductionKind};
use strata_runtime::stack::{Base, BaseConduction, Conductivity, Layer};
use strata_tablegen::spot::Spot;

use crate::support::{fresh_dir, repo, stderr_of};

const SCENE: &str = "[stack]\nfile = \"STACK\"\n[surface]\n[surface.generate]\nsize = 1e-3\ngrid = 64\n\
                     fractal_dimension = 2.4\nk_min = 2\nk_max = 10\nrms = 3.4e-6\nseed = 5\n\
                     [model]\nkind = \"bem\"\n[load]\napproach = { from = 1e-6, to = 7e-6, steps = 4 }\n";

fn scene_text(extra: &str) -> String {
    let stack = repo().join("tables/stacks/coating-on-steel-conducting.toml");
    format!(
        "{}{extra}",
        SCENE.replace("STACK", &stack.display().to_string())
    )
}

use crate::support::solve_text as solve;

const HEADER: &str =
    "delta,gap,mean_pressure,pressure_ratio,area_fraction,contacts,stiffness,valid";

/// `[conductance]` through `strata solve`: the `conductance` column (after
/// `plastic_area_fraction` when both are asked for), curve.json's per-step values and
/// summary; the mechanics are the scene's without it, byte for byte; the conductance
/// grows with the load and a conducting flat conducts less than a perfect one; a missing
/// counterface conduction is refused by name; the I model with isolated images solves.
#[test]
fn conductance_scenes_through_solve() {
    let d = fresh_dir("conductance_bem", "scenes");
    let flat = "[counterface]\nkind = \"rigid\"\nthermal_conductivity = 50\n";
    let (o, out) = solve(
        &d,
        "thermal",
        &scene_text(&format!("[conductance]\nkind = \"thermal\"\n{flat}")),
    );
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(out.join("curve.csv")).unwrap();
    assert!(csv.starts_with(&format!("{HEADER},conductance\n")), "{csv}");
    let (o0, plain) = solve(&d, "plain", &scene_text(flat));
    assert!(o0.status.success(), "{}", stderr_of(&o0));
    let plain_csv = std::fs::read_to_string(plain.join("curve.csv")).unwrap();
    assert!(plain_csv.starts_with(&format!("{HEADER}\n")));
    // the mechanics unchanged: every line is the plain one plus the conductance
    let mut h = Vec::new();
    for (a, b) in csv.lines().zip(plain_csv.lines()).skip(1) {
        let (head, last) = a.rsplit_once(',').unwrap();
        assert_eq!(head, b);
        h.push(last.parse::<f64>().unwrap());
    }
    assert_eq!(h.len(), 4);
    assert!(h.windows(2).all(|w| w[1] > w[0] && w[0] > 0.0), "{h:?}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("curve.json")).unwrap()).unwrap();
    assert_eq!(json["conductance"]["kind"], "thermal");
    assert_eq!(json["conductance"]["units"]["conductance"], "W/(m^2 K)");
    assert_eq!(json["steps"][3]["conductance"].as_f64().unwrap(), h[3]);
    assert!(json["steps"][3]["conductance_iterations"].as_u64().unwrap() > 0);
    assert!(json.get("conductance_steps").is_none());
    let plain_json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(plain.join("curve.json")).unwrap()).unwrap();
    assert!(plain_json.get("conductance").is_none());
    assert!(plain_json["steps"][0].get("conductance").is_none());
    // a perfect counterface conducts better; electrical uses the other conductivities
    let (o, perfect) = solve(
        &d,
        "perfect",
        &scene_text(
            "[conductance]\nkind = \"electrical\"\n[counterface]\nconduction = \"perfect\"\n",
        ),
    );
    assert!(o.status.success(), "{}", stderr_of(&o));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(perfect.join("curve.json")).unwrap())
            .unwrap();
    assert_eq!(json["conductance"]["units"]["conductance"], "S/m^2");
    assert!(json["steps"][3]["conductance"].as_f64().unwrap() > 1e3 * h[3]);
    // with plasticity: both columns, plastic_area_fraction first
    let (o, both) = solve(
        &d,
        "both",
        &scene_text(&format!(
            "[plasticity]\nhardness = 5e9\n[conductance]\nkind = \"thermal\"\n{flat}"
        )),
    );
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(both.join("curve.csv")).unwrap();
    assert!(
        csv.starts_with(&format!("{HEADER},plastic_area_fraction,conductance\n")),
        "{csv}"
    );
    // refusals name the field
    let (o, _) = solve(
        &d,
        "missing",
        &scene_text("[conductance]\nkind = \"thermal\"\n"),
    );
    assert!(!o.status.success());
    assert!(
        stderr_of(&o).contains("counterface.thermal_conductivity"),
        "{}",
        stderr_of(&o)
    );
    let (o, _) = solve(
        &d,
        "imodel",
        &scene_text(&format!("[conductance]\nkind = \"thermal\"\n{flat}")).replace(
            "kind = \"bem\"",
            "kind = \"interacting\"\nimages = \"isolated\"",
        ),
    );
    // the I model on an isolated sample of the coated stack: the layered point-source
    // field of unbounded bodies (refused before it was built)
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(d.join("imodel").join("curve.csv")).unwrap();
    let hi: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.rsplit_once(',').unwrap().1.parse().unwrap())
        .collect();
    assert!(hi.windows(2).all(|w| w[1] > w[0] && w[0] > 0.0), "{hi:?}");
}

/// One isothermal disc on a two-layer conductor over an isothermal sink, in a periodic
/// cell of side L = 8a: the BEM against the Fredholm spot solver G(a) = 4k₁aψ(a).
/// The sink confines each spot's field to ~ its depth H = a, so the images add only
/// e^{−πL/(2H)} ≈ 4e-6 and the cell's one correction is the excluded k = 0 term:
/// 1/G_cell = 1/G(a) − (Σhᵢ/kᵢ)/L². With a the radius of the disc's pixel area the
/// error is first order in the pixel and halves with each grid doubling.
#[test]
fn one_spot_on_a_layered_stack_matches_the_spot_solver() {
    let a = 1e-4;
    let l = 8.0 * a;
    let k = Conductivity::thermal;
    let layer = |h: f64| Layer {
        thickness: h,
        young: 1e9,
        poisson: 0.3,
    };
    let stack = Stack::new(vec![layer(0.5 * a), layer(0.5 * a)], Base::Rigid)
        .unwrap()
        .with_conduction(
            vec![k(2.0), k(20.0)],
            Conductivity::default(),
            BaseConduction::Isothermal,
        )
        .unwrap();
    let cc = ConductionCompliance::new(&stack, ConductionKind::Thermal).unwrap();
    let spot = Spot::new(&stack, ConductionKind::Thermal).unwrap();
    let mut errors = Vec::new();
    for n in [64, 128, 256] {
        let s = ConductanceSolver::new(
            n,
            n,
            Geometry::square(l),
            Conductor::Layered(&cc),
            Conductor::Perfect,
            ConductanceOptions::default(),
        )
        .unwrap();
        let dx = l / n as f64;
        let c = (n as f64 - 1.0) / 2.0;
        let set: Vec<bool> = (0..n * n)
            .map(|i| ((i / n) as f64 - c).hypot((i % n) as f64 - c) * dx <= a)
            .collect();
        let pts = set.iter().filter(|&&v| v).count() as f64;
        let a_eq = (pts / std::f64::consts::PI).sqrt() * dx;
        let g_bem = s.solve(&set).unwrap().conductance * l * l;
        let g_spot = spot.conductance(a_eq).unwrap().conductance;
        let g_cell = 1.0 / (1.0 / g_spot - cc.series_resistance() / (l * l));
        let e = g_bem / g_cell - 1.0;
        eprintln!(
            "layered spot a/dx {}: BEM {g_bem:e} vs spot solver {g_cell:e} (ψ = {:.6}): {e:.3e}",
            a / dx,
            g_spot / (4.0 * 2.0 * a_eq)
        );
        errors.push(e);
    }
    for w in errors.windows(2) {
        let ratio = w[0] / w[1];
        assert!((1.8..2.2).contains(&ratio), "{errors:?}");
    }
    let last = errors[errors.len() - 1];
    assert!(last.abs() < 0.02, "{errors:?}");
    // measured: −2.95e-2, −1.46e-2, −7.03e-3 at a/dx = 8, 16, 32; extrapolated 5.5e-4
    let extrapolated = 2.0 * errors[2] - errors[1];
    assert!(extrapolated.abs() < 5e-3, "{errors:?}");
}

/// The N model's conductance (`model.kind = "independent"`): Σ G(aᵢ)/A₀ over its own
/// contact radii, each spot's G with both bodies in series, checked against direct
/// spot solves (homogeneous: 4k_s a exactly; the coated steel: the Fredholm ψ at every
/// radius, against the interpolated table); and beside the BEM on the same scene.
#[test]
fn n_model_sums_the_spots() {
    use strata::engine::{EngineOptions, Quiet, solve};
    use strata::scene::Scene;
    use strata::spots::SpotSum;
    let d = fresh_dir("conductance_bem", "nmodel");
    let opts = EngineOptions {
        cache_dir: Some(d.join("cache")),
        ..Default::default()
    };
    let flat = "[conductance]\nkind = \"thermal\"\n[counterface]\nkind = \"rigid\"\nthermal_conductivity = 50\n";
    let homogeneous = "[stack]\n[[stack.layer]]\nthickness = 1e-4\nyoung = 2e11\npoisson = 0.3\n\
                       thermal_conductivity = 30\n[stack.base]\nkind = \"elastic\"\nyoung = 2e11\n\
                       poisson = 0.3\nthermal_conductivity = 30\n";
    let coated = format!(
        "[stack]\nfile = \"{}\"\n",
        repo()
            .join("tables/stacks/coating-on-steel-conducting.toml")
            .display()
    );
    let rest = SCENE.split_once("[surface]").unwrap().1;
    for (name, stack) in [("homogeneous", homogeneous.to_string()), ("coated", coated)] {
        let mut h = Vec::new();
        for model in ["independent", "bem"] {
            let text = format!("{stack}[surface]{rest}{flat}")
                .replace("kind = \"bem\"", &format!("kind = \"{model}\""));
            let path = d.join(format!("{name}-{model}.toml"));
            std::fs::write(&path, &text).unwrap();
            let scene = Scene::from_file(&path).unwrap();
            let sol = solve(&scene, None, &opts, &mut Quiet).unwrap();
            let hc: Vec<f64> = sol.conductances().unwrap();
            if model == "independent" {
                let area = sol.summary.nominal_area;
                let sum = SpotSum::new(&scene, scene.conductance.as_ref().unwrap()).unwrap();
                let mut worst: f64 = 0.0;
                for (s, &got) in sol.steps.iter().zip(&hc) {
                    let direct: f64 = s
                        .radii
                        .iter()
                        .filter(|&&a| a > 0.0)
                        .map(|&a| {
                            if name == "homogeneous" {
                                4.0 * a / (1.0 / 30.0 + 1.0 / 50.0)
                            } else {
                                sum.direct(a).unwrap()
                            }
                        })
                        .sum::<f64>()
                        / area;
                    worst = worst.max((got / direct - 1.0).abs());
                }
                eprintln!("N model {name}: Σ G(a)/A0 vs direct spot solves: {worst:.2e}");
                // homogeneous: round-off; coated: the ψ table's interpolation (≤ 5e-6)
                assert!(worst < 5e-5, "{name}: {worst}");
                // the ψ table kept in the table cache: a second solve reads it, and the
                // h_c equals the in-memory table's bit for bit
                let psi_files = || {
                    std::fs::read_dir(d.join("cache"))
                        .map(|r| {
                            r.filter_map(|e| e.ok())
                                .filter(|e| e.file_name().to_string_lossy().starts_with("psi-"))
                                .count()
                        })
                        .unwrap_or(0)
                };
                let again = solve(&scene, None, &opts, &mut Quiet).unwrap();
                assert_eq!(again.conductance, sol.conductance);
                let uncached = sum.conductances(&sol.steps, area).unwrap();
                assert_eq!(uncached, hc, "{name}: cached vs in-memory ψ table");
                assert_eq!(psi_files(), usize::from(name == "coated"), "{name}");
            }
            h.push(hc);
        }
        // beside the BEM (64², not a check of either): the same order, N below
        for (n, b) in h[0].iter().zip(&h[1]) {
            eprintln!("{name}: N model {n:e} BEM {b:e}: N/BEM {:.3}", n / b);
            assert!(*n > 0.2 * b && *n < 5.0 * b, "{name}: {n} vs {b}");
        }
    }
}

/// `strata law --format all` of a `[conductance]` scene (BEM, N and I model): the
/// CSV's `conductance` column, the
/// `*GAP CONDUCTANCE, PRESSURE` block after the pressure-overclosure table (first line
/// `0., 0.`, pressures strictly increasing and equal to the table's, conductances those
/// of the JSON's samples), nothing of it without `[conductance]`; CalculiX 2.20 reads
/// the deck with the block (a warning for the PRESSURE parameter, no error).
#[test]
fn law_writes_gap_conductance() {
    let d = fresh_dir("conductance_bem", "law");
    let flat = "[counterface]\nkind = \"rigid\"\nthermal_conductivity = 50\n";
    for model in ["bem", "independent", "interacting"] {
        let scene = d.join(format!("{model}.toml"));
        std::fs::write(
            &scene,
            scene_text(&format!("[conductance]\nkind = \"thermal\"\n{flat}"))
                .replace("kind = \"bem\"", &format!("kind = \"{model}\"")),
        )
        .unwrap();
        let o = crate::support::strata_in(&d)
            .args(["law", "-q"])
            .arg(&scene)
            .arg("--out")
            .arg(d.join(model))
            .args(["--format", "all", "--samples", "8"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr_of(&o));
        let inp = std::fs::read_to_string(d.join(format!("{model}.inp"))).unwrap();
        let (table, gap) = inp.split_once("*GAP CONDUCTANCE, PRESSURE\n").unwrap();
        assert!(table.contains("*SURFACE BEHAVIOR"));
        let read =
            |l: &str| -> Vec<f64> { l.split(',').map(|x| x.trim().parse().unwrap()).collect() };
        let lines: Vec<Vec<f64>> = gap.lines().map(read).collect();
        assert_eq!(lines[0], vec![0.0, 0.0]);
        let json: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(d.join(format!("{model}.json"))).unwrap(),
        )
        .unwrap();
        let law = json["law"].as_array().unwrap();
        assert_eq!(lines.len(), law.len(), "{model}");
        assert_eq!(json["units"]["conductance"], "W/(m^2 K)");
        // the CSV's conductance column: the JSON's samples (empty where infinite)
        let csv = std::fs::read_to_string(d.join(format!("{model}.csv"))).unwrap();
        assert!(
            csv.starts_with(
                "gap,overclosure,mean_pressure,area_fraction,dp_dg,valid,conductance\n"
            ),
            "{csv}"
        );
        for (row, s) in csv.lines().skip(1).zip(law) {
            let cell = row.rsplit(',').next().unwrap();
            match s["conductance"].as_f64() {
                // the same text in both files; serde_json's default float parser (no
                // `float_roundtrip`) may land 1 ulp off the correctly rounded value
                Some(h) => {
                    let c = cell.parse::<f64>().unwrap();
                    assert!(
                        c == h || (c / h - 1.0).abs() <= 2.0 * f64::EPSILON,
                        "{model}: {row}: {h}"
                    );
                }
                None => assert_eq!(cell, "", "{model}: {row}"),
            }
        }
        for (l, s) in lines.iter().zip(law).skip(1) {
            let (h, p) = (
                s["conductance"].as_f64().unwrap(),
                s["mean_pressure"].as_f64().unwrap(),
            );
            assert!((l[0] / h - 1.0).abs() < 1e-13 && (l[1] / p - 1.0).abs() < 1e-13);
        }
        assert!(
            lines
                .windows(2)
                .all(|w| w[1][1] > w[0][1] && w[1][0] > w[0][0])
        );
        if model == "bem"
            && let Some(ccx) =
                crate::tools::optional_tool("ccx", "-v", "apt-get install calculix-ccx")
        {
            let run = d.join("ccx");
            std::fs::create_dir_all(&run).unwrap();
            std::fs::copy(
                repo().join("examples/calculix/rough_block.inp"),
                run.join("rough_block.inp"),
            )
            .unwrap();
            std::fs::write(run.join("law.inp"), &inp).unwrap();
            let o = std::process::Command::new(ccx)
                .args(["-i", "rough_block"])
                .current_dir(&run)
                .output()
                .unwrap();
            let log = String::from_utf8_lossy(&o.stdout);
            assert!(o.status.success() && !log.contains("*ERROR"), "{log}");
            assert!(
                log.contains("parameter not recognized:\n          PRESSURE"),
                "{log}"
            );
        }
    }
    // without [conductance]: no block
    let scene = d.join("plain.toml");
    std::fs::write(&scene, scene_text(flat)).unwrap();
    let o = crate::support::strata_in(&d)
        .args(["law", "-q"])
        .arg(&scene)
        .arg("--out")
        .arg(d.join("plain.inp"))
        .args(["--samples", "8"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(
        !std::fs::read_to_string(d.join("plain.inp"))
            .unwrap()
            .contains("GAP")
    );
}

/// `strata compare` on a `[conductance]` scene: conductance.csv (the N and I models'
/// h_c at every BEM step's separation and pressure against the BEM's) and a section in
/// compare.md.
#[test]
fn compare_reports_conductance() {
    let d = fresh_dir("conductance_bem", "compare");
    let scene = d.join("scene.toml");
    std::fs::write(
        &scene,
        scene_text("[conductance]\nkind = \"thermal\"\n[counterface]\nthermal_conductivity = 50\n"),
    )
    .unwrap();
    let o = crate::support::strata_in(&d)
        .args(["compare", "-q", "--no-plots"])
        .arg(&scene)
        .arg("--out")
        .arg(d.join("out"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    let csv = std::fs::read_to_string(d.join("out/conductance.csv")).unwrap();
    assert!(csv.starts_with(
        "step,separation,p_bem,conductance_bem,conductance_n,rel_conductance_n,conductance_i,\
         rel_conductance_i,conductance_n_at_p,rel_conductance_n_at_p,conductance_i_at_p,\
         rel_conductance_i_at_p\n"
    ));
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|x| {
                    if x.is_empty() {
                        f64::NAN
                    } else {
                        x.parse().unwrap()
                    }
                })
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 4);
    for r in &rows {
        // N and I model at equal separation: both conduct, within a factor 2 of the BEM
        for (h, rel) in [(r[4], r[5]), (r[6], r[7])] {
            assert!(h > 0.0 && rel.is_finite() && rel.abs() < 1.0, "{r:?}");
            assert_eq!(rel, h / r[3] - 1.0, "{r:?}");
        }
    }
    let md = std::fs::read_to_string(d.join("out/compare.md")).unwrap();
    assert!(md.contains("## Interface conductance"), "{md}");
}
