#!/usr/bin/env python3
"""Reference load curves from independent public solvers, for tests/bem_reference.rs.

    python compare.py tamaas SURFACE.npy OUT.csv  # homogeneous half-space, Tamaas 2.9
    python compare.py tamaas_pair SURFACE.npy OUT.csv  # steel on steel: composite E*, Tamaas 2.9
    python compare.py cm_plastic SURFACE.npy OUT.csv   # hardness cap on a half-space, loading and
                                                       # unloading, ContactMechanics 1.8 plastic system
    python compare.py cm SURFACE.npy OUT.csv      # one layer on a rigid base, ContactMechanics 1.8
    python compare.py free SURFACE.npy OUT.csv    # non-periodic half-space, ContactMechanics 1.8
    python compare.py speed DIR OUT.csv           # Tamaas seconds per load step (surfaces of the bem bench)
    python compare.py cm_plastic_speed DIR OUT.csv  # ContactMechanics' capped step beside the bem bench's

SURFACE.npy is an n x n f64 height map (m) of a periodic cell of side L = 1 mm; run.sh
has strata write it (its self-affine generator, the paper's parameters: D_f = 2.4,
k = 2...10, RMS 3.4 um, seed 20240611), so the check needs nothing outside the repository.
The loads depend on the grid (the generator draws a different surface for each n):
n = 256 (CI, 4 loads) or n = 512 (8-9 loads), both spanning A/A0 from below 1 % to
above 20 % (tests/bem_reference.rs asserts the span).

Top material E = 4 GPa, nu = 0.15 (E* = E/(1-nu^2)), SI units. Columns are documented
in each CSV's header. Conventions match strata's bem module:
  * Tamaas (zero-mean deflection, half-space): load by mean gap g = mean(w - z + c).
  * ContactMechanics (layer of thickness h on a rigid base, finite k = 0 stiffness M/h):
    load by the rigid offset, which is strata's approach delta = offset + z_M.
"""
import sys
import time

import numpy as np

L = 1e-3
E, NU = 4e9, 0.15
ESTAR = E / (1 - NU**2)
H_LAYER = 1e-4  # single layer on rigid (ContactMechanics case)

# Loads per grid n. Tamaas: mean gap as a fraction of z_M - z_mean; ContactMechanics:
# approach delta (m). Measured A/A0: n = 256 Tamaas and CM 0.6 %...24 %; n = 512
# Tamaas 0.12 %...25 %, CM 0.12 %...30 %.
TAMAAS_FRACTIONS = {
    256: [0.85, 0.6, 0.4, 0.26],
    512: [0.9, 0.85, 0.75, 0.6, 0.5, 0.4, 0.3, 0.22, 0.18],
}
# Non-periodic (free-boundary) half-space, ContactMechanics FreeFFTElasticHalfSpace: the
# same surface taken as an isolated sample; approaches delta (m). At n = 512 not 14 µm:
# there ContactMechanics' iteration does not converge (3 000 iterations, 257 s), while 12,
# 15, 16 and 18 µm converge in 178–247 (18 µm: A/A0 23.8 %).
FREE_DELTAS = {
    256: [1.0e-6, 4e-6, 9e-6, 14e-6],
    512: [0.8e-6, 2e-6, 4e-6, 7e-6, 10e-6, 12e-6, 18e-6],
}
# Iteration cap of the free-boundary solves: they converge in a few hundred iterations; a
# load that does not fails in minutes (at 100 000 it took hours before failing).
FREE_MAX_ITER = 5000
CM_DELTAS = {
    256: [1.2e-6, 3e-6, 4.5e-6, 6.8e-6],
    512: [1e-6, 1.5e-6, 3e-6, 4.5e-6, 6e-6, 7.5e-6, 9e-6, 1.0e-5],
}


def loads(table, z, what):
    n = z.shape[0]
    if n not in table:
        raise SystemExit(f"{what}: no load list for a {n}^2 surface (have {sorted(table)})")
    return table[n]


def surface(path):
    z = np.load(path)
    if z.ndim != 2 or z.shape[0] != z.shape[1] or z.dtype != np.float64:
        raise SystemExit(f"{path}: expected a square f64 height map, got {z.shape} {z.dtype}")
    return z


def tamaas_solver(z, tol, young=E, poisson=NU):
    import tamaas as tm

    n = z.shape[0]
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
    model.E = young
    model.nu = poisson
    solver = tm.PolonskyKeerRey(model, z, tol, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.gap)
    solver.dump_freq = 10**9
    return tm, model, solver


def run_tamaas(surf, out):
    z = surface(surf)
    sep = z.max() - z.mean()
    _, model, solver = tamaas_solver(z, 1e-10)
    rows = []
    for frac in loads(TAMAAS_FRACTIONS, z, "tamaas"):
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
        f.write(f"# Tamaas 2.9 PolonskyKeerRey(gap, gap), tol 1e-10; half-space E={E}, nu={NU}; E*={ESTAR!r}; "
                f"surface {surf} ({z.shape[0]}^2, L={L})\n")
        f.write("target_mean_gap,mean_gap,pressure_ratio,area_fraction,seconds\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


# Two steel half-spaces (E = 210 GPa, nu = 0.3 each; strata's [counterface], physics.md
# §6.1): Tamaas has one deformable body, so it is given the composite modulus
# E*_pair = 1/(1/E* + 1/E*) = E*/2 as E with nu = 0 (E* = E/(1 - 0^2)).
E_STEEL, NU_STEEL = 210e9, 0.3
ESTAR_PAIR = 1.0 / (2.0 / (E_STEEL / (1 - NU_STEEL**2)))


def run_tamaas_pair(surf, out):
    z = surface(surf)
    n = z.shape[0]
    sep = z.max() - z.mean()
    _, model, solver = tamaas_solver(z, 1e-10, young=ESTAR_PAIR, poisson=0.0)
    rows = []
    for frac in loads(TAMAAS_FRACTIONS, z, "tamaas_pair"):
        g = frac * sep
        solver.solve(g)
        p = np.asarray(model.traction).reshape(z.shape)
        gap = np.asarray(model["gap"]).reshape(z.shape)
        area = np.count_nonzero(gap == 0.0) / gap.size
        rows.append((g, gap.mean(), p.mean(), area))
        print(f"tamaas steel/steel mean gap {g:.4e}: p {p.mean():.8e} Pa, A/A0 {area:.5e}", flush=True)
    with open(out, "w") as f:
        f.write(f"# Tamaas 2.9 PolonskyKeerRey(gap, gap), tol 1e-10; steel on steel (E={E_STEEL}, nu={NU_STEEL} each) "
                f"as one half-space of E*_pair={ESTAR_PAIR!r}; surface {surf} ({n}^2, L={L})\n")
        f.write("target_mean_gap,mean_gap,mean_pressure,area_fraction\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


# Elastic-perfectly plastic half-space (strata's [plasticity], physics.md §6.3): the
# ContactMechanics plastic system (PlasticTopography + PlasticNonSmoothContactSystem,
# which keeps the plastic depth between solves) under offset control along a path that
# loads and unloads; approaches delta = offset + z_M (m).
CM_PLASTIC_HARDNESS = 0.2e9
CM_PLASTIC_DELTAS = [2e-6, 4e-6, 6e-6, 4e-6, 2e-6]


def run_cm_plastic(surf, out):
    from SurfaceTopography import PlasticTopography, Topography
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Factory import make_plastic_system

    z = surface(surf)
    n = z.shape[0]
    zmax = z.max()
    rms = z.std()
    # stiffness_q0 = 0: the zero-mean deflection of strata's (and Tamaas') periodic
    # half-space (CM's default stiffens the q = 0 mode like the lowest wavevector).
    substrate = PeriodicFFTElasticHalfSpace((n, n), ESTAR, (L, L), stiffness_q0=0.0)
    topo = PlasticTopography(Topography(z, (L, L), periodic=True), CM_PLASTIC_HARDNESS)
    system = make_plastic_system(substrate=substrate, surface=topo)
    rows = []
    u0 = None
    for delta in CM_PLASTIC_DELTAS:
        t = time.perf_counter()
        sol = system.minimize_proxy(offset=delta - zmax, initial_displacements=u0,
                                    pentol=1e-12 * rms, forcetol=1e-12, maxiter=100000)
        dt = time.perf_counter() - t
        if not sol.success:
            raise SystemExit(f"ContactMechanics (plastic) did not converge at delta={delta}: {sol.message}")
        u0 = sol.x
        p = np.asarray(sol.jac) / (L * L / (n * n))
        area = np.count_nonzero(p > 0) / p.size
        plastic = np.count_nonzero(p >= CM_PLASTIC_HARDNESS * (1 - 1e-9)) / p.size
        rows.append((delta, p.mean(), area, plastic, dt))
        print(f"cm plastic delta {delta:.3e}: p {p.mean():.8e} Pa, A/A0 {area:.5e}, plastic {plastic:.5e}, {dt:.2f} s", flush=True)
    with open(out, "w") as f:
        f.write(f"# ContactMechanics 1.8 plastic system (PlasticTopography, hardness {CM_PLASTIC_HARDNESS}), offset control, "
                f"half-space E*={ESTAR!r}; load then unload; surface {surf} ({n}^2, L={L})\n")
        f.write("delta,mean_pressure,area_fraction,plastic_area_fraction,seconds\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def run_cm(surf, out):
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients

    z = surface(surf)
    n = z.shape[0]
    zmax = z.max()
    rms = z.std()
    substrate = PeriodicFFTElasticHalfSpace((n, n), E, (L, L), thickness=H_LAYER, poisson=NU)
    rows = []
    u0 = None
    for delta in loads(CM_DELTAS, z, "cm"):
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
        f.write(f"# ContactMechanics 1.8 constrained_conjugate_gradients, offset control; one layer h={H_LAYER} E={E} nu={NU} on rigid; "
                f"E*={ESTAR!r}; surface {surf} ({n}^2, L={L})\n")
        f.write("delta,mean_gap,pressure_ratio,area_fraction,seconds\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def run_free(surf, out):
    from ContactMechanics import FreeFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients

    z = surface(surf)
    n = z.shape[0]
    zmax = z.max()
    rms = z.std()
    substrate = FreeFFTElasticHalfSpace((n, n), ESTAR, (L, L))
    rows = []
    for delta in loads(FREE_DELTAS, z, "free"):
        offset = delta - zmax
        t = time.perf_counter()
        res = constrained_conjugate_gradients(
            substrate, z, offset=offset,
            pentol=1e-13 * rms, forcetol=1e-12, thermotol=1e-13, maxiter=FREE_MAX_ITER,
        )
        dt = time.perf_counter() - t
        if not res.success:
            raise SystemExit(f"ContactMechanics (free) did not converge at delta={delta}: {res.message}")
        forces = np.asarray(res.jac)[:n, :n]
        pressure = forces / (L * L / (n * n))
        area = np.count_nonzero(pressure > 0) / pressure.size
        rows.append((delta, pressure.mean() / ESTAR, area, dt))
        print(f"cm free delta {delta:.3e}: p/E* {pressure.mean() / ESTAR:.8e}, A/A0 {area:.5e}, {dt:.2f} s", flush=True)
    with open(out, "w") as f:
        f.write(f"# ContactMechanics 1.8 FreeFFTElasticHalfSpace + constrained_conjugate_gradients, offset control; "
                f"non-periodic half-space E*={ESTAR!r}; surface {surf} ({n}^2, L={L}) as an isolated sample\n")
        f.write("delta,pressure_ratio,area_fraction,seconds\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def run_cm_plastic_speed(directory, out):
    """Seconds of one capped load step from the undeformed surface with ContactMechanics'
    plastic system, on the surface and at the approaches and hardnesses the strata bench
    wrote (DIR/surface.npy, DIR/strata_plastic_speed.csv); tolerance 1e-10 sigma_z on the
    gap as strata's; best of 2. Writes OUT and prints the ratio table."""
    from pathlib import Path
    from SurfaceTopography import PlasticTopography, Topography
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Factory import make_plastic_system

    d = Path(directory)
    z = surface(d / "surface.npy")
    n = z.shape[0]
    zmax, rms = z.max(), z.std()
    strata = [r for r in csv_rows(d / "strata_plastic_speed.csv")]
    rows = []
    print("| H (GPa) | ContactMechanics (s) | strata (s) | CM / strata | p rel. diff | A_pl/A0 CM / strata |")
    print("|---|---|---|---|---|---|")
    for r in strata:
        h, delta = float(r["hardness"]), float(r["approach"])
        times = []
        for _ in range(2):
            substrate = PeriodicFFTElasticHalfSpace((n, n), ESTAR, (L, L), stiffness_q0=0.0)
            topo = PlasticTopography(Topography(z, (L, L), periodic=True), h)
            system = make_plastic_system(substrate=substrate, surface=topo)
            t = time.perf_counter()
            sol = system.minimize_proxy(offset=delta - zmax, pentol=1e-10 * rms, forcetol=1e-10, maxiter=100000)
            times.append(time.perf_counter() - t)
            if not sol.success:
                raise SystemExit(f"ContactMechanics (plastic) did not converge at H={h}: {sol.message}")
        p = np.asarray(sol.jac) / (L * L / (n * n))
        plastic = np.count_nonzero(p >= h * (1 - 1e-9)) / p.size
        tc, ts = min(times), float(r["seconds"])
        dp = abs(p.mean() / float(r["mean_pressure"]) - 1)
        rows.append((h, delta, tc, float(p.mean()), plastic))
        print(f"| {h / 1e9:.2f} | {tc:.2f} | {ts:.3f} | {tc / ts:.0f} | {dp:.1e} | {plastic:.4f} / {float(r['plastic_area_fraction']):.4f} |", flush=True)
    with open(out, "w") as f:
        f.write("# ContactMechanics 1.8 plastic system, one capped step from the undeformed surface, best of 2\n")
        f.write("hardness,approach,seconds,mean_pressure,plastic_area_fraction\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def csv_rows(path):
    import csv
    with open(path) as f:
        return list(csv.DictReader(l for l in f if not l.startswith("#")))


def run_speed(directory, out):
    """Seconds per load step, cold start, tolerance 1e-8, on the surfaces the strata bench
    wrote (DIR/surface_{512,2048}.npy), under mean-pressure (0.005 E*) and mean-gap
    (0.5 (z_M - z_mean)) control, as in benches/benches/bem.rs (bem_vs_tamaas).
    STRATA_TAMAAS_MAX_ITER raises Tamaas' iteration cap (its default stops 2048² solves
    before they converge); the error Tamaas returns is written beside the time."""
    import os
    import tamaas as tm
    from pathlib import Path

    max_iter = os.environ.get("STRATA_TAMAAS_MAX_ITER")

    tol = 1e-8
    rows = []
    for n in (512, 2048):
        if not (Path(directory) / f"surface_{n}.npy").is_file():
            continue
        z = surface(Path(directory) / f"surface_{n}.npy")
        sep = z.max() - z.mean()
        for control, value in (("pressure", 0.005 * ESTAR), ("gap", 0.5 * sep)):
            times = []
            for _ in range(3 if n <= 512 else 1):
                model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
                model.E = E
                model.nu = NU
                kind = tm.PolonskyKeerRey.pressure if control == "pressure" else tm.PolonskyKeerRey.gap
                solver = tm.PolonskyKeerRey(model, z, tol, tm.PolonskyKeerRey.gap, kind)
                solver.dump_freq = 10**9
                if max_iter:
                    solver.max_iter = int(max_iter)
                t = time.perf_counter()
                err = float(solver.solve(value))
                times.append(time.perf_counter() - t)
            p = np.asarray(model.traction).mean() / ESTAR
            gap = np.asarray(model["gap"]).reshape(z.shape)
            area = np.count_nonzero(gap == 0.0) / gap.size
            # Plain floats: numpy 2 writes np.float64(...) as its repr.
            rows.append((n, control, float(value), min(times), float(p), float(area)))
            print(f"tamaas n={n} {control} {value:e}: {min(times):.3f} s, p/E* {p:.8e}, A/A0 {area:.5e}, error {err:.2e} (tolerance {tol:e}, cap {solver.max_iter})", flush=True)
    with open(out, "w") as f:
        f.write("# Tamaas 2.9 PolonskyKeerRey, one load step from a cold start (best of 3 at n=512, 1 run at 2048), tolerance 1e-8\n")
        f.write("n,control,load,seconds,iterations,pressure_ratio,area_fraction\n")
        for n, control, value, secs, p, area in rows:
            f.write(f"{n},{control},{value!r},{secs!r},nan,{p!r},{area!r}\n")


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) != 3 or args[0] not in ("tamaas", "tamaas_pair", "cm", "cm_plastic", "free", "speed",
                                           "cm_plastic_speed"):
        raise SystemExit(__doc__)
    {"tamaas": run_tamaas, "tamaas_pair": run_tamaas_pair, "cm": run_cm, "cm_plastic": run_cm_plastic,
     "free": run_free,
     "speed": run_speed, "cm_plastic_speed": run_cm_plastic_speed}[args[0]](args[1], args[2])
