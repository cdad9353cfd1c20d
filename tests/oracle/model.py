"""Independent oracles of reldesign's actuator model.

Two implementations of the same equations, written separately on purpose:

- `build(desc)`: CasADi (SX) expressions -> dict of `casadi.Function`s
    f(x, u, t)      state derivative in free motion
    i(x, u, t)      coil current
    v_coil(x, u, t) coil voltage (= u for voltage drive)
    f_mag(x)        magnetic force  −½·R_gap'(z)·φ²
    acc(x, u, t)    free-motion acceleration (= f[1])
    r_gap(z), r_gap_dz(z)
    df_dx(x, u, t)  ∂f/∂x by CasADi's algorithmic differentiation (row i = ∂f_i/∂x)
    cond(x, u, t)   -> (f, i, df_dx) magnitudes of the terms that cancel in each value
                    (rounding-noise scale; see check_eval.py)
  R_gap' (and R_gap'' inside df_dx) come from AD of R_gap.

- `rhs_numpy(desc)` -> (f(t, x, u), current(t, x, u)): plain float code with the
  `math` module (what a user would hand to scipy.integrate.solve_ivp), with
  R_gap' derived by hand.  `numpy_model(desc)` gives the object with all of it.

`desc` is a path to a TOML description, a dict parsed from one (tomllib), or a
`desc.Params`.  State x = [z, v, φ] (+ H_c with a Jiles–Atherton core).
"""

from __future__ import annotations

import bisect
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import casadi as ca  # noqa: E402

from desc import JA_SERIES_LIMIT, MU0, Z_EPS, Params, load  # noqa: E402

__all__ = ["build", "rhs_numpy", "numpy_model", "NumpyModel", "load"]


# ----------------------------------------------------------------------------
# CasADi
# ----------------------------------------------------------------------------

def _ca_r_gap(p: Params, z):
    g = p.gap
    if p.gap_model == "linear":
        return g["offset"] + g["slope"] * z
    if p.gap_model == "mclyman":
        A, lw = g["area"], g["winding_length"]
        return (z / (MU0 * A)) / (1 + (z / ca.sqrt(A)) * ca.log(2 * lw / (z + Z_EPS)))
    if p.gap_model == "mclyman-fit":
        return g["r0"] + g["r0_prime"] * z / (1 + g["k1"] * z * ca.log(g["k2"] / (z + Z_EPS)))
    if p.gap_model == "table":
        x, c = p.table.x, p.table.c
        npieces = len(x) - 1

        def piece(k):
            s = z - float(x[k])
            return ((float(c[0, k]) * s + float(c[1, k])) * s + float(c[2, k])) * s + float(c[3, k])

        # piece k on [x_k, x_{k+1}); piece 0 extends left, the last piece right
        expr = piece(npieces - 1)
        for k in range(npieces - 2, -1, -1):
            expr = ca.if_else(z < float(x[k + 1]), piece(k), expr)
        return expr
    raise ValueError(p.gap_model)


def _ca_langevin(x):
    """L(x) and L'(x), series for |x| < 0.1 (both branches guarded)."""
    small = ca.fabs(x) < JA_SERIES_LIMIT
    xs = ca.if_else(small, x, 0.0)
    xb = ca.if_else(small, 1.0, x)  # keeps coth finite in the unused branch
    x2 = xs * xs
    L_series = xs * (1.0 / 3 + x2 * (-1.0 / 45 + x2 * (2.0 / 945 + x2 * (-1.0 / 4725 + x2 * (2.0 / 93555)))))
    dL_series = 1.0 / 3 + x2 * (-1.0 / 15 + x2 * (2.0 / 189 + x2 * (-1.0 / 675 + x2 * (2.0 / 10395))))
    coth = 1.0 / ca.tanh(xb)
    L_big = coth - 1.0 / xb
    dL_big = 1.0 - coth * coth + 1.0 / (xb * xb)
    return ca.if_else(small, L_series, L_big), ca.if_else(small, dL_series, dL_big)


def build(desc) -> dict:
    p = load(desc)
    n = p.nx
    x = ca.SX.sym("x", n)
    u = ca.SX.sym("u")
    t = ca.SX.sym("t")
    zs = ca.SX.sym("z")

    z, v, phi = x[0], x[1], x[2]
    Hc = x[3] if p.ja else None

    rg_z = _ca_r_gap(p, zs)
    drg_z = ca.jacobian(rg_z, zs)
    r_gap = ca.Function("r_gap", [zs], [rg_z], ["z"], ["r_gap"])
    r_gap_dz = ca.Function("r_gap_dz", [zs], [drg_z], ["z"], ["r_gap_dz"])

    rg = ca.substitute(rg_z, zs, z)
    drg = ca.substitute(drg_z, zs, z)

    if p.core_model == "linear":
        mmf = p.core["r0"] * phi
    elif p.core_model == "saturating":
        mmf = p.core["r0"] * phi / (1 - ca.fabs(phi) / p.core["phi_sat"])
    else:
        mmf = Hc * p.core["length"]

    R = p.resistance + p.resistance_drift * t
    N, ke = p.turns, p.eddy
    mmf_total = rg * phi + mmf
    if p.drive == "voltage":
        k = N * N + R * ke
        dphi = (N * u - R * mmf_total) / k
        i = (N * mmf_total + ke * u) / k
        v_coil = u
    else:
        dphi = (N * u - mmf_total) / ke
        i = u
        v_coil = R * u + N * dphi

    f_mag = -0.5 * drg * phi * phi
    F = p.stiffness * z + p.damping * v + p.f0
    acc = (f_mag - F) / p.mass

    rhs = [v, acc, dphi]
    if p.ja:
        c = p.core
        Ac, msat, b, cr, kappa, alpha = c["area"], c["m_sat"], c["b"], c["c"], c["kappa"], c["alpha"]
        Bc = phi / Ac
        Mc = Bc / MU0 - Hc
        Be = MU0 * (Hc + alpha * Mc)
        L, dL = _ca_langevin(Be / b)
        Man = msat * L
        dMan = msat / b * dL
        Mirr = (Mc - cr * Man) / (1 - cr)
        delta = ca.sign(dphi)
        if c["reversal"] == "reversible":
            # no irreversible change against the field's direction
            dMirr = ca.fmax(delta * (Man - Mirr), 0.0) / (MU0 * kappa)
        else:
            dMirr = delta * (Man - Mirr) / (MU0 * kappa)
        dMc = (1 - cr) * dMirr + cr * dMan
        dBc = ca.fmax(1 + MU0 * (1 - alpha) * dMc, c["epsilon"])
        dHdB = 1 / MU0 - dMc / dBc
        rhs.append(dHdB * dphi / Ac)
    f = ca.vertcat(*rhs)
    J = ca.jacobian(f, x)

    # Rounding-noise scales ("condition"): for each value, the magnitude of the
    # terms that cancel in it.  Two correct double-precision implementations may
    # differ by a few ulps of these (e.g. Ḣ_c = (1/μ0 − dM_c/dB_c)·φ̇/A_c loses up
    # to ~6 digits when dH_c/dB_c is small); check_eval uses them as a floor.
    if p.drive == "voltage":
        c_dphi = (N * ca.fabs(u) + R * (ca.fabs(rg * phi) + ca.fabs(mmf))) / k
        c_i = (N * (ca.fabs(rg * phi) + ca.fabs(mmf)) + ke * ca.fabs(u)) / k
    else:
        c_dphi = (N * ca.fabs(u) + ca.fabs(rg * phi) + ca.fabs(mmf)) / ke
        c_i = ca.fabs(u)
    c_acc = (ca.fabs(f_mag) + ca.fabs(p.stiffness * z) + ca.fabs(p.damping * v) + abs(p.f0)) / p.mass
    cond_f = [ca.fabs(v), c_acc, c_dphi]
    cond_J = ca.SX(ca.fabs(J))
    d2rg = ca.jacobian(drg, z)
    cond_J[1, 0] = (0.5 * ca.fabs(d2rg) * phi * phi + abs(p.stiffness)) / p.mass
    if p.ja:
        ratio = dMc / dBc
        cond_f.append((1 / MU0 + ca.fabs(ratio)) * c_dphi / Ac)
        dratio = ca.jacobian(ratio, x)
        ddphi = ca.jacobian(dphi, x)
        for j in range(n):
            cond_J[3, j] = (ca.fabs(dratio[j]) * c_dphi + (1 / MU0 + ca.fabs(ratio)) * ca.fabs(ddphi[j])) / Ac
    cond = ca.Function("cond", [x, u, t], [ca.vertcat(*cond_f), c_i, cond_J], ["x", "u", "t"],
                       ["f", "i", "df_dx"])

    xa = [x, u, t]
    names = ["x", "u", "t"]
    fx = ca.Function("f_mag", [x], [f_mag], ["x"], ["f_mag"])
    return {
        "f": ca.Function("f", xa, [f], names, ["f"]),
        "i": ca.Function("i", xa, [i], names, ["i"]),
        "v_coil": ca.Function("v_coil", xa, [v_coil], names, ["v_coil"]),
        "acc": ca.Function("acc", xa, [acc], names, ["acc"]),
        "f_mag": fx,
        "r_gap": r_gap,
        "r_gap_dz": r_gap_dz,
        "df_dx": ca.Function("df_dx", xa, [J], names, ["df_dx"]),
        "cond": cond,
    }


# ----------------------------------------------------------------------------
# plain floats (math)
# ----------------------------------------------------------------------------

def _langevin(x: float) -> tuple[float, float]:
    if abs(x) < JA_SERIES_LIMIT:
        x2 = x * x
        L = x / 3 - x ** 3 / 45 + 2 * x ** 5 / 945 - x ** 7 / 4725 + 2 * x ** 9 / 93555
        dL = 1 / 3 - x2 / 15 + 2 * x2 ** 2 / 189 - x2 ** 3 / 675 + 2 * x2 ** 4 / 10395
        return L, dL
    coth = math.cosh(x) / math.sinh(x) if abs(x) < 20 else math.copysign(1.0, x) / math.tanh(abs(x))
    return coth - 1 / x, 1 - coth * coth + 1 / (x * x)


class NumpyModel:
    """Float implementation of the model (math module, hand-derived R_gap')."""

    def __init__(self, desc):
        p = load(desc)
        self.p = p
        self.nx = p.nx
        self._build_gap()

    # --- gap ---------------------------------------------------------------
    def _build_gap(self):
        p = self.p
        g = p.gap
        if p.gap_model == "linear":
            off, sl = g["offset"], g["slope"]
            self.r_gap = lambda z: off + sl * z
            self.r_gap_dz = lambda z: sl
        elif p.gap_model == "mclyman":
            A, lw = g["area"], g["winding_length"]
            sA = math.sqrt(A)

            def r(z):
                return (z / (MU0 * A)) / (1 + z / sA * math.log(2 * lw / (z + Z_EPS)))

            def dr(z):
                num = z / (MU0 * A)
                den = 1 + z / sA * math.log(2 * lw / (z + Z_EPS))
                dden = math.log(2 * lw / (z + Z_EPS)) / sA - (z / sA) / (z + Z_EPS)
                return (den / (MU0 * A) - num * dden) / (den * den)

            self.r_gap, self.r_gap_dz = r, dr
        elif p.gap_model == "mclyman-fit":
            r0, r0p, k1, k2 = g["r0"], g["r0_prime"], g["k1"], g["k2"]

            def r(z):
                return r0 + r0p * z / (1 + k1 * z * math.log(k2 / (z + Z_EPS)))

            def dr(z):
                lg = math.log(k2 / (z + Z_EPS))
                E = 1 + k1 * z * lg
                dE = k1 * lg - k1 * z / (z + Z_EPS)
                return r0p * (E - z * dE) / (E * E)

            self.r_gap, self.r_gap_dz = r, dr
        else:
            xs = [float(v) for v in p.table.x]
            cs = [[float(p.table.c[m, k]) for m in range(4)] for k in range(len(xs) - 1)]
            last = len(xs) - 2
            inner = xs[1:-1]

            def piece(z):
                k = bisect.bisect_right(inner, z)  # piece k on [x_k, x_{k+1})
                return min(k, last)

            def r(z):
                k = piece(z)
                a, b, c, d = cs[k]
                s = z - xs[k]
                return ((a * s + b) * s + c) * s + d

            def dr(z):
                k = piece(z)
                a, b, c, _ = cs[k]
                s = z - xs[k]
                return (3 * a * s + 2 * b) * s + c

            self.r_gap, self.r_gap_dz = r, dr
            self.table_piece = piece

    # --- pieces --------------------------------------------------------------
    def mmf_core(self, phi: float, Hc: float = 0.0) -> float:
        p = self.p
        if p.core_model == "linear":
            return p.core["r0"] * phi
        if p.core_model == "saturating":
            return p.core["r0"] * phi / (1 - abs(phi) / p.core["phi_sat"])
        return Hc * p.core["length"]

    def resistance(self, t: float) -> float:
        return self.p.resistance + self.p.resistance_drift * t

    def dphi(self, t, z, phi, Hc, u):
        p = self.p
        R = self.resistance(t)
        m = self.r_gap(z) * phi + self.mmf_core(phi, Hc)
        if p.drive == "voltage":
            return (p.turns * u - R * m) / (p.turns ** 2 + R * p.eddy)
        return (p.turns * u - m) / p.eddy

    def f_mag(self, z, phi):
        return -0.5 * self.r_gap_dz(z) * phi * phi

    def acc(self, z, v, phi):
        p = self.p
        F = p.stiffness * z + p.damping * v + p.f0
        return (self.f_mag(z, phi) - F) / p.mass

    def ja_terms(self, phi, Hc, dphi):
        """(dH_c/dB_c, clamp active?) of the inverse Jiles–Atherton model."""
        c = self.p.core
        Ac, alpha, cr = c["area"], c["alpha"], c["c"]
        Bc = phi / Ac
        Mc = Bc / MU0 - Hc
        Be = MU0 * (Hc + alpha * Mc)
        L, dL = _langevin(Be / c["b"])
        Man = c["m_sat"] * L
        dMan = c["m_sat"] / c["b"] * dL
        Mirr = (Mc - cr * Man) / (1 - cr)
        delta = 1.0 if dphi > 0 else (-1.0 if dphi < 0 else 0.0)
        if c["reversal"] == "reversible":
            dMirr = max(delta * (Man - Mirr), 0.0) / (MU0 * c["kappa"])
        else:
            dMirr = delta * (Man - Mirr) / (MU0 * c["kappa"])
        dMc = (1 - cr) * dMirr + cr * dMan
        raw = 1 + MU0 * (1 - alpha) * dMc
        dBc = max(raw, c["epsilon"])
        return 1 / MU0 - dMc / dBc, raw < c["epsilon"]

    # --- the user-facing functions --------------------------------------------
    def f(self, t, x, u):
        z, v, phi = x[0], x[1], x[2]
        Hc = x[3] if self.nx == 4 else 0.0
        dphi = self.dphi(t, z, phi, Hc, u)
        out = [v, self.acc(z, v, phi), dphi]
        if self.nx == 4:
            dHdB, _ = self.ja_terms(phi, Hc, dphi)
            out.append(dHdB * dphi / self.p.core["area"])
        return out

    def current(self, t, x, u):
        p = self.p
        if p.drive == "current":
            return u
        z, phi = x[0], x[2]
        Hc = x[3] if self.nx == 4 else 0.0
        R = self.resistance(t)
        m = self.r_gap(z) * phi + self.mmf_core(phi, Hc)
        return (p.turns * m + p.eddy * u) / (p.turns ** 2 + R * p.eddy)

    def v_coil(self, t, x, u):
        if self.p.drive == "voltage":
            return u
        Hc = x[3] if self.nx == 4 else 0.0
        return self.resistance(t) * u + self.p.turns * self.dphi(t, x[0], x[2], Hc, u)

    def regime(self, t, x, u):
        """Discrete indicators of the smooth piece the point lies in (for
        finite-difference checks: the model is not differentiable across them)."""
        z, phi = x[0], x[2]
        Hc = x[3] if self.nx == 4 else 0.0
        key = []
        if self.p.gap_model == "table":
            key.append(self.table_piece(z))
        if self.p.core_model == "saturating":
            key.append(phi > 0)
        if self.nx == 4:
            d = self.dphi(t, z, phi, Hc, u)
            c = self.p.core
            key.append(1 if d > 0 else (-1 if d < 0 else 0))
            key.append(self.ja_terms(phi, Hc, d)[1])
            key.append(abs(MU0 * (Hc + c["alpha"] * (phi / c["area"] / MU0 - Hc)) / c["b"]) < JA_SERIES_LIMIT)
        return tuple(key)


def numpy_model(desc) -> NumpyModel:
    return NumpyModel(desc)


def rhs_numpy(desc):
    """(f(t, x, u) -> list, current(t, x, u) -> float), plain float code."""
    m = NumpyModel(desc)
    return m.f, m.current
