#!/usr/bin/env python3
"""Reference load curves from independent public solvers, for tests/bem_reference.rs.

    python compare.py tamaas OUT.csv   # homogeneous half-space, Tamaas 2.9 (PolonskyKeerRey)
    python compare.py cm OUT.csv       # one layer bonded to a rigid base, ContactMechanics 1.8
    python compare.py speed OUT.csv    # Tamaas seconds per load step at n = 512

All on the shared surface ../shared/reference/surface_km10.npy (512², L = 1 mm), SI units,
top material E = 4 GPa, nu = 0.15 (E* = E/(1-nu^2)). Columns are documented in each CSV's
header. Conventions match strata's bem module:
  * Tamaas (zero-mean deflection, half-space): load by mean gap g = mean(w - z + c).
  * ContactMechanics (layer of thickness h on a rigid base, finite k = 0 stiffness M/h):
    load by the rigid offset, which is strata's approach delta = offset + z_M.
"""
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REF = HERE.parent.parent.parent / "shared" / "reference"
L = 1e-3
E, NU = 4e9, 0.15
ESTAR = E / (1 - NU**2)
H_LAYER = 1e-4  # single layer on rigid (ContactMechanics case)


def surface():
    z = np.load(REF / "surface_km10.npy")
    assert z.shape == (512, 512) and z.dtype == np.float64
    return z


def tamaas_solver(z, tol):
    import tamaas as tm

    n = z.shape[0]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
    model.E = E
    model.nu = NU
    solver = tm.PolonskyKeerRey(model, z, tol, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.gap)
    solver.dump_freq = 10**9
    return tm, model, solver


def run_tamaas(out):
    z = surface()
    sep = z.max() - z.mean()
    _, model, solver = tamaas_solver(z, 1e-10)
    rows = []
    # A/A0 from 0.4 % to 22 %.
    for frac in [0.72, 0.65, 0.55, 0.45, 0.35, 0.25, 0.18]:
        g = frac * sep
        t = time.perf_counter()
        solver.solve(g)
        dt = time.perf_counter() - t
        p = np.asarray(model.traction).reshape(z.shape)
        gap = np.asarray(model["gap"]).reshape(z.shape)
        area = np.count_nonzero(gap == 0.0) / gap.size
        rows.append((g, gap.mean(), p.mean() / ESTAR, area, dt))
        print(f"tamaas mean gap {g:.4e}: p/E* {p.mean() / ESTAR:.8e}, A/A0 {area:.5e}, {dt:.2f} s", flush=True)
    with open(out, "w") as f:
        f.write(f"# Tamaas 2.9 PolonskyKeerRey(gap, gap), tol 1e-10; half-space E={E}, nu={NU}; E*={ESTAR!r}\n")
        f.write("target_mean_gap,mean_gap,pressure_ratio,area_fraction,seconds\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def run_cm(out):
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients

    z = surface()
    n = z.shape[0]
    zmax = z.max()
    rms = z.std()
    substrate = PeriodicFFTElasticHalfSpace((n, n), E, (L, L), thickness=H_LAYER, poisson=NU)
    rows = []
    u0 = None
    for delta in [2e-6, 3e-6, 4e-6, 5e-6, 6e-6, 7e-6, 8e-6, 9e-6, 1.0e-5, 1.1e-5, 1.2e-5]:
        offset = delta - zmax
        t = time.perf_counter()
        res = constrained_conjugate_gradients(
            substrate, z, offset=offset, initial_displacements=u0,
            pentol=1e-13 * rms, forcetol=1e-12, thermotol=1e-13, maxiter=100000,
        )
        dt = time.perf_counter() - t
        if not res.success:
            raise SystemExit(f"ContactMechanics did not converge at delta={delta}: {res.message}")
        u0 = res.x
        forces = np.asarray(res.jac)
        pressure = forces / (L * L / (n * n))
        gap = res.x - z - offset
        area = np.count_nonzero(pressure > 0) / pressure.size
        rows.append((delta, gap.mean(), pressure.mean() / ESTAR, area, dt))
        print(f"cm delta {delta:.3e}: mean gap {gap.mean():.4e}, p/E* {pressure.mean() / ESTAR:.8e}, A/A0 {area:.5e}, {dt:.2f} s", flush=True)
    with open(out, "w") as f:
        f.write(f"# ContactMechanics 1.8 constrained_conjugate_gradients, offset control; one layer h={H_LAYER} E={E} nu={NU} on rigid; E*={ESTAR!r}\n")
        f.write("delta,mean_gap,pressure_ratio,area_fraction,seconds\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def run_speed(out):
    """Seconds per load step at n = 512, cold start, at Tamaas' tolerance 1e-10."""
    z = surface()
    sep = z.max() - z.mean()
    rows = []
    for tol in [1e-8, 1e-10]:
        times = []
        for _ in range(3):
            _, model, solver = tamaas_solver(z, tol)
            t = time.perf_counter()
            solver.solve(0.5 * sep)
            times.append(time.perf_counter() - t)
        p = np.asarray(model.traction).mean() / ESTAR
        rows.append((tol, min(times), p))
        print(f"tamaas n=512 mean gap 0.5*(zM-zmean) tol {tol:g}: best of 3 {min(times):.3f} s, p/E* {p:.10e}", flush=True)
    with open(out, "w") as f:
        f.write("# Tamaas 2.9 PolonskyKeerRey(gap, gap), one load step (mean gap 0.5*(zM - zmean)) from a cold start, best of 3\n")
        f.write("tolerance,seconds,pressure_ratio\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("tamaas", "cm", "speed"):
        raise SystemExit(__doc__)
    {"tamaas": run_tamaas, "cm": run_cm, "speed": run_speed}[sys.argv[1]](sys.argv[2])
