//! The global collocation Jacobian factored by block elimination.
//!
//! The Jacobian is block-bidiagonal plus the boundary rows [B_a 0 … 0 B_b].
//! It is factored in O(m·n³) time and memory by sequential block elimination
//! with Householder QR: each interior yᵢ is eliminated from the 2n rows that
//! contain it (the carried rows and block row i), the y₀ column being carried
//! along; the last 2n×2n system in (y₀, y_{m−1}) together with the boundary
//! rows is solved by LU with partial pivoting. This is Gaussian elimination of
//! the whole matrix with the column order (y₁, …, y_{m−2}, y₀, y_{m−1}) and
//! orthogonal row transformations, which is stable for dichotomic problems
//! (growing and decaying modes, as in Hamiltonian systems).

/// Factorization of
/// ```text
/// [A₀ B₀            ]
/// [   A₁ B₁         ]
/// [      …  …       ]
/// [         A B     ]
/// [Ba            Bb ]
/// ```
///
/// The buffers are kept across factorizations (Newton iterations and meshes)
/// so that the hot loop does not allocate; the Householder vectors are stored
/// column-major so that the dot products of the solve run over contiguous
/// memory, and the reflections are applied to the work matrix row by row.
#[derive(Default)]
pub(super) struct BlockFactor {
    n: usize,
    m: usize,
    /// Householder vectors of each interior step: (m−2) × (n × 2n), column-
    /// major: vector k occupies `[k * 2n .. (k + 1) * 2n]`, v_k in rows k..2n.
    hv: Vec<f64>,
    /// (m−2) × n.
    beta: Vec<f64>,
    /// (m−2) × (n × n): R (upper), coefficient rows on y₀, on yᵢ₊₁.
    r: Vec<f64>,
    c0: Vec<f64>,
    e: Vec<f64>,
    /// Final (2n × 2n) LU with row pivots.
    lu: Vec<f64>,
    piv: Vec<usize>,
    // scratch
    cw: Vec<f64>,
    dw: Vec<f64>,
    /// Work matrix, 2n rows × 3n columns [y₀ | yᵢ | yᵢ₊₁], row-major.
    w: Vec<f64>,
    /// Householder coefficients of the 3n columns of `w`.
    dots: Vec<f64>,
    v: Vec<f64>,
    g: Vec<f64>,
    wr: Vec<f64>,
    carried: Vec<f64>,
    z: Vec<f64>,
    t: Vec<f64>,
}

/// A pivot below the rank tolerance: the matrix is numerically singular.
pub(super) struct Singular;

/// `v` as `len` zeros, keeping its allocation.
pub(super) fn resize(v: &mut Vec<f64>, len: usize) {
    v.clear();
    v.resize(len, 0.0);
}

impl BlockFactor {
    /// Factors into `self`. `a`, `b`: (m−1) blocks n×n row-major; `ba`, `bb`: n×n.
    pub(super) fn factor(
        &mut self,
        n: usize,
        m: usize,
        a: &[f64],
        b: &[f64],
        ba: &[f64],
        bb: &[f64],
    ) -> Result<(), Singular> {
        // the common small dimensions get loops of constant length (unrolled,
        // no bounds checks); the arithmetic is the same in every instance
        match n {
            2 => self.factor_n::<2>(n, m, a, b, ba, bb),
            3 => self.factor_n::<3>(n, m, a, b, ba, bb),
            4 => self.factor_n::<4>(n, m, a, b, ba, bb),
            6 => self.factor_n::<6>(n, m, a, b, ba, bb),
            _ => self.factor_n::<0>(n, m, a, b, ba, bb),
        }
    }

    /// Solves J·x = rhs (rhs: (m−1)·n collocation rows, then n bc rows).
    pub(super) fn solve(&mut self, rhs: &[f64], x: &mut [f64]) {
        match self.n {
            2 => self.solve_n::<2>(rhs, x),
            3 => self.solve_n::<3>(rhs, x),
            4 => self.solve_n::<4>(rhs, x),
            6 => self.solve_n::<6>(rhs, x),
            _ => self.solve_n::<0>(rhs, x),
        }
    }

    /// [`Self::factor`] with n = N when N > 0, else n = `n_rt`.
    #[allow(clippy::too_many_arguments)]
    fn factor_n<const N: usize>(
        &mut self,
        n_rt: usize,
        m: usize,
        a: &[f64],
        b: &[f64],
        ba: &[f64],
        bb: &[f64],
    ) -> Result<(), Singular> {
        let n = if N > 0 { N } else { n_rt };
        let nn = n * n;
        let steps = m - 2;
        let n2 = 2 * n;
        let w3 = 3 * n;
        self.n = n;
        self.m = m;
        // every entry below is written before it is read
        self.hv.resize(steps * 2 * nn, 0.0);
        self.beta.resize(steps * n, 0.0);
        self.r.resize(steps * nn, 0.0);
        self.c0.resize(steps * nn, 0.0);
        self.e.resize(steps * nn, 0.0);
        resize(&mut self.lu, 4 * nn);
        self.piv.clear();
        self.piv.resize(n2, 0);
        resize(&mut self.v, n2);
        resize(&mut self.w, n2 * w3);
        // Carried rows W = [C | D] on (y₀, yᵢ).
        self.cw.clear();
        self.cw.extend_from_slice(&a[..nn]);
        self.dw.clear();
        self.dw.extend_from_slice(&b[..nn]);
        resize(&mut self.dots, w3);
        let (cw, dw, w, v, dots) = (
            &mut self.cw,
            &mut self.dw,
            &mut self.w,
            &mut self.v,
            &mut self.dots,
        );
        for st in 0..steps {
            let i = st + 1;
            w.iter_mut().for_each(|x| *x = 0.0);
            let (ai, bi) = (&a[i * nn..(i + 1) * nn], &b[i * nn..(i + 1) * nn]);
            for r in 0..n {
                for c in 0..n {
                    w[r * w3 + c] = cw[r * n + c];
                    w[r * w3 + n + c] = dw[r * n + c];
                    w[(n + r) * w3 + n + c] = ai[r * n + c];
                    w[(n + r) * w3 + 2 * n + c] = bi[r * n + c];
                }
            }
            let mut maxnorm: f64 = 0.0;
            for c in 0..n {
                let s: f64 = (0..n2).map(|r| w[r * w3 + n + c].powi(2)).sum();
                maxnorm = maxnorm.max(s.sqrt());
            }
            let hv = &mut self.hv[st * 2 * nn..(st + 1) * 2 * nn];
            let beta = &mut self.beta[st * n..(st + 1) * n];
            for k in 0..n {
                let col = n + k;
                let norm: f64 = (k..n2).map(|r| w[r * w3 + col].powi(2)).sum::<f64>().sqrt();
                if !(norm > 4.0 * n as f64 * f64::EPSILON * maxnorm) {
                    return Err(Singular);
                }
                let x0 = w[k * w3 + col];
                let alpha = if x0 >= 0.0 { -norm } else { norm };
                for r in k..n2 {
                    v[r] = w[r * w3 + col];
                }
                v[k] -= alpha;
                let vv: f64 = v[k..].iter().map(|x| x * x).sum();
                let bt = if vv > 0.0 { 2.0 / vv } else { 0.0 };
                // w ← (I − bt·v·vᵀ)·w, row by row: every column's dot product
                // vᵀw_j still sums over the rows in order k..2n, but the
                // columns are processed side by side (contiguous, vectorizable)
                let dots = &mut dots[..w3];
                dots.iter_mut().for_each(|d| *d = 0.0);
                for r in k..n2 {
                    let vr = v[r];
                    let row = &w[r * w3..(r + 1) * w3];
                    for (d, &q) in dots.iter_mut().zip(row) {
                        *d += vr * q;
                    }
                }
                for d in dots.iter_mut() {
                    *d *= bt;
                }
                // the already-reduced columns n..col of the yᵢ block are left alone
                dots[n..col].iter_mut().for_each(|d| *d = 0.0);
                for r in k..n2 {
                    let vr = v[r];
                    let row = &mut w[r * w3..(r + 1) * w3];
                    for (q, &g) in row.iter_mut().zip(dots.iter()) {
                        *q -= g * vr;
                    }
                }
                let hk = &mut hv[k * n2..(k + 1) * n2];
                hk[..k].iter_mut().for_each(|x| *x = 0.0);
                hk[k..].copy_from_slice(&v[k..]);
                beta[k] = bt;
            }
            let base = st * nn;
            for r in 0..n {
                for c in 0..n {
                    self.c0[base + r * n + c] = w[r * w3 + c];
                    self.r[base + r * n + c] = if c >= r { w[r * w3 + n + c] } else { 0.0 };
                    self.e[base + r * n + c] = w[r * w3 + 2 * n + c];
                    cw[r * n + c] = w[(n + r) * w3 + c];
                    dw[r * n + c] = w[(n + r) * w3 + 2 * n + c];
                }
            }
        }
        // Final system [[C, D], [Ba, Bb]] on (y₀, y_{m−1}).
        for r in 0..n {
            for c in 0..n {
                self.lu[r * n2 + c] = cw[r * n + c];
                self.lu[r * n2 + n + c] = dw[r * n + c];
                self.lu[(n + r) * n2 + c] = ba[r * n + c];
                self.lu[(n + r) * n2 + n + c] = bb[r * n + c];
            }
        }
        let maxabs = self.lu.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
        let lu = &mut self.lu;
        for k in 0..n2 {
            let (mut p, mut pv) = (k, lu[k * n2 + k].abs());
            for r in k + 1..n2 {
                if lu[r * n2 + k].abs() > pv {
                    p = r;
                    pv = lu[r * n2 + k].abs();
                }
            }
            if !(pv > 4.0 * n2 as f64 * f64::EPSILON * maxabs) {
                return Err(Singular);
            }
            self.piv[k] = p;
            if p != k {
                for c in 0..n2 {
                    lu.swap(k * n2 + c, p * n2 + c);
                }
            }
            let d = lu[k * n2 + k];
            for r in k + 1..n2 {
                let l = lu[r * n2 + k] / d;
                lu[r * n2 + k] = l;
                if l != 0.0 {
                    for c in k + 1..n2 {
                        lu[r * n2 + c] -= l * lu[k * n2 + c];
                    }
                }
            }
        }
        Ok(())
    }

    /// [`Self::solve`] with n = N when N > 0, else n = `self.n`.
    fn solve_n<const N: usize>(&mut self, rhs: &[f64], x: &mut [f64]) {
        let n = if N > 0 { N } else { self.n };
        let m = self.m;
        let nn = n * n;
        let n2 = 2 * n;
        let steps = m - 2;
        resize(&mut self.g, steps * n);
        resize(&mut self.wr, n2);
        resize(&mut self.t, n);
        resize(&mut self.z, n2);
        self.carried.clear();
        self.carried.extend_from_slice(&rhs[..n]);
        let (g, wr, carried) = (&mut self.g, &mut self.wr, &mut self.carried);
        for st in 0..steps {
            let i = st + 1;
            wr[..n].copy_from_slice(carried);
            wr[n..].copy_from_slice(&rhs[i * n..(i + 1) * n]);
            let hv = &self.hv[st * 2 * nn..(st + 1) * 2 * nn];
            for k in 0..n {
                let bt = self.beta[st * n + k];
                let hk = &hv[k * n2 + k..(k + 1) * n2];
                let wk = &mut wr[k..];
                let dot: f64 = hk.iter().zip(wk.iter()).map(|(p, q)| p * q).sum();
                let gm = bt * dot;
                for (q, p) in wk.iter_mut().zip(hk) {
                    *q -= gm * p;
                }
            }
            g[st * n..(st + 1) * n].copy_from_slice(&wr[..n]);
            carried.copy_from_slice(&wr[n..]);
        }
        // Final 2n system.
        let z = &mut self.z;
        z[..n].copy_from_slice(carried);
        z[n..].copy_from_slice(&rhs[(m - 1) * n..m * n]);
        for k in 0..n2 {
            z.swap(k, self.piv[k]);
        }
        for r in 0..n2 {
            let mut s = z[r];
            for c in 0..r {
                s -= self.lu[r * n2 + c] * z[c];
            }
            z[r] = s;
        }
        for r in (0..n2).rev() {
            let mut s = z[r];
            for c in r + 1..n2 {
                s -= self.lu[r * n2 + c] * z[c];
            }
            z[r] = s / self.lu[r * n2 + r];
        }
        x[..n].copy_from_slice(&z[..n]);
        x[(m - 1) * n..m * n].copy_from_slice(&z[n..]);
        // Back substitution: R yᵢ = gᵢ − C₀ y₀ − E yᵢ₊₁.
        let t = &mut self.t;
        for st in (0..steps).rev() {
            let i = st + 1;
            let base = st * nn;
            for r in 0..n {
                let mut s = g[st * n + r];
                for c in 0..n {
                    s -= self.c0[base + r * n + c] * x[c]
                        + self.e[base + r * n + c] * x[(i + 1) * n + c];
                }
                t[r] = s;
            }
            for r in (0..n).rev() {
                let mut s = t[r];
                for c in r + 1..n {
                    s -= self.r[base + r * n + c] * t[c];
                }
                t[r] = s / self.r[base + r * n + r];
            }
            x[i * n..(i + 1) * n].copy_from_slice(t);
        }
    }
}
