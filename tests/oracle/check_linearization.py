#!/usr/bin/env python3
"""CasADi oracle for the feedback-linearization quantities of `reldesign eval`.

Independently of reldesign: builds f(x, u, t) from the TOML (tests/oracle/model.py),
splits it into drift f(x) = f(x, 0, t) and input field g(x) = ∂f/∂u, derives the
Lie derivatives of h = z by CasADi AD, and compares at 200 random states per
example (perfect-tracking-soft-landing eqs. 30-35, 41; model-free sliding mode
(25)-(26)):

    lf3h = L_f³h, lglf2h = L_g L_f²h, alpha = −L_f³h/L_g L_f²h, beta = 1/L_g L_f²h,
    t = [z, v, L_f²h], f_j = L_f³h, b_j = −L_g L_f²h.

Usage: check_linearization.py RELDESIGN MODEL.toml [MODEL.toml ...] [--tol 1e-9]

With a Jiles–Atherton core (state [z, v, phi, Hc]) the chain is derived on the
rows (z, v, phi) with Hc exogenous (jiles-atherton-actuator-model (89)): the
oracle asserts that a = L_f²h does not depend on Hc, so that Hc's row (whose
branch sign(dphi/dt) depends on u) never enters L_f³h; the quantities then
depend on Hc through dphi/dt.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile

import casadi as ca
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_eval import run_eval, sample_states  # noqa: E402
from desc import load  # noqa: E402
from model import build  # noqa: E402

KEYS = ["lf3h", "lglf2h", "alpha", "beta", "t", "f_j", "b_j"]


def lie_functions(p):
    fns = build(p)
    n = p.nx
    x, u, t = ca.SX.sym("x", n), ca.SX.sym("u"), ca.SX.sym("t")
    F = fns["f"](x, u, t)
    drift = ca.substitute(F, u, ca.SX(0))
    g = ca.jacobian(F, u)
    chain = x[:3]  # (z, v, phi); Hc, if any, exogenous
    lie = lambda h, field: ca.mtimes(ca.jacobian(h, chain), field[:3])  # noqa: E731
    h = x[0]
    lf1 = lie(h, drift)
    lf2 = lie(lf1, drift)
    if n == 4:
        assert not ca.depends_on(lf2, x[3]), "a = L_f²z depends on Hc"
        assert ca.depends_on(lie(lf2, drift), x[3]), "L_f³z should read Hc"
    lf3 = lie(lf2, drift)
    lglf2 = lie(lf2, g)
    for lower in (lie(h, g), lie(lf1, g)):  # relative degree 3: structurally zero
        assert lower.is_zero(), f"L_g L_f^k z is not identically zero for k < 2: {lower}"
    outs = {
        "lf3h": lf3, "lglf2h": lglf2, "alpha": -lf3 / lglf2, "beta": 1 / lglf2,
        "t": ca.vertcat(x[0], x[1], lf2), "f_j": lf3, "b_j": -lglf2,
    }
    return {k: ca.Function(k, [x, t], [v]) for k, v in outs.items()}


def compare(name, got, ref, tol):
    got, ref = np.asarray(got, dtype=float), np.asarray(ref, dtype=float)
    if got.shape != ref.shape:
        return False, f"shape {got.shape} != {ref.shape}"
    floor = 1e-9 * np.max(np.abs(ref), axis=0, keepdims=True)
    err = np.abs(got - ref) / np.maximum(np.abs(ref), floor)
    k = np.unravel_index(int(np.argmax(err)), err.shape)
    return float(err[k]) <= tol, f"max rel err {float(err[k]):.3e} at state {k[0]} ({got[k]!r} vs {ref[k]!r})"


def check(cmd, toml, n, seed, tol):
    p = load(toml)
    x, u, t = sample_states(p, n, seed)
    # the linearizable region D0+ ∪ D0−: keep |φ| away from 0 (α, β ∝ 1/φ)
    small = np.abs(x[:, 2]) < 1e-3 * p.flux_scale()
    x[small, 2] = np.copysign(1e-3 * p.flux_scale(), x[small, 2] + 1e-300)
    out = run_eval(cmd, toml, x, u, t, tempfile.mkdtemp(prefix="check_lin_"))
    print(f"\n== {toml}")
    if p.ja:
        print("  Jiles–Atherton core: chain on (z, v, phi), Hc exogenous")
    fns = lie_functions(p)
    ok = True
    for key in KEYS:
        if key not in out:
            print(f"  {key:<7} MISSING from reldesign eval")
            ok = False
            continue
        ref = [np.array(fns[key](x[k], t[k])).reshape(-1) for k in range(len(u))]
        ref = np.array(ref).squeeze()
        good, text = compare(key, out[key], ref, tol)
        print(f"  {key:<7} {text}  {'ok' if good else 'FAIL'}")
        ok &= good
    return ok


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("reldesign")
    ap.add_argument("models", nargs="+")
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=20240521)
    ap.add_argument("--tol", type=float, default=1e-9)
    a = ap.parse_args()
    ok = all([check(a.reldesign, m, a.n, a.seed, a.tol) for m in a.models])
    print("\ncheck_linearization:", "OK" if ok else "FAIL")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
