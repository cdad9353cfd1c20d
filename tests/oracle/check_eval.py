#!/usr/bin/env python3
"""Check `reldesign eval` against the independent CasADi oracle (model.py).

Usage:
  check_eval.py RELDESIGN MODEL.toml [MODEL.toml ...] [--n 200] [--seed S] [--tol 1e-10] [--keep DIR]
  check_eval.py --self-test [MODEL.toml ...]

RELDESIGN is the path of the `reldesign` binary (or a quoted command, e.g.
"cargo run -q --release --bin reldesign --"; it is split like a shell would).

For each description: draws --n states in the physical domain with a fixed seed,
writes STATES.json {"x": [[...]], "u": [...], "t": [...]}, runs
`RELDESIGN eval MODEL.toml STATES.json`, and compares f, i, f_mag, r_gap,
r_gap_dz and df_dx with CasADi.  Error measure per value:
    |a − b| / max(|b|, floor)
with b the oracle and floor the larger of
  - 1e-12·max|b| over the batch, per component (for df_dx[i][j] also
    1e-12·max|f_i|/scale_j, so an entry that is identically zero is judged
    against the size of f_i, not against 0), and
  - per state, (1e-14/tol)·(magnitude of the terms that cancel in the value),
    i.e. ~50 ulp of those terms are always accepted.  Needed for the JA core:
    Ḣ_c = (1/μ0 − dM_c/dB_c)·φ̇/A_c cancels up to ~6 digits, so two correct
    double implementations differ by ~1e-10 relative there.
Exits 1 on any failure (error > --tol, missing key, NaN, wrong shape, command
failure), with the quantity, component and state named.

--self-test checks the oracle itself: CasADi against the plain-float numpy
implementation (same measure, --tol), R_gap of tables against scipy, and the
AD Jacobian against Richardson-extrapolated central finite differences (1e-6),
on built-in descriptions covering every gap/core/drive variant plus the given
TOML files.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shlex
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from desc import Z_EPS, load  # noqa: E402
from model import build, numpy_model  # noqa: E402

QUANTITIES = ["f", "i", "f_mag", "r_gap", "r_gap_dz", "df_dx"]
FLOOR_REL = 1e-12
COND_EPS = 1e-14


# ----------------------------------------------------------------------------
# states
# ----------------------------------------------------------------------------

def sample_states(p, n: int = 200, seed: int = 20240521):
    """n states in the physical domain, deterministic for a given seed."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(p.z_min, p.z_max, n)
    n_edge = min(5, n // 4)
    z[:n_edge] = p.z_min
    z[n_edge:2 * n_edge] = p.z_max
    v = rng.uniform(-2.0, 2.0, n)
    phi_amp = p.flux_scale()
    phi = rng.uniform(-phi_amp, phi_amp, n)
    cols = [z, v, phi]
    if p.ja:
        cols.append(rng.uniform(-2000.0, 2000.0, n))
    x = np.column_stack(cols)
    u = rng.uniform(p.u_min, p.u_max, n)
    t = np.zeros(n)
    if p.resistance_drift != 0.0:
        t_max = min(10.0, 0.5 * p.resistance / abs(p.resistance_drift))
        idx = np.arange(n) % 2 == 1
        t[idx] = rng.uniform(0.0, t_max, int(idx.sum()))
    return x, u, t


# ----------------------------------------------------------------------------
# oracle evaluation
# ----------------------------------------------------------------------------

def eval_casadi(fns, x, u, t):
    n = len(u)
    nx = x.shape[1]
    out = {q: [] for q in QUANTITIES}
    for q in ("acc", "cond_f", "cond_i", "cond_df_dx"):
        out[q] = []
    for k in range(n):
        xk, uk, tk = x[k].tolist(), float(u[k]), float(t[k])
        out["f"].append(np.array(fns["f"](xk, uk, tk)).reshape(nx))
        out["i"].append(float(fns["i"](xk, uk, tk)))
        out["f_mag"].append(float(fns["f_mag"](xk)))
        out["acc"].append(float(fns["acc"](xk, uk, tk)))
        out["r_gap"].append(float(fns["r_gap"](xk[0])))
        out["r_gap_dz"].append(float(fns["r_gap_dz"](xk[0])))
        out["df_dx"].append(np.array(fns["df_dx"](xk, uk, tk)).reshape(nx, nx))
        cf, ci, cj = fns["cond"](xk, uk, tk)
        out["cond_f"].append(np.array(cf).reshape(nx))
        out["cond_i"].append(float(ci))
        out["cond_df_dx"].append(np.array(cj).reshape(nx, nx))
    return {q: np.array(v) for q, v in out.items() if v}


def eval_numpy(m, x, u, t):
    out = {"f": [], "i": [], "f_mag": [], "r_gap": [], "r_gap_dz": []}
    for k in range(len(u)):
        xk, uk, tk = x[k].tolist(), float(u[k]), float(t[k])
        out["f"].append(m.f(tk, xk, uk))
        out["i"].append(m.current(tk, xk, uk))
        out["f_mag"].append(m.f_mag(xk[0], xk[2]))
        out["r_gap"].append(m.r_gap(xk[0]))
        out["r_gap_dz"].append(m.r_gap_dz(xk[0]))
    return {q: np.array(v, dtype=float) for q, v in out.items()}


# ----------------------------------------------------------------------------
# comparison
# ----------------------------------------------------------------------------

def floors(ref: dict, xscale, tol) -> dict:
    """Floors of the relative error, broadcastable to each quantity's shape.

    - batch floor: 1e-12·max|b| over the batch, per component (for df_dx[i][j]
      also 1e-12·max|f_i|/scale_j, the size of f_i over a state's range);
    - rounding floor, per state: the magnitude of the terms that cancel in the
      value (model.py `cond`) times COND_EPS/tol, i.e. an absolute error of
      COND_EPS (~50 ulp) relative to those terms is always accepted.  This only
      matters where the value is much smaller than its terms (Ḣ_c near
      dH_c/dB_c ≈ 0, v̇ near force balance, φ̇ near steady state)."""
    fl = {}
    for q, b in ref.items():
        if q not in QUANTITIES:
            continue
        if q == "df_dx":
            fmax = np.max(np.abs(ref["f"]), axis=0)  # per f_i
            jmax = np.max(np.abs(b), axis=0)  # (nx, nx)
            nat = fmax[:, None] / np.asarray(xscale)[None, :]
            fl[q] = FLOOR_REL * np.maximum(jmax, nat)[None, :, :]
        else:
            fl[q] = FLOOR_REL * np.max(np.abs(b), axis=0)[None, ...]
        cq = {"f": "cond_f", "i": "cond_i", "df_dx": "cond_df_dx"}.get(q)
        if cq in ref:
            fl[q] = np.maximum(fl[q], ref[cq] * (COND_EPS / tol))
    return fl


def compare(q, got, ref, floor):
    """-> (max error, state index, component index tuple, message or None)."""
    def nulls_to_nan(v):
        return [nulls_to_nan(e) for e in v] if isinstance(v, list) else (math.nan if v is None else v)

    try:
        got = np.asarray(nulls_to_nan(got), dtype=float)
    except (TypeError, ValueError) as e:
        return math.inf, -1, (), f"{q}: not an array of numbers of the expected shape ({e})"
    if got.shape != ref.shape:
        return math.inf, -1, (), f"{q}: shape {got.shape}, expected {ref.shape}"
    floor = np.maximum(floor, 1e-300)
    bad_nan = np.isnan(got) | np.isnan(ref)
    with np.errstate(invalid="ignore", over="ignore"):
        err = np.abs(got - ref) / np.maximum(np.abs(ref), floor)
    same_inf = np.isinf(got) & np.isinf(ref) & (np.sign(got) == np.sign(ref))
    err = np.where(same_inf, 0.0, err)
    err = np.where(bad_nan | np.isnan(err), np.inf, err)
    flat = int(np.argmax(err))
    idx = np.unravel_index(flat, err.shape)
    return float(err[idx]), int(idx[0]), tuple(int(i) for i in idx[1:]), None


def report(title, results, tol) -> bool:
    print(f"\n== {title}")
    print(f"  {'quantity':<10} {'max rel err':>12}  {'worst state':>11}  component   oracle / other")
    ok = True
    for q, (e, k, comp, msg, vals) in results.items():
        if msg is not None:
            print(f"  {q:<10} {'FAIL':>12}  {msg}")
            ok = False
            continue
        flag = "" if e <= tol else "   <-- FAIL"
        ok &= e <= tol
        cs = ",".join(map(str, comp)) if comp else "-"
        print(f"  {q:<10} {e:12.3e}  {k:>11}  {cs:<10}  {vals}{flag}")
    return ok


def compare_all(got: dict, ref: dict, xscale, tol, title, keys=QUANTITIES) -> bool:
    fl = floors(ref, xscale, tol)
    results = {}
    for q in keys:
        if q not in got:
            results[q] = (math.inf, -1, (), f"missing quantity `{q}` in the output", None)
            continue
        if q not in ref:
            continue
        e, k, comp, msg = compare(q, got[q], ref[q], fl[q])
        vals = ""
        if msg is None and k >= 0:
            g = np.asarray(got[q], dtype=float)[(k, *comp)]
            r = ref[q][(k, *comp)]
            vals = f"{r:.17g} / {g:.17g}"
        results[q] = (e, k, comp, msg, vals)
    return report(title, results, tol)


# ----------------------------------------------------------------------------
# the reldesign side
# ----------------------------------------------------------------------------

def run_eval(cmd, toml, x, u, t, workdir):
    states = os.path.join(workdir, "STATES.json")
    with open(states, "w") as fh:
        json.dump({"x": x.tolist(), "u": u.tolist(), "t": t.tolist()}, fh)
    argv = [*shlex.split(cmd), "eval", toml, states]
    try:
        r = subprocess.run(argv, capture_output=True, text=True, timeout=600)
    except FileNotFoundError as e:
        raise SystemExit(f"check_eval: cannot run {argv[0]!r}: {e}")
    if r.returncode != 0:
        raise RuntimeError(f"`{shlex.join(argv)}` exited with {r.returncode}:\n{r.stderr.strip()}")
    with open(os.path.join(workdir, "OUT.json"), "w") as fh:
        fh.write(r.stdout)
    try:
        out = json.loads(r.stdout)
    except json.JSONDecodeError as e:
        raise RuntimeError(f"`{shlex.join(argv)}` did not print one JSON object: {e}\n{r.stdout[:500]}")
    if not isinstance(out, dict):
        raise RuntimeError("eval output is not a JSON object")
    return out


def check_binary(cmd, tomls, n, seed, tol, keep) -> bool:
    all_ok = True
    for toml in tomls:
        p = load(toml)
        fns = build(p)
        x, u, t = sample_states(p, n, seed)
        ref = eval_casadi(fns, x, u, t)
        workdir = keep or tempfile.mkdtemp(prefix="check_eval_")
        if keep:
            workdir = os.path.join(keep, os.path.splitext(os.path.basename(toml))[0])
            os.makedirs(workdir, exist_ok=True)
        try:
            out = run_eval(cmd, toml, x, u, t, workdir)
        except RuntimeError as e:
            print(f"\n== {toml}\n  FAIL: {e}")
            all_ok = False
            continue
        got = {q: out[q] for q in QUANTITIES if q in out}
        extra = sorted(set(out) - set(QUANTITIES))
        ok = compare_all(got, ref, p.state_scale(), tol,
                         f"{toml}  ({p.gap_model} gap, {p.core_model} core, {p.drive} drive, {n} states)")
        if extra:
            print(f"  (not compared: {', '.join(extra)})")
        print(f"  states: {os.path.join(workdir, 'STATES.json')}")
        all_ok &= ok
    return all_ok


# ----------------------------------------------------------------------------
# self-test
# ----------------------------------------------------------------------------

def _base(gap, core, drive="voltage", drift=0.0, **mech):
    m = {"mass": 2e-3, "stiffness": 50.0, "damping": 0.1, "preload": -0.75, "z_min": 0.0, "z_max": 1e-3,
         "restitution": 0.5, "bounce_threshold": 1e-3}
    m.update(mech)
    sup = {"drive": drive, "u_min": -24.0, "u_max": 24.0} if drive == "voltage" else \
        {"drive": drive, "u_min": -2.0, "u_max": 2.0}
    return {"name": "t", "coil": {"turns": 1200, "resistance": 75.0, "eddy": 1500.0, "resistance_drift": drift},
            "gap": gap, "core": core, "mechanics": m, "supply": sup}


def builtin_descriptions():
    mcl = {"model": "mclyman", "area": 20e-6, "winding_length": 15e-3}
    fit = {"model": "mclyman-fit", "r0": 2.41e6, "r0_prime": 7.94e10, "k1": 1350.0, "k2": 9.95e-3}
    ja = {"model": "jiles-atherton", "length": 0.055, "area": 1.26e-5, "m_sat": 1.45e6, "b": 2.45e-3,
          "c": 0.736, "kappa": 943.0, "alpha": 3.66e-3}
    sat = {"model": "saturating", "r0": 3e6, "phi_sat": 25e-6}
    lin = {"model": "linear", "r0": 3e6}
    # a smooth table (McLyman sampled): the C² spline is monotone
    zt = np.linspace(0.0, 1e-3, 9)
    nm = numpy_model(_base(mcl, lin))
    rt = [nm.r_gap(z) + 1e5 for z in zt]
    rpt = [nm.r_gap_dz(z) for z in zt]
    # a table whose not-a-knot spline is not monotone -> PCHIP
    zk = [0.0, 1e-4, 2e-4, 3e-4, 6e-4, 1e-3]
    rk = [1e6, 1e6 + 5e3, 3e6, 3.02e6, 3.05e6, 9e6]
    return [
        ("builtin linear/linear, voltage, drift", _base({"model": "linear", "slope": 3e10, "offset": 2e5}, lin,
                                                        drift=2.0), None),
        ("builtin mclyman/saturating, voltage", _base(mcl, sat), None),
        ("builtin mclyman-fit/jiles-atherton (valve), voltage",
         _base(fit, ja, mass=1.6e-3, stiffness=55.0, damping=0.0, preload=None, rest_position=0.015,
               z_max=9e-4, restitution=0.3, bounce_threshold=0.01), None),
        ("builtin table r_prime (hermite)/saturating, current",
         _base({"model": "table", "z": zt.tolist(), "r": rt, "r_prime": rpt}, sat, drive="current"), "hermite"),
        ("builtin table smooth (cubic-spline)/linear, voltage, drift",
         _base({"model": "table", "z": zt.tolist(), "r": rt}, lin, drift=-1.0), "cubic-spline"),
        ("builtin table non-monotone spline (pchip)/jiles-atherton, current",
         _base({"model": "table", "z": zk, "r": rk}, ja, drive="current"), "pchip"),
        ("builtin mclyman/jiles-atherton, voltage, drift", _base(mcl, dict(ja, epsilon=1e-2), drift=3.0), None),
    ]


def _clean(d):
    d = json.loads(json.dumps(d))
    d["mechanics"] = {k: v for k, v in d["mechanics"].items() if v is not None}
    return d


def fd_jacobian_check(m, x, u, t, J_ad, xscale, tol=1e-6):
    """AD Jacobian vs Richardson-extrapolated central differences of the numpy f.
    Entries whose stencil crosses a non-smooth switch (sign of dφ/dt, the JA clamp,
    the Langevin series switch, |φ| = 0, a table knot) or the log singularity at
    z = −z_ε are skipped. -> (ok, max err, worst (k,i,j), n checked, n skipped)."""
    n, nx = x.shape
    f_abs_max = np.max(np.abs(np.array([m.f(t[k], x[k].tolist(), u[k]) for k in range(n)])), axis=0)
    worst, worst_at, checked, skipped = 0.0, None, 0, 0
    log_gap = m.p.gap_model in ("mclyman", "mclyman-fit")
    for k in range(n):
        xk = x[k].tolist()
        key0 = m.regime(t[k], xk, u[k])
        for j in range(nx):
            h = 1e-4 * xscale[j]
            if j == 0 and log_gap:
                if xk[0] + Z_EPS < 1e-7:
                    skipped += nx
                    continue
                h = min(h, 1e-3 * (xk[0] + Z_EPS))
            pts = {}
            smooth = True
            for s in (-2, -1, 1, 2):
                xp = list(xk)
                xp[j] += s * h / 2
                if m.regime(t[k], xp, u[k]) != key0:
                    smooth = False
                    break
                pts[s] = np.array(m.f(t[k], xp, u[k]))
            if not smooth:
                skipped += nx
                continue
            d_h = (pts[2] - pts[-2]) / (2 * h)
            d_h2 = (pts[1] - pts[-1]) / h
            d = (4 * d_h2 - d_h) / 3
            for i in range(nx):
                ref = J_ad[k, i, j]
                # FD rounding is ~1e-12·|f_i|/scale_j (h = 1e-4·scale_j): accept
                # 1e-10·max|f_i|/scale_j absolute
                floor = max(1e-4 * f_abs_max[i] / xscale[j], 1e-300)
                e = abs(d[i] - ref) / max(abs(ref), floor)
                checked += 1
                if e > worst:
                    worst, worst_at = e, (k, i, j, ref, d[i])
    return worst <= tol, worst, worst_at, checked, skipped


def self_test(tomls, n, seed, tol) -> bool:
    cases = [(name, _clean(d), kind) for name, d, kind in builtin_descriptions()]
    cases += [(t, t, None) for t in tomls]
    all_ok = True
    for name, d, kind in cases:
        p = load(d)
        fns = build(p)
        m = numpy_model(p)
        x, u, t = sample_states(p, n, seed)
        ref = eval_casadi(fns, x, u, t)
        got = eval_numpy(m, x, u, t)
        ok = compare_all(got, ref, p.state_scale(), tol, f"self-test {name}: numpy vs CasADi",
                         keys=["f", "i", "f_mag", "r_gap", "r_gap_dz"])
        # acc == f[1]
        if not np.array_equal(ref["acc"], ref["f"][:, 1]):
            print("  FAIL: acc differs from f[1]")
            ok = False
        if p.gap_model == "table":
            if kind is not None and p.table.kind != kind:
                print(f"  FAIL: table interpolant is {p.table.kind}, expected {kind}")
                ok = False
            zz = np.concatenate([x[:, 0], p.table.x, [p.table.x[0] - 1e-5, p.table.x[-1] + 1e-5]])
            obj = p.table.scipy_obj
            e0 = max(abs(m.r_gap(z) - obj(z)) / max(abs(obj(z)), 1e-6 * np.max(np.abs(p.gap["r"]))) for z in zz)
            e1 = max(abs(m.r_gap_dz(z) - obj(z, 1)) / max(abs(obj(z, 1)), 1e-9 * abs(obj(p.table.x[-1], 1)))
                     for z in zz)
            e2 = max(abs(float(fns["r_gap"](z)) - obj(z)) / max(abs(obj(z)), 1e-6 * np.max(np.abs(p.gap["r"])))
                     for z in zz)
            print(f"  table ({p.table.kind}) vs scipy: r_gap {max(e0, e2):.2e}, r_gap_dz {e1:.2e}")
            if max(e0, e1, e2) > 1e-12:
                print("  FAIL: table interpolant differs from scipy")
                ok = False
        fd_ok, worst, at, checked, skipped = fd_jacobian_check(m, x, u, t, ref["df_dx"], p.state_scale())
        where = f" at state {at[0]} entry [{at[1]}][{at[2]}] (AD {at[3]:.10g}, FD {at[4]:.10g})" if at else ""
        print(f"  df_dx vs finite differences: max rel err {worst:.2e}{where}; "
              f"{checked} entries checked, {skipped} skipped (non-smooth stencil)"
              + ("" if fd_ok else "   <-- FAIL"))
        ok &= fd_ok
        if checked < 0.5 * n * p.nx * p.nx:
            print("  FAIL: fewer than half of the Jacobian entries could be checked")
            ok = False
        all_ok &= ok
    return all_ok


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--self-test", action="store_true", help="check the oracle itself (no binary)")
    ap.add_argument("args", nargs="*", help="RELDESIGN MODEL.toml... (or MODEL.toml... with --self-test)")
    ap.add_argument("--n", type=int, default=200, help="states per description (default 200)")
    ap.add_argument("--seed", type=int, default=20240521)
    ap.add_argument("--tol", type=float, default=1e-10, help="max relative error (default 1e-10)")
    ap.add_argument("--keep", metavar="DIR", help="write STATES.json / OUT.json under DIR")
    a = ap.parse_args(argv)
    if a.self_test:
        ok = self_test(a.args, a.n, a.seed, a.tol)
        print("\nself-test: " + ("OK" if ok else "FAILED"))
        return 0 if ok else 1
    if len(a.args) < 2:
        ap.error("expected RELDESIGN MODEL.toml [MODEL.toml ...]")
    ok = check_binary(a.args[0], a.args[1:], a.n, a.seed, a.tol, a.keep)
    print("\ncheck_eval: " + ("OK" if ok else "FAILED: reldesign eval disagrees with the oracle (see above)"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
