"""Tamaas' PolonskyKeerTan on a surface written by tests/it/tangential_peer.rs.

Usage: pkt_stick.py HEIGHTS.txt E NU MU MEAN_PRESSURE MEAN_TRACTION_X TOL
Solves the coupled normal–tangential contact (surface_2d model, Boussinesq–Cerruti,
normal and tangential traction applied in one step, force control) on a periodic square
cell of side 1 (the mean traction along x, the columns) and prints `contact_points stick_points` (stick: |q| < μp(1 − 1e-6)).
"""
import sys

import numpy as np
import tamaas as tm

path, e, nu, mu, p_mean, q_mean, tol = sys.argv[1:8]
e, nu, mu, p_mean, q_mean, tol = map(float, (e, nu, mu, p_mean, q_mean, tol))
z = np.loadtxt(path)
n = z.shape[0]
tm.set_log_level(tm.LogLevel.error)
model = tm.ModelFactory.createModel(tm.model_type.surface_2d, [1.0, 1.0], [n, n])
model.E = e
model.nu = nu
solver = tm.PolonskyKeerTan(model, z, tol, mu)
solver.max_iter = 20000
# Tamaas' first axis is the rows (y in strata's row-major heights): the traction along x
# (the columns) is its second component.
solver.solve([0.0, q_mean, p_mean])
t = np.asarray(model.traction)
p = t[..., 2]
q = np.hypot(t[..., 0], t[..., 1])
contact = p > 0
stick = contact & (q < mu * p * (1.0 - 1e-6))
print(int(contact.sum()), int(stick.sum()))
