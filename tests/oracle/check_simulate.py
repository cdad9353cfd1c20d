#!/usr/bin/env python3
"""Check `reldesign simulate` against the scipy hybrid automaton (hybrid.py).

Usage:
  check_simulate.py RELDESIGN [--model MODEL.toml] [--input IN.csv] [--tol 1e-6] [--keep DIR]
                    [--reldesign-args "--rtol 1e-10"]
  check_simulate.py --scipy-only [--model ...] [--input ...] [--write OUT.csv]
  check_simulate.py --self-test [--model ...] [--input ...]

Defaults: --model examples/jiles-atherton-valve.toml, --input
tests/data/ja-three-pulses.csv (relative to the repository root).  RELDESIGN is
the binary's path or a quoted command ("cargo run -q --release --bin reldesign --").

Runs the scipy automaton (solve_ivp DOP853, rtol 1e-10, atol = 1e-10·state
scale, restarts at input breakpoints and events), then
`RELDESIGN simulate MODEL --input IN --out OUT.csv` (columns t,v,i,z,vz,phi[,Hc],mode
at the input's time points) and compares:
    max|Δi| / max|i|  <= tol   and   max|Δφ| / max|φ| <= tol   (tol = 1e-6)
and reports (not judged) the position / velocity / H_c errors, the impact and
lift-off times, and the samples whose mode differs.  Exit 1 on failure.

--self-test checks the scipy automaton itself: the bounce sequence of a
free spring-mass (φ ≡ 0) against the closed-form solution, every event's
consistency (direction, reset, stick/bounce rule), and DOP853 against RK45 at a
tighter tolerance on the experiment.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.optimize import brentq

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
ROOT = os.path.dirname(os.path.dirname(HERE))

import hybrid  # noqa: E402
from desc import load  # noqa: E402

DEFAULT_MODEL = os.path.join(ROOT, "examples", "jiles-atherton-valve.toml")
DEFAULT_INPUT = os.path.join(ROOT, "tests", "data", "ja-three-pulses.csv")
MODE_WORDS = {"stuckmin": 1, "free": 2, "stuckmax": 3, "1": 1, "2": 2, "3": 3}


def mode_numbers(col) -> np.ndarray:
    out = []
    for v in col:
        key = re.sub(r"[^a-z0-9]", "", str(v).lower())
        if key.endswith(".0") or re.fullmatch(r"[123]0", key):
            key = key[0]
        if key not in MODE_WORDS:
            try:
                key = str(int(float(v)))
            except ValueError:
                raise ValueError(f"unknown mode value {v!r}")
        out.append(MODE_WORDS[key])
    return np.array(out)


def pulses(t, v):
    """[(start time, end time)] of the runs where the input is non-zero."""
    on = np.abs(v) > 0
    out, k = [], 0
    while k < len(t):
        if on[k]:
            j = k
            while j + 1 < len(t) and on[j + 1]:
                j += 1
            out.append((t[max(k - 1, 0)], t[min(j + 1, len(t) - 1)]))
            k = j + 1
        else:
            k += 1
    return out


def summarize(p, r: hybrid.Result, t_sim: float | None = None):
    t, z = r.t, r.x[:, 0]
    print(f"  scipy automaton: {len(r.events)} events, {r.nsolves} solve_ivp calls, {r.nfev} RHS evaluations"
          + (f", {t_sim * 1e3:.1f} ms" if t_sim is not None else ""))
    for e in r.events:
        print(f"    t = {e.t * 1e3:10.6f} ms  {e.kind:<13} v- = {e.v_before:+.6f} m/s  v+ = {e.v_after:+.6f} m/s"
              f"  -> {hybrid.MODE_NAMES[e.mode_to]}")
    ps = pulses(t, r.u)
    for n, (a, b) in enumerate(ps):
        nxt = ps[n + 1][0] if n + 1 < len(ps) else t[-1]
        sel = (t >= a) & (t <= nxt)
        k0 = int(np.argmax(sel))
        moved = bool(np.any(z[sel] != z[k0]))
        closes = [e for e in r.events if a <= e.t <= nxt and e.kind in ("bounce-min", "stick-min")]
        first = f", first impact at {closes[0].t * 1e3:.4f} ms ({closes[0].v_before:+.4f} m/s)" if closes else ""
        state = (f"moves: z {z[k0] * 1e3:.4f} -> min {z[sel].min() * 1e3:.4f} mm, "
                 f"{z[sel][-1] * 1e3:.4f} mm at {nxt * 1e3:.2f} ms") if moved else \
            f"does not move (z stays {z[k0] * 1e3:.4f} mm)"
        print(f"  pulse {n + 1} ({a * 1e3:.2f}-{b * 1e3:.2f} ms, {np.max(np.abs(r.u[sel])):g} V): {state}{first}")
    k = int(np.argmax(np.abs(r.i)))
    print(f"  peak current {r.i[k]:.6f} A at {t[k] * 1e3:.2f} ms; peak flux {np.max(np.abs(r.x[:, 2])):.6e} Wb")


def run_reldesign(cmd, model, inp, out, extra=()):
    argv = [*shlex.split(cmd), "simulate", model, "--input", inp, "--out", out, *extra]
    try:
        t0 = time.perf_counter()
        res = subprocess.run(argv, capture_output=True, text=True, timeout=3600)
        dt = time.perf_counter() - t0
    except FileNotFoundError as e:
        raise RuntimeError(f"cannot run {argv[0]!r}: {e}")
    if res.returncode != 0:
        raise RuntimeError(f"`{shlex.join(argv)}` exited with {res.returncode}:\n{res.stderr.strip()}")
    return res, dt


def compare(p, ref: hybrid.Result, out_csv, tol) -> bool:
    d = hybrid.read_csv(out_csv)
    need = ["t", "v", "i", "z", "vz", "phi", "mode"] + (["Hc"] if p.ja else [])
    missing = [c for c in need if c not in d]
    if missing:
        print(f"  FAIL: {out_csv} lacks column(s) {missing} (has {list(d)})")
        return False
    t = d["t"]
    if len(t) != len(ref.t) or np.max(np.abs(t - ref.t)) > 1e-12 * max(1.0, np.max(np.abs(ref.t))):
        print(f"  FAIL: output times are not the input's time points ({len(t)} rows vs {len(ref.t)})")
        return False
    ok = True
    rows = [("i", d["i"], ref.i, True), ("phi", d["phi"], ref.x[:, 2], True),
            ("z", d["z"], ref.x[:, 0], False), ("vz", d["vz"], ref.x[:, 1], False)]
    if p.ja:
        rows.append(("Hc", d["Hc"], ref.x[:, 3], False))
    rows.append(("v (input)", d["v"], ref.u, False))
    print(f"  {'quantity':<10} {'max|Δ|/max|ref|':>16} {'max|Δ|':>12}  {'at t [ms]':>10}   judged")
    for name, got, exp, judged in rows:
        diff = np.abs(got - exp)
        if np.any(~np.isfinite(got)):
            print(f"  {name:<10} non-finite values in the output")
            ok = False
            continue
        scale = np.max(np.abs(exp))
        if name == "z":
            scale = p.z_max - p.z_min
        k = int(np.argmax(diff))
        rel = diff[k] / scale if scale > 0 else diff[k]
        flag = ""
        if judged:
            flag = "yes" + ("" if rel <= tol else "   <-- FAIL")
            ok &= rel <= tol
        print(f"  {name:<10} {rel:16.3e} {diff[k]:12.3e}  {t[k] * 1e3:10.3f}   {flag}")
    mode = mode_numbers(d["mode"])
    bad = np.nonzero(mode != ref.mode)[0]
    print(f"  mode differs at {len(bad)} of {len(t)} samples"
          + (f" (first at t = {t[bad[0]] * 1e3:.3f} ms: reldesign {mode[bad[0]]}, scipy {ref.mode[bad[0]]})"
             if len(bad) else ""))
    ch_r = [(t[k] * 1e3, mode[k - 1], mode[k]) for k in range(1, len(t)) if mode[k] != mode[k - 1]]
    ch_s = [(t[k] * 1e3, ref.mode[k - 1], ref.mode[k]) for k in range(1, len(t)) if ref.mode[k] != ref.mode[k - 1]]
    print("  mode changes at samples (t ms: from->to):")
    print("    scipy:     " + ", ".join(f"{a:.2f}: {b}->{c}" for a, b, c in ch_s))
    print("    reldesign: " + ", ".join(f"{a:.2f}: {b}->{c}" for a, b, c in ch_r))
    return ok


# ----------------------------------------------------------------------------
# self-test of the scipy automaton
# ----------------------------------------------------------------------------

def _spring_mass_desc(restitution=0.5, threshold=0.05):
    return {"name": "spring", "coil": {"turns": 100, "resistance": 10.0, "eddy": 0.0},
            "gap": {"model": "linear", "slope": 1e10, "offset": 1e5}, "core": {"model": "linear", "r0": 1e6},
            "mechanics": {"mass": 2e-3, "stiffness": 50.0, "damping": 0.0, "rest_position": 0.3e-3,
                          "z_min": 0.0, "z_max": 1e-3, "restitution": restitution,
                          "bounce_threshold": threshold},
            "supply": {"u_min": -1.0, "u_max": 1.0}}


def analytic_bounces(p, z0, v0, t0, t_end):
    """Closed-form event sequence of the undamped spring-mass between the stops
    (φ ≡ 0): arcs z(t) = z_eq + (z0 − z_eq)·cos ωs + (v0/ω)·sin ωs."""
    w = math.sqrt(p.stiffness / p.mass)
    z_eq = -p.f0 / p.stiffness
    out = []
    while t0 < t_end and len(out) < 50:
        A, B = z0 - z_eq, v0 / w

        def z(s):
            return z_eq + A * math.cos(w * s) + B * math.sin(w * s)

        # first s > 0 where z leaves [z_min, z_max] (scan a period finely, then brentq)
        period = 2 * math.pi / w
        s_prev, hit = 1e-12 * period, None
        for k in range(1, 20001):
            s = k * period / 20000
            if z(s) < p.z_min or z(s) > p.z_max:
                lim = p.z_min if z(s) < p.z_min else p.z_max
                hit = (brentq(lambda q: z(q) - lim, s_prev, s, xtol=1e-18, rtol=1e-15), lim)
                break
            s_prev = s
        if hit is None:
            break
        s, lim = hit
        vb = -A * w * math.sin(w * s) + B * w * math.cos(w * s)
        t0 += s
        if t0 > t_end:
            break
        if abs(vb) > p.bounce_threshold:
            out.append((t0, "bounce-" + ("min" if lim == p.z_min else "max"), vb))
            z0, v0 = lim, -p.restitution * vb
        else:
            out.append((t0, "stick-" + ("min" if lim == p.z_min else "max"), vb))
            break
    return out


def _closed_form_case(title, p, x0, t_end) -> bool:
    t = np.linspace(0.0, t_end, 5001)
    r = hybrid.simulate(p, t, np.zeros_like(t), rtol=1e-12, x0=x0)
    ana = analytic_bounces(p, x0[0], x0[1], 0.0, t[-1])
    num = [e for e in r.events if not e.kind.startswith("lift-off")][:len(ana)]
    print(f"\n== self-test {title} vs closed form")
    ok = True
    if len(ana) != len(num) or not ana:
        print(f"  FAIL: {len(num)} impacts simulated, {len(ana)} expected")
        ok = False
    worst_t = worst_v = 0.0
    for (ta, ka, va), e in zip(ana, num):
        et, ev = abs(e.t - ta), abs(e.v_before - va) / abs(va)
        worst_t, worst_v = max(worst_t, et), max(worst_v, ev)
        mark = "" if (ka == e.kind and et < 1e-9 and ev < 1e-6) else "   <-- FAIL"
        ok &= mark == ""
        print(f"  {ka:<11} closed form t = {ta * 1e3:.9f} ms v = {va:+.9f}   scipy t = {e.t * 1e3:.9f} ms"
              f" v = {e.v_before:+.9f}  ({e.kind}){mark}")
    print(f"  max |Δt| = {worst_t:.2e} s, max rel |Δv| = {worst_v:.2e}")
    return ok, r


def _release_desc(model_path):
    """The given model with a linear core (it releases after a pulse): exercises
    lift-off from z_min, impacts at z_max."""
    p = load(model_path)
    d = {k: (dict(v) if isinstance(v, dict) else v) for k, v in p.raw.items()}
    d["core"] = {"model": "linear", "r0": 3.5e6}
    return d


def self_test(model, inp) -> bool:
    ok = True
    # 1. closed-form bounce sequences of an undamped spring-mass (φ ≡ 0)
    p = load(_spring_mass_desc(restitution=0.6, threshold=0.02))
    ok1, r = _closed_form_case("1a: spring-mass released at z_max (φ ≡ 0)", p, [p.z_max, 0.0, 0.0], 0.2)
    if not r.events or r.events[0].kind != "lift-off-max" or r.events[0].t != 0.0:
        print("  FAIL: expected an immediate lift-off from z_max (spring rest position inside the range)")
        ok1 = False
    ok &= ok1
    d = _spring_mass_desc(restitution=0.7, threshold=0.02)
    d["mechanics"]["rest_position"] = 0.5e-3
    p = load(d)
    ok1, r = _closed_form_case("1b: spring-mass thrown from mid-range, both stops (φ ≡ 0)", p, [0.5e-3, 0.3, 0.0], 0.1)
    ok &= ok1 and any(e.kind == "bounce-max" for e in r.events)

    # 2./3. event consistency and DOP853 vs RK45 on the experiment, and on a
    # released variant (linear core, 5 ms pulse)
    t_in, v_in = hybrid.read_input(inp)
    t_rel = np.linspace(0.0, 0.04, 4001)
    v_rel = np.where((t_rel >= 0.002 - 1e-12) & (t_rel < 0.007 - 1e-12), 24.0, 0.0)
    for title, desc, t, v in [(f"{os.path.basename(model)} on {os.path.basename(inp)}", model, t_in, v_in),
                              ("linear-core variant, 5 ms 24 V pulse (closes and releases)", _release_desc(model),
                               t_rel, v_rel)]:
        p = load(desc)
        r1 = hybrid.simulate(p, t, v, rtol=1e-10, method="DOP853")
        print(f"\n== self-test 2: {title}: event consistency")
        print("  events: " + ", ".join(f"{e.kind}@{e.t * 1e3:.4f}ms" for e in r1.events))
        ok &= check_events(p, r1)
        r2 = hybrid.simulate(p, t, v, rtol=1e-12, method="RK45")
        di = np.max(np.abs(r1.i - r2.i)) / np.max(np.abs(r2.i))
        dphi = np.max(np.abs(r1.x[:, 2] - r2.x[:, 2])) / np.max(np.abs(r2.x[:, 2]))
        dz = np.max(np.abs(r1.x[:, 0] - r2.x[:, 0])) / (p.z_max - p.z_min)
        same = len(r1.events) == len(r2.events) and all(a.kind == b.kind for a, b in zip(r1.events, r2.events))
        dte = max((abs(a.t - b.t) for a, b in zip(r1.events, r2.events)), default=0.0)
        print(f"== self-test 3: {title}: DOP853 rtol 1e-10 vs RK45 rtol 1e-12: max|Δi|/max|i| = {di:.2e}, "
              f"max|Δφ|/max|φ| = {dphi:.2e}, max|Δz|/range = {dz:.2e}, same events: {same}, "
              f"max |Δt_event| = {dte:.2e} s")
        if not (same and di < 1e-7 and dphi < 1e-7 and dte < 1e-8):
            print("  FAIL: the two integrations disagree")
            ok = False
    return ok


def check_events(p, r: hybrid.Result) -> bool:
    from model import numpy_model

    m = numpy_model(p)
    ok = True
    for e in r.events:
        if e.kind.startswith("bounce"):
            good = abs(e.v_before) > p.bounce_threshold and e.v_after == -p.restitution * e.v_before \
                and (e.v_before < 0) == e.kind.endswith("min")
        elif e.kind.startswith("stick"):
            good = abs(e.v_before) <= p.bounce_threshold and e.v_after == 0.0
        else:
            # a located lift-off sits where the stop's free acceleration crosses 0
            # (an immediate one, right after sticking, where it already points away)
            zl = p.z_min if e.kind.endswith("min") else p.z_max
            a = m.acc(zl, 0.0, e.x[2])
            sgn = 1 if e.kind.endswith("min") else -1
            spring = abs(p.stiffness * zl + p.f0) / p.mass
            good = sgn * a > 0 and (a * sgn < 1e-6 * spring or e.t == 0.0
                                   or any(o.t == e.t and o.kind.startswith("stick") for o in r.events))
        if not good:
            print(f"  FAIL: inconsistent event {e}")
            ok = False
    # modes in the samples: stuck samples sit on the stop with v = 0, free ones inside
    for k in range(len(r.t)):
        md, x = r.mode[k], r.x[k]
        if md == hybrid.STUCK_MIN and not (x[0] == p.z_min and x[1] == 0.0):
            ok = False
        if md == hybrid.STUCK_MAX and not (x[0] == p.z_max and x[1] == 0.0):
            ok = False
        if md == hybrid.FREE and not (p.z_min - 1e-12 <= x[0] <= p.z_max + 1e-12):
            print(f"  FAIL: free sample outside the stops at t = {r.t[k]}: z = {x[0]}")
            ok = False
        # a stuck sample's free acceleration must point into its stop
        if md == hybrid.STUCK_MIN and m.acc(p.z_min, 0.0, x[2]) > 1e-9:
            print(f"  FAIL: stuck at z_min with acceleration pointing away at t = {r.t[k]}")
            ok = False
        if md == hybrid.STUCK_MAX and m.acc(p.z_max, 0.0, x[2]) < -1e-9:
            print(f"  FAIL: stuck at z_max with acceleration pointing away at t = {r.t[k]}")
            ok = False
    print("  events and sampled modes consistent" if ok else "  FAIL: inconsistent events/modes")
    return ok


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("reldesign", nargs="?", help="path of the reldesign binary (or a quoted command)")
    ap.add_argument("--model", default=DEFAULT_MODEL)
    ap.add_argument("--input", default=DEFAULT_INPUT)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--rtol", type=float, default=1e-10, help="scipy rtol (default 1e-10)")
    ap.add_argument("--keep", metavar="DIR", help="keep reldesign's output and the scipy trajectory in DIR")
    ap.add_argument("--reldesign-args", default="", metavar="ARGS",
                    help="extra arguments for `reldesign simulate`, e.g. \"--rtol 1e-10\"")
    ap.add_argument("--write", metavar="CSV", help="write the scipy trajectory (same columns) to CSV")
    ap.add_argument("--scipy-only", action="store_true", help="only run and summarise the scipy side")
    ap.add_argument("--self-test", action="store_true", help="check the scipy automaton itself")
    a = ap.parse_args(argv)
    for path in (a.model, a.input):
        if not os.path.exists(path):
            ap.error(f"{path} does not exist")
    if a.self_test:
        ok = self_test(a.model, a.input)
        print("\nself-test: " + ("OK" if ok else "FAILED"))
        return 0 if ok else 1
    if not a.scipy_only and not a.reldesign:
        ap.error("give RELDESIGN (or --scipy-only / --self-test)")

    p = load(a.model)
    t_in, v_in = hybrid.read_input(a.input)
    print(f"== {a.model} on {a.input} ({len(t_in)} samples, {t_in[0]}..{t_in[-1]} s)")
    t0 = time.perf_counter()
    ref = hybrid.simulate(p, t_in, v_in, rtol=a.rtol, method="DOP853")
    t_sim = time.perf_counter() - t0
    summarize(p, ref, t_sim)
    if a.write:
        ref.write_csv(a.write)
    if a.scipy_only:
        return 0

    workdir = a.keep or tempfile.mkdtemp(prefix="check_simulate_")
    os.makedirs(workdir, exist_ok=True)
    out = os.path.join(workdir, "reldesign.csv")
    ref.write_csv(os.path.join(workdir, "scipy.csv"))
    try:
        res, dt = run_reldesign(a.reldesign, a.model, a.input, out, shlex.split(a.reldesign_args))
    except RuntimeError as e:
        print(f"\ncheck_simulate: FAILED: {e}")
        return 1
    print(f"\n  reldesign simulate: {dt * 1e3:.1f} ms wall (process), output {out}")
    try:
        ok = compare(p, ref, out, a.tol)
    except (ValueError, KeyError, OSError) as e:
        print(f"  FAIL: cannot read {out}: {e}")
        ok = False
    print("\ncheck_simulate: " + ("OK" if ok else
                                  f"FAILED: reldesign simulate differs from scipy by more than {a.tol:g} (see above)"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
