//! The capped (plastic) asperity on rings (`strata_runtime::rough::plastic::asperity`,
//! feature `capped`, where the run time reaches it without the table builder) checked
//! against the Abel–Fredholm asperity, this crate's solver.

mod tests {
    use strata_runtime::Stack;
    use strata_runtime::rough::plastic::asperity::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / a.abs().max(b.abs())
    }

    /// H = ∞ on the paper's layered stack (and against a steel counterface) is the
    /// Abel–Fredholm asperity (`asperity::Asperity`, a second method) to the rings'
    /// discretisation error.
    #[test]
    fn infinite_hardness_is_the_fredholm_asperity() {
        let paper = Stack::paper_two_layer(5.0).unwrap();
        let pair = paper
            .clone()
            .against(Stack::half_space(210e9, 0.3).unwrap());
        let mut worst: f64 = 0.0;
        for st in [strata_runtime::Bodies::rigid(paper), pair] {
            let full =
                crate::asperity::Asperity::new(&st, crate::asperity::Options::default()).unwrap();
            let s = PlasticAsperity::new(&st, f64::INFINITY).unwrap();
            for d in [1e-8, 1e-6, 2e-5] {
                let (x, y) = (
                    s.at_delta(d, 1e-4).unwrap(),
                    full.paraboloid_at_delta(d, 1e-4).unwrap(),
                );
                worst = worst.max(rel(x.force, y.force));
            }
        }
        eprintln!("rings (400) vs Fredholm, layered: worst {worst:.1e}");
        assert!(worst < 3e-5, "{worst:e}");
    }
}
