"""The hybrid automaton of the actuator, integrated with scipy's solve_ivp.

The scipy side of "simulator against scipy" (check_simulate.py, and
benches/simulate_vs_scipy.py).  Written independently of the Rust simulator:

- modes 1 = StuckMin (z = z_min, v = 0), 2 = Free, 3 = StuckMax (z = z_max, v = 0);
  stuck modes integrate only φ (and H_c), with z, v frozen at the limit;
- Free: terminal events z − z_min (direction −1) and z − z_max (direction +1).
  At an impact |v| > bounce_threshold bounces (v⁺ = −restitution·v, stays Free),
  otherwise the armature sticks (v⁺ = 0);
- StuckMin lifts off when the free acceleration a(z_min, 0, φ) becomes > 0
  (event direction +1); StuckMax when a(z_max, 0, φ) becomes < 0 (direction −1).
  Entering a stuck mode whose acceleration already points away goes straight
  back to Free;
- the input is linear between samples: integration restarts at every sample
  where the slope changes (the RHS is not smooth there), and after every event;
- start at rest at z_max, φ = 0, H_c = 0: StuckMax unless a(z_max, 0, 0) < 0.

Outputs are sampled from the solvers' dense output at the input's time points.
"""

from __future__ import annotations

import csv
import math
import os
import sys
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from desc import load  # noqa: E402
from model import numpy_model  # noqa: E402

STUCK_MIN, FREE, STUCK_MAX = 1, 2, 3
MODE_NAMES = {1: "StuckMin", 2: "Free", 3: "StuckMax"}


def read_csv(path: str) -> dict[str, np.ndarray]:
    """A CSV in the measured-data format: '#' comment lines anywhere, one header."""
    with open(path, newline="") as fh:
        rows = [r for r in csv.reader(line for line in fh if line.strip() and not line.lstrip().startswith("#"))]
    header = [h.strip() for h in rows[0]]
    cols: dict[str, list] = {h: [] for h in header}
    for r in rows[1:]:
        for h, cell in zip(header, r):
            cols[h].append(cell.strip())
    out = {}
    for h, vals in cols.items():
        try:
            out[h] = np.array([float(v) for v in vals])
        except ValueError:
            out[h] = np.array(vals)
    return out


def read_input(path: str) -> tuple[np.ndarray, np.ndarray]:
    d = read_csv(path)
    if "t" not in d or "v" not in d:
        raise ValueError(f"{path}: needs columns t and v")
    t, v = d["t"], d["v"]
    if not np.all(np.diff(t) > 0):
        raise ValueError(f"{path}: t is not strictly increasing")
    return t, v


def breakpoints(t: np.ndarray, v: np.ndarray) -> list[int]:
    """Indices of the samples where the piecewise-linear input's slope changes
    (plus the first and last sample)."""
    s = np.diff(v) / np.diff(t)
    smax = float(np.max(np.abs(s))) if len(s) else 0.0
    idx = [0]
    for k in range(1, len(t) - 1):
        if abs(s[k] - s[k - 1]) > 1e-12 * smax:
            idx.append(k)
    idx.append(len(t) - 1)
    return idx


@dataclass
class Event:
    t: float
    kind: str  # "bounce-min" | "stick-min" | "bounce-max" | "stick-max" | "lift-off-min" | "lift-off-max"
    v_before: float
    v_after: float
    mode_to: int
    x: list | None = None  # state just after the event


@dataclass
class Result:
    t: np.ndarray
    u: np.ndarray
    x: np.ndarray  # (n, nx)
    mode: np.ndarray
    i: np.ndarray
    events: list[Event] = field(default_factory=list)
    nfev: int = 0
    nsolves: int = 0

    def columns(self) -> dict[str, np.ndarray]:
        d = {"t": self.t, "v": self.u, "i": self.i, "z": self.x[:, 0], "vz": self.x[:, 1], "phi": self.x[:, 2]}
        if self.x.shape[1] == 4:
            d["Hc"] = self.x[:, 3]
        d["mode"] = self.mode
        return d

    def write_csv(self, path: str) -> None:
        cols = self.columns()
        with open(path, "w") as fh:
            fh.write(",".join(cols) + "\n")
            for k in range(len(self.t)):
                fh.write(",".join(repr(float(c[k])) if n != "mode" else str(int(c[k])) for n, c in cols.items())
                         + "\n")


def simulate(desc, t_in, v_in, rtol=1e-10, atol=None, method="DOP853", x0=None, mode0=None,
             max_events=100000) -> Result:
    """Replay the input (t_in, v_in) through the hybrid model.

    atol: per-state absolute tolerances; default rtol·(typical state magnitude)
    (z: z_max − z_min, v: 1 m/s, φ: the flux scale, H_c: 1000 A/m)."""
    p = load(desc)
    m = numpy_model(p)
    nx = p.nx
    if p.gap_model in ("mclyman", "mclyman-fit"):
        # Runge–Kutta stages of the step that crosses z_min evaluate the RHS a little
        # beyond the stop, where ln(·/(z + z_ε)) is undefined: there R_gap is
        # continued by its tangent at z_min (C¹).  Only the step that contains the
        # impact sees it; its error estimate still controls the result.
        r_in, dr_in = m.r_gap, m.r_gap_dz
        r_lo, dr_lo, zlo = r_in(p.z_min), dr_in(p.z_min), p.z_min
        m.r_gap = lambda z: r_in(z) if z >= zlo else r_lo + dr_lo * (z - zlo)
        m.r_gap_dz = lambda z: dr_in(z) if z >= zlo else dr_lo
    f, acc = m.f, m.acc
    zmin, zmax = p.z_min, p.z_max
    gamma, v_eps = p.restitution, p.bounce_threshold
    if atol is None:
        atol = [rtol * s for s in p.state_scale()]
    t_in = np.asarray(t_in, dtype=float)
    v_in = np.asarray(v_in, dtype=float)

    # initial state: at rest at z_max, demagnetised
    y = list(x0) if x0 is not None else [zmax, 0.0, 0.0] + ([0.0] if nx == 4 else [])
    events: list[Event] = []

    def settle(mode, y, t):
        """A stuck mode whose free acceleration points away is left at once."""
        if mode == STUCK_MAX and acc(zmax, 0.0, y[2]) < 0:
            events.append(Event(t, "lift-off-max", 0.0, 0.0, FREE, list(y)))
            return FREE
        if mode == STUCK_MIN and acc(zmin, 0.0, y[2]) > 0:
            events.append(Event(t, "lift-off-min", 0.0, 0.0, FREE, list(y)))
            return FREE
        return mode

    t_cur = float(t_in[0])
    if mode0 is None:
        mode = STUCK_MAX if y[0] >= zmax and y[1] == 0 else (STUCK_MIN if y[0] <= zmin and y[1] == 0 else FREE)
    else:
        mode = mode0
    mode = settle(mode, y, t_cur)

    pieces = []  # (t0, t1, mode, OdeSolution, z offset)
    nfev = 0
    nsolves = 0
    n_events_here, t_last_event = 0, None
    bps = breakpoints(t_in, v_in)
    for a, b in zip(bps[:-1], bps[1:]):
        ta, tb, ua, ub = float(t_in[a]), float(t_in[b]), float(v_in[a]), float(v_in[b])
        du, dt = ub - ua, tb - ta

        def uf(t, ua=ua, du=du, ta=ta, dt=dt):
            return ua + du * ((t - ta) / dt)

        while t_cur < tb:
            if mode == FREE:
                # Integrate dz = z − zref (zref: z at the start of the piece) so that
                # a piece starting on a stop sees exactly dz = 0 there.  A piece that
                # starts on a stop (after a bounce or a lift-off) watches that stop
                # with g = dz/(t − t0)^q (q = 1 if v0 ≠ 0, else 2; at t0 its limit
                # v0 or a0/2, which points away): same roots for t > t0, but not the
                # trivial one at t0 itself.
                zref, t0 = y[0], t_cur
                v0 = y[1]
                a0 = acc(zref, v0, y[2])
                y = [0.0] + y[1:]

                def rhs(t, yy, zref=zref):
                    xx = yy.tolist()
                    xx[0] += zref
                    return f(t, xx, uf(t))

                def make_ev(z_lim, direction):
                    off = zref - z_lim
                    if off == 0.0:
                        q, g0 = (1, v0) if v0 != 0.0 else (2, 0.5 * a0)

                        def ev(t, yy):
                            return g0 if t == t0 else yy[0] / (t - t0) ** q
                    else:
                        def ev(t, yy):
                            return off + yy[0]
                    ev.terminal, ev.direction = True, direction
                    return ev

                evs = [make_ev(zmin, -1), make_ev(zmax, +1)]
            else:
                zl = zmin if mode == STUCK_MIN else zmax

                def rhs(t, yy, zl=zl):
                    xx = yy.tolist()
                    xx[0], xx[1] = zl, 0.0
                    d = f(t, xx, uf(t))
                    d[0] = d[1] = 0.0
                    return d

                def ev_lift(t, yy, zl=zl):
                    return acc(zl, 0.0, float(yy[2]))

                ev_lift.terminal = True
                ev_lift.direction = +1 if mode == STUCK_MIN else -1
                evs = [ev_lift]

            sol = solve_ivp(rhs, (t_cur, tb), np.array(y, dtype=float), method=method, rtol=rtol, atol=atol,
                            events=evs, dense_output=True)
            nsolves += 1
            nfev += sol.nfev
            if sol.status < 0:
                raise RuntimeError(f"solve_ivp failed at t={t_cur}: {sol.message}")
            t_end = float(sol.t[-1])
            zoff = zref if mode == FREE else 0.0
            if t_end > t_cur:
                pieces.append((t_cur, t_end, mode, sol.sol, zoff))
            y = sol.y[:, -1].tolist()
            y[0] += zoff
            if sol.status == 1:
                # which event fired
                fired = [k for k, te in enumerate(sol.t_events) if len(te)]
                k = fired[0]
                te = float(sol.t_events[k][0])
                ye = sol.y_events[k][0].tolist()
                ye[0] += zoff
                y = ye
                if t_last_event is not None and te == t_last_event:
                    n_events_here += 1
                    if n_events_here > 50:
                        raise RuntimeError(f"event loop at t={te} (mode {MODE_NAMES[mode]})")
                else:
                    n_events_here, t_last_event = 0, te
                if len(events) > max_events:
                    raise RuntimeError("too many events (Zeno?)")
                if mode == FREE:
                    vb = ye[1]
                    lim, z_lim = ("min", zmin) if k == 0 else ("max", zmax)
                    y[0] = z_lim
                    if abs(vb) > v_eps:
                        y[1] = -gamma * vb
                        events.append(Event(te, "bounce-" + lim, vb, y[1], FREE, list(y)))
                        mode = FREE
                    else:
                        y[1] = 0.0
                        mode = STUCK_MIN if lim == "min" else STUCK_MAX
                        events.append(Event(te, "stick-" + lim, vb, 0.0, mode, list(y)))
                        mode = settle(mode, y, te)
                else:
                    zl = zmin if mode == STUCK_MIN else zmax
                    y[0], y[1] = zl, 0.0
                    # the located root may sit a hair before the crossing: move to the
                    # first time at which the acceleration really points away
                    sgn = +1 if mode == STUCK_MIN else -1
                    te2, span = te, 1e-15 * max(1.0, abs(te))
                    for _ in range(60):
                        if sgn * acc(zl, 0.0, float(sol.sol(te2)[2])) > 0:
                            break
                        te2 = te + span
                        span *= 2
                    if te2 != te:
                        y = sol.sol(te2).tolist()
                        y[0], y[1] = zl, 0.0
                        te = min(te2, tb)
                    kind = "lift-off-" + ("min" if mode == STUCK_MIN else "max")
                    events.append(Event(te, kind, 0.0, 0.0, FREE, list(y)))
                    mode = FREE
                t_cur = te
            else:
                t_cur = tb

    # sample the pieces at the input's time points
    n = len(t_in)
    X = np.empty((n, nx))
    modes = np.empty(n, dtype=int)
    starts = np.array([pc[0] for pc in pieces])
    which = np.searchsorted(starts, t_in, side="right") - 1
    which[which < 0] = 0
    for j in np.unique(which):
        sel = np.nonzero(which == j)[0]
        t0, t1, md, sl, zoff = pieces[j]
        X[sel] = sl(t_in[sel]).T
        X[sel, 0] += zoff
        modes[sel] = md
        if md != FREE:
            X[sel, 0] = zmin if md == STUCK_MIN else zmax
            X[sel, 1] = 0.0
    cur = np.array([m.current(float(t_in[k]), X[k].tolist(), float(v_in[k])) for k in range(n)])
    return Result(t=t_in, u=v_in, x=X, mode=modes, i=cur, events=events, nfev=nfev, nsolves=nsolves)


def harmonic_first_impact(p, z0):
    """Analytic check of the automaton: with φ ≡ 0 and no damping the armature,
    released at rest at z0, moves as z(t) = z_eq + (z0 − z_eq)·cos(ωt).  Returns
    the time and velocity of the first contact with z_min or z_max (or None)."""
    w = math.sqrt(p.stiffness / p.mass)
    z_eq = -p.f0 / p.stiffness
    A = z0 - z_eq
    target = p.z_min if A > 0 else p.z_max
    c = (target - z_eq) / A
    if not -1.0 <= c <= 1.0:
        return None
    tt = math.acos(c) / w
    return tt, -A * w * math.sin(w * tt)
