//! `reldesign_runtime::linalg` against straightforward std f64 computations
//! (index loops over `Vec`s), on random matrices of sizes 1 to 5, f64 and
//! f32: products, symmetric updates, the Joseph form, Cholesky (and its
//! failures), the unscented transform's helpers.

// the reference computations are plain index loops on purpose
#![allow(clippy::needless_range_loop)]

use reldesign_runtime::linalg::{self, Matrix};

/// SplitMix64, uniform in [−1, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn matrix<const N: usize>(&mut self) -> Matrix<f64, N> {
        std::array::from_fn(|_| std::array::from_fn(|_| self.next()))
    }

    fn vector<const N: usize>(&mut self) -> [f64; N] {
        std::array::from_fn(|_| self.next())
    }

    /// B·Bᵀ + 0.1·I, with rows of very different scales (like z, φ, H_c).
    fn spd<const N: usize>(&mut self) -> Matrix<f64, N> {
        let b: Matrix<f64, N> = self.matrix();
        let scale: [f64; N] = std::array::from_fn(|i| 10f64.powi(3 * i as i32 - 4));
        let mut a = naive_mul(&b, &naive_transpose(&b));
        for (i, row) in a.iter_mut().enumerate() {
            row[i] += 0.1;
        }
        for i in 0..N {
            for j in 0..N {
                a[i][j] *= scale[i] * scale[j];
            }
        }
        a
    }
}

fn naive_mul<const N: usize>(a: &Matrix<f64, N>, b: &Matrix<f64, N>) -> Matrix<f64, N> {
    let mut c = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            for k in 0..N {
                c[i][j] += a[i][k] * b[k][j];
            }
        }
    }
    c
}

fn naive_transpose<const N: usize>(a: &Matrix<f64, N>) -> Matrix<f64, N> {
    let mut t = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            t[j][i] = a[i][j];
        }
    }
    t
}

/// max |a − b| over max |b| (entries), i.e. error relative to the matrix's size.
fn rel_err<const N: usize>(a: &Matrix<f64, N>, b: &Matrix<f64, N>) -> f64 {
    let mut err: f64 = 0.0;
    let mut size: f64 = 0.0;
    for i in 0..N {
        for j in 0..N {
            err = err.max((a[i][j] - b[i][j]).abs());
            size = size.max(b[i][j].abs());
        }
    }
    err / size.max(f64::MIN_POSITIVE)
}

fn symmetric<T: PartialEq + Copy, const N: usize>(a: &Matrix<T, N>) -> bool {
    (0..N).all(|i| (0..N).all(|j| a[i][j] == a[j][i]))
}

fn check_size<const N: usize>(rng: &mut Rng) {
    let (a, b): (Matrix<f64, N>, Matrix<f64, N>) = (rng.matrix(), rng.matrix());
    let (x, y): ([f64; N], [f64; N]) = (rng.vector(), rng.vector());
    let tol = 1e-14;

    // products
    let naive_dot: f64 = (0..N).map(|i| x[i] * y[i]).sum();
    assert!((linalg::dot(&x, &y) - naive_dot).abs() <= tol * N as f64);
    let ax = linalg::mat_vec(&a, &x);
    for i in 0..N {
        let want: f64 = (0..N).map(|k| a[i][k] * x[k]).sum();
        assert!((ax[i] - want).abs() <= tol * N as f64);
    }
    assert_eq!(linalg::transpose(&a), naive_transpose(&a));
    assert!(rel_err(&linalg::mat_mul(&a, &b), &naive_mul(&a, &b)) <= tol);
    assert!(
        rel_err(
            &linalg::mul_transpose(&a, &b),
            &naive_mul(&a, &naive_transpose(&b))
        ) <= tol
    );
    assert_eq!(linalg::identity::<f64, N>(), {
        let mut i = [[0.0; N]; N];
        for (k, row) in i.iter_mut().enumerate() {
            row[k] = 1.0;
        }
        i
    });
    let d = linalg::diagonal(&x);
    assert_eq!(linalg::diag_of(&d), x);
    assert!(
        rel_err(&linalg::add(&a, &b), &{
            let mut c = a;
            for i in 0..N {
                for j in 0..N {
                    c[i][j] += b[i][j];
                }
            }
            c
        }) == 0.0
    );

    // symmetric updates
    let p = rng.spd::<N>();
    let s = linalg::sandwich(&a, &p);
    assert!(symmetric(&s));
    assert!(rel_err(&s, &naive_mul(&naive_mul(&a, &p), &naive_transpose(&a))) <= 1e-13);
    let want_quad: f64 = (0..N)
        .map(|i| (0..N).map(|j| x[i] * p[i][j] * x[j]).sum::<f64>())
        .sum();
    assert!((linalg::quad_form(&p, &x) - want_quad).abs() <= 1e-13 * want_quad.abs().max(1e-300));
    let mut r = p;
    linalg::rank1_update(&mut r, -0.3, &x);
    assert!(symmetric(&r));
    for i in 0..N {
        for j in 0..N {
            assert!((r[i][j] - (p[i][j] - 0.3 * x[i] * x[j])).abs() <= tol * (1.0 + p[i][j].abs()));
        }
    }
    let mut asym = a;
    linalg::symmetrize(&mut asym);
    assert!(symmetric(&asym));
    for i in 0..N {
        for j in 0..N {
            assert!((asym[i][j] - 0.5 * (a[i][j] + a[j][i])).abs() <= tol);
        }
    }
    let mut yy = y;
    linalg::axpy(&mut yy, 2.5, &x);
    for i in 0..N {
        assert!((yy[i] - (y[i] + 2.5 * x[i])).abs() <= tol);
    }

    // Joseph form: (I − k hᵀ) P (I − k hᵀ)ᵀ + r k kᵀ, and with the optimal gain
    // k = P h / (hᵀ P h + r) it equals P − k·S·kᵀ
    let h = x;
    let r_var = 0.7 * want_quad.abs() + 1e-6;
    let sv = linalg::quad_form(&p, &h) + r_var;
    let k = linalg::mat_vec(&p, &h).map(|v| v / sv);
    let j = linalg::joseph_update(&p, &k, &h, r_var);
    assert!(symmetric(&j));
    let mut a_mat = [[0.0; N]; N];
    for i in 0..N {
        for jj in 0..N {
            a_mat[i][jj] = f64::from(u8::from(i == jj)) - k[i] * h[jj];
        }
    }
    let mut want = naive_mul(&naive_mul(&a_mat, &p), &naive_transpose(&a_mat));
    for i in 0..N {
        for jj in 0..N {
            want[i][jj] += r_var * k[i] * k[jj];
        }
    }
    assert!(rel_err(&j, &want) <= 1e-12);
    let mut short = p;
    for i in 0..N {
        for jj in 0..N {
            short[i][jj] -= sv * k[i] * k[jj];
        }
    }
    assert!(rel_err(&j, &short) <= 1e-10, "{}", rel_err(&j, &short));

    // Cholesky: L lower, positive diagonal, L·Lᵀ = A
    let l = linalg::cholesky(&p).expect("B·Bᵀ + 0.1·I is positive definite");
    for i in 0..N {
        assert!(l[i][i] > 0.0);
        for jj in i + 1..N {
            assert_eq!(l[i][jj], 0.0);
        }
    }
    assert!(rel_err(&naive_mul(&l, &naive_transpose(&l)), &p) <= 1e-13);
    // only the lower triangle is read
    let mut upper_garbage = p;
    for i in 0..N {
        for jj in i + 1..N {
            upper_garbage[i][jj] = f64::NAN;
        }
    }
    assert_eq!(linalg::cholesky(&upper_garbage), Some(l));
    // failures are reported
    let mut indefinite = p;
    indefinite[N - 1][N - 1] = -1.0;
    assert_eq!(linalg::cholesky(&indefinite), None);
    assert_eq!(linalg::cholesky(&[[0.0; N]; N]), None);
    let mut nan = p;
    nan[N / 2][0] = f64::NAN;
    assert_eq!(linalg::cholesky(&nan), None);
    let mut inf = p;
    inf[0][0] = f64::INFINITY;
    assert_eq!(linalg::cholesky(&inf), None);
    assert!(linalg::all_finite_matrix(&p) && !linalg::all_finite_matrix(&nan));
    assert!(linalg::all_finite(&x) && !linalg::all_finite(&[f64::NAN; N]));
}

/// The unscented transform of the identity reproduces mean and covariance:
/// Σ Wᵢ χᵢ = x̄ and Σ Wᵢ (χᵢ − x̄)(χᵢ − x̄)ᵀ = P when 2·W·γ² = 1.
fn check_unscented<const N: usize, const M: usize>(rng: &mut Rng) {
    assert_eq!(M, 2 * N + 1);
    let mean: [f64; N] = rng.vector();
    let p = rng.spd::<N>();
    let l = linalg::cholesky(&p).unwrap();
    for (alpha, kappa, beta) in [(1.0, 0.0, 2.0), (0.5, 1.0, 2.0), (1.0, 3.0 - N as f64, 0.0)] {
        let n = N as f64;
        let lambda: f64 = alpha * alpha * (n + kappa) - n;
        let gamma = (n + lambda).sqrt();
        let (w0, wc0, w) = (
            lambda / (n + lambda),
            lambda / (n + lambda) + 1.0 - alpha * alpha + beta,
            0.5 / (n + lambda),
        );
        let pts: [[f64; N]; M] = linalg::sigma_points(&mean, &l, gamma);
        assert_eq!(pts[0], mean);
        for j in 0..N {
            for i in 0..N {
                assert!(
                    (pts[1 + j][i] - (mean[i] + gamma * l[i][j])).abs()
                        <= 1e-15 * (1.0 + mean[i].abs())
                );
                assert!(
                    (pts[1 + N + j][i] - (mean[i] - gamma * l[i][j])).abs()
                        <= 1e-15 * (1.0 + mean[i].abs())
                );
            }
        }
        let m = linalg::weighted_mean(&pts, w0, w);
        for i in 0..N {
            // the points lie ±γ·σᵢ around x̄ (σ up to 10⁵ here)
            let spread = mean[i].abs() + 10.0 * p[i][i].sqrt();
            assert!((m[i] - mean[i]).abs() <= 1e-14 * spread);
        }
        // W₀ᶜ multiplies a zero deviation: P is reproduced for any β (χ − x̄
        // cancels up to |x̄|/σ ≈ 10⁴ of the digits: the smallest σ is 10⁻⁴)
        let c = linalg::weighted_covariance(&pts, &mean, wc0, w);
        assert!(symmetric(&c));
        assert!(rel_err(&c, &p) <= 1e-10, "{}", rel_err(&c, &p));
        // cross covariance with y = aᵀχ: P·a (the same cancellation)
        let a: [f64; N] = rng.vector();
        let ys: [f64; M] = std::array::from_fn(|k| linalg::dot(&a, &pts[k]));
        let y_mean = linalg::dot(&a, &mean);
        let cross = linalg::weighted_cross(&pts, &mean, &ys, y_mean, wc0, w);
        let pa = linalg::mat_vec(&p, &a);
        let size = pa.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        for i in 0..N {
            assert!(
                (cross[i] - pa[i]).abs() <= 1e-10 * size,
                "{i}: {} vs {} (size {size})",
                cross[i],
                pa[i]
            );
        }
    }
}

#[test]
fn matches_the_naive_computations_for_sizes_1_to_5() {
    let mut rng = Rng(0xA11CE);
    for _ in 0..50 {
        check_size::<1>(&mut rng);
        check_size::<2>(&mut rng);
        check_size::<3>(&mut rng);
        check_size::<4>(&mut rng);
        check_size::<5>(&mut rng);
    }
}

#[test]
fn unscented_transform_reproduces_mean_and_covariance() {
    let mut rng = Rng(0xB0B);
    for _ in 0..20 {
        check_unscented::<1, 3>(&mut rng);
        check_unscented::<3, 7>(&mut rng);
        check_unscented::<4, 9>(&mut rng);
    }
}

#[test]
fn works_in_f32() {
    let mut rng = Rng(0xF32);
    let p64 = rng.spd::<4>();
    let p: Matrix<f32, 4> = p64.map(|r| r.map(|v| v as f32));
    let l = linalg::cholesky(&p).expect("positive definite in f32 too");
    let ll = linalg::mul_transpose(&l, &l);
    for i in 0..4 {
        for j in 0..4 {
            let scale = (p[i][i] * p[j][j]).sqrt();
            assert!((ll[i][j] - p[i][j]).abs() <= 1e-5 * scale, "{i} {j}");
        }
    }
    let k = [0.1f32, -0.2, 0.3, 0.05];
    let h = [1.0f32, 2.0, -1.0, 0.5];
    let j = linalg::joseph_update(&p, &k, &h, 0.25);
    assert!(symmetric(&j) && linalg::all_finite_matrix(&j));
    let mut bad = p;
    bad[3][3] = f32::NAN;
    assert_eq!(linalg::cholesky(&bad), None);
    let pts: [[f32; 4]; 9] = linalg::sigma_points(&[0.0; 4], &l, 2.0);
    let c = linalg::weighted_covariance(&pts, &[0.0; 4], 0.0, 0.125);
    for i in 0..4 {
        for j in 0..4 {
            let scale = (p[i][i] * p[j][j]).sqrt();
            assert!((c[i][j] - p[i][j]).abs() <= 1e-5 * scale);
        }
    }
}
