//! Fixed-size linear algebra for the generated Kalman filters.
//!
//! Everything works on arrays (`[T; N]` vectors, `[[T; N]; N]` row-major
//! matrices) of a [`Scalar`] (`f32` or `f64`), with the sizes as const
//! generics, so the emitted filters need no allocator. No function panics or
//! indexes with a runtime index (`a[i]`): loops are zipped iterators, and the
//! few single-element accesses go through `get`/`get_mut`, so the code passes
//! clippy's `indexing_slicing`, `unwrap_used` and `panic` lints like the code
//! that calls it. Sums are accumulated left to right in index order (the
//! reference filters of the designer do the same, so both round alike).
//!
//! What a filter needs and nothing more:
//!
//! - products: [`dot`], [`mat_vec`], [`mat_mul`], [`mul_transpose`] (A·Bᵀ),
//!   [`sandwich`] (F·P·Fᵀ), [`quad_form`] (hᵀ·P·h);
//! - symmetric updates: [`rank1_update`] (P + α·x·xᵀ, exactly symmetric),
//!   [`joseph_update`] (the Joseph form of a scalar measurement update),
//!   [`symmetrize`];
//! - [`cholesky`] (lower factor; `None` when the matrix is not numerically
//!   positive definite or not finite: the failure is reported, never hidden);
//! - the unscented transform's [`sigma_points`], [`weighted_mean`],
//!   [`weighted_covariance`] and [`weighted_cross`];
//! - finiteness checks ([`all_finite`], [`all_finite_matrix`]).

use core::ops::{Add, Div, Mul, Neg, Sub};

use crate::math::Real;

/// The scalar of the filters: [`Real`] plus arithmetic, constants and a
/// finiteness test (implemented for `f32` and `f64`).
pub trait Scalar:
    Real
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    /// Neither NaN nor ±∞.
    fn finite(self) -> bool;
}

impl Scalar for f64 {
    const ZERO: f64 = 0.0;
    const ONE: f64 = 1.0;
    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Scalar for f32 {
    const ZERO: f32 = 0.0;
    const ONE: f32 = 1.0;
    #[inline]
    fn finite(self) -> bool {
        self.is_finite()
    }
}

/// An N×N matrix, row-major: `m[i][j]` is row i, column j.
pub type Matrix<T, const N: usize> = [[T; N]; N];

/// The identity matrix.
#[inline]
pub fn identity<T: Scalar, const N: usize>() -> Matrix<T, N> {
    let mut m = [[T::ZERO; N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        if let Some(d) = row.get_mut(i) {
            *d = T::ONE;
        }
    }
    m
}

/// diag(d).
#[inline]
pub fn diagonal<T: Scalar, const N: usize>(d: &[T; N]) -> Matrix<T, N> {
    let mut m = [[T::ZERO; N]; N];
    for (i, (row, &di)) in m.iter_mut().zip(d).enumerate() {
        if let Some(x) = row.get_mut(i) {
            *x = di;
        }
    }
    m
}

/// The diagonal of `a`.
#[inline]
pub fn diag_of<T: Scalar, const N: usize>(a: &Matrix<T, N>) -> [T; N] {
    let mut d = [T::ZERO; N];
    for (i, (di, row)) in d.iter_mut().zip(a).enumerate() {
        if let Some(&x) = row.get(i) {
            *di = x;
        }
    }
    d
}

/// a·b = Σ aᵢ·bᵢ (left to right).
#[inline]
pub fn dot<T: Scalar, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    a.iter().zip(b).fold(T::ZERO, |s, (&x, &y)| s + x * y)
}

/// Σ_{i<n} aᵢ·bᵢ (left to right).
#[inline]
fn dot_prefix<T: Scalar>(a: &[T], b: &[T], n: usize) -> T {
    a.iter()
        .zip(b)
        .take(n)
        .fold(T::ZERO, |s, (&x, &y)| s + x * y)
}

/// A·x.
#[inline]
pub fn mat_vec<T: Scalar, const N: usize>(a: &Matrix<T, N>, x: &[T; N]) -> [T; N] {
    let mut y = [T::ZERO; N];
    for (yi, row) in y.iter_mut().zip(a) {
        *yi = dot(row, x);
    }
    y
}

/// Aᵀ.
#[inline]
pub fn transpose<T: Scalar, const N: usize>(a: &Matrix<T, N>) -> Matrix<T, N> {
    let mut t = [[T::ZERO; N]; N];
    for (i, row) in a.iter().enumerate() {
        for (t_row, &x) in t.iter_mut().zip(row) {
            if let Some(y) = t_row.get_mut(i) {
                *y = x;
            }
        }
    }
    t
}

/// A·Bᵀ: entry (i, j) is the dot product of row i of A and row j of B.
#[inline]
pub fn mul_transpose<T: Scalar, const N: usize>(
    a: &Matrix<T, N>,
    b: &Matrix<T, N>,
) -> Matrix<T, N> {
    let mut c = [[T::ZERO; N]; N];
    for (c_row, a_row) in c.iter_mut().zip(a) {
        for (cij, b_row) in c_row.iter_mut().zip(b) {
            *cij = dot(a_row, b_row);
        }
    }
    c
}

/// A·B.
#[inline]
pub fn mat_mul<T: Scalar, const N: usize>(a: &Matrix<T, N>, b: &Matrix<T, N>) -> Matrix<T, N> {
    mul_transpose(a, &transpose(b))
}

/// F·P·Fᵀ, symmetrised (for a symmetric P the result is symmetric up to
/// rounding; [`symmetrize`] makes it exactly so).
#[inline]
pub fn sandwich<T: Scalar, const N: usize>(f: &Matrix<T, N>, p: &Matrix<T, N>) -> Matrix<T, N> {
    let mut s = mul_transpose(&mat_mul(f, p), f);
    symmetrize(&mut s);
    s
}

/// hᵀ·P·h.
#[inline]
pub fn quad_form<T: Scalar, const N: usize>(p: &Matrix<T, N>, h: &[T; N]) -> T {
    dot(h, &mat_vec(p, h))
}

/// A + B.
#[inline]
pub fn add<T: Scalar, const N: usize>(a: &Matrix<T, N>, b: &Matrix<T, N>) -> Matrix<T, N> {
    let mut c = *a;
    for (c_row, b_row) in c.iter_mut().zip(b) {
        for (x, &y) in c_row.iter_mut().zip(b_row) {
            *x = *x + y;
        }
    }
    c
}

/// A ← (A + Aᵀ)/2: exactly symmetric afterwards (the sum commutes).
#[inline]
pub fn symmetrize<T: Scalar, const N: usize>(a: &mut Matrix<T, N>) {
    let t = transpose(a);
    let half = T::ONE / (T::ONE + T::ONE);
    for (a_row, t_row) in a.iter_mut().zip(&t) {
        for (x, &y) in a_row.iter_mut().zip(t_row) {
            *x = (*x + y) * half;
        }
    }
}

/// P ← P + α·x·xᵀ, written α·(xᵢ·xⱼ) so that a symmetric P stays exactly
/// symmetric.
#[inline]
pub fn rank1_update<T: Scalar, const N: usize>(p: &mut Matrix<T, N>, alpha: T, x: &[T; N]) {
    for (p_row, &xi) in p.iter_mut().zip(x) {
        for (pij, &xj) in p_row.iter_mut().zip(x) {
            *pij = *pij + alpha * (xi * xj);
        }
    }
}

/// y ← y + α·x.
#[inline]
pub fn axpy<T: Scalar, const N: usize>(y: &mut [T; N], alpha: T, x: &[T; N]) {
    for (yi, &xi) in y.iter_mut().zip(x) {
        *yi = *yi + alpha * xi;
    }
}

/// The Joseph form of the update with one scalar measurement y = hᵀ·x + e,
/// var e = r, gain k: (I − k·hᵀ)·P·(I − k·hᵀ)ᵀ + r·k·kᵀ, symmetrised. It
/// is symmetric and positive semi-definite for any gain (not only the
/// optimal one), which keeps rounding from making P indefinite.
#[inline]
pub fn joseph_update<T: Scalar, const N: usize>(
    p: &Matrix<T, N>,
    k: &[T; N],
    h: &[T; N],
    r: T,
) -> Matrix<T, N> {
    let mut a = identity::<T, N>();
    for (a_row, &ki) in a.iter_mut().zip(k) {
        for (aij, &hj) in a_row.iter_mut().zip(h) {
            *aij = *aij - ki * hj;
        }
    }
    let mut out = sandwich(&a, p);
    rank1_update(&mut out, r, k);
    out
}

/// The lower Cholesky factor L of A = L·Lᵀ (only the lower triangle of A is
/// read), or `None` when a pivot is not positive and finite: A is then not
/// numerically positive definite (or holds a NaN/∞). The caller decides how
/// to repair; nothing is hidden.
pub fn cholesky<T: Scalar, const N: usize>(a: &Matrix<T, N>) -> Option<Matrix<T, N>> {
    let mut l = [[T::ZERO; N]; N];
    for (i, a_row) in a.iter().enumerate() {
        let mut row = [T::ZERO; N];
        for (j, &a_ij) in a_row.iter().enumerate().take(i + 1) {
            if j == i {
                let s = a_ij - dot_prefix(&row, &row, j);
                // not positive, or NaN/∞
                if s <= T::ZERO || !s.finite() {
                    return None;
                }
                *row.get_mut(j)? = Real::sqrt(s);
            } else {
                let lj = l.get(j)?;
                let s = a_ij - dot_prefix(&row, lj, j);
                let d = *lj.get(j)?;
                *row.get_mut(j)? = s / d;
            }
        }
        *l.get_mut(i)? = row;
    }
    Some(l)
}

/// The 2N + 1 (= M) sigma points of the unscented transform: the mean, then
/// mean + γ·(column j of L) for j = 0..N, then mean − γ·(column j of L).
/// Points beyond 2N + 1 (if M is larger) are the mean.
#[inline]
pub fn sigma_points<T: Scalar, const N: usize, const M: usize>(
    mean: &[T; N],
    l: &Matrix<T, N>,
    gamma: T,
) -> [[T; N]; M] {
    let mut pts = [*mean; M];
    let lt = transpose(l);
    for (j, col) in lt.iter().enumerate() {
        if let Some(p) = pts.get_mut(1 + j) {
            axpy(p, gamma, col);
        }
        if let Some(p) = pts.get_mut(1 + N + j) {
            axpy(p, -gamma, col);
        }
    }
    pts
}

/// Σ wᵢ·χᵢ with weight `w0` for the first point and `wi` for the others.
#[inline]
pub fn weighted_mean<T: Scalar, const N: usize, const M: usize>(
    points: &[[T; N]; M],
    w0: T,
    wi: T,
) -> [T; N] {
    let mut m = [T::ZERO; N];
    for (k, p) in points.iter().enumerate() {
        let w = if k == 0 { w0 } else { wi };
        axpy(&mut m, w, p);
    }
    m
}

/// Σ wᵢ·(χᵢ − m)·(χᵢ − m)ᵀ (`w0` for the first point, `wi` for the others),
/// exactly symmetric.
#[inline]
pub fn weighted_covariance<T: Scalar, const N: usize, const M: usize>(
    points: &[[T; N]; M],
    mean: &[T; N],
    w0: T,
    wi: T,
) -> Matrix<T, N> {
    let mut c = [[T::ZERO; N]; N];
    for (k, p) in points.iter().enumerate() {
        let w = if k == 0 { w0 } else { wi };
        let mut d = *p;
        axpy(&mut d, -T::ONE, mean);
        rank1_update(&mut c, w, &d);
    }
    c
}

/// Σ wᵢ·(χᵢ − m)·(yᵢ − ȳ) for scalar outputs yᵢ (the cross covariance of
/// the state with one measurement).
#[inline]
pub fn weighted_cross<T: Scalar, const N: usize, const M: usize>(
    points: &[[T; N]; M],
    mean: &[T; N],
    ys: &[T; M],
    y_mean: T,
    w0: T,
    wi: T,
) -> [T; N] {
    let mut c = [T::ZERO; N];
    for (k, (p, &y)) in points.iter().zip(ys).enumerate() {
        let w = if k == 0 { w0 } else { wi };
        let dy = w * (y - y_mean);
        for ((ci, &pi), &mi) in c.iter_mut().zip(p).zip(mean) {
            *ci = *ci + (pi - mi) * dy;
        }
    }
    c
}

/// Whether every entry is finite.
#[inline]
pub fn all_finite<T: Scalar, const N: usize>(x: &[T; N]) -> bool {
    x.iter().all(|&v| v.finite())
}

/// Whether every entry is finite.
#[inline]
pub fn all_finite_matrix<T: Scalar, const N: usize>(a: &Matrix<T, N>) -> bool {
    a.iter().all(all_finite)
}

/// x with A·x = b for a symmetric positive definite A, by [`cholesky`] and
/// two triangular solves; `None` where A does not factor.
pub fn cholesky_solve<T: Scalar, const N: usize>(a: &Matrix<T, N>, b: &[T; N]) -> Option<[T; N]> {
    let l = cholesky(a)?;
    // L·y = b
    let mut y = [T::ZERO; N];
    for (i, (l_row, bi)) in l.iter().zip(b).enumerate() {
        let s = *bi - dot_prefix(l_row, &y, i);
        *y.get_mut(i)? = s / *l_row.get(i)?;
    }
    // Lᵀ·x = y
    let mut x = [T::ZERO; N];
    for i in (0..N).rev() {
        let mut s = *y.get(i)?;
        for (k, xk) in x.iter().enumerate().skip(i + 1) {
            s = s - *l.get(k)?.get(i)? * *xk;
        }
        *x.get_mut(i)? = s / *l.get(i)?.get(i)?;
    }
    Some(x)
}
