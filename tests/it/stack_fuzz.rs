//! Property tests of the stack reader: arbitrary text and arbitrary (valid-syntax)
//! stacks never panic; every accepted stack satisfies the documented invariants and
//! gives a finite compliance; every rejection is a one-line message.

use proptest::prelude::*;
use strata_runtime::{Base, Compliance, Stack};

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|x| format!("{x:e}")),
        (-3i64..3).prop_map(|i| i.to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("\"text\"".to_string()),
        Just("[1, 2]".to_string()),
        (1e-9f64..1e-2).prop_map(|x| format!("{x:e}")),
        (1e6f64..1e12).prop_map(|x| format!("{x:e}")),
        (-0.99f64..0.5).prop_map(|x| format!("{x:e}")),
    ]
}

fn layer_text() -> impl Strategy<Value = String> {
    (
        proptest::option::of(number()),
        proptest::option::of(number()),
        proptest::option::of(number()),
        proptest::option::of(number()),
    )
        .prop_map(|(h, e, nu, extra)| {
            let mut s = String::from("[[layer]]\n");
            if let Some(h) = h {
                s += &format!("thickness = {h}\n");
            }
            if let Some(e) = e {
                s += &format!("young = {e}\n");
            }
            if let Some(nu) = nu {
                s += &format!("poisson = {nu}\n");
            }
            if let Some(x) = extra {
                s += &format!("extra = {x}\n");
            }
            s
        })
}

fn base_text() -> impl Strategy<Value = String> {
    prop_oneof![
        Just(String::new()),
        Just("[base]\nkind = \"rigid\"\n".to_string()),
        (number(), number()).prop_map(|(e, nu)| format!(
            "[base]\nkind = \"elastic\"\nyoung = {e}\npoisson = {nu}\n"
        )),
        Just("[base]\nkind = \"foam\"\n".to_string()),
        Just("base = 3\n".to_string()),
    ]
}

fn check(text: &str) {
    match Stack::from_toml_str(text) {
        Ok(s) => {
            for l in s.layers() {
                assert!(l.thickness.is_finite() && l.thickness > 0.0);
                assert!(l.young.is_finite() && l.young > 0.0);
                assert!(l.poisson > -1.0 && l.poisson <= 0.5);
            }
            if let Base::Elastic { young, poisson } = s.base() {
                assert!(young.is_finite() && young > 0.0 && poisson > -1.0 && poisson <= 0.5);
            } else {
                assert!(!s.layers().is_empty());
            }
            let c = Compliance::new(&s);
            let h = s.top_thickness().unwrap_or(1.0);
            for t in [1e-3, 1.0, 1e3] {
                let v = c.s(t / h);
                assert!(v.is_finite() && v >= 0.0, "S = {v} for {text}");
            }
        }
        Err(e) => {
            let m = e.to_string();
            assert!(!m.is_empty() && !m.contains('\n'), "{m}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn structured_stacks_never_panic(layers in proptest::collection::vec(layer_text(), 0..4), base in base_text()) {
        let text = layers.concat() + &base;
        check(&text);
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        check(&text);
    }
}
