#!/usr/bin/env python3
"""The tracking law (50) of perfect-tracking-soft-landing, built with CasADi from the
TOML alone and emitted as C with `casadi.CodeGenerator`.

    u = sat(α + β·(K·(ξ_r − T(x)) + z_r⁽³⁾)),   T(x) = [z, v, L_f²h],
    α = −L_f³h / L_g L_f²h,  β = 1 / L_g L_f²h,  sat = fmin(fmax(·, u_min), u_max)

f(x, u) comes from tests/oracle/model.py `build` (independent of reldesign), split into
drift f(x, 0) and input field g = ∂f/∂u; the Lie derivatives of h = z are taken by
CasADi AD, as in tests/oracle/check_linearization.py. Inputs (z, v, phi, zr, vr, ar, jr),
output u. Four C functions:

    casadi_law_sat, casadi_law_raw          (default Function options)
    casadi_law_sat_cse, casadi_law_raw_cse  (option cse=True: common subexpression elimination)

`_raw` is the law without saturation (what the generated `f64::law` returns), `_sat`
the saturated one. The gains K = [λ³, 3λ², 3λ] are read from the generated module's
GAIN_K1..3 (design outputs); λ from the 5 % settling time of a triple pole is
recomputed here and printed as a cross-check.

Usage: casadi_law.py MODEL.toml GENERATED.rs OUTDIR   (writes OUTDIR/casadi_law.{c,h})
"""
from __future__ import annotations

import math
import os
import re
import sys
import tomllib

import casadi as ca

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "oracle"))

from desc import load  # noqa: E402
from model import build  # noqa: E402


def generated_gains(rs_path: str) -> list[float]:
    text = open(rs_path, encoding="utf-8").read()
    f64 = text[text.index("pub mod f64"):]
    return [float(re.search(rf"pub const GAIN_K{k}: f64 = ([-0-9.eE+]+);", f64).group(1)) for k in (1, 2, 3)]


def settling_lambda(ts: float) -> float:
    """λ with (1 + λt + (λt)²/2)·e^{−λt} = 0.05 at t = ts (5 % settling of a triple pole)."""
    lo, hi = 1.0, 20.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (1 + mid + mid * mid / 2) * math.exp(-mid) > 0.05:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi) / ts


def law_expressions(toml: str, gains: list[float]):
    p = load(toml)
    fns = build(p)
    z, v, phi = ca.SX.sym("z"), ca.SX.sym("v"), ca.SX.sym("phi")
    zr, vr, ar, jr = ca.SX.sym("zr"), ca.SX.sym("vr"), ca.SX.sym("ar"), ca.SX.sym("jr")
    u = ca.SX.sym("u")
    x = ca.vertcat(z, v, phi)
    F = fns["f"](x, u, 0.0)
    drift = ca.substitute(F, u, ca.SX(0))
    g = ca.jacobian(F, u)
    lie = lambda h, field: ca.mtimes(ca.jacobian(h, x), field)  # noqa: E731
    lf1 = lie(z, drift)
    lf2 = lie(lf1, drift)
    lf3 = lie(lf2, drift)
    lglf2 = lie(lf2, g)
    alpha = -lf3 / lglf2
    beta = 1 / lglf2
    k1, k2, k3 = gains
    w = k1 * (zr - z) + k2 * (vr - v) + k3 * (ar - lf2) + jr
    u_raw = alpha + beta * w
    u_sat = ca.fmin(ca.fmax(u_raw, p.u_min), p.u_max)
    return p, [z, v, phi, zr, vr, ar, jr], u_raw, u_sat


def main():
    toml, rs, outdir = sys.argv[1:4]
    gains = generated_gains(rs)
    p, ins, u_raw, u_sat = law_expressions(toml, gains)
    names = ["z", "v", "phi", "zr", "vr", "ar", "jr"]
    with open(toml, "rb") as fh:
        ts = tomllib.load(fh)["controller"]["settling_time"]
    lam = settling_lambda(ts)
    indep = [lam ** 3, 3 * lam ** 2, 3 * lam]
    rel = max(abs(a - b) / abs(b) for a, b in zip(indep, gains))
    print(f"casadi {ca.__version__}: K from the generated file {gains}; "
          f"from λ = {lam:.6f} (5 % settling in {ts} s): max rel diff {rel:.1e}")
    cg = ca.CodeGenerator("casadi_law.c", {"with_header": True})
    for cse in (False, True):
        opts = {"cse": True} if cse else {}
        suffix = "_cse" if cse else ""
        for tag, expr in (("sat", u_sat), ("raw", u_raw)):
            f = ca.Function(f"casadi_law_{tag}{suffix}", ins, [expr], names, ["u"], opts)
            print(f"  {f.name()}: {f.n_instructions()} SX instructions")
            cg.add(f)
    os.makedirs(outdir, exist_ok=True)
    cg.generate(outdir.rstrip("/") + "/")


if __name__ == "__main__":
    main()
