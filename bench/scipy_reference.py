#!/usr/bin/python3
"""Reference timing: the same BH-7 calibration as `kincal calibrate` (standard
DH, 12 identifiable robot parameters + the 6-parameter measuring frame, 3D
residuals, training rows only) with scipy.optimize.least_squares (TRF,
2-point numeric Jacobian), as a careful Python user would write it.

Usage: /usr/bin/python3 bench/scipy_reference.py OBS.csv
Needs Debian's python3-scipy (not a kincal dependency; bench only).
"""
import sys
import time

import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

NOMINAL = np.array([  # rows: theta(deg), d, a, alpha(deg); j1..j5, tool
    [0, 0, 0, 0], [0, 0, 200, 0], [0, 0, 200, 0], [-90, -170, 0, -90],
    [0, 145, 0, -90], [0, 150, 0, 0]], dtype=float)
PRISMATIC = [True, False, False, False, False]
# (row, field) of the identifiable parameters kincal reports for BH-7.
FREE = [(0, 3), (1, 2), (1, 3), (2, 0), (2, 2), (2, 3), (3, 0), (3, 2),
        (3, 3), (4, 0), (4, 1), (5, 1)]


def tips(dh, q):
    n = q.shape[0]
    t = np.tile(np.eye(4), (n, 1, 1))
    for r in range(6):
        theta = np.radians(dh[r, 0]) + (0 if r == 5 or PRISMATIC[r] else np.radians(q[:, r]))
        d = dh[r, 1] + (q[:, r] if r < 5 and PRISMATIC[r] else 0)
        a, al = dh[r, 2], np.radians(dh[r, 3])
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(al), np.sin(al)
        m = np.zeros((n, 4, 4))
        m[:, 0, 0], m[:, 0, 1], m[:, 0, 2], m[:, 0, 3] = ct, -st * ca, st * sa, a * ct
        m[:, 1, 0], m[:, 1, 1], m[:, 1, 2], m[:, 1, 3] = st, ct * ca, -ct * sa, a * st
        m[:, 2, 1], m[:, 2, 2], m[:, 2, 3] = sa, ca, d
        m[:, 3, 3] = 1
        t = t @ m
    return t[:, :3, 3]


def main():
    rows = [l for l in open(sys.argv[1]) if not l.startswith('#')]
    header = rows[0].strip().split(',')
    data = np.array([[float(v) for v in l.strip().split(',')[1:9]] for l in rows[1:]])
    q, p = data[:, 0:5], data[:, 5:8]
    rng = np.random.default_rng(1)
    idx = rng.permutation(len(q))
    train = idx[len(q) // 5:]

    def unpack(x):
        dh = NOMINAL.copy()
        for k, (r, f) in enumerate(FREE):
            dh[r, f] += x[k]
        return dh, Rotation.from_rotvec(x[12:15]), x[15:18]

    def residual(x):
        dh, rot, t = unpack(x)
        return (rot.apply(tips(dh, q[train])) + t - p[train]).ravel()

    start = time.perf_counter()
    # Initial frame: Kabsch on nominal tips (as kincal does).
    a = tips(NOMINAL, q[train])
    rot, _ = Rotation.align_vectors(p[train] - p[train].mean(0), a - a.mean(0))
    t0 = p[train].mean(0) - rot.apply(a.mean(0))
    x0 = np.concatenate([np.zeros(12), rot.as_rotvec(), t0])
    sol = least_squares(residual, x0, method='trf', x_scale='jac',
                        xtol=1e-12, ftol=1e-12, gtol=1e-12)
    seconds = time.perf_counter() - start
    r = sol.fun.reshape(-1, 3)
    print(f"scipy least_squares: {seconds:.3f} s, {sol.nfev} evaluations, "
          f"train RMS {np.sqrt((r ** 2).sum(1).mean()):.4f} mm, {len(train)} poses")


if __name__ == '__main__':
    main()
