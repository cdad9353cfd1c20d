#!/usr/bin/env python3
"""Direct-collocation oracle of the energy-optimal motion WITH the stroke
limits (issue 11): min ∫u² dt (perfect-tracking-soft-landing (58)) subject to
the model (CasADi expressions of tests/oracle/model.py, written from the paper),
u_min ≤ u ≤ u_max (60), rest at both ends (61)-(62) and z_min ≤ z ≤ z_max (57),
φ ≥ 0, transcribed by Hermite–Simpson collocation on N uniform intervals and
solved by IPOPT. It knows nothing of reldesign's rest-move-rest structure or of
Pontryagin: it is the state-constrained problem itself.

Usage: check_optimal_nlp.py MODEL.toml Z0 ZF DURATION U_MIN U_MAX [N]
Prints one JSON object: {"status": "ok"|"infeasible"|..., "cost": J or null,
"min_z", "max_z"}.
"""
from __future__ import annotations

import json
import os
import sys

import casadi as ca
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from desc import load  # noqa: E402
from model import build  # noqa: E402


def rest_state(fns, z):
    """[z, 0, φ] with zero acceleration: acc is a₀(z) + c₂(z)·φ²."""
    a0 = float(fns["acc"]([z, 0.0, 0.0], 0.0, 0.0))
    c2 = (float(fns["acc"]([z, 0.0, 1e-5], 0.0, 0.0)) - a0) / 1e-10
    return np.array([z, 0.0, np.sqrt(-a0 / c2)])


def solve(path, z0, zf, duration, umin, umax, n=400):
    fns = build(load(path))
    x0, xf = rest_state(fns, z0), rest_state(fns, zf)
    scale = np.array([abs(zf - z0), 2 * abs(zf - z0) / duration, max(x0[2], xf[2])])
    opti = ca.Opti()
    X = opti.variable(3, n + 1)
    U = opti.variable(1, n + 1)
    h = duration / n
    cost = 0
    for k in range(n):
        xa, xb = X[:, k] * scale, X[:, k + 1] * scale
        fa, fb = fns["f"](xa, U[k], 0), fns["f"](xb, U[k + 1], 0)
        xm = 0.5 * (xa + xb) + h / 8 * (fa - fb)
        um = 0.5 * (U[k] + U[k + 1])
        fm = fns["f"](xm, um, 0)
        opti.subject_to((xb - xa - h / 6 * (fa + 4 * fm + fb)) / scale == 0)
        cost += h / 6 * (U[k] ** 2 + 4 * um ** 2 + U[k + 1] ** 2)
    opti.subject_to(X[:, 0] == x0 / scale)
    opti.subject_to(X[:, n] == xf / scale)
    opti.subject_to(opti.bounded(umin, U, umax))
    lo, hi = min(z0, zf), max(z0, zf)
    opti.subject_to(opti.bounded(lo / scale[0], X[0, :], hi / scale[0]))
    opti.subject_to(X[2, :] >= 0)
    s = np.linspace(0, 1, n + 1)
    opti.set_initial(X[0, :], (z0 + (zf - z0) * s ** 3 * (10 - 15 * s + 6 * s * s)) / scale[0])
    opti.set_initial(X[2, :], np.interp(s, [0, 1], [x0[2], xf[2]]) / scale[2])
    opti.minimize(cost)
    opti.solver("ipopt", {"print_time": 0}, {"print_level": 0, "max_iter": 3000, "tol": 1e-10,
                                             "sb": "yes"})
    try:
        sol = opti.solve()
    except RuntimeError:
        status = opti.stats().get("return_status", "failed")
        return {"status": "infeasible" if "Infeasible" in status else status,
                "cost": None, "min_z": None, "max_z": None}
    z = sol.value(X[0, :]) * scale[0]
    return {"status": "ok", "cost": float(sol.value(cost)), "min_z": float(z.min()),
            "max_z": float(z.max())}


def main():
    a = sys.argv[1:]
    n = int(a[6]) if len(a) > 6 else 400
    print(json.dumps(solve(a[0], *(float(v) for v in a[1:6]), n=n)))


if __name__ == "__main__":
    main()
