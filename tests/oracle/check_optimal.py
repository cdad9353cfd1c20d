#!/usr/bin/env python3
"""Oracle for reldesign's energy-optimal trajectory (designer/src/design/trajectory/optimal.rs;
perfect-tracking-soft-landing §4, eqs. 58-66).

Independently of reldesign: f(x, u, t) from the TOML (tests/oracle/model.py
`build`), the Hamiltonian system H = u² + pᵀf, u* = clip(−pᵀg/2, u_min, u_max),
ẋ = f(x, u*), ṗ = −(∂f/∂x)ᵀp at u*, and its Jacobian by CasADi AD; solved by
scipy.integrate.solve_bvp in scaled variables ŷ = y/s (scipy has no scaling
option; reldesign's solver scales the same way), same tolerance, same initial
guess construction (5th-degree polynomial, x_r = T⁻¹ by the quadratic-in-φ
acceleration, u_r = α + β·jerk from CasADi Lie derivatives, p₃ from
pᵀg = −2u_r, p₂, p₁ from the costate equations along the chain with
np.gradient), written here from the paper, not from the Rust code.

J = ∫u*² dt is integrated on scipy's interpolant (5-point Gauss–Legendre per
mesh interval, split at the switching times, located by brentq on the
interpolant).

Usage:
    check_optimal.py MODEL.toml [--bound 20] [--tol 1e-6] [--rust]
--rust runs `cargo test -p reldesign-designer --test optimal -- --ignored
export_optimal_json --nocapture` (which prints reldesign's summaries as
`OPTIMAL_JSON {...}` lines) and compares: J within 1e-6 relative, max|u|
within 1e-6 relative, switching times within one mesh interval.
Exit status 1 on a mismatch.
"""
from __future__ import annotations

import argparse
import tomllib
import json
import os
import subprocess
import sys
import time

import casadi as ca
import numpy as np
from scipy.integrate import solve_bvp
from scipy.optimize import brentq

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from desc import load  # noqa: E402
from model import build  # noqa: E402

T0, TF = 1e-3, 6e-3
GL5 = [(0.0, 0.5688888888888889), (-0.5384693101056831, 0.4786286704993665),
       (0.5384693101056831, 0.4786286704993665), (-0.9061798459386640, 0.2369268850561891),
       (0.9061798459386640, 0.2369268850561891)]


def hamiltonian_system(p, umin, umax):
    fns = build(p)
    x, u, t, q = ca.SX.sym("x", 3), ca.SX.sym("u"), ca.SX.sym("t"), ca.SX.sym("p", 3)
    F = fns["f"](x, u, t)
    g = ca.jacobian(F, u)
    drift = ca.substitute(F, u, ca.SX(0))
    raw = -ca.dot(q, g) / 2
    us = ca.fmin(ca.fmax(raw, umin), umax)
    A = ca.jacobian(F, x)
    xdot = ca.substitute(F, u, us)
    pdot = -ca.substitute(ca.mtimes(A.T, q), u, us)
    y = ca.vertcat(x, q)
    rhs = ca.vertcat(xdot, pdot)
    H = us ** 2 + ca.dot(q, xdot)
    # Lie derivatives for α, β (guess) and the acceleration a = L_f²z
    lie = lambda h, fld: ca.mtimes(ca.jacobian(h, x), fld)  # noqa: E731
    lf1 = lie(x[0], drift)
    lf2 = lie(lf1, drift)
    lf3 = lie(lf2, drift)
    lglf2 = lie(lf2, g)
    return {
        "rhs": ca.Function("rhs", [t, y], [rhs]),
        "jac": ca.Function("jac_y", [t, y], [ca.jacobian(rhs, y)]),
        "aux": ca.Function("aux", [t, y], [us, raw, H]),
        "alpha_beta": ca.Function("ab", [x], [-lf3 / lglf2, 1 / lglf2]),
        "acc": ca.Function("acc", [x], [F[1]]),
        "A": ca.Function("A", [x, u], [A]),
        "g": ca.Function("g", [x], [g]),
    }


def poly(z0, zf, t, t0=T0, tf=TF):
    T = tf - t0
    s = (t - t0) / T
    d = zf - z0
    return (z0 + d * s ** 3 * (10 - 15 * s + 6 * s * s),
            d * 30 * s * s * (1 - s) ** 2 / T,
            d * 60 * s * (1 - s) * (1 - 2 * s) / T ** 2,
            d * 60 * (1 - 6 * s + 6 * s * s) / T ** 3)


def inverse(hs, z, v, a):
    """x with ż = v, v̇ = a: acc = a0(z, v) + c2(z)·φ² (quadratic, no linear term)."""
    a0 = float(hs["acc"]([z, v, 0.0]))
    c2 = float(hs["acc"]([z, v, 1e-5])) - a0
    phi2 = (a - a0) / c2 * 1e-10
    assert phi2 > 0, f"φ² = {phi2} ≤ 0 at z = {z}"
    return np.array([z, v, np.sqrt(phi2)])


def guess(hs, z0, zf, m=151, t0=T0, tf=TF):
    t = np.linspace(t0, tf, m)
    X, U, G, As = [], [], [], []
    for ti in t:
        z, v, a, j = poly(z0, zf, ti, t0, tf)
        x = inverse(hs, z, v, a)
        al, be = (float(w) for w in hs["alpha_beta"](x))
        u = al + be * j
        X.append(x), U.append(u)
        G.append(np.array(hs["g"](x)).ravel()), As.append(np.array(hs["A"](x, u)))
    X, U = np.array(X), np.array(U)
    P = np.array([-2 * U[i] * G[i] / G[i].dot(G[i]) for i in range(m)])
    p3 = P[:, 2]
    p2 = np.array([-(d + As[i][2, 2] * p3[i]) / As[i][1, 2]
                   for i, d in enumerate(np.gradient(p3, t, edge_order=2))])
    p1 = np.array([-(d + As[i][1, 1] * p2[i] + As[i][2, 1] * p3[i]) / As[i][0, 1]
                   for i, d in enumerate(np.gradient(p2, t, edge_order=2))])
    P = np.column_stack([p1, p2, p3])
    tfine = np.linspace(t0, tf, 2001)
    uf = []
    for ti in tfine:
        z, v, a, j = poly(z0, zf, min(max(ti, t0 + 1e-12 * (tf - t0)), tf - 1e-12 * (tf - t0)),
                          t0, tf)
        x = inverse(hs, z, v, a)
        al, be = (float(w) for w in hs["alpha_beta"](x))
        uf.append(al + be * j)
    uf = np.array(uf)
    w = np.ones(2001); w[1:-1:2] = 4; w[2:-1:2] = 2
    guess_cost = float(np.sum(w * uf ** 2) * (tfine[1] - tfine[0]) / 3)
    return t, np.column_stack([X, P]).T, guess_cost, float(np.max(np.abs(uf)))


def scaled_bvp(sysd, t, Y, s, x0, xf, tol, max_nodes):
    """scipy's solve_bvp on the Hamiltonian system `sysd` in the variables
    y/s, from the guess (t, Y), z, v, φ fixed to x0 at t[0] and to xf at t[-1]."""
    rhs, jac = sysd["rhs"], sysd["jac"]

    def f(tt, yh):
        y = yh * s[:, None]
        return np.column_stack([np.array(rhs(tt[i], y[:, i])).ravel() / s
                                for i in range(tt.size)])

    def fj(tt, yh):
        y = yh * s[:, None]
        out = np.empty((6, 6, tt.size))
        for i in range(tt.size):
            out[:, :, i] = np.array(jac(tt[i], y[:, i])) * s[None, :] / s[:, None]
        return out

    def bc(ya, yb):
        return np.concatenate([(ya[:3] * s[:3] - x0) / s[:3], (yb[:3] * s[:3] - xf) / s[:3]])

    def bcj(ya, yb):
        ja, jb = np.zeros((6, 6)), np.zeros((6, 6))
        for k in range(3):
            ja[k, k] = 1.0
            jb[3 + k, k] = 1.0
        return ja, jb

    sol = solve_bvp(f, bc, t, Y / s[:, None], fun_jac=fj, bc_jac=bcj, tol=tol,
                    max_nodes=max_nodes)
    if sol.status != 0:
        raise RuntimeError(f"scipy solve_bvp failed: {sol.message}")
    return sol


def solve(desc, z0, zf, bound, tol, t0=T0, tf=TF, umin=None):
    """The free arc on [t0, tf] with u in [umin (default −bound), bound]."""
    p = load(desc)
    hs = hamiltonian_system(p, -bound if umin is None else umin, bound)
    x0 = inverse(hs, z0, 0.0, 0.0)
    xf = inverse(hs, zf, 0.0, 0.0)
    t, Y, gcost, gmax = guess(hs, z0, zf, t0=t0, tf=tf)
    stroke = abs(zf - z0)
    s = np.array([stroke, 2 * stroke / (tf - t0), np.max(np.abs(Y[2]))]
                 + [np.max(np.abs(Y[3 + k])) for k in range(3)])
    start = time.perf_counter()
    sol = scaled_bvp(hs, t, Y, s, x0, xf, tol, max_nodes=20000)
    elapsed = time.perf_counter() - start
    aux = hs["aux"]

    def ax(tt):
        out = aux(tt, sol.sol(tt) * s)
        return [float(w) for w in out]

    # switches: sign changes of raw − bound on 8 samples per interval
    xs = sol.x
    samples = np.concatenate([xs[i] + (xs[i + 1] - xs[i]) * np.arange(8) / 8
                              for i in range(xs.size - 1)] + [xs[-1:]])
    raw = np.array([ax(ti)[1] for ti in samples])
    switches = []
    for b in (-bound if umin is None else umin, bound):
        for i in range(samples.size - 1):
            fa, fb = raw[i] - b, raw[i + 1] - b
            if (fa < 0) != (fb < 0):
                ts = brentq(lambda tt: ax(tt)[1] - b, samples[i], samples[i + 1], xtol=1e-15)
                switches.append({"t": ts, "bound": b,
                                 "entering": bool(fb >= 0) if b > 0 else bool(fb < 0)})
    switches.sort(key=lambda w: w["t"])
    cuts_all = [w["t"] for w in switches]
    J, umax = 0.0, 0.0
    for i in range(xs.size - 1):
        cuts = [xs[i]] + [c for c in cuts_all if xs[i] < c < xs[i + 1]] + [xs[i + 1]]
        for a, b in zip(cuts[:-1], cuts[1:]):
            c, h = (a + b) / 2, (b - a) / 2
            for xg, wg in GL5:
                uu = ax(c + h * xg)[0]
                umax = max(umax, abs(uu))
                J += wg * h * uu * uu
    for ti in xs:
        umax = max(umax, abs(ax(ti)[0]))
    H = np.array([ax(ti)[2] for ti in xs])
    return {
        "cost": J, "max_abs_input": umax, "switches": switches, "nodes": int(xs.size),
        "guess_cost": gcost, "guess_max_abs_input": gmax, "seconds": elapsed,
        "max_residual": float(np.max(sol.rms_residuals)),
        "hamiltonian_spread": float((H.max() - H.min()) / np.abs(H).max()),
        "mesh": xs,
    }


def rust_summaries():
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    out = subprocess.run(
        ["cargo", "test", "-q", "-p", "reldesign-designer", "--test", "optimal", "--",
         "--ignored", "export_optimal_json", "--nocapture"],
        cwd=root, capture_output=True, text=True, check=True).stdout
    res = {}
    for line in out.splitlines():
        if line.startswith("OPTIMAL_JSON "):
            d = json.loads(line[len("OPTIMAL_JSON "):])
            res[(d["case"], d["bound"])] = d
    return res


def binary_summaries(binary, model):
    """`reldesign build MODEL --report-json`: the design's own figures, for the
    bound of the description's [trajectory] section."""
    import shlex
    import tempfile
    with tempfile.TemporaryDirectory(prefix="check_optimal_") as tmp:
        report = os.path.join(tmp, "report.json")
        subprocess.run([*shlex.split(binary), "build", model, "--quiet", "--out",
                        os.path.join(tmp, "code.rs"), "--report-json", report],
                       check=True, capture_output=True, text=True)
        with open(report) as fh:
            data = json.load(fh)
    with open(model, "rb") as fh:
        bound = tomllib.load(fh)["trajectory"]["u_bound"]
    return bound, {(case, bound): op["optimal"] for case, op in data["operations"].items()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("model")
    ap.add_argument("--bound", type=float, action="append")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--rust", action="store_true",
                    help="compare with the designer's ignored test (cargo)")
    ap.add_argument("--reldesign", metavar="BIN",
                    help="compare with `BIN build MODEL --report-json` (the bound of [trajectory])")
    args = ap.parse_args()
    bounds = args.bound or [20.0, 1000.0]
    rust = rust_summaries() if args.rust else {}
    if args.reldesign:
        bound, rust = binary_summaries(args.reldesign, args.model)
        bounds = [bound]
    ok = True
    for case, (z0, zf) in (("closing", (1e-3, 0.0)), ("opening", (0.0, 1e-3))):
        for b in bounds:
            r = solve(args.model, z0, zf, b, args.tol)
            mesh = r.pop("mesh")
            sw = [round(w["t"], 12) for w in r["switches"]]
            print(f"{case} ±{b:g} V: J = {r['cost']:.12g}, max|u| = {r['max_abs_input']:.10g}, "
                  f"switches {sw}, nodes {r['nodes']}, {r['seconds']:.2f} s, "
                  f"guess J {r['guess_cost']:.10g} (max|u_r| {r['guess_max_abs_input']:.6g}), "
                  f"H spread {r['hamiltonian_spread']:.2e}")
            got = rust.get((case, b))
            if got is None:
                if args.rust or args.reldesign:
                    print(f"  reldesign: no summary for {case} ±{b:g}")
                    ok = False
                continue
            dj = abs(got["cost"] - r["cost"]) / r["cost"]
            du = abs(got["max_abs_input"] - r["max_abs_input"]) / r["max_abs_input"]
            h = np.max(np.diff(mesh))
            sw_ok = len(got["switches"]) == len(r["switches"]) and all(
                abs(a["t"] - b_["t"]) <= h and a["bound"] == b_["bound"]
                and a["entering"] == b_["entering"]
                for a, b_ in zip(got["switches"], r["switches"]))
            good = dj <= 1e-6 and du <= 1e-6 and sw_ok
            ok &= good
            print(f"  reldesign: J = {got['cost']:.12g} (rel {dj:.1e}), max|u| = "
                  f"{got['max_abs_input']:.10g} (rel {du:.1e}), switches "
                  f"{[round(w['t'], 12) for w in got['switches']]} (max mesh h {h:.2e}), "
                  f"nodes {got['nodes']}: {'OK' if good else 'MISMATCH'}")
    print("\ncheck_optimal:", "OK" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
