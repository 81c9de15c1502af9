"""Peer benchmark for `tyrekit bench mf`.

A NumPy-vectorised MF 6.1 combined-slip evaluation (Fx, Fy, Mx, My, Mz), written
for this comparison from the MF 6.1 equations (Pacejka, Tyre and Vehicle
Dynamics 3rd ed. 4.E1-4.E78; Besselink et al. 2010) with the same choices
tyrekit makes to match MFeval 4.0, for inputs inside the tyre's ranges and above
VXLOW (use mode 111 then clips nothing). Also times the PyPI `pacejka` package
where it applies.

usage: bench_mf.py PARAMS.json INPUTS.csv [REPEATS]
prints one JSON line: numpy_ns, check (first points: Fx Fy Mx My Mz),
pacejka_ns / pacejka_error.
"""

import json
import sys
import time

EPS = 1e-6


def mf61_forces(np, P, fz, kappa, alpha, gamma, vx, p):
    """Fx, Fy, Mx, My, Mz for arrays of inputs (ISO-W, SI)."""
    g = P.__getitem__
    fz0 = g("FNOMIN")
    r0 = g("UNLOADED_RADIUS")
    fz0p = g("LFZO") * fz0
    dfz = (fz - fz0p) / fz0p
    dpi = (p - g("NOMPRES")) / g("NOMPRES")
    sgn1 = lambda x: np.where(x < 0, -1.0, 1.0)
    cap = lambda x: np.minimum(x, 1.0)
    mf = lambda d, c, b, x, e: d * np.sin(c * np.arctan(b * x - e * (b * x - np.arctan(b * x))))

    # Pure longitudinal (4.E9-4.E18)
    cx = g("PCX1") * g("LCX")
    mux = (g("PDX1") + g("PDX2") * dfz) * (1 + g("PPX3") * dpi + g("PPX4") * dpi**2) * (1 - g("PDX3") * gamma**2) * g("LMUX")
    dx = mux * fz
    kxk = fz * (g("PKX1") + g("PKX2") * dfz) * np.exp(g("PKX3") * dfz) * (1 + g("PPX1") * dpi + g("PPX2") * dpi**2) * g("LKX")
    bx = kxk / (cx * dx + EPS * sgn1(dx))
    kx = kappa + (g("PHX1") + g("PHX2") * dfz) * g("LHX")
    ex = cap((g("PEX1") + g("PEX2") * dfz + g("PEX3") * dfz**2) * (1 - g("PEX4") * np.sign(kx)) * g("LEX"))
    fx0 = mf(dx, cx, bx, kx, ex) + fz * (g("PVX1") + g("PVX2") * dfz) * g("LVX") * g("LMUX")

    # Pure lateral (4.E19-4.E30), as a function of camber
    def fy0(gs):
        kya = (g("PKY1") * fz0p * (1 + g("PPY1") * dpi) * (1 - g("PKY3") * np.abs(gs))
               * np.sin(g("PKY4") * np.arctan((fz / fz0p) / ((g("PKY2") + g("PKY5") * gs**2) * (1 + g("PPY2") * dpi)))) * g("LKY"))
        svyg = fz * (g("PVY3") + g("PVY4") * dfz) * gs * g("LKYC") * g("LMUY")
        kyg0 = fz * (g("PKY6") + g("PKY7") * dfz) * (1 + g("PPY5") * dpi) * g("LKYC")
        shy = (g("PHY1") + g("PHY2") * dfz) * g("LHY") + (kyg0 * gs - svyg) / (kya + EPS * sgn1(kya))
        svy = fz * (g("PVY1") + g("PVY2") * dfz) * g("LVY") * g("LMUY") + svyg
        ay = alpha + shy
        cy = g("PCY1") * g("LCY")
        muy = (g("PDY1") + g("PDY2") * dfz) * (1 + g("PPY3") * dpi + g("PPY4") * dpi**2) * (1 - g("PDY3") * gs**2) * g("LMUY")
        dy = muy * fz
        ey = cap((g("PEY1") + g("PEY2") * dfz) * (1 + g("PEY5") * gs**2 - (g("PEY3") + g("PEY4") * gs) * sgn1(ay)) * g("LEY"))
        by = kya / (cy * dy + EPS * sgn1(dy))
        return mf(dy, cy, by, ay, ey) + svy, muy, kya, shy, svy, by, cy

    def gyk(gs, muy):
        dvyk = muy * fz * (g("RVY1") + g("RVY2") * dfz + g("RVY3") * gs) * np.cos(np.arctan(g("RVY4") * alpha))
        svyk = dvyk * np.sin(g("RVY5") * np.arctan(g("RVY6") * kappa)) * g("LVYKA")
        shyk = g("RHY1") + g("RHY2") * dfz
        eyk = cap(g("REY1") + g("REY2") * dfz)
        byk = (g("RBY1") + g("RBY4") * gs**2) * np.cos(np.arctan(g("RBY2") * (alpha - g("RBY3")))) * g("LYKA")
        w = lambda x: np.cos(g("RCY1") * np.arctan(byk * x - eyk * (byk * x - np.arctan(byk * x))))
        return w(kappa + shyk) / w(shyk), svyk

    fy0v, muy, kya, shy, svy, by, cy = fy0(gamma)

    # Combined slip (4.E50-4.E67)
    exa = cap(g("REX1") + g("REX2") * dfz)
    bxa = (g("RBX1") + g("RBX3") * gamma**2) * np.cos(np.arctan(g("RBX2") * kappa)) * g("LXAL")
    wx = lambda x: np.cos(g("RCX1") * np.arctan(bxa * x - exa * (bxa * x - np.arctan(bxa * x))))
    fx = wx(alpha + g("RHX1")) / wx(g("RHX1")) * fx0
    gk, svyk = gyk(gamma, muy)
    fy = gk * fy0v + svyk

    # Aligning torque (4.E31-4.E47, 4.E71-4.E78, paper A54-A60)
    fzm = np.maximum(fz, g("FZMIN"))
    sht = g("QHZ1") + g("QHZ2") * dfz + (g("QHZ3") + g("QHZ4") * dfz) * gamma
    kyap = kya + EPS * sgn1(kya)
    alphar = alpha + shy + svy / kyap
    alphat = alpha + sht
    dt = (g("QDZ1") + g("QDZ2") * dfz) * (1 - g("PPZ1") * dpi) * (1 + g("QDZ3") * gamma + g("QDZ4") * gamma**2) * fzm * (r0 / fz0p) * g("LTR")
    bt = (g("QBZ1") + g("QBZ2") * dfz + g("QBZ3") * dfz**2) * (1 + g("QBZ4") * gamma + g("QBZ5") * np.abs(gamma)) * g("LKY") / g("LMUY")
    ct = g("QCZ1")
    et = cap((g("QEZ1") + g("QEZ2") * dfz + g("QEZ3") * dfz**2) * (1 + (g("QEZ4") + g("QEZ5") * gamma) * (2 / np.pi) * np.arctan(bt * ct * alphat)))
    dr = (fzm * r0 * ((g("QDZ6") + g("QDZ7") * dfz) * g("LRES") + ((g("QDZ8") + g("QDZ9") * dfz) * (1 + g("PPZ2") * dpi)
          + (g("QDZ10") + g("QDZ11") * dfz) * np.abs(gamma)) * gamma * g("LKZC")) * g("LMUY") * np.sign(vx) * np.cos(alpha))
    br = g("QBZ9") * g("LKY") / g("LMUY") + g("QBZ10") * by * cy
    kk2 = (kxk / kyap) ** 2 * kappa**2
    ar_eq = np.arctan(np.sqrt(np.tan(alphar) ** 2 + kk2)) * np.sign(alphar)
    at_eq = np.arctan(np.sqrt(np.tan(alphat) ** 2 + kk2)) * np.sign(alphat)
    s = r0 * (g("SSZ1") + g("SSZ2") * (fy / fz0) + (g("SSZ3") + g("SSZ4") * dfz) * gamma) * g("LS")
    mzr = dr * np.cos(np.arctan(br * ar_eq))
    fy00, muy0 = fy0(np.zeros_like(gamma))[:2]
    gk0, _ = gyk(gamma, muy0)
    vc = np.sqrt(vx**2 + (np.tan(alpha) * np.abs(vx)) ** 2)
    cos_ap = np.cos(np.arccos(vx / (vc + EPS)))
    t = dt * np.cos(ct * np.arctan(bt * at_eq - et * (bt * at_eq - np.arctan(bt * at_eq)))) * cos_ap * g("LFZO")
    mz = -t * (gk0 * fy00) + mzr + s * fx

    # Overturning (Besselink draft eq. 49) and rolling resistance (paper A48)
    fzx = np.where(fz < g("FZMIN"), fz * (fz / g("FZMIN")) ** 2, fz)
    fyn, fzn = fy / fz0, fzx / fz0
    mx = (r0 * fzx * g("LMX") * (g("QSX1") * g("LVMX") - g("QSX2") * gamma * (1 + g("PPMX1") * dpi) - g("QSX12") * gamma * np.abs(gamma)
          + g("QSX3") * fyn + g("QSX4") * np.cos(g("QSX5") * np.arctan((g("QSX6") * fzn) ** 2)) * np.sin(g("QSX7") * gamma + g("QSX8") * np.arctan(g("QSX9") * fyn))
          + g("QSX10") * np.arctan(g("QSX11") * fzn) * gamma) + r0 * fy * g("LMX") * (g("QSX13") + g("QSX14") * np.abs(gamma)))
    fzy = np.where(fz < g("FZMIN"), fz * (fz / g("FZMIN")), fz)
    vr = vx / g("LONGVL")
    my = -(r0 * fz0 * g("LMY") * (g("QSY1") + g("QSY2") * (fx / fz0) + g("QSY3") * np.abs(vr) + g("QSY4") * vr**4
           + (g("QSY5") + g("QSY6") * (fzy / fz0)) * gamma**2) * ((fzy / fz0) ** g("QSY7") * (p / g("NOMPRES")) ** g("QSY8")))
    return fx, fy, mx, my, mz


def best_ns(fn, n, reps):
    best = float("inf")
    for _ in range(reps):
        t0 = time.thread_time_ns()  # CPU time, like the Rust side (shared machine)
        fn()
        best = min(best, (time.thread_time_ns() - t0) / n)
    return best


def main():
    out = {}
    try:
        import numpy as np
    except ImportError as e:
        print(json.dumps({"numpy_error": f"numpy not installed ({e})", "pacejka_error": "numpy not installed"}))
        return
    params = json.load(open(sys.argv[1]))
    data = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1)
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    fz, kappa, alpha, gamma, vx, p = (np.ascontiguousarray(data[:, i]) for i in range(6))
    n = len(fz)
    res = mf61_forces(np, params, fz, kappa, alpha, gamma, vx, p)
    out["check"] = [[float(r[i]) for r in res] for i in range(min(8, n))]
    out["numpy_ns"] = best_ns(lambda: mf61_forces(np, params, fz, kappa, alpha, gamma, vx, p), n, reps)
    try:
        import pacejka

        # Same load scale, peak friction and stiffnesses as the tyre at Fz0.
        fz0 = params["FNOMIN"]
        tyre = pacejka.Tire.from_macro_properties(
            "bench",
            mu_base=params["PDY1"],
            cornering_stiffness_per_rad=abs(params["PKY1"] * fz0 * np.sin(2 * np.arctan(1 / params["PKY2"]))),
            longitudinal_stiffness=params["PKX1"] * fz0,
            f_z0=fz0,
        )
        out["pacejka_version"] = getattr(pacejka, "__version__", "?")
        out["pacejka_ns"] = best_ns(lambda: tyre.calculate_forces(fz, alpha, kappa, friction_circle=True, alpha_unit="rad"), n, reps)
    except Exception as e:  # missing package or API mismatch: report, do not fail
        out["pacejka_error"] = f"{type(e).__name__}: {e}"
    print(json.dumps(out))


if __name__ == "__main__":
    main()
