"""The paper's Fig. 15-style curve: mean pressure p_n/E*1 against the separation g_n
for the N model (independent asperities), the I model (interacting asperities,
periodic images) and the full-field BEM, on the paper's rough surface and two-layer
stack (Waddad et al., section 5).

    python python/examples/fig15_curve.py [--ratio 1] [--grid 512] [--out fig15.png]

--ratio picks the stack E2/E1 = 0.2, 1 or 5 (tables/stacks/); --grid 128 is a quick
look (the BEM at 512² takes ~20 s). Run from anywhere: paths are found from this file.
"""

import argparse
import pathlib
import time

import matplotlib.pyplot as plt
import numpy as np

import strata

ROOT = pathlib.Path(__file__).resolve().parents[2]
STACKS = {"0.2": "paper-two-layer-E2E1-0.2.toml", "1": "paper-two-layer-E2E1-1.toml", "5": "paper-two-layer.toml"}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ratio", choices=sorted(STACKS), default="1", help="E2/E1 of the stack")
    ap.add_argument("--grid", type=int, default=512, help="grid points per side")
    ap.add_argument("--out", default="fig15.png", help="output picture")
    args = ap.parse_args()

    stack = strata.Stack.from_file(ROOT / "tables" / "stacks" / STACKS[args.ratio])
    # One table serves the whole E2/E1 family of the paper's stack.
    table = strata.Table.load(ROOT / "tables" / "paper-two-layer.strata")
    surface = strata.Surface.generate(size=1e-3, grid=args.grid, fractal_dimension=2.4, k_min=2, k_max=10,
                                      rms=3.4e-6, seed=20240611)
    load = {"approach": {"from": 1.3e-6, "to": 9.8e-6, "steps": 18}}

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for model, label, style in [("independent", "N model", "--"), ("interacting", "I model (periodic 5×5)", "-"),
                                ("bem", "BEM", "o")]:
        t0 = time.perf_counter()
        curve = strata.Scene(stack, surface, model=model, load=load, table=table).solve()
        print(f"{label}: {len(curve)} steps in {time.perf_counter() - t0:.2f} s; "
              f"p/E*1 from {curve.pressure_ratio.min():.3e} to {curve.pressure_ratio.max():.3e}")
        ax.semilogy(curve.gap * 1e6, curve.pressure_ratio, style, label=label, markersize=4)
    ax.set_xlabel("separation $g_n$ (µm)")
    ax.set_ylabel("$p_n / E^*_1$")
    ax.set_title(f"Mean pressure against separation, E2/E1 = {args.ratio}, {args.grid}² grid")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")
    assert np.all(np.diff(curve.mean_pressure) > 0)


if __name__ == "__main__":
    main()
