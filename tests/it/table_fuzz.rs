//! Property tests of the table decoder: random bytes, truncations, bit flips
//! and byte overwrites of a small valid table — raw (the checksum must catch them) and
//! re-sealed (length and checksum recomputed, so the damage reaches the bincode payload
//! decoder and the table validation) — and tables with arbitrary header fields never
//! panic. Whatever decodes is valid and serves lookups without panicking.
//!
//! Bounded for CI: fixed case counts and a fixed seed (~2 s in the test profile).
//! Longer run: `PROPTEST_CASES=100000 cargo test -p strata-runtime --test table_fuzz`.

use proptest::prelude::*;
use strata_runtime::law::AsperityLaw;
use strata_runtime::stack::Stack;
use strata_runtime::table::{Axis, FORMAT_VERSION, Family, Header, Table, Vary, codec};

fn config(cases: u32) -> ProptestConfig {
    crate::support::fuzz_config(cases, 0x7ab1e)
}

/// A small, valid two-layer family table (contents smooth and plausible, not physical).
fn small_table(x: Axis, w: Axis, s: Axis, ratio: Option<Axis>) -> Table {
    let stack = Stack::paper_two_layer(5.0).expect("paper stack");
    let family = ratio.map(|r| Family {
        vary: Vary::Layer(2),
        ratio: r,
    });
    let m = ratio.map_or(1, |r| r.n);
    let mut chi = Vec::new();
    let mut zeta = Vec::new();
    let mut g = Vec::new();
    let mut sv = Vec::new();
    for k in 0..m {
        let c = 0.1 * k as f64;
        for i in 0..x.n {
            let t = x.node(i);
            chi.push(1.0 + 0.5 * (1.0 + t.tanh()) * (1.0 + c));
            zeta.push(1.0 - 0.2 * (1.0 + t.tanh()));
            for j in 0..w.n {
                g.push(0.3 * (1.0 + t.tanh()) / (1.0 + w.node(j)));
            }
        }
        for i in 0..s.n {
            sv.push(1.0 - 0.8 / (1.0 + s.node(i).exp()));
        }
    }
    Table {
        header: Header {
            format_version: FORMAT_VERSION,
            strata_version: "fuzz".into(),
            build_time: 0,
            stack,
            counterface: Default::default(),
            family,
            x,
            w,
            s,
            far_field_error: 1e-9,
            far_terms: 0,
            tolerance: 1e-4,
            interp_error: None,
        },
        chi,
        zeta,
        g,
        s: sv,
        k0: vec![-0.8; m],
    }
}

fn valid_bytes() -> Vec<u8> {
    let ax = |lo: f64, hi: f64, n: usize| Axis { lo, hi, n };
    small_table(
        ax(-3.0, 3.0, 9),
        ax(0.0, 2.0, 7),
        ax(-4.0, 4.0, 8),
        Some(ax(-1.0, 1.0, 6)),
    )
    .to_bytes()
    .expect("valid table encodes")
}

/// Recomputes the length and FNV-1a checksum of a (damaged) payload.
fn reseal(mut bytes: Vec<u8>) -> Vec<u8> {
    if bytes.len() < 28 {
        return bytes;
    }
    let payload = bytes[28..].to_vec();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in &payload {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    bytes[12..20].copy_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes[20..28].copy_from_slice(&h.to_le_bytes());
    bytes
}

/// Decodes; a decoded table must be valid and serve lookups; an error is one line.
fn check(bytes: &[u8]) -> bool {
    match Table::from_bytes(bytes) {
        Ok(t) => {
            assert!(t.validate().is_ok());
            let stack = t.header.stack.clone();
            if let Ok(law) = t.law_for(&stack) {
                for a in [0.0, -1.0, f64::NAN, 1e-9, 1e-4, 1e3, f64::INFINITY] {
                    let _ = law.chi(a);
                    let _ = law.zeta(a);
                    let _ = law.chi_zeta_derivs(a);
                    let _ = law.try_chi_zeta(a);
                    for r in [0.0, a, 2.0 * a + 1e-6, f64::NAN, 1e9] {
                        let _ = law.g(a, r);
                        let _ = law.try_g(a, r);
                    }
                    let _ = law.s(a);
                }
            }
            for c in [-1e300, -1.0, 0.0, 0.5, f64::NAN] {
                let _ = t.member_stack(c);
            }
            true
        }
        Err(e) => {
            let m = e.to_string();
            assert!(!m.is_empty() && !m.contains('\n'), "{m}");
            false
        }
    }
}

#[test]
fn valid_table_roundtrips() {
    let b = valid_bytes();
    assert!(check(&b));
    assert_eq!(
        Table::from_bytes(&b)
            .expect("decodes")
            .to_bytes()
            .expect("encodes"),
        b
    );
}

/// Every truncation of the valid table is refused (as truncated or not a table).
#[test]
fn every_truncation_is_refused() {
    let b = valid_bytes();
    for len in 0..b.len() {
        assert!(!check(&b[..len]), "truncation to {len} bytes accepted");
    }
}

#[derive(Debug, Clone)]
enum Damage {
    Flip(usize, u8),
    Set(usize, u8),
    Insert(usize, Vec<u8>),
    Delete(usize, usize),
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        (any::<usize>(), 0u8..8).prop_map(|(i, b)| Damage::Flip(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, v)| Damage::Set(i, v)),
        (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..9))
            .prop_map(|(i, v)| Damage::Insert(i, v)),
        (any::<usize>(), 1usize..16).prop_map(|(i, n)| Damage::Delete(i, n)),
    ]
}

fn apply(mut b: Vec<u8>, ds: &[Damage], from: usize) -> Vec<u8> {
    for d in ds {
        let span = b.len().saturating_sub(from).max(1);
        match d {
            Damage::Flip(i, bit) => {
                let k = from + i % span;
                if k < b.len() {
                    b[k] ^= 1 << bit;
                }
            }
            Damage::Set(i, v) => {
                let k = from + i % span;
                if k < b.len() {
                    b[k] = *v;
                }
            }
            Damage::Insert(i, v) => {
                let k = (from + i % span).min(b.len());
                b.splice(k..k, v.iter().copied());
            }
            Damage::Delete(i, n) => {
                let k = (from + i % span).min(b.len());
                let e = (k + n).min(b.len());
                b.drain(k..e);
            }
        }
    }
    b
}

fn axis() -> impl Strategy<Value = Axis> {
    let n = prop_oneof![
        Just(0usize),
        Just(1),
        Just(5),
        6usize..12,
        Just(1 << 23),
        Just(usize::MAX),
    ];
    let x = prop_oneof![
        -10.0f64..10.0,
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(0.0),
        Just(-1e308),
    ];
    (x.clone(), x, n).prop_map(|(lo, hi, n)| Axis { lo, hi, n })
}

proptest! {
    #![proptest_config(config(1000))]

    /// Raw damage anywhere: refused (checksum, signature, version, length) or, if the
    /// damage happens to keep the file valid, a valid table.
    #[test]
    fn damaged_files_never_panic(ds in proptest::collection::vec(damage(), 1..4)) {
        check(&apply(valid_bytes(), &ds, 0));
    }

    /// Damage to the payload with a recomputed checksum: the bincode decoder and the
    /// table validation see it.
    #[test]
    fn resealed_damage_never_panics(ds in proptest::collection::vec(damage(), 1..4)) {
        check(&reseal(apply(valid_bytes(), &ds, 28)));
    }

    /// Random bytes, with and without a valid signature and prefix.
    #[test]
    fn random_bytes_never_panic(mut b in proptest::collection::vec(any::<u8>(), 0..400), sign in any::<bool>()) {
        if sign && b.len() >= 12 {
            b[..8].copy_from_slice(codec::MAGIC);
            b[8..12].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
            b = reseal(b);
        }
        check(&b);
    }
}

proptest! {
    #![proptest_config(config(300))]

    /// Arbitrary header axes and family (arrays sized from them when small, else
    /// empty), encoded without validation: decoding never panics (no overflow in the
    /// size checks) and accepts only consistent tables.
    #[test]
    fn arbitrary_headers_never_panic(x in axis(), w in axis(), s in axis(), ratio in proptest::option::of(axis())) {
        let small = |a: &Axis| a.n <= 64;
        let t = if small(&x) && small(&w) && small(&s) && ratio.is_none_or(|r| small(&r)) {
            small_table(x, w, s, ratio)
        } else {
            let mut t = small_table(
                Axis { lo: -3.0, hi: 3.0, n: 9 },
                Axis { lo: 0.0, hi: 2.0, n: 7 },
                Axis { lo: -4.0, hi: 4.0, n: 8 },
                None,
            );
            t.header.x = x;
            t.header.w = w;
            t.header.s = s;
            t.header.family = ratio.map(|r| Family { vary: Vary::Base, ratio: r });
            t
        };
        if let Ok(b) = codec::encode(&t) {
            check(&b);
        }
    }
}

/// Huge (valid-looking) axes on every dimension: the array-size check must not
/// overflow; the table is refused as inconsistent.
#[test]
fn huge_axes_are_refused_without_overflow() {
    let big = Axis {
        lo: 0.0,
        hi: 1.0,
        n: (1 << 24) - 1,
    };
    let mut t = small_table(
        Axis {
            lo: -3.0,
            hi: 3.0,
            n: 9,
        },
        Axis {
            lo: 0.0,
            hi: 2.0,
            n: 7,
        },
        Axis {
            lo: -4.0,
            hi: 4.0,
            n: 8,
        },
        None,
    );
    t.header.x = big;
    t.header.w = big;
    t.header.s = big;
    t.header.family = Some(Family {
        vary: Vary::Layer(2),
        ratio: big,
    });
    let b = codec::encode(&t).expect("encodes without validation");
    assert!(!check(&b));
}
