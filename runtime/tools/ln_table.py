#!/usr/bin/env python3
"""Generates the lookup table and polynomial of runtime/src/ln.rs (f64 natural log).

Usage (from the repository root):
    python3 runtime/tools/ln_table.py            # print the generated Rust block
    python3 runtime/tools/ln_table.py --write    # replace the marked blocks of
                                                 # runtime/src/ln.rs and runtime/tests/ln.rs
    python3 runtime/tools/ln_table.py --test-data  # print only the test vectors

Deterministic; needs mpmath and numpy; takes about a minute.

Algorithm (ARM optimized-routines / glibc `log`, with Gal's accurate tables):
x = 2^k * z with z in [OFF, 2*OFF), OFF = 0x3fe6000000000000 (= 0.6875), split
into N = 128 subintervals by the top 7 bits of bits(x) - OFF. Subinterval i has a
double c_i within 2^-20 (relative) of its centre, chosen (Gal's method) so that
log(c_i) lies within 2^-64 of a multiple of 2^-43: logc_i, that multiple, is a
double with at most 42 significant bits, so k*Ln2hi + logc_i is exact for every
exponent k (Ln2hi has 42 significant bits, |k| <= 1024). Among the candidates
found (a fixed-point filter over 2^21 consecutive doubles at a time, then an
exact check at 256 bits) the one minimising |log c - logc| + max|r| * |invc*c - 1|
is kept, invc_i = 1/c_i rounded. Then z - c_i is exact (Sterbenz) and
r = (z - c_i) * invc_i is z/c_i - 1 within about 2^-61.

log1p(r) = r + r^2 * (A0 + A1 r + A2 r^2 + A3 r^3 + A4 r^4) on |r| <= max |r|:
minimax (Remez) fit of the absolute error, coefficients rounded to double, error
re-measured after rounding.
"""
from __future__ import annotations

import argparse
import os
import re
import struct
import sys
from fractions import Fraction

import mpmath
import numpy as np
from mpmath import mp, mpf

mp.prec = 256

N_BITS = 7
N = 1 << N_BITS
OFF = 0x3FE6000000000000
LOGC_QUANTUM_EXP = -43  # logc is a multiple of 2^-43
J = 1 << 20  # candidates c0_bits + m, |m| <= J, around each search centre
# Search centres: the subinterval centre plus these ulps (|offset| + J < 2^32 << 2^44,
# so c stays in its subinterval and within 2^-20 of its centre, relatively); blocks
# are searched in turn until MIN_HITS candidates are found.
SEARCH_OFFSETS = [(-1) ** n * ((n + 1) * 0x1F3A5C27 % (1 << 31)) for n in range(64)]
MIN_HITS = 12
CHUNK = 1 << 21
LOG_THRESHOLD = mpf(2) ** -64  # keep candidates with |log c - logc| below this
POLY_DEGREE = 4  # A0..A4, i.e. log1p(r) - r to r^6

HERE = os.path.dirname(os.path.abspath(__file__))
LN_RS = os.path.join(HERE, "..", "src", "ln.rs")
TEST_RS = os.path.join(HERE, "..", "tests", "ln.rs")


def bits_to_f(b: int) -> float:
    return struct.unpack("<d", struct.pack("<Q", b))[0]


def f_to_bits(x: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", x))[0]


def ulp_of_bits(b: int) -> Fraction:
    e = (b >> 52) & 0x7FF
    return Fraction(2) ** (e - 1023 - 52)


def mpf_to_float(v) -> float:
    """v rounded to the nearest double (exact conversion to a fraction, then
    Python's correctly rounded Fraction -> float); 256-bit v, so the double
    rounding cannot matter for a logarithm."""
    sign, man, exp, _ = v._mpf_
    return float((-1) ** sign * Fraction(man) * Fraction(2) ** exp)


def hx(b: int) -> str:
    """A u64 as a Rust hex literal with separators: 0x3fe6_0fff_830d_b3f9."""
    h = f"{b:016x}"
    return "0x" + "_".join(h[k:k + 4] for k in range(0, 16, 4))


def rnd_multiple(v, q):
    """v rounded to the nearest multiple of q (mpf), as mpf."""
    return mpmath.nint(v / q) * q


def search_entry(i: int):
    """(c, invc, logc, log error, invc relative error, max |r|) of subinterval i."""
    lo_bits = OFF + (i << (52 - N_BITS))
    hi_bits = lo_bits + (1 << (52 - N_BITS))
    a, b = Fraction(bits_to_f(lo_bits)), Fraction(bits_to_f(hi_bits))
    centre_bits = lo_bits + (1 << (52 - N_BITS - 1))  # the centre, exactly a double
    assert Fraction(bits_to_f(centre_bits)) == (a + b) / 2
    hits = []
    for offset in SEARCH_OFFSETS:
        hits += [offset + m for m in stage1(centre_bits + offset)]
        if len(hits) >= MIN_HITS:
            break
    return stage2(i, a, b, centre_bits, hits)


def stage1(c0_bits: int):
    """Fast filter: the m in [-J, J] for which log(double(c0_bits + m)) is within
    about LOG_THRESHOLD of a multiple of 2^-43.

    log(c0 + m u) = L0 + t - t^2/2 + t^3/3, t = m u / c0, in fixed point with unit
    2^-103, modulo 2^-43 (= 2^60 units). int64 arithmetic wraps modulo 2^64, a
    multiple of 2^60, so its overflow is harmless. c0 is a full-precision double
    (the centre plus an odd offset): around the short centre itself, u/c0 * 2^43
    would be a rational with a small denominator and the values m -> log mod 2^-43
    would only visit a coarse lattice.
    """
    c0 = Fraction(bits_to_f(c0_bits))
    u = ulp_of_bits(c0_bits)
    assert ulp_of_bits(c0_bits - J) == u and ulp_of_bits(c0_bits + J) == u
    unit_exp = -103
    mod_bits = LOGC_QUANTUM_EXP - unit_exp  # 60
    mask = np.int64((1 << mod_bits) - 1)
    scale = mpf(2) ** (-unit_exp)
    c0m = mpf(c0.numerator) / c0.denominator
    L0 = int(mpmath.nint(mpmath.log(c0m) * scale)) & ((1 << mod_bits) - 1)
    s = mpf(u.numerator) / u.denominator / c0m
    B = s * scale
    B_int = int(mpmath.floor(B))
    B_frac = float(B - B_int)
    Q = float(s * s / 2 * scale)
    C3 = float(s ** 3 / 3 * scale)
    thr_units = int(LOG_THRESHOLD * scale) + (1 << 20)  # slack for the filter's own error
    found = []
    for start in range(-J, J + 1, CHUNK):
        m = np.arange(start, min(start + CHUNK, J + 1), dtype=np.int64)
        mf = m.astype(np.float64)
        small = np.rint(mf * B_frac - mf * mf * Q + mf * mf * mf * C3).astype(np.int64)
        with np.errstate(over="ignore"):
            v = (np.int64(L0) + m * np.int64(B_int) + small) & mask
        dist = np.minimum(v, (np.int64(1) << mod_bits) - v)
        found.extend(int(x) for x in m[dist <= thr_units])
    return found


def stage2(i, a, b, c0_bits, hits):
    """Exact check of the stage-1 hits at 256 bits; the best candidate."""
    # Stage 2 (exact): verify each hit at 256 bits and pick the best.
    q = mpf(2) ** LOGC_QUANTUM_EXP
    best = None
    for jj in hits:
        cb = c0_bits + jj
        c = Fraction(bits_to_f(cb))
        cm = mpf(c.numerator) / c.denominator
        lg = mpmath.log(cm)
        logc = rnd_multiple(lg, q)
        err_log = lg - logc
        if abs(err_log) > LOG_THRESHOLD:
            continue
        invc = float(1 / c)  # Fraction -> float is correctly rounded
        eps_inv = (Fraction(invc) * c) - 1  # invc = (1 + eps) / c
        # max |z/c - 1| over the subinterval
        rmax = max(abs(a / c - 1), abs(b / c - 1))
        metric = abs(err_log) + mpf(rmax.numerator) / rmax.denominator * abs(
            mpf(eps_inv.numerator) / eps_inv.denominator)
        key = (metric, abs(jj), jj)
        if best is None or key < best[0]:
            best = (key, cb, invc, logc, err_log, eps_inv, rmax)
    if best is None:
        sys.exit(f"entry {i}: no candidate within the threshold; widen J")
    _, cb, invc, logc, err_log, eps_inv, rmax = best
    logc_f = mpf_to_float(logc)
    assert mpf(logc_f) == logc, "logc must be exactly a double"
    return cb, f_to_bits(invc), f_to_bits(logc_f), err_log, eps_inv, rmax


def remez(R, degree):
    """Minimax coefficients A of max |log1p(r) - r - r^2 * sum A_k r^k| on [-R, R]."""
    n = degree + 1
    f = lambda r: mpmath.log1p(r) - r  # noqa: E731
    # initial reference: Chebyshev extrema
    m = n + 1
    pts = [R * mpmath.cos(mpmath.pi * (m - 1 - k) / (m - 1)) for k in range(m)]
    A = None
    for _ in range(30):
        # solve r^2 * p(r_k) + (-1)^k E = f(r_k)
        M = mpmath.matrix(m, m)
        rhs = mpmath.matrix(m, 1)
        for k, r in enumerate(pts):
            for d in range(n):
                M[k, d] = r ** (d + 2)
            M[k, n] = (-1) ** k
            rhs[k] = f(r)
        sol = mpmath.lu_solve(M, rhs)
        A = [sol[d] for d in range(n)]
        err = lambda r: f(r) - sum(A[d] * r ** (d + 2) for d in range(n))  # noqa: E731
        # new reference: extrema of err between sign changes on a dense grid
        grid = [R * mpmath.cos(mpmath.pi * (2000 - k) / 2000) for k in range(2001)]
        vals = [err(r) for r in grid]
        ext = []
        k = 0
        while k < len(grid):
            sgn = vals[k] >= 0
            best = k
            while k < len(grid) and (vals[k] >= 0) == sgn:
                if abs(vals[k]) > abs(vals[best]):
                    best = k
                k += 1
            ext.append(grid[best])
        if len(ext) < m:
            break
        # keep m alternating extrema with the largest magnitudes, contiguous
        while len(ext) > m:
            if abs(err(ext[0])) < abs(err(ext[-1])):
                ext.pop(0)
            else:
                ext.pop()
        pts = ext
    return A


def poly_error(A, R, points=20001):
    """max |log1p(r) - (r + r^2 p(r))| on [-R, R] with the double coefficients A."""
    worst = mpf(0)
    for k in range(points):
        r = R * (2 * mpf(k) / (points - 1) - 1)
        p = sum(mpf(a) * r ** (d + 2) for d, a in enumerate(A))
        worst = max(worst, abs(mpmath.log1p(r) - r - p))
    return worst


def log2_str(v) -> str:
    v = abs(v)
    return "0" if v == 0 else f"2^{float(mpmath.log(v, 2)):.1f}"


def generate():
    entries = []
    for i in range(N):
        entries.append(search_entry(i))
        print(f"entry {i:3}/{N}", file=sys.stderr, end="\r")
    print(file=sys.stderr)
    max_log_err = max(abs(e[3]) for e in entries)
    max_eps = max(abs(mpf(e[4].numerator) / e[4].denominator) for e in entries)
    rmax = max(e[5] for e in entries)
    # |r| as computed: (z - c) exact, times invc = (1 + eps)/c, rounded
    R = mpf(rmax.numerator) / rmax.denominator * (1 + max_eps) * (1 + mpf(2) ** -52)
    A_exact = remez(R, POLY_DEGREE)
    A = [mpf_to_float(a) for a in A_exact]
    perr = poly_error(A, R)
    ln2 = mpmath.log(2)
    ln2hi = mpf_to_float(rnd_multiple(ln2, mpf(2) ** -42))
    assert f_to_bits(ln2hi) & ((1 << 11) - 1) == 0
    ln2lo = mpf_to_float(ln2 - ln2hi)

    out = []
    out.append("// Generated by runtime/tools/ln_table.py; do not edit by hand. Regenerate with")
    out.append("// `python3 runtime/tools/ln_table.py --write` (from the repository root).")
    out.append(f"// Max |log(c) - logc| = {log2_str(max_log_err)}; max |invc*c - 1| = {log2_str(max_eps)};")
    out.append(f"// max |r| = {float(R):.6g}; max |log1p(r) - r - r^2 A(r)| = {log2_str(perr)}.")
    out.append("")
    # Bit patterns (u64) rather than `f64::from_bits` in consts, which needs Rust 1.83:
    # ln.rs converts them where it uses them (free: the bits are loaded as they are).
    out.append("/// ln 2 rounded to 42 significant bits, so `k * LN2_HI` is exact for |k| < 2^11.")
    out.append(f"const LN2_HI: u64 = {hx(f_to_bits(ln2hi))}; // {ln2hi!r}")
    out.append("/// ln 2 - LN2_HI.")
    out.append(f"const LN2_LO: u64 = {hx(f_to_bits(ln2lo))}; // {ln2lo!r}")
    out.append("/// log1p(r) - r = r² (A0 + A1 r + A2 r² + A3 r³ + A4 r⁴) (minimax on |r| ≤ max |r|).")
    for d, a in enumerate(A):
        out.append(f"const A{d}: u64 = {hx(f_to_bits(a))}; // {a!r}")
    out.append("")
    out.append(f"/// [c, 1/c rounded, log c (a multiple of 2^-43)] of the {N} subintervals, as bits.")
    out.append("#[rustfmt::skip]")
    out.append(f"const TABLE: [[u64; 3]; {N}] = [")
    for cb, ib, lb, *_ in entries:
        out.append(f"    [{hx(cb)}, {hx(ib)}, {hx(lb)}],")
    out.append("];")
    return "\n".join(out), A, entries


def test_data():
    """Correctly rounded log of a few hundred deterministic doubles, as (x, log x) bits."""
    xs = []
    # table path and fallback boundaries, both sides of 1
    for b in [0x3FEE000000000000, f_to_bits(1.0 + float.fromhex("0x1.09p-4"))]:
        for d in range(-8, 9):
            xs.append(b + d)
    # every 4th table boundary and centre, scaled by a few powers of two
    for i in range(0, N, 4):
        lb = OFF + (i << (52 - N_BITS))
        for kk in (-1, 0, 1, 7):
            xs.append(lb + (kk << 52) - 1)
            xs.append(lb + (kk << 52))
            xs.append(lb + (kk << 52) + (1 << (52 - N_BITS - 1)))
    # deterministic pseudo-random over the normal range and the controller's range
    s = 0x9E3779B97F4A7C15
    for n in range(160):
        s ^= (s << 13) & 0xFFFFFFFFFFFFFFFF
        s ^= s >> 7
        s ^= (s << 17) & 0xFFFFFFFFFFFFFFFF
        if n % 2 == 0:
            xs.append(0x0010000000000000 + s % (0x7FF0000000000000 - 0x0010000000000000))
        else:
            x = mpf_to_float(30 * mpf(10) ** (6 * mpf(s >> 11) / 2**53))  # no libm: reproducible
            xs.append(f_to_bits(x))
    # subnormals, extremes, near 1
    xs += [1, 0x000FFFFFFFFFFFFF, 0x0010000000000000, 0x7FEFFFFFFFFFFFFF, f_to_bits(1.0),
           f_to_bits(1.0) + 1, f_to_bits(1.0) - 1, f_to_bits(2.0), f_to_bits(0.5), f_to_bits(3.0e7)]
    rows = []
    for xb in xs:
        x = Fraction(bits_to_f(xb))
        y = mpmath.log(mpf(x.numerator) / x.denominator)
        rows.append((xb, f_to_bits(mpf_to_float(y))))
    out = ["// Generated by runtime/tools/ln_table.py --test-data (mpmath, correctly rounded).",
           f"const CORRECTLY_ROUNDED: [(u64, u64); {len(rows)}] = ["]
    for xb, yb in rows:
        out.append(f"    ({hx(xb)}, {hx(yb)}),")
    out.append("];")
    return "\n".join(out)


def replace_block(path, begin, end, text):
    src = open(path).read()
    pat = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if not pat.search(src):
        sys.exit(f"markers not found in {path}")
    src = pat.sub(lambda _m: begin + "\n" + text + "\n" + end, src)
    open(path, "w").write(src)


BEGIN = "// BEGIN GENERATED TABLE (runtime/tools/ln_table.py)"
END = "// END GENERATED TABLE"
TBEGIN = "// BEGIN GENERATED TEST DATA (runtime/tools/ln_table.py --test-data)"
TEND = "// END GENERATED TEST DATA"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help="update the marked blocks in place")
    ap.add_argument("--test-data", action="store_true", help="print only the test vectors")
    a = ap.parse_args()
    if a.test_data:
        print(test_data())
        return
    table, _, _ = generate()
    if a.write:
        replace_block(LN_RS, BEGIN, END, table)
        replace_block(TEST_RS, TBEGIN, TEND, test_data())
    else:
        print(table)


if __name__ == "__main__":
    main()
