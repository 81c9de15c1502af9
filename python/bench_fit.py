#!/usr/bin/env python3
"""Peer of `tyrekit bench fit`: the same pure-lateral Magic Formula stand-in
(see src/bench/fit.rs for the equations; BENCHMARK STAND-IN, not the
project's MF) fitted with SciPy `least_squares` over NumPy, on the data the
Rust side wrote to a CSV (columns alpha,fz,gamma,fy), from the same start
and bounds.

Prints one JSON line per method: {"method", "seconds", "cost", "nfev"}.
  trf-jac : method='trf' with the analytic Jacobian (the fair comparison)
  trf-2pt : method='trf' with 2-point finite differences (the usual route)
Prints "skipped: ..." when NumPy/SciPy are missing. The Rust side runs it with
one BLAS thread (OPENBLAS_NUM_THREADS=1 …), to compare 1 thread with 1 thread.
Usage: bench_fit.py DATA.csv
"""
import json
import sys
import time

try:
    import numpy as np
    from scipy.optimize import least_squares
except ImportError as e:  # pragma: no cover
    print(f"skipped: {e}")
    sys.exit(0)

FZ0 = 4000.0
START = [1.5, 0.9, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -12.0, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
LOWER = [1.0, 0.1, -1.0, -10.0, -5.0, -5.0, -1.0, -20.0, -100.0, 0.3, -2.0, -0.1, -0.1, -1.0, -0.5,
         -0.5, -2.0, -2.0]
UPPER = [2.0, 3.0, 1.0, 10.0, 0.9, 5.0, 1.0, 20.0, -1.0, 5.0, 2.0, 0.1, 0.1, 1.0, 0.5, 0.5, 2.0, 2.0]


def model(t, alpha, fz, gamma, want_jac):
    """Fy and (optionally) the m x 18 Jacobian, vectorised over samples."""
    (pcy1, pdy1, pdy2, pdy3, pey1, pey2, pey3, pey4, pky1, pky2, pky3,
     phy1, phy2, phy3, pvy1, pvy2, pvy3, pvy4) = t
    dfz = (fz - FZ0) / FZ0
    ay = alpha + phy1 + phy2 * dfz + phy3 * gamma
    c = pcy1
    mu0 = pdy1 + pdy2 * dfz
    cg = 1.0 - pdy3 * gamma ** 2
    d = mu0 * cg * fz
    u = fz / (pky2 * FZ0)
    s2 = 2.0 * u / (1.0 + u ** 2)  # = sin(2 atan u)
    kg = 1.0 - pky3 * np.abs(gamma)
    ky = pky1 * FZ0 * s2 * kg
    b = ky / (c * d)
    sg = np.sign(ay)
    e0 = pey1 + pey2 * dfz
    es = 1.0 - (pey3 + pey4 * gamma) * sg
    e = e0 * es
    sv = fz * (pvy1 + pvy2 * dfz + (pvy3 + pvy4 * dfz) * gamma)
    x = b * ay
    atx = np.arctan(x)
    phi = x - e * (x - atx)
    atphi = np.arctan(phi)
    y = c * atphi
    sy, cy = np.sin(y), np.cos(y)
    fy = d * sy + sv
    if not want_jac:
        return fy
    gphi = d * cy * c / (1.0 + phi ** 2)
    dphidx = 1.0 - e * x ** 2 / (1.0 + x ** 2)
    dfe = -gphi * (x - atx)
    dfb = gphi * dphidx * ay
    dfsh = gphi * dphidx * b
    dfc = d * cy * atphi - dfb * b / c
    dfd = sy - dfb * b / d
    dfky = dfb / (c * d)
    j = np.empty((fy.size, 18))
    j[:, 0] = dfc
    j[:, 1] = dfd * cg * fz
    j[:, 2] = dfd * cg * fz * dfz
    j[:, 3] = -dfd * mu0 * gamma ** 2 * fz
    j[:, 4] = dfe * es
    j[:, 5] = dfe * es * dfz
    j[:, 6] = -dfe * e0 * sg
    j[:, 7] = -dfe * e0 * sg * gamma
    j[:, 8] = dfky * FZ0 * s2 * kg
    j[:, 9] = dfky * pky1 * FZ0 * kg * (1.0 - u ** 2) / (1.0 + u ** 2) * 2.0 / (1.0 + u ** 2) * (-u / pky2)
    j[:, 10] = -dfky * pky1 * FZ0 * s2 * np.abs(gamma)
    j[:, 11] = dfsh
    j[:, 12] = dfsh * dfz
    j[:, 13] = dfsh * gamma
    j[:, 14] = fz
    j[:, 15] = fz * dfz
    j[:, 16] = fz * gamma
    j[:, 17] = fz * dfz * gamma
    return fy, j


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    data = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1)
    alpha, fz, gamma, fy = data[:, 0], data[:, 1], data[:, 2], data[:, 3]

    def res(t):
        return model(t, alpha, fz, gamma, False) - fy

    def jac(t):
        return model(t, alpha, fz, gamma, True)[1]

    for name, j in (("trf-jac", jac), ("trf-2pt", "2-point")):
        t0 = time.perf_counter()
        r = least_squares(res, START, jac=j, bounds=(LOWER, UPPER), method="trf", x_scale="jac")
        dt = time.perf_counter() - t0
        print(json.dumps({"method": name, "seconds": dt, "cost": float(r.cost), "nfev": int(r.nfev)}))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
