#!/usr/bin/env python3
"""Oracle for reldesign's probability-based energy-optimal reference
(designer/src/design/trajectory/optimal/robust.rs; Moya-Lasheras,
Ramirez-Laboreo, Sagues, IEEE TCST 28(5), 2020, arXiv 2404.01125).

Independently of reldesign: the model f(x, u, t) from the TOML
(tests/oracle/model.py), the stop d ≥ 0 into the stroke from the arrival stop,
half-normal of scale σ = [trajectory] contact_uncertainty,
ρ(d) = 2/(σ√(2π))·exp(−d²/(2σ²)); the cost

    J = ∫u² dt + W·∫ρ(d(z))·|v|³ dt        (= ∫u² dt + W·E[v_c²])

with W = K·J₀/v̄², K = 100, J₀ the deterministic optimum's ∫u² dt and
v̄ = stroke/(t_f − t₀) (the definition in docs/guide, not reldesign's code).
Pontryagin: H = u² + W·ρ|v|³ + pᵀf, u* = clip(−pᵀg/2, u_min, u_max),
ẋ = f(x, u*), ṗ = −∂H/∂x, all by CasADi AD; scipy.integrate.solve_bvp in
scaled variables from the polynomial guess (tests/oracle/check_optimal.py's
construction) for W = 0, then continuation in W (six geometric steps from
W/1000, a failed step split at its geometric midpoint) on scipy's own
solutions. J by 5-point Gauss–Legendre on scipy's
interpolant, split at the switching times (brentq).

Usage:
    check_robust.py MODEL.toml --reldesign BIN [--tol 1e-6]
compares W and J with `BIN build MODEL --report-json` (operations' optimal
.contact.weight and .contact.cost) to 1e-5 relative; exit status 1 on a mismatch.
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
import tomllib

import casadi as ca
import numpy as np
from scipy.optimize import brentq

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from desc import load  # noqa: E402
from model import build  # noqa: E402
import check_optimal as co  # noqa: E402

K = 100.0
GL5 = co.GL5


def system(p, umin, umax, W, sigma, zs):
    fns = build(p)
    x, u, t, q = ca.SX.sym("x", 3), ca.SX.sym("u"), ca.SX.sym("t"), ca.SX.sym("p", 3)
    F = fns["f"](x, u, t)
    g = ca.jacobian(F, u)
    raw = -ca.dot(q, g) / 2
    us = ca.fmin(ca.fmax(raw, umin), umax)
    rho = 2 / (sigma * np.sqrt(2 * np.pi)) * ca.exp(-0.5 * ((x[0] - zs) / sigma) ** 2)
    L = W * rho * ca.fabs(x[1]) ** 3
    H = u ** 2 + L + ca.dot(q, F)
    xdot = ca.substitute(F, u, us)
    pdot = -ca.substitute(ca.gradient(H, x), u, us)
    y = ca.vertcat(x, q)
    rhs = ca.vertcat(xdot, pdot)
    return {
        "rhs": ca.Function("rhs", [t, y], [rhs]),
        "jac": ca.Function("jac_y", [t, y], [ca.jacobian(rhs, y)]),
        "aux": ca.Function("aux", [t, y], [us, raw, rho * ca.fabs(x[1]) ** 3]),
    }


def bvp(sysd, t, Y, s, x0, xf, tol):
    return co.scaled_bvp(sysd, t, Y, s, x0, xf, tol, max_nodes=40000)


def costs(sysd, sol, s, umin, umax):
    """(∫u² dt, ∫ρ|v|³ dt) on the interpolant, split at the switches."""
    aux = sysd["aux"]

    def ax(tt):
        return [float(w) for w in aux(tt, sol.sol(tt) * s)]

    xs = sol.x
    samples = np.concatenate([xs[i] + (xs[i + 1] - xs[i]) * np.arange(8) / 8
                              for i in range(xs.size - 1)] + [xs[-1:]])
    raw = np.array([ax(ti)[1] for ti in samples])
    cuts_all = []
    for b in (umin, umax):
        for i in range(samples.size - 1):
            fa, fb = raw[i] - b, raw[i + 1] - b
            if (fa < 0) != (fb < 0):
                cuts_all.append(brentq(lambda tt: ax(tt)[1] - b, samples[i], samples[i + 1],
                                       xtol=1e-15))
    cuts_all.sort()
    e, c = 0.0, 0.0
    for i in range(xs.size - 1):
        cuts = [xs[i]] + [q for q in cuts_all if xs[i] < q < xs[i + 1]] + [xs[i + 1]]
        for a, b in zip(cuts[:-1], cuts[1:]):
            m, h = (a + b) / 2, (b - a) / 2
            for xg, wg in GL5:
                uu, _, lc = ax(m + h * xg)
                e += wg * h * uu * uu
                c += wg * h * lc
    return e, c


def solve(model, z0, zf, bound, sigma, t0, tf, tol):
    p = load(model)
    umin, umax = -bound, bound
    hs = co.hamiltonian_system(p, umin, umax)
    x0 = co.inverse(hs, z0, 0.0, 0.0)
    xf = co.inverse(hs, zf, 0.0, 0.0)
    t, Y, _, _ = co.guess(hs, z0, zf, t0=t0, tf=tf)
    stroke = abs(zf - z0)
    s = np.array([stroke, 2 * stroke / (tf - t0), np.max(np.abs(Y[2]))]
                 + [np.max(np.abs(Y[3 + k])) for k in range(3)])
    det = system(p, umin, umax, 0.0, sigma, zf)
    sol = bvp(det, t, Y, s, x0, xf, tol)
    j0, _ = costs(det, sol, s, umin, umax)
    vbar = stroke / (tf - t0)
    W = K * j0 / vbar ** 2
    # continuation: six geometric steps from W/1000; a step scipy cannot take
    # is split at the geometric midpoint from the last solved weight
    todo = list(W * 1e-3 ** (1 - np.arange(6) / 5))[::-1]
    done, splits = 0.0, 0
    while todo:
        w = todo.pop()
        sysd = system(p, umin, umax, w, sigma, zf)
        try:
            sol = bvp(sysd, sol.x, sol.y * s[:, None], s, x0, xf, tol)
            done = w
        except RuntimeError:
            splits += 1
            if splits > 8:
                raise
            todo += [w, np.sqrt(done * w) if done > 0 else 0.1 * w]
    e, c = costs(sysd, sol, s, umin, umax)
    return {"J0": j0, "W": W, "energy": e, "contact": c, "J": e + W * c,
            "nodes": int(sol.x.size)}


def reldesign_report(binary, model):
    with tempfile.TemporaryDirectory(prefix="check_robust_") as tmp:
        report = os.path.join(tmp, "report.json")
        subprocess.run([*shlex.split(binary), "build", model, "--quiet", "--out",
                        os.path.join(tmp, "code.rs"), "--report-json", report],
                       check=True, capture_output=True, text=True)
        with open(report) as fh:
            return json.load(fh)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model")
    ap.add_argument("--reldesign", metavar="BIN")
    ap.add_argument("--tol", type=float, default=1e-6)
    args = ap.parse_args()
    with open(args.model, "rb") as fh:
        d = tomllib.load(fh)
    tr, mech = d["trajectory"], d["mechanics"]
    sigma = tr["contact_uncertainty"]
    zmin, zmax = mech.get("z_min", 0.0), mech["z_max"]
    got = reldesign_report(args.reldesign, args.model) if args.reldesign else None
    ok = True
    for case in tr["operations"]:
        z0, zf = (zmax, zmin) if case == "closing" else (zmin, zmax)
        r = solve(args.model, z0, zf, tr["u_bound"], sigma, tr["takeoff"], tr["landing"],
                  args.tol)
        print(f"{case}: J0 = {r['J0']:.12g}, W = {r['W']:.10g}, ∫u² = {r['energy']:.12g}, "
              f"E[v_c²] = {r['contact']:.6g}, J = {r['J']:.12g}, nodes {r['nodes']}")
        if got is None:
            continue
        c = got["operations"][case]["optimal"]["contact"]
        dw = abs(c["weight"] - r["W"]) / r["W"]
        dj = abs(c["cost"] - r["J"]) / r["J"]
        good = dw <= 1e-5 and dj <= 1e-5
        ok &= good
        print(f"  reldesign: W = {c['weight']:.10g} (rel {dw:.1e}), J = {c['cost']:.12g} "
              f"(rel {dj:.1e}): {'OK' if good else 'MISMATCH'}")
    print("\ncheck_robust:", "OK" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
