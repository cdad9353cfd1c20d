#!/usr/bin/env python3
"""cvxpy SDP oracle for the backstepping law's certified region.

Independently of reldesign, from the TOML alone (switched-force-backstepping
Theorem 1, lemma 1, Theorem 3, in reldesign's signs: z is the gap, the
magnet pulls towards z_min, m·v̇ = −F − (k_s·z + c·v + F0)):

    A = [[−α₁, 1], [−1, −α₂]]                      (the closed loop of Z, (14))
    F_d = m·(z₁ + α₂·z₂ + α₁·v) − F_p(z, v) = g − kᵀZ  (Theorem 1)
    k = −[m·(1 − α₁²) − k_s + c·α₁, m·(α₁ + α₂) − c],  g = −(k_s·y_r + F0)
    X₀: the zero of F_p(z, 0) in [z_min, z_max], else the stop it pushes to;
        Z₀ = (x₀ − y_r, α₁·(x₀ − y_r))
    decay α: controller.decay, else 0.2 · 2·min|Re λ(A)|

and solves with cvxpy's PSD cone (not reldesign's second-order-cone form):

    paper:    min tr P  s.t.  AᵀP + PA + αP ⪯ 0,  P ⪰ I
    extended: the same with, per target, P − (Z₀ᵀPZ₀ / (0.9·g²))·kkᵀ ⪰ 0
              (X₀ inside D at 90 % of its level), where the paper's leaves X₀ out
              (decided here from the oracle's own solution of the paper's program)

It compares `reldesign build --report-json`'s region: tr P within --tol
(relative), reldesign's P certified by eigenvalues, C = g²/(kᵀP⁻¹k) and
"contains_rest" recomputed from reldesign's P, A and the decay exactly.

Usage: check_region.py RELDESIGN MODEL.toml [MODEL.toml ...] [--tol 1e-6]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import tomllib

import cvxpy as cp
import numpy as np

MARGIN = 0.9


def problem(path):
    with open(path, "rb") as f:
        d = tomllib.load(f)
    mech, ctl = d["mechanics"], d["controller"]
    a1, a2, _ = ctl["gains"]
    m, ks, c = mech["mass"], mech["stiffness"], mech["damping"]
    f0 = mech["preload"] if "preload" in mech else -ks * mech["rest_position"]
    A = np.array([[-a1, 1.0], [-1.0, -a2]])
    k = -np.array([m * (1 - a1 * a1) - ks + c * a1, m * (a1 + a2) - c])
    zmin, zmax = mech["z_min"], mech["z_max"]
    fp = lambda z: ks * z + f0  # noqa: E731
    if fp(zmax) < 0:
        rest = zmax
    elif fp(zmin) > 0:
        rest = zmin
    else:
        rest = -f0 / ks
    if "position" in ctl:
        targets = [ctl["position"]]
    else:
        targets = ctl["square"][:2]
    limit = -2 * max(np.linalg.eigvals(A).real)
    decay = ctl.get("decay", 0.2 * limit)
    tg = [(y, -(ks * y + f0), np.array([rest - y, a1 * (rest - y)])) for y in targets]
    return A, k, decay, tg


def solve(A, k, decay, targets, extended):
    P = cp.Variable((2, 2), symmetric=True)
    cons = [-(A.T @ P + P @ A + decay * P) >> 0, P >> np.eye(2)]
    if extended:
        for _, g, z0 in targets:
            K = np.outer(k, k) / (MARGIN * g * g)
            cons.append(P - (z0 @ P @ z0) * K >> 0)
    prob = cp.Problem(cp.Minimize(cp.trace(P)), cons)
    solvers = cp.installed_solvers()
    if "CLARABEL" in solvers:
        prob.solve(solver="CLARABEL", tol_gap_abs=1e-11, tol_gap_rel=1e-11, tol_feas=1e-11)
    else:
        prob.solve(solver="SCS", eps=1e-11, max_iters=200000)
    if prob.status not in ("optimal",):
        raise SystemExit(f"the oracle's SDP ended {prob.status}")
    return P.value


def build(bin_, model):
    with tempfile.TemporaryDirectory() as tmp:
        out, rep = os.path.join(tmp, "c.rs"), os.path.join(tmp, "r.json")
        subprocess.run([bin_, "build", model, "--out", out, "--report-json", rep, "--quiet"], check=True)
        with open(rep) as f:
            return json.load(f)["region"]


def check(bin_, model, tol):
    A, k, decay, targets = problem(model)
    region = build(bin_, model)
    assert np.allclose(region["a"], A, rtol=0, atol=0), f"A {region['a']} vs {A}"
    assert abs(region["decay"] - decay) <= 1e-12 * decay, f"decay {region['decay']} vs {decay}"
    assert np.allclose(region["force_gradient"], k, rtol=1e-9, atol=1e-12), f"k {region['force_gradient']} vs {k}"
    P = np.array(region["p"])
    # the certificate, by eigenvalues
    lyap = A.T @ P + P @ A + decay * P
    norm = max(np.linalg.eigvalsh(P))
    assert min(np.linalg.eigvalsh(P - np.eye(2))) > -1e-7 * norm, "P ⪰ I fails"
    assert max(np.linalg.eigvalsh(lyap)) < 1e-7 * norm * decay, f"AᵀP + PA + αP: {np.linalg.eigvalsh(lyap)}"
    # the paper's program decides whether the rest constraints are needed
    paper = solve(A, k, decay, targets, False)
    def holds_rest(P_):
        return all(z0 @ P_ @ z0 < g * g / (k @ np.linalg.solve(P_, k)) for _, g, z0 in targets)
    extended = not holds_rest(paper)
    assert extended == region["extended"], f"extended: oracle {extended}, reldesign {region['extended']}"
    oracle = solve(A, k, decay, targets, True) if extended else paper
    want, got = np.trace(oracle), region["trace"]
    rel = abs(got - want) / want
    assert rel <= tol, f"tr P = {got}, the oracle's {want} (relative {rel:.2e})"
    # C and X₀ ∈ D from reldesign's P, per target
    for (y, g, z0), t in zip(targets, region["targets"]):
        c = g * g / (k @ np.linalg.solve(P, k))
        assert abs(t["c"] - c) <= 1e-9 * c, f"C at {y}: {t['c']} vs {c}"
        assert t["contains_rest"] == bool(z0 @ P @ z0 < c), f"contains_rest at {y}"
        ci = g * g / (k @ np.linalg.solve(0.5 * np.eye(2), k))
        assert abs(t["identity"]["c"] - ci) <= 1e-9 * ci, f"identity C at {y}"
        if region["extended"]:
            assert z0 @ P @ z0 <= MARGIN * c * (1 + 1e-6), f"X₀ beyond {MARGIN}·C at {y}"
    print(f"{model}: tr P = {got:.12g} (oracle {want:.12g}, relative {rel:.1e}), "
          f"extended {region['extended']}, C = {[t['c'] for t in region['targets']]}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reldesign")
    ap.add_argument("models", nargs="+")
    ap.add_argument("--tol", type=float, default=1e-6)
    a = ap.parse_args()
    for m in a.models:
        check(a.reldesign, m, a.tol)
    print("check_region: OK")


if __name__ == "__main__":
    sys.exit(main())
