#!/usr/bin/env python3
"""Independent oracle of `reldesign robustness --json` (model-free-sliding-mode
soft landing §4.1) for descriptions with a polynomial [trajectory] and a
sliding-mode [controller].

From the TOML alone (tests/oracle/desc.py, model.py), for each operation:
the 5th-degree polynomial reference (perfect-tracking-soft-landing (51)) on the
instants 0, t_end/n, …, t_end plus takeoff and landing, t_end = landing +
takeoff (SM (45)); at each instant the flux that tracks it, found by root
finding on f_v(z_r, v_r, φ) = a_r (scipy brentq, φ > 0) — not by reldesign's
closed form; f_j = L_f³z and B_j = −L_g L_f²z by CasADi AD; then

    F*_mag = m·a_r − F_pas(z_r, v_r) ≤ 0 (13),  F*_mag ≥ m·(f_v(φ_sat) − f_v(0)) (14),
    u* = |f_j − j_r| / |B_j| (48),
    ε̄ = (λ1 + λ2)·0.2·max|a_r| + λ1·λ2·0.2·max|v_r| (50), (52),
    required u_max = max u* + (ε̄ + η) / min|B_j| (49).

Compares max_u_star, min_b_j, required_u_max and feasibility with reldesign's.

Usage: check_robustness.py RELDESIGN MODEL.toml [--samples N] [--tol 1e-6]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tomllib

import casadi as ca
import numpy as np
from scipy.optimize import brentq

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from desc import load  # noqa: E402
from model import build  # noqa: E402


def polynomial(z0, zf, t0, tf, t):
    d = tf - t0
    tau = min(max((t - t0) / d, 0.0), 1.0)
    moving = 1.0 if t0 < t < tf else 0.0
    dz = zf - z0
    s = tau**3 * (10 - 15 * tau + 6 * tau**2)
    s1 = 30 * tau**2 * (1 - tau) ** 2
    s2 = 60 * tau * (1 - tau) * (1 - 2 * tau)
    s3 = 60 * (1 - 6 * tau + 6 * tau**2)
    return z0 + dz * s, moving * dz * s1 / d, moving * dz * s2 / d**2, moving * dz * s3 / d**3


def functions(p):
    fns = build(p)
    x, u, t = ca.SX.sym("x", 3), ca.SX.sym("u"), ca.SX.sym("t")
    F = fns["f"](x, u, t)
    drift = ca.substitute(F, u, ca.SX(0))
    g = ca.jacobian(F, u)
    lie = lambda h, field: ca.mtimes(ca.jacobian(h, x), field)  # noqa: E731
    lf1 = lie(x[0], drift)
    lf2 = lie(lf1, drift)
    return (
        ca.Function("a", [x, t], [lf2]),
        ca.Function("fj", [x, t], [lie(lf2, drift)]),
        ca.Function("bj", [x, t], [-lie(lf2, g)]),
    )


def analyse(p, raw, z0, zf, n):
    tr, sm = raw["trajectory"], raw["controller"]
    t0, tf = float(tr["takeoff"]), float(tr["landing"])
    t_end = tf + t0
    times = sorted(set(list(np.linspace(0.0, t_end, n + 1)) + [t0, tf]))
    accel, fj, bj = functions(p)
    a_of = lambda z, v, phi, t: float(accel([z, v, phi], t))  # noqa: E731
    phi_sat = p.core["phi_sat"] if p.core_model == "saturating" else None
    rows = []
    for t in times:
        z, v, a, j = polynomial(z0, zf, t0, tf, t)
        a0 = a_of(z, v, 0.0, t)
        force = p.mass * (a - a0)
        bound = p.mass * (a_of(z, v, phi_sat, t) - a0) if phi_sat else -np.inf
        if not (force < 0.0 and force >= bound):
            rows.append((t, v, a, np.inf, 0.0))
            continue
        top = phi_sat * (1 - 1e-12) if phi_sat else 1.0
        phi = brentq(lambda f: a_of(z, v, f, t) - a, 0.0, top, xtol=1e-20, rtol=1e-15, maxiter=500)
        b = abs(float(bj([z, v, phi], t)))
        rows.append((t, v, a, abs(float(fj([z, v, phi], t)) - j) / b, b))
    rows = np.array(rows)
    lam1, lam2, eta = float(sm["lambda1"]), float(sm["lambda2"]), float(sm["eta"])
    eps = (lam1 + lam2) * 0.2 * np.max(np.abs(rows[:, 2])) + lam1 * lam2 * 0.2 * np.max(np.abs(rows[:, 1]))
    max_u, min_b = np.max(rows[:, 3]), np.min(rows[:, 4])
    feasible = bool(np.all(np.isfinite(rows[:, 3])))
    return {
        "feasible": feasible,
        "max_u_star": float(max_u) if feasible else None,
        "min_b_j": float(min_b),
        "required_u_max": float(max_u + (eps + eta) / min_b) if feasible else None,
    }


def close(a, b, tol):
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= tol * max(abs(b), 1e-300)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("reldesign")
    ap.add_argument("model")
    ap.add_argument("--samples", type=int, default=400)
    ap.add_argument("--tol", type=float, default=1e-6)
    a = ap.parse_args()
    with open(a.model, "rb") as fh:
        raw = tomllib.load(fh)
    p = load(raw)
    out = subprocess.run(
        [a.reldesign, "robustness", a.model, "--json", "--samples", str(a.samples)],
        check=True, capture_output=True, text=True,
    )
    got = {o["operation"]: o for o in json.loads(out.stdout)["operations"]}
    ends = {"closing": (p.z_max, p.z_min), "opening": (p.z_min, p.z_max)}
    ok = True
    print(f"== {a.model}")
    for op in raw["trajectory"]["operations"]:
        ref = analyse(p, raw, *ends[op], a.samples)
        for key in ("feasible", "max_u_star", "min_b_j", "required_u_max"):
            g, r = got[op][key], ref[key]
            good = g == r if key == "feasible" else close(g, r, a.tol)
            if key == "min_b_j" and not ref["feasible"]:
                good = True  # 0 at an infeasible instant on both sides
            print(f"  {op:<8} {key:<15} reldesign {g!r:<24} oracle {r!r:<24} {'ok' if good else 'FAIL'}")
            ok &= good
    print("\ncheck_robustness:", "OK" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
