#!/usr/bin/env python3
"""Benchmark: reldesign's energy-optimal trajectory against scipy's solve_bvp.

Usage:
  benches/trajectory_vs_scipy.py [--model MODEL.toml] [--bound 20] [--tol 1e-6]
                                 [--repeat 3] [--rounds 7] [--target 50]
                                 [--scipy-only | --rust-only]

The problem is the one of designer/tests/optimal.rs: the perfect-tracking valve
(examples/perfect-tracking-valve.toml), closing 1 -> 0 mm and opening 0 -> 1 mm
in [1 ms, 6 ms], |u| <= 20 V, collocation tolerance 1e-6.

1. scipy: tests/oracle/check_optimal.py's `solve` (CasADi-derived Hamiltonian
   system and analytic Jacobians, the same polynomial/costate-chain initial
   guess, scaled variables, scipy.integrate.solve_bvp with fun_jac and bc_jac,
   tol, max_nodes 20000), imported, not copied.  Its `solve_bvp` call is
   wrapped so that the identical call is timed --repeat times (best wall time);
   J is computed once by check_optimal on the returned interpolant.
2. reldesign: `cargo bench -p reldesign-designer --bench trajectory` (release
   profile), which prints `TRAJECTORY_JSON {...}` per case with
   `solve_s` (energy_optimal alone: Hamiltonian derivation + compilation,
   guess, collocation, switches and cost) and `total_s` (model build +
   linearization + energy_optimal), each the best of --rounds runs.
3. Checks |J_reldesign - J_scipy| / J_scipy <= 1e-6 for both cases and prints
   a table with the ratios (scipy solve_bvp alone) / (reldesign solve) and
   / (reldesign total), closing + opening.

Exit status 1 when J disagrees, a side fails, or the ratio is below --target
(reported, the ratio is machine dependent: run on an otherwise idle machine).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "oracle"))

import check_optimal  # noqa: E402

CASES = (("closing", 1e-3, 0.0), ("opening", 0.0, 1e-3))


def scipy_case(model, z0, zf, bound, tol, repeat):
    """check_optimal.solve with its solve_bvp call timed `repeat` times."""
    real = check_optimal.solve_bvp
    times = []

    def timed(*args, **kwargs):
        sol = None
        for _ in range(repeat):
            start = time.perf_counter()
            sol = real(*args, **kwargs)
            times.append(time.perf_counter() - start)
        return sol

    check_optimal.solve_bvp = timed
    try:
        start = time.perf_counter()
        r = check_optimal.solve(model, z0, zf, bound, tol)
        wall = time.perf_counter() - start
    finally:
        check_optimal.solve_bvp = real
    r.pop("mesh", None)
    r["solve_s"] = min(times)
    r["runs"] = len(times)
    # setup (CasADi derivation, guess) and post-processing (switches, J), once
    r["other_s"] = wall - sum(times)
    return r


def rust_cases(rounds):
    env = dict(os.environ, TRAJECTORY_ROUNDS=str(rounds))
    argv = ["cargo", "bench", "-q", "-p", "reldesign-designer", "--bench", "trajectory"]
    p = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        raise RuntimeError(f"`{' '.join(argv)}` exited with {p.returncode}:\n{p.stderr.strip()}")
    res = {}
    for line in p.stdout.splitlines():
        if line.startswith("TRAJECTORY_JSON "):
            d = json.loads(line[len("TRAJECTORY_JSON "):])
            res[d["case"]] = d
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model", default=os.path.join(ROOT, "examples", "perfect-tracking-valve.toml"))
    ap.add_argument("--bound", type=float, default=20.0)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--repeat", type=int, default=3, help="timed scipy runs per case (best; default 3)")
    ap.add_argument("--rounds", type=int, default=7, help="timed reldesign runs per case (best; default 7)")
    ap.add_argument("--target", type=float, default=50.0, help="required speed-up (default 50)")
    ap.add_argument("--agree", type=float, default=1e-6, help="max relative |ΔJ| (default 1e-6)")
    a = ap.parse_args(argv)
    if a.bound != 20.0 or a.tol != 1e-6:
        print("note: the reldesign bench is fixed at ±20 V, tol 1e-6; "
              "J is compared only for those settings")

    print(f"== energy-optimal trajectory, {os.path.relpath(a.model, ROOT)}, "
          f"[{check_optimal.T0 * 1e3:g}, {check_optimal.TF * 1e3:g}] ms, ±{a.bound:g} V, tol {a.tol:g}")
    print(f"  reldesign: cargo bench (release), best of {a.rounds} ...", flush=True)
    rust = rust_cases(a.rounds)
    sp = {}
    for case, z0, zf in CASES:
        print(f"  scipy {case}: solve_bvp best of {a.repeat} ...", flush=True)
        sp[case] = scipy_case(a.model, z0, zf, a.bound, a.tol, a.repeat)

    ok = True
    hdr = (f"{'case':<9} {'side':<10} {'J':>16} {'rel ΔJ':>8} {'nodes':>6} "
           f"{'solve [ms]':>11} {'total [ms]':>11} {'speed-up':>9}")
    print()
    print(hdr)
    print("-" * len(hdr))
    sums = {"scipy": 0.0, "solve": 0.0, "total": 0.0}
    for case, _, _ in CASES:
        s, r = sp[case], rust.get(case)
        if r is None:
            print(f"{case:<9} reldesign: no TRAJECTORY_JSON line")
            ok = False
            continue
        dj = abs(r["cost"] - s["cost"]) / abs(s["cost"])
        good = dj <= a.agree
        ok &= good
        sums["scipy"] += s["solve_s"]
        sums["solve"] += r["solve_s"]
        sums["total"] += r["total_s"]
        print(f"{case:<9} {'scipy':<10} {s['cost']:>16.12f} {'':>8} {s['nodes']:>6} "
              f"{s['solve_s'] * 1e3:>11.1f} {'':>11} {'1.0':>9}")
        print(f"{'':<9} {'reldesign':<10} {r['cost']:>16.12f} {dj:>8.1e} {r['nodes']:>6} "
              f"{r['solve_s'] * 1e3:>11.2f} {r['total_s'] * 1e3:>11.2f} "
              f"{s['solve_s'] / r['solve_s']:>8.1f}x"
              + ("" if good else f"  J MISMATCH (> {a.agree:g})"))
    print("-" * len(hdr))
    if sums["solve"] > 0:
        ratio = sums["scipy"] / sums["solve"]
        ratio_total = sums["scipy"] / sums["total"]
        print(f"{'both':<9} {'scipy':<10} {'':>16} {'':>8} {'':>6} {sums['scipy'] * 1e3:>11.1f}")
        print(f"{'':<9} {'reldesign':<10} {'':>16} {'':>8} {'':>6} {sums['solve'] * 1e3:>11.2f} "
              f"{sums['total'] * 1e3:>11.2f} {ratio:>8.1f}x")
        print()
        print(f"speed-up, closing + opening: scipy solve_bvp / reldesign energy_optimal = {ratio:.1f}x; "
              f"/ (model build + linearization + energy_optimal) = {ratio_total:.1f}x "
              f"(target ≥ {a.target:g}x: {'met' if min(ratio, ratio_total) >= a.target else 'NOT met'})")
        print("(scipy: the solve_bvp call alone, CasADi setup and J excluded: "
              + ", ".join(f"{c} {sp[c]['other_s']:.1f} s" for c, _, _ in CASES) + " besides)")
        if min(ratio, ratio_total) < a.target:
            ok = False
    else:
        ok = False
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
