"""Reading an actuator description (shared/spec/actuator.md) for the oracles.

This is the *oracle's* reader, written independently of the Rust parser: it
turns a TOML file (or an already parsed dict) into a flat `Params` object with
every default applied, and builds the interpolant of a tabulated gap.  It does
only the validation the oracles need to not compute nonsense; the contract's
error messages are the Rust side's business.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

MU0 = 4e-7 * math.pi
Z_EPS = 1e-9  # regularisation of the McLyman logarithm [m]
JA_SERIES_LIMIT = 0.1  # |x| below which the Langevin series is used


class DescriptionError(ValueError):
    pass


@dataclass
class Table:
    """Piecewise cubic R_gap(z) as scipy gives it: knots x (n), coefficients
    c (4 x n-1), piece k is sum_m c[m, k]·(z − x[k])^(3−m); piece 0 extends to
    the left, piece n−2 to the right (scipy `extrapolate=True`)."""

    kind: str  # "hermite" | "cubic-spline" | "pchip"
    x: np.ndarray
    c: np.ndarray
    scipy_obj: object = None


@dataclass
class Params:
    name: str
    # coil
    turns: float
    resistance: float
    eddy: float
    resistance_drift: float
    # gap
    gap_model: str
    gap: dict
    table: Table | None
    # core
    core_model: str
    core: dict
    # mechanics
    mass: float
    stiffness: float
    damping: float
    f0: float
    z_min: float
    z_max: float
    restitution: float
    bounce_threshold: float
    # supply
    drive: str
    u_min: float
    u_max: float
    raw: dict = field(default_factory=dict, repr=False)

    @property
    def ja(self) -> bool:
        return self.core_model == "jiles-atherton"

    @property
    def nx(self) -> int:
        return 4 if self.ja else 3

    def flux_scale(self) -> float:
        """A realistic flux magnitude: 0.9·phi_sat for a saturating core, else the
        flux giving ~2 T over the (core or McLyman gap) area, else 3e-5 Wb."""
        if self.core_model == "saturating":
            return 0.9 * self.core["phi_sat"]
        if self.ja:
            return 2.0 * self.core["area"]
        if self.gap_model == "mclyman":
            return 2.0 * self.gap["area"]
        return 3e-5

    def state_scale(self) -> list[float]:
        """Typical magnitude of each state (tolerance / finite-difference scale)."""
        s = [self.z_max - self.z_min, 1.0, self.flux_scale()]
        if self.ja:
            s.append(1000.0)
        return s


def _num(sec: dict, key: str, where: str, default=None) -> float:
    if key not in sec:
        if default is None:
            raise DescriptionError(f"missing key `{where}.{key}`")
        return float(default)
    v = sec[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise DescriptionError(f"`{where}.{key}` must be a number, got {v!r}")
    v = float(v)
    if not math.isfinite(v):
        raise DescriptionError(f"`{where}.{key}` must be finite, got {v!r}")
    return v


def _numlist(sec: dict, key: str, where: str) -> np.ndarray:
    v = sec.get(key)
    if not isinstance(v, list) or not all(isinstance(e, (int, float)) and not isinstance(e, bool) for e in v):
        raise DescriptionError(f"`{where}.{key}` must be an array of numbers")
    return np.asarray(v, dtype=float)


def _check_keys(sec: dict, allowed: set[str], where: str) -> None:
    unknown = set(sec) - allowed
    if unknown:
        raise DescriptionError(f"unknown key(s) in [{where}]: {sorted(unknown)}")


def make_table(z: np.ndarray, r: np.ndarray, r_prime: np.ndarray | None) -> Table:
    """The interpolant of a tabulated gap, as the model text defines it:
    - r_prime given: cubic Hermite through (z_k, r_k, r'_k);
    - else the not-a-knot cubic spline if its derivative is > 0 on [z_0, z_last];
    - else PCHIP."""
    from scipy.interpolate import CubicHermiteSpline, CubicSpline, PchipInterpolator

    if len(z) < 4 or len(r) != len(z):
        raise DescriptionError("gap table needs >= 4 points and len(r) == len(z)")
    if not np.all(np.diff(z) > 0):
        raise DescriptionError("gap table z must be strictly increasing")
    if r_prime is not None:
        if len(r_prime) != len(z):
            raise DescriptionError("gap table r_prime must have the length of z")
        obj = CubicHermiteSpline(z, r, r_prime)
        return Table("hermite", np.array(obj.x), np.array(obj.c), obj)
    cs = CubicSpline(z, r)  # bc_type="not-a-knot"
    if _derivative_positive(cs.x, cs.c):
        return Table("cubic-spline", np.array(cs.x), np.array(cs.c), cs)
    pc = PchipInterpolator(z, r)
    return Table("pchip", np.array(pc.x), np.array(pc.c), pc)


def _derivative_positive(x: np.ndarray, c: np.ndarray) -> bool:
    """Is the derivative of the piecewise cubic > 0 everywhere on [x_0, x_last]?
    Piece k's derivative in s = z − x_k is 3a·s² + 2b·s + d on [0, h_k]: its
    minimum is at an end or at the vertex s* = −b/(3a) when that is inside."""
    for k in range(len(x) - 1):
        a, b, d = c[0, k], c[1, k], c[2, k]
        h = x[k + 1] - x[k]

        def dp(s):
            return (3 * a * s + 2 * b) * s + d

        cands = [0.0, h]
        if a != 0.0:
            s_star = -b / (3 * a)
            if 0.0 < s_star < h:
                cands.append(s_star)
        if min(dp(s) for s in cands) <= 0.0:
            return False
    return True


def load(desc) -> Params:
    """`desc`: a path (str/Path) to a TOML file, or an already parsed dict."""
    if isinstance(desc, (str, Path)):
        with open(desc, "rb") as fh:
            d = tomllib.load(fh)
    elif isinstance(desc, Params):
        return desc
    else:
        d = desc
    for sec in ("coil", "gap", "core", "mechanics", "supply"):
        if sec not in d or not isinstance(d[sec], dict):
            raise DescriptionError(f"missing section [{sec}]")

    coil = d["coil"]
    _check_keys(coil, {"turns", "resistance", "eddy", "resistance_drift"}, "coil")
    turns = _num(coil, "turns", "coil")
    resistance = _num(coil, "resistance", "coil")
    eddy = _num(coil, "eddy", "coil")
    drift = _num(coil, "resistance_drift", "coil", 0.0)

    gap = d["gap"]
    gm = gap.get("model")
    table = None
    if gm == "linear":
        _check_keys(gap, {"model", "slope", "offset"}, "gap")
        g = {"slope": _num(gap, "slope", "gap"), "offset": _num(gap, "offset", "gap", 0.0)}
    elif gm == "mclyman":
        _check_keys(gap, {"model", "area", "winding_length"}, "gap")
        g = {"area": _num(gap, "area", "gap"), "winding_length": _num(gap, "winding_length", "gap")}
    elif gm == "mclyman-fit":
        _check_keys(gap, {"model", "r0", "r0_prime", "k1", "k2"}, "gap")
        g = {k: _num(gap, k, "gap") for k in ("r0", "r0_prime", "k1", "k2")}
    elif gm == "table":
        _check_keys(gap, {"model", "z", "r", "r_prime"}, "gap")
        zt = _numlist(gap, "z", "gap")
        rt = _numlist(gap, "r", "gap")
        rp = _numlist(gap, "r_prime", "gap") if "r_prime" in gap else None
        table = make_table(zt, rt, rp)
        g = {"z": zt, "r": rt, "r_prime": rp}
    else:
        raise DescriptionError(f"unknown gap.model {gm!r}")

    core = d["core"]
    cm = core.get("model")
    if cm == "linear":
        _check_keys(core, {"model", "r0"}, "core")
        c = {"r0": _num(core, "r0", "core")}
    elif cm == "saturating":
        _check_keys(core, {"model", "r0", "phi_sat"}, "core")
        c = {"r0": _num(core, "r0", "core"), "phi_sat": _num(core, "phi_sat", "core")}
        if c["phi_sat"] <= 0:
            raise DescriptionError("core.phi_sat must be > 0")
    elif cm == "jiles-atherton":
        keys = ("length", "area", "m_sat", "b", "c", "kappa", "alpha")
        _check_keys(core, {"model", "epsilon", "reversal", *keys}, "core")
        c = {k: _num(core, k, "core") for k in keys}
        c["epsilon"] = _num(core, "epsilon", "core", 1e-3)
        c["reversal"] = core.get("reversal", "clamp")
        if c["reversal"] not in ("clamp", "reversible"):
            raise DescriptionError(f"unknown core.reversal {c['reversal']!r}")
        if not 0.0 <= c["c"] < 1.0:
            raise DescriptionError("core.c must be in [0, 1)")
    else:
        raise DescriptionError(f"unknown core.model {cm!r}")

    mech = d["mechanics"]
    _check_keys(mech, {"mass", "stiffness", "damping", "preload", "rest_position", "z_min", "z_max",
                       "restitution", "bounce_threshold"}, "mechanics")
    stiffness = _num(mech, "stiffness", "mechanics")
    if "preload" in mech and "rest_position" in mech:
        raise DescriptionError("give mechanics.preload or mechanics.rest_position, not both")
    if "rest_position" in mech:
        f0 = -stiffness * _num(mech, "rest_position", "mechanics")
    else:
        f0 = _num(mech, "preload", "mechanics", 0.0)
    z_min = _num(mech, "z_min", "mechanics")
    z_max = _num(mech, "z_max", "mechanics")
    if not z_min < z_max:
        raise DescriptionError("mechanics.z_min must be < z_max")
    mass = _num(mech, "mass", "mechanics")
    if mass <= 0:
        raise DescriptionError("mechanics.mass must be > 0")

    sup = d["supply"]
    _check_keys(sup, {"drive", "u_min", "u_max"}, "supply")
    drive = sup.get("drive", "voltage")
    if drive not in ("voltage", "current"):
        raise DescriptionError(f"unknown supply.drive {drive!r}")

    return Params(
        name=str(d.get("name", "actuator")),
        turns=turns, resistance=resistance, eddy=eddy, resistance_drift=drift,
        gap_model=gm, gap=g, table=table,
        core_model=cm, core=c,
        mass=mass, stiffness=stiffness, damping=_num(mech, "damping", "mechanics"), f0=f0,
        z_min=z_min, z_max=z_max,
        restitution=_num(mech, "restitution", "mechanics"),
        bounce_threshold=_num(mech, "bounce_threshold", "mechanics"),
        drive=drive, u_min=_num(sup, "u_min", "supply"), u_max=_num(sup, "u_max", "supply"),
        raw=d,
    )
