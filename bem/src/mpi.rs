//! The MPI decomposition (feature `mpi`): [`World`], the ranks of `MPI_COMM_WORLD`, over
//! the system's MPI library (built and tested with OpenMPI). Start a program under
//! `mpirun -np P`; each rank calls the solver together (see [`crate::distributed`]).

use std::cell::Cell;

use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

use crate::decomp::Decomposition;

/// The ranks of `MPI_COMM_WORLD`. MPI is initialised by [`World::init`] and finalised
/// when the value is dropped (once per process).
pub struct World {
    // Dropped after `world`: finalises MPI.
    world: SimpleCommunicator,
    _universe: mpi::environment::Universe,
    sent: Cell<u64>,
}

impl World {
    /// Initialises MPI; `None` if it was initialised already in this process.
    pub fn init() -> Option<Self> {
        let universe = mpi::initialize()?;
        let world = universe.world();
        Some(World {
            world,
            _universe: universe,
            sent: Cell::new(0),
        })
    }

    fn count(&self, bytes: usize) {
        self.sent.set(self.sent.get() + bytes as u64);
    }
}

impl Decomposition for World {
    fn rank(&self) -> usize {
        usize::try_from(self.world.rank()).unwrap_or(0)
    }

    fn size(&self) -> usize {
        usize::try_from(self.world.size()).unwrap_or(1)
    }

    fn all_to_all(&self, send: &[f64], recv: &mut [f64]) {
        let p = self.size();
        // The own block stays on the rank.
        self.count(8 * send.len() / p * (p - 1));
        self.world.all_to_all_into(send, recv);
    }

    fn all_gather(&self, send: &[f64], recv: &mut [f64]) {
        self.count(8 * send.len() * (self.size() - 1));
        self.world.all_gather_into(send, recv);
    }

    fn bytes_sent(&self) -> u64 {
        self.sent.get()
    }
}
