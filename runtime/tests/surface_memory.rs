//! What checking a measured surface allocates, measured by a counting allocator against
//! the estimate the memory limit is checked with (34 B per point beside the heights to
//! judge them; 28 B per point and 72 B per filled point more to repair them): the
//! estimate must bound the measured peak, and not by a wide margin (a 16384² periodic
//! scan on a 24 GB machine fits only if it is honest).
//!
//! One test in this binary: the allocator counts every thread's allocations.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use strata_runtime::resources::MemoryLimit;
use strata_runtime::surface::{Detrend, Repair, Spacing, Surface};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded to the system allocator unchanged; only counters move.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's layout is passed on as given.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(now, Ordering::SeqCst);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as `alloc`.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Ordering::SeqCst) + layout.size();
            PEAK.fetch_max(now, Ordering::SeqCst);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from this allocator with `layout`.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::SeqCst);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as `alloc`; `ptr` came from this allocator with `layout`.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::SeqCst);
            let now = LIVE.fetch_add(new_size, Ordering::SeqCst) + new_size;
            PEAK.fetch_max(now, Ordering::SeqCst);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const N0: usize = 384;
const N1: usize = 320;

/// A smooth rough-looking map (m) with a tilt: a few sines and a deterministic
/// pseudo-random texture, no spikes.
fn heights() -> Vec<f64> {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut z = Vec::with_capacity(N0 * N1);
    for i in 0..N0 {
        for j in 0..N1 {
            let (x, y) = (i as f64 / N0 as f64, j as f64 / N1 as f64);
            let wave = (2.0 * std::f64::consts::PI * 3.0 * x).sin()
                + 0.5 * (2.0 * std::f64::consts::PI * 5.0 * y).cos();
            z.push(1e-6 * (wave + 0.2 * noise()) + 2e-6 * x);
        }
    }
    z
}

/// Peak bytes allocated beside the heights while `measured_judged` checks (and
/// repairs) them, per grid point, and the surface's filled count.
fn peak_per_point(z: Vec<f64>, periodic: bool, repair: Repair) -> (f64, usize) {
    let base = LIVE.load(Ordering::SeqCst);
    PEAK.store(base, Ordering::SeqCst);
    let s = Surface::measured_judged(
        z,
        N0,
        N1,
        Spacing::Size(1e-3),
        periodic,
        repair,
        Detrend::Plane,
        &MemoryLimit::default(),
    )
    .expect("a measured surface");
    let peak = PEAK.load(Ordering::SeqCst) - base;
    let filled = s.repaired();
    drop(s);
    (peak as f64 / (N0 * N1) as f64, filled)
}

#[test]
fn judging_and_repairing_stay_within_their_estimates() {
    // Warm up whatever allocates once (thread-locals, lazily built tables).
    let _ = peak_per_point(heights(), true, Repair::Median);
    let judge = 34.0;
    // The heights themselves were allocated before the call; the surface keeps them.
    let clean_periodic = peak_per_point(heights(), true, Repair::Median);
    let clean_free = peak_per_point(heights(), false, Repair::Median);
    let mut z = heights();
    for k in (0..z.len()).step_by(97) {
        z[k] = f64::NAN;
    }
    for k in (50..z.len()).step_by(1013) {
        z[k] += 1e-4;
    }
    let damaged = peak_per_point(z, false, Repair::Median);
    println!(
        "peak beside the heights, B/pt: periodic {:.2}, non-periodic {:.2}, repaired \
         ({} filled) {:.2}",
        clean_periodic.0, clean_free.0, damaged.1, damaged.0
    );
    assert_eq!(clean_periodic.1, 0);
    assert_eq!(clean_free.1, 0);
    // Non-periodic: the form and the heights less it are held (≈ 33 B/pt counted).
    assert!(clean_free.0 <= judge, "{clean_free:?}");
    assert!(clean_free.0 >= 0.8 * judge, "{clean_free:?}");
    // Periodic: no form and no copy less it (≈ 18 B/pt counted).
    assert!(clean_periodic.0 <= 0.6 * judge, "{clean_periodic:?}");
    // Repaired: the larger of the two stages.
    let n = (N0 * N1) as f64;
    let repair = 28.0 + 72.0 * damaged.1 as f64 / n;
    assert!(damaged.1 > (N0 * N1) / 97, "{damaged:?}");
    assert!(
        damaged.0 <= judge.max(repair),
        "{damaged:?} against {repair}"
    );
}
