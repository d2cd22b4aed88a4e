//! The decomposition of a grid over processes (ranks): which rows each rank owns, the
//! exchanges of the distributed 2-D transform (an all-to-all of equal blocks) and the
//! global reductions, in a fixed order.
//!
//! A grid of ny rows is cut into P slabs of consecutive rows ([`slab`]): rank q owns rows
//! ⌊q·ny/P⌋-sized runs, the first ny mod P ranks one row more. The same cut splits the
//! NX/2 + 1 kx columns of the half spectrum for the column stage of a transform.
//!
//! [`Serial`] is the one-rank decomposition (no MPI): every exchange is a copy and every
//! reduction returns its input, so a solver run on it does exactly the serial arithmetic.
//! `strata_bem::mpi::World` (feature `mpi`) is the MPI one.
//!
//! Reductions are formed in rank order on every rank ([`sum`], [`max`]): each rank's
//! partial value is gathered to all ranks, which add them up 0, 1, …, P − 1. The result is
//! the same on every rank and, for a given P, from run to run; between different P it
//! differs by the round-off of the partial sums' order only.

use std::ops::Range;

/// A communicator over P ranks (P ≥ 1) for the slab decomposition.
pub trait Decomposition {
    /// This process's rank, 0 ≤ rank < size.
    fn rank(&self) -> usize;
    /// The number of ranks P.
    fn size(&self) -> usize;
    /// All-to-all of equal blocks: `send` holds P blocks of `send.len() / P` values, block q
    /// for rank q; on return block q of `recv` (same length) holds what rank q sent here.
    fn all_to_all(&self, send: &[f64], recv: &mut [f64]);
    /// Every rank's `send` (the same length on every rank) into `recv` (P times as long),
    /// in rank order.
    fn all_gather(&self, send: &[f64], recv: &mut [f64]);
    /// Bytes this rank has sent to other ranks so far (exchanges and reductions; a
    /// count, for the communication volume per iteration).
    fn bytes_sent(&self) -> u64;
}

/// The one-rank decomposition: no communication.
#[derive(Debug, Default, Clone, Copy)]
pub struct Serial;

impl Decomposition for Serial {
    fn rank(&self) -> usize {
        0
    }

    fn size(&self) -> usize {
        1
    }

    fn all_to_all(&self, send: &[f64], recv: &mut [f64]) {
        recv.copy_from_slice(send);
    }

    fn all_gather(&self, send: &[f64], recv: &mut [f64]) {
        recv.copy_from_slice(send);
    }

    fn bytes_sent(&self) -> u64 {
        0
    }
}

/// The part `part` of `n` items cut into `parts` runs of consecutive items (the first
/// n mod parts runs one item longer).
pub fn slab(n: usize, parts: usize, part: usize) -> Range<usize> {
    let parts = parts.max(1);
    let (base, extra) = (n / parts, n % parts);
    let start = part * base + part.min(extra);
    let len = base + usize::from(part < extra);
    start..(start + len).min(n)
}

/// The longest run of [`slab`] (the first one).
pub fn slab_max(n: usize, parts: usize) -> usize {
    n.div_ceil(parts.max(1))
}

/// Element-wise global sums of `values` over the ranks, added up in rank order; on
/// return every rank holds the sums. One rank: unchanged.
pub fn sum(comm: &dyn Decomposition, values: &mut [f64]) {
    reduce(comm, values, |a, b| a + b);
}

/// Element-wise global maxima of `values` over the ranks.
pub fn max(comm: &dyn Decomposition, values: &mut [f64]) {
    reduce(comm, values, f64::max);
}

fn reduce(comm: &dyn Decomposition, values: &mut [f64], op: impl Fn(f64, f64) -> f64) {
    let p = comm.size();
    if p == 1 {
        return;
    }
    let k = values.len();
    let mut all = vec![0.0; k * p];
    comm.all_gather(values, &mut all);
    values.copy_from_slice(&all[..k]);
    for q in 1..p {
        for (v, &x) in values.iter_mut().zip(&all[q * k..(q + 1) * k]) {
            *v = op(*v, x);
        }
    }
}

/// `f` applied to `acc` on each rank in turn, in rank order: rank 0 applies it to the
/// `acc` it is given, rank 1 to rank 0's result, and so on; on return every rank holds
/// the last rank's result. A sum over the rows of a slab decomposition continued this
/// way (each rank adding its rows in order to the running value) is the serial sum bit
/// for bit: the same additions in the same order. P small exchanges; one rank: `f(acc)`.
pub fn in_rank_order(comm: &dyn Decomposition, acc: &mut [f64], f: impl FnOnce(&mut [f64])) {
    let (p, rank) = (comm.size(), comm.rank());
    let mut f = Some(f);
    if p == 1 {
        if let Some(f) = f.take() {
            f(acc);
        }
        return;
    }
    let k = acc.len();
    let mut all = vec![0.0; k * p];
    for q in 0..p {
        if q == rank
            && let Some(f) = f.take()
        {
            f(acc);
        }
        comm.all_gather(acc, &mut all);
        acc.copy_from_slice(&all[q * k..(q + 1) * k]);
    }
}

/// Whether `flag` holds on any rank.
pub fn any(comm: &dyn Decomposition, flag: bool) -> bool {
    let mut v = [f64::from(u8::from(flag))];
    max(comm, &mut v);
    v[0] > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slabs_cover_the_items_once_in_order() {
        for n in [0, 1, 5, 7, 512, 513] {
            for parts in 1..6 {
                let mut next = 0;
                for q in 0..parts {
                    let r = slab(n, parts, q);
                    assert_eq!(r.start, next, "n {n} parts {parts} part {q}");
                    assert!(r.len() <= slab_max(n, parts));
                    next = r.end;
                }
                assert_eq!(next, n);
            }
        }
    }

    #[test]
    fn serial_reductions_return_their_input() {
        let mut v = [1.5, -0.0, f64::INFINITY];
        sum(&Serial, &mut v);
        assert_eq!(v[0].to_bits(), 1.5f64.to_bits());
        assert_eq!(v[1].to_bits(), (-0.0f64).to_bits());
        assert!(any(&Serial, true) && !any(&Serial, false));
    }
}
