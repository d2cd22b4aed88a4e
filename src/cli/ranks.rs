//! The ranks of an MPI launch (the `mpi` build): `strata solve` under `mpirun -np P`
//! solves a BEM scene distributed over the P processes.

use strata_bem::mpi::World;

/// Variables the launchers set in each process they start: OpenMPI's `mpirun`
/// (`OMPI_COMM_WORLD_SIZE`), PMIx launchers such as SLURM's `srun --mpi=pmix`
/// (`PMIX_RANK`), PMI-1/2 ones such as MPICH's Hydra (`PMI_SIZE`).
const LAUNCHED: [&str; 3] = ["OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"];

/// MPI's world, initialised if this process was started by an MPI launcher; `None` for
/// a plain `strata` (no MPI is initialised: the serial solve).
pub fn launched() -> Option<World> {
    if !LAUNCHED.iter().any(|v| std::env::var_os(v).is_some()) {
        return None;
    }
    World::init()
}
