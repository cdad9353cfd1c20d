#!/usr/bin/env python3
"""scipy `solve_bvp` oracle for a grid of energy-optimal arcs (issue 11).

Reads a JSON list of cases from the file named on the command line, each
{"file": TOML, "z0", "zf", "a", "b", "u_min", "u_max"}: the free arc that
reldesign chose on [a, b] (rest at one end when a > t0 or b < tf is
reldesign's business; the arc itself is the Hamiltonian two-point problem
(58)-(66) with rest states at both ends). Solves each with check_optimal.solve
(CasADi expressions of the model written from the paper, scipy's collocation
solver, the same tolerance and guess construction) and prints one JSON list:
{"converged": bool, "cost": J or null, "message": str, "seconds": s} per case.
"""
from __future__ import annotations

import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_optimal import solve  # noqa: E402


def main():
    with open(sys.argv[1]) as fh:
        cases = json.load(fh)
    out = []
    for c in cases:
        start = time.perf_counter()
        try:
            r = solve(c["file"], c["z0"], c["zf"], c["u_max"], 1e-6,
                      t0=c["a"], tf=c["b"], umin=c["u_min"])
            out.append({"converged": True, "cost": r["cost"], "message": "",
                        "seconds": time.perf_counter() - start})
        except Exception as e:  # scipy's failure, or the guess leaving T⁻¹
            out.append({"converged": False, "cost": None, "message": str(e)[:200],
                        "seconds": time.perf_counter() - start})
    json.dump(out, sys.stdout)
    print()


if __name__ == "__main__":
    main()
