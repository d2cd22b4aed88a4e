"""The peers' side of the bem_memory probe (benches/examples/bem_memory.rs): one
pressure-controlled step (mean pressure 0.005 E*) on the periodic surface SURFACE.npy
(L = 1 mm, heights in m) on a homogeneous half-space E = 4 GPa, nu = 0.15, then a
displacement-controlled step from it (the stiffness probe), with each solver's own
buffers. The parent reads this process's peak RSS; only memory is measured, so each
solve's iteration count is capped (every buffer is allocated before the first
iteration ends).

    python peers_memory.py tamaas SURFACE.npy
    python peers_memory.py contactmechanics SURFACE.npy
"""

import sys

import numpy as np

L = 1e-3
E = 4e9
NU = 0.15
ESTAR = E / (1 - NU**2)
P = 0.005 * ESTAR
CAP = 30


def tamaas(z):
    import tamaas as tm

    n = z.shape[0]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
    model.E = E
    model.nu = NU
    solver = tm.PolonskyKeerRey(model, z, 1e-8, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.pressure)
    solver.dump_freq = 10**9
    solver.max_iter = CAP
    solver.solve(P)
    gap = np.asarray(model["gap"]).mean()
    probe = tm.PolonskyKeerRey(model, z, 1e-8, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.gap)
    probe.dump_freq = 10**9
    probe.max_iter = CAP
    probe.solve(0.999 * gap)


def contactmechanics(z):
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients

    n = z.shape[0]
    substrate = PeriodicFFTElasticHalfSpace((n, n), ESTAR, (L, L))
    res = constrained_conjugate_gradients(substrate, z, external_force=P * L * L, maxiter=CAP)
    offset = res.offset if hasattr(res, "offset") else 0.0
    constrained_conjugate_gradients(
        substrate, z, offset=offset + 1e-4 * z.std(), initial_displacements=res.x, maxiter=CAP
    )


def main():
    which, path = sys.argv[1], sys.argv[2]
    z = np.load(path)
    {"tamaas": tamaas, "contactmechanics": contactmechanics}[which](z)


if __name__ == "__main__":
    main()
