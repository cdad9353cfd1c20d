//! Accuracy of the f64 natural logarithm (`Real::ln`, runtime/src/ln.rs) against
//! two independent oracles: std's `f64::ln` (glibc's `log` on Linux, ≤ 0.52 ulp)
//! and correctly rounded values computed with mpmath (`CORRECTLY_ROUNDED` below).
//! Run with `--nocapture` to see the max error of each input set.

use reldesign_runtime::math::Real;

fn ln(x: f64) -> f64 {
    <f64 as Real>::ln(x)
}

/// Position of `x` on the line of doubles (monotonic in x; −0 and +0 coincide).
fn ordinal(x: f64) -> i64 {
    let b = i64::from_ne_bytes(x.to_bits().to_ne_bytes());
    if b < 0 {
        i64::MIN - b
    } else {
        b
    }
}

/// Distance in ulps between two finite doubles.
fn ulps(a: f64, b: f64) -> u64 {
    assert!(a.is_finite() && b.is_finite(), "{a} vs {b}");
    ordinal(a).abs_diff(ordinal(b))
}

/// xorshift64 (deterministic).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Asserts `ln` is within 1 ulp of glibc's on every x of `xs` (positive, finite)
/// and prints the max distance and how many results differ from glibc's.
fn check_against_glibc(name: &str, xs: impl IntoIterator<Item = f64>) {
    let (mut worst, mut worst_x, mut differ, mut n) = (0, 0.0, 0, 0);
    for x in xs {
        assert!(x > 0.0 && x.is_finite(), "{name}: bad input {x:e}");
        let d = ulps(ln(x), x.ln());
        if d > worst {
            (worst, worst_x) = (d, x);
        }
        differ += usize::from(d != 0);
        n += 1;
    }
    eprintln!(
        "{name:<36} {n:>9} points: max {worst} ulp vs glibc (at {worst_x:e}), {differ} differ"
    );
    assert!(
        worst <= 1,
        "{name}: {worst} ulp at x = {worst_x:e} ({:#x})",
        worst_x.to_bits()
    );
}

#[test]
fn random_bits_over_the_whole_positive_range() {
    // Uniform bit patterns of positive finite doubles: every exponent, subnormals too.
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let xs = core::iter::from_fn(|| loop {
        let x = f64::from_bits(rng.next() >> 1);
        if x.is_finite() && x > 0.0 {
            return Some(x);
        }
    });
    check_against_glibc("random bits, all exponents", xs.take(2_000_000));
}

#[test]
fn random_in_the_controllers_range_and_around_one() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let n = 1_000_000;
    // [30, 3e7], log-uniform: the arguments of the generated control law.
    let xs: Vec<f64> = (0..n).map(|_| 30.0 * 1e6f64.powf(rng.unit())).collect();
    check_against_glibc("log-uniform [30, 3e7]", xs);
    // [0.25, 4]: k ∈ {−2, −1, 0, 1}, where |log x| is smallest on the table path.
    let xs: Vec<f64> = (0..n).map(|_| 0.25 * 16f64.powf(rng.unit())).collect();
    check_against_glibc("log-uniform [0.25, 4]", xs);
}

#[test]
fn dense_around_one_and_the_fallback_boundaries() {
    let one = 1f64.to_bits();
    // ±200 000 ulps of 1 (all on the fallback side).
    let xs = (one - 200_000..one + 200_000)
        .map(f64::from_bits)
        .filter(|&x| x != 1.0);
    check_against_glibc("1 ± 200k ulps", xs);
    // [0.875, 1.125] in 400 000 steps: both sides of both fallback boundaries.
    let xs = (0..=400_000).map(|j| 0.875 + 0.25 * f64::from(j) / 400_000.0);
    check_against_glibc("[0.875, 1.125] sweep", xs.filter(|&x| x != 1.0));
    // ±20 000 ulps of each fallback boundary, 1 − 2^-4 and 1 + 0x1.09p-4.
    for b in [0x3fee_0000_0000_0000u64, 0x3ff1_0900_0000_0000] {
        let xs = (b - 20_000..b + 20_000).map(f64::from_bits);
        check_against_glibc("fallback boundary ± 20k ulps", xs);
    }
}

#[test]
fn around_every_table_boundary_at_every_exponent() {
    // The subinterval boundaries: bits OFF + i·2^45 + k·2^52, ± 3 ulps.
    const OFF: u64 = 0x3fe6_0000_0000_0000;
    let mut xs = Vec::new();
    for k in -1021i64..=1022 {
        for i in 0..128u64 {
            let b = (OFF + (i << 45)).wrapping_add_signed(k << 52);
            xs.extend((b - 3..=b + 3).map(f64::from_bits));
        }
    }
    check_against_glibc("table boundaries ± 3 ulps, all k", xs);
}

#[test]
fn powers_of_two_and_their_neighbours() {
    // 2^-1074 ..= 2^1023 (subnormal ones: a single mantissa bit).
    let powers: Vec<u64> = (0..52)
        .map(|s| 1u64 << s)
        .chain((1..2047).map(|e| e << 52))
        .collect();
    check_against_glibc("powers of two", powers.iter().map(|&b| f64::from_bits(b)));
    let neighbours = powers
        .iter()
        .flat_map(|&b| [b - 1, b + 1])
        .map(f64::from_bits);
    check_against_glibc(
        "powers of two ± 1 ulp",
        neighbours.filter(|x| x.is_finite() && *x > 0.0),
    );
}

#[test]
fn special_values_are_exact() {
    assert_eq!(ln(1.0).to_bits(), 0f64.to_bits(), "ln 1 = +0");
    assert_eq!(ln(0.0), f64::NEG_INFINITY);
    assert_eq!(ln(-0.0), f64::NEG_INFINITY);
    assert_eq!(ln(f64::INFINITY), f64::INFINITY);
    assert!(ln(f64::NEG_INFINITY).is_nan());
    assert!(ln(f64::NAN).is_nan());
    assert!(ln(-f64::NAN).is_nan());
    for x in [-1.0, -f64::MIN_POSITIVE, -5e-324, -f64::MAX, -3.0e7] {
        assert!(ln(x).is_nan(), "ln({x:e}) must be NaN");
    }
    assert_eq!(ln(2.0), core::f64::consts::LN_2);
    assert_eq!(ln(10.0), core::f64::consts::LN_10);
    assert_eq!(ln(core::f64::consts::E), 1.0);
    // Extremes: correctly rounded values (mpmath).
    assert_eq!(ln(5e-324), -744.4400719213812);
    assert_eq!(ln(f64::MIN_POSITIVE), -708.3964185322641);
    assert_eq!(ln(f64::MAX), 709.782712893384);
}

#[test]
fn correctly_rounded_values() {
    // Within 1 ulp of the correctly rounded result (≤ 0.53 ulp of the exact value
    // implies it); prints how many are not correctly rounded.
    let (mut worst, mut not_cr) = (0, 0);
    for &(xb, yb) in CORRECTLY_ROUNDED.iter() {
        let (x, want) = (f64::from_bits(xb), f64::from_bits(yb));
        let got = ln(x);
        let d = ulps(got, want);
        assert!(
            d <= 1,
            "ln({x:e}) = {got:e}, correctly rounded {want:e}: {d} ulp"
        );
        worst = worst.max(d);
        not_cr += usize::from(d != 0);
    }
    let n = CORRECTLY_ROUNDED.len();
    eprintln!(
        "{:<36} {n:>9} points: max {worst} ulp vs correctly rounded, {not_cr} not correctly rounded",
        "mpmath (ln_table.py --test-data)",
    );
}

// BEGIN GENERATED TEST DATA (runtime/tools/ln_table.py --test-data)
// Generated by runtime/tools/ln_table.py --test-data (mpmath, correctly rounded).
const CORRECTLY_ROUNDED: [(u64, u64); 588] = [
    (0x3fed_ffff_ffff_fff8, 0xbfb0_8598_b59e_3a4b),
    (0x3fed_ffff_ffff_fff9, 0xbfb0_8598_b59e_3a42),
    (0x3fed_ffff_ffff_fffa, 0xbfb0_8598_b59e_3a3a),
    (0x3fed_ffff_ffff_fffb, 0xbfb0_8598_b59e_3a31),
    (0x3fed_ffff_ffff_fffc, 0xbfb0_8598_b59e_3a29),
    (0x3fed_ffff_ffff_fffd, 0xbfb0_8598_b59e_3a20),
    (0x3fed_ffff_ffff_fffe, 0xbfb0_8598_b59e_3a18),
    (0x3fed_ffff_ffff_ffff, 0xbfb0_8598_b59e_3a0f),
    (0x3fee_0000_0000_0000, 0xbfb0_8598_b59e_3a07),
    (0x3fee_0000_0000_0001, 0xbfb0_8598_b59e_39fe),
    (0x3fee_0000_0000_0002, 0xbfb0_8598_b59e_39f5),
    (0x3fee_0000_0000_0003, 0xbfb0_8598_b59e_39ed),
    (0x3fee_0000_0000_0004, 0xbfb0_8598_b59e_39e4),
    (0x3fee_0000_0000_0005, 0xbfb0_8598_b59e_39dc),
    (0x3fee_0000_0000_0006, 0xbfb0_8598_b59e_39d3),
    (0x3fee_0000_0000_0007, 0xbfb0_8598_b59e_39cb),
    (0x3fee_0000_0000_0008, 0xbfb0_8598_b59e_39c2),
    (0x3ff1_08ff_ffff_fff8, 0x3fb0_0c7c_1418_4e4c),
    (0x3ff1_08ff_ffff_fff9, 0x3fb0_0c7c_1418_4e5b),
    (0x3ff1_08ff_ffff_fffa, 0x3fb0_0c7c_1418_4e6b),
    (0x3ff1_08ff_ffff_fffb, 0x3fb0_0c7c_1418_4e7a),
    (0x3ff1_08ff_ffff_fffc, 0x3fb0_0c7c_1418_4e89),
    (0x3ff1_08ff_ffff_fffd, 0x3fb0_0c7c_1418_4e98),
    (0x3ff1_08ff_ffff_fffe, 0x3fb0_0c7c_1418_4ea7),
    (0x3ff1_08ff_ffff_ffff, 0x3fb0_0c7c_1418_4eb6),
    (0x3ff1_0900_0000_0000, 0x3fb0_0c7c_1418_4ec5),
    (0x3ff1_0900_0000_0001, 0x3fb0_0c7c_1418_4ed4),
    (0x3ff1_0900_0000_0002, 0x3fb0_0c7c_1418_4ee3),
    (0x3ff1_0900_0000_0003, 0x3fb0_0c7c_1418_4ef2),
    (0x3ff1_0900_0000_0004, 0x3fb0_0c7c_1418_4f01),
    (0x3ff1_0900_0000_0005, 0x3fb0_0c7c_1418_4f10),
    (0x3ff1_0900_0000_0006, 0x3fb0_0c7c_1418_4f1f),
    (0x3ff1_0900_0000_0007, 0x3fb0_0c7c_1418_4f2e),
    (0x3ff1_0900_0000_0008, 0x3fb0_0c7c_1418_4f3d),
    (0x3fd5_ffff_ffff_ffff, 0xbff1_15e0_0e73_223f),
    (0x3fd6_0000_0000_0000, 0xbff1_15e0_0e73_223f),
    (0x3fd6_1000_0000_0000, 0xbff1_0a41_5eea_377b),
    (0x3fe5_ffff_ffff_ffff, 0xbfd7_fafa_3bd8_151f),
    (0x3fe6_0000_0000_0000, 0xbfd7_fafa_3bd8_151c),
    (0x3fe6_1000_0000_0000, 0xbfd7_cc7f_7db4_6a0e),
    (0x3ff5_ffff_ffff_ffff, 0x3fd4_618b_c21c_5ec0),
    (0x3ff6_0000_0000_0000, 0x3fd4_618b_c21c_5ec2),
    (0x3ff6_1000_0000_0000, 0x3fd4_9006_8040_09d1),
    (0x4055_ffff_ffff_ffff, 0x4011_e8ca_fb5d_715f),
    (0x4056_0000_0000_0000, 0x4011_e8ca_fb5d_7160),
    (0x4056_1000_0000_0000, 0x4011_ebb2_a73f_ac10),
    (0x3fd6_7fff_ffff_ffff, 0xbff0_b9d3_8f24_377d),
    (0x3fd6_8000_0000_0000, 0xbff0_b9d3_8f24_377d),
    (0x3fd6_9000_0000_0000, 0xbff0_ae76_e2d0_54fa),
    (0x3fe6_7fff_ffff_ffff, 0xbfd6_8ac8_3e9c_6a17),
    (0x3fe6_8000_0000_0000, 0xbfd6_8ac8_3e9c_6a14),
    (0x3fe6_9000_0000_0000, 0xbfd6_5d55_8d4c_e00b),
    (0x3ff6_7fff_ffff_ffff, 0x3fd5_d1bd_bf58_09c7),
    (0x3ff6_8000_0000_0000, 0x3fd5_d1bd_bf58_09ca),
    (0x3ff6_9000_0000_0000, 0x3fd5_ff30_70a7_93d4),
    (0x4056_7fff_ffff_ffff, 0x4011_ffce_1b31_2c10),
    (0x4056_8000_0000_0000, 0x4011_ffce_1b31_2c10),
    (0x4056_9000_0000_0000, 0x4012_02a5_4646_24b1),
    (0x3fd6_ffff_ffff_ffff, 0xbff0_5fcd_014b_45ee),
    (0x3fd7_0000_0000_0000, 0xbff0_5fcd_014b_45ee),
    (0x3fd7_1000_0000_0000, 0xbff0_54af_7a6b_c2fc),
    (0x3fe6_ffff_ffff_ffff, 0xbfd5_22ae_0738_a3db),
    (0x3fe7_0000_0000_0000, 0xbfd5_22ae_0738_a3d8),
    (0x3fe7_1000_0000_0000, 0xbfd4_f637_ebba_9810),
    (0x3ff6_ffff_ffff_ffff, 0x3fd7_39d7_f6bb_d004),
    (0x3ff7_0000_0000_0000, 0x3fd7_39d7_f6bb_d007),
    (0x3ff7_1000_0000_0000, 0x3fd7_664e_1239_dbcf),
    (0x4056_ffff_ffff_ffff, 0x4012_164f_bea7_6874),
    (0x4057_0000_0000_0000, 0x4012_164f_bea7_6874),
    (0x4057_1000_0000_0000, 0x4012_1917_205f_4930),
    (0x3fd7_7fff_ffff_ffff, 0xbff0_07b6_1d49_e959),
    (0x3fd7_8000_0000_0000, 0xbff0_07b6_1d49_e959),
    (0x3fd7_9000_0000_0000, 0xbfef_f9aa_19c8_1999),
    (0x3fe7_7fff_ffff_ffff, 0xbfd3_c252_7733_3186),
    (0x3fe7_8000_0000_0000, 0xbfd3_c252_7733_3184),
    (0x3fe7_9000_0000_0000, 0xbfd3_96ce_359b_bf54),
    (0x3ff7_7fff_ffff_ffff, 0x3fd8_9a33_86c1_4258),
    (0x3ff7_8000_0000_0000, 0x3fd8_9a33_86c1_425b),
    (0x3ff7_9000_0000_0000, 0x3fd8_c5b7_c858_b48b),
    (0x4057_7fff_ffff_ffff, 0x4012_2c55_77a7_bf99),
    (0x4057_8000_0000_0000, 0x4012_2c55_77a7_bf99),
    (0x4057_9000_0000_0000, 0x4012_2f0d_bbc1_36bc),
    (0x3fd7_ffff_ffff_ffff, 0xbfef_62f4_0794_a7ba),
    (0x3fd8_0000_0000_0000, 0xbfef_62f4_0794_a7b8),
    (0x3fd8_1000_0000_0000, 0xbfef_4da5_cb89_9714),
    (0x3fe7_ffff_ffff_ffff, 0xbfd2_6962_1134_db95),
    (0x3fe8_0000_0000_0000, 0xbfd2_6962_1134_db92),
    (0x3fe8_1000_0000_0000, 0xbfd2_3ec5_991e_ba49),
    (0x3ff7_ffff_ffff_ffff, 0x3fd9_f323_ecbf_9849),
    (0x3ff8_0000_0000_0000, 0x3fd9_f323_ecbf_984c),
    (0x3ff8_1000_0000_0000, 0x3fda_1dc0_64d5_b995),
    (0x4057_ffff_ffff_ffff, 0x4012_41e4_7e07_a4f8),
    (0x4058_0000_0000_0000, 0x4012_41e4_7e07_a4f8),
    (0x4058_1000_0000_0000, 0x4012_448e_4589_070d),
    (0x3fd8_7fff_ffff_ffff, 0xbfee_ba0a_400e_2c2e),
    (0x3fd8_8000_0000_0000, 0xbfee_ba0a_400e_2c2d),
    (0x3fd8_9000_0000_0000, 0xbfee_a52b_2f55_fa30),
    (0x3fe8_7fff_ffff_ffff, 0xbfd1_178e_8227_e47e),
    (0x3fe8_8000_0000_0000, 0xbfd1_178e_8227_e47c),
    (0x3fe8_9000_0000_0000, 0xbfd0_edd0_60b7_8081),
    (0x3ff8_7fff_ffff_ffff, 0x3fdb_44f7_7bcc_8f60),
    (0x3ff8_8000_0000_0000, 0x3fdb_44f7_7bcc_8f63),
    (0x3ff8_9000_0000_0000, 0x3fdb_6eb5_9d3c_f35e),
    (0x4058_7fff_ffff_ffff, 0x4012_5701_b6f8_7469),
    (0x4058_8000_0000_0000, 0x4012_5701_b6f8_746a),
    (0x4058_9000_0000_0000, 0x4012_599d_990f_7aa9),
    (0x3fd8_ffff_ffff_ffff, 0xbfee_148a_1a27_26cf),
    (0x3fd9_0000_0000_0000, 0xbfee_148a_1a27_26ce),
    (0x3fd9_1000_0000_0000, 0xbfee_0015_c3cd_b679),
    (0x3fe8_ffff_ffff_ffff, 0xbfcf_991c_6cb3_b37f),
    (0x3fe9_0000_0000_0000, 0xbfcf_991c_6cb3_b379),
    (0x3fe9_1000_0000_0000, 0xbfcf_474b_134d_f229),
    (0x3ff8_ffff_ffff_ffff, 0x3fdc_8ff7_c79a_9a1f),
    (0x3ff9_0000_0000_0000, 0x3fdc_8ff7_c79a_9a22),
    (0x3ff9_1000_0000_0000, 0x3fdc_b8e0_744d_7aca),
    (0x4058_ffff_ffff_ffff, 0x4012_6bb1_bbb5_5515),
    (0x4059_0000_0000_0000, 0x4012_6bb1_bbb5_5516),
    (0x4059_1000_0000_0000, 0x4012_6e40_4680_8320),
    (0x3fd9_7fff_ffff_ffff, 0xbfed_7250_fb93_918f),
    (0x3fd9_8000_0000_0000, 0xbfed_7250_fb93_918e),
    (0x3fd9_9000_0000_0000, 0xbfed_5e43_3171_0904),
    (0x3fe9_7fff_ffff_ffff, 0xbfcd_1037_f265_5e80),
    (0x3fe9_8000_0000_0000, 0xbfcd_1037_f265_5e7b),
    (0x3fe9_9000_0000_0000, 0xbfcc_c000_c9db_3c52),
    (0x3ff9_7fff_ffff_ffff, 0x3fdd_d46a_04c1_c49e),
    (0x3ff9_8000_0000_0000, 0x3fdd_d46a_04c1_c4a1),
    (0x3ff9_9000_0000_0000, 0x3fdd_fc85_9906_d5b5),
    (0x4059_7fff_ffff_ffff, 0x4012_7ff8_df87_c7bd),
    (0x4059_8000_0000_0000, 0x4012_7ff8_df87_c7bd),
    (0x4059_9000_0000_0000, 0x4012_827a_98cc_18cf),
    (0x3fd9_ffff_ffff_ffff, 0xbfec_d33e_4e1c_f069),
    (0x3fda_0000_0000_0000, 0xbfec_d33e_4e1c_f068),
    (0x3fda_1000_0000_0000, 0xbfec_bf93_1fb3_e4b1),
    (0x3fe9_ffff_ffff_ffff, 0xbfca_93ed_3c8a_d9e8),
    (0x3fea_0000_0000_0000, 0xbfca_93ed_3c8a_d9e3),
    (0x3fea_1000_0000_0000, 0xbfca_4540_82e6_ab05),
    (0x3ff9_ffff_ffff_ffff, 0x3fdf_128f_5faf_06ea),
    (0x3ffa_0000_0000_0000, 0x3fdf_128f_5faf_06ed),
    (0x3ffa_1000_0000_0000, 0x3fdf_39e5_bc81_1e5c),
    (0x4059_ffff_ffff_ffff, 0x4012_93db_3536_9be2),
    (0x405a_0000_0000_0000, 0x4012_93db_3536_9be2),
    (0x405a_1000_0000_0000, 0x4012_9650_9b03_bd59),
    (0x3fda_7fff_ffff_ffff, 0xbfec_3733_584e_a2e1),
    (0x3fda_8000_0000_0000, 0xbfec_3733_584e_a2e0),
    (0x3fda_9000_0000_0000, 0xbfec_23e7_0e26_10a3),
    (0x3fea_7fff_ffff_ffff, 0xbfc8_23c1_6551_a3c7),
    (0x3fea_8000_0000_0000, 0xbfc8_23c1_6551_a3c2),
    (0x3fea_9000_0000_0000, 0xbfc7_d690_3caf_5ad0),
    (0x3ffa_7fff_ffff_ffff, 0x3fe0_2552_a5a5_d0fe),
    (0x3ffa_8000_0000_0000, 0x3fe0_2552_a5a5_d0ff),
    (0x3ffa_9000_0000_0000, 0x3fe0_389e_efce_633b),
    (0x405a_7fff_ffff_ffff, 0x4012_a75c_93f0_6593),
    (0x405a_8000_0000_0000, 0x4012_a75c_93f0_6593),
    (0x405a_9000_0000_0000, 0x4012_a9c6_1d35_77db),
    (0x3fda_ffff_ffff_ffff, 0xbfeb_9e13_19cf_495d),
    (0x3fdb_0000_0000_0000, 0xbfeb_9e13_19cf_495c),
    (0x3fdb_1000_0000_0000, 0xbfeb_8b22_313a_9d27),
    (0x3fea_ffff_ffff_ffff, 0xbfc5_bf40_6b54_3db7),
    (0x3feb_0000_0000_0000, 0xbfc5_bf40_6b54_3db2),
    (0x3feb_1000_0000_0000, 0xbfc5_737c_c901_8cdd),
    (0x3ffa_ffff_ffff_ffff, 0x3fe0_be72_e425_2a82),
    (0x3ffb_0000_0000_0000, 0x3fe0_be72_e425_2a83),
    (0x3ffb_1000_0000_0000, 0x3fe0_d163_ccb9_d6b8),
    (0x405a_ffff_ffff_ffff, 0x4012_ba80_9bc0_50c4),
    (0x405b_0000_0000_0000, 0x4012_ba80_9bc0_50c4),
    (0x405b_1000_0000_0000, 0x4012_bcde_b8d2_e64a),
    (0x3fdb_7fff_ffff_ffff, 0xbfeb_07c2_2aff_9df6),
    (0x3fdb_8000_0000_0000, 0xbfeb_07c2_2aff_9df5),
    (0x3fdb_9000_0000_0000, 0xbfea_f529_5248_cdd0),
    (0x3feb_7fff_ffff_ffff, 0xbfc3_65fc_b015_901b),
    (0x3feb_8000_0000_0000, 0xbfc3_65fc_b015_9016),
    (0x3feb_9000_0000_0000, 0xbfc3_1b99_4d3a_4f85),
    (0x3ffb_7fff_ffff_ffff, 0x3fe1_54c3_d2f4_d5e8),
    (0x3ffb_8000_0000_0000, 0x3fe1_54c3_d2f4_d5ea),
    (0x3ffb_9000_0000_0000, 0x3fe1_675c_abab_a60e),
    (0x405b_7fff_ffff_ffff, 0x4012_cd4a_b99a_4630),
    (0x405b_8000_0000_0000, 0x4012_cd4a_b99a_4631),
    (0x405b_9000_0000_0000, 0x4012_cf9d_d4b1_2035),
    (0x3fdb_ffff_ffff_ffff, 0xbfea_7426_9f84_330f),
    (0x3fdc_0000_0000_0000, 0xbfea_7426_9f84_330e),
    (0x3fdc_1000_0000_0000, 0xbfea_61e2_b26d_6a92),
    (0x3feb_ffff_ffff_ffff, 0xbfc1_178e_8227_e480),
    (0x3fec_0000_0000_0000, 0xbfc1_178e_8227_e47c),
    (0x3fec_1000_0000_0000, 0xbfc0_ce7e_cdcc_c28d),
    (0x3ffb_ffff_ffff_ffff, 0x3fe1_e85f_5e70_40cf),
    (0x3ffc_0000_0000_0000, 0x3fe1_e85f_5e70_40d0),
    (0x3ffc_1000_0000_0000, 0x3fe1_faa3_4b87_094c),
    (0x405b_ffff_ffff_ffff, 0x4012_dfbe_2b09_b38d),
    (0x405c_0000_0000_0000, 0x4012_dfbe_2b09_b38d),
    (0x405c_1000_0000_0000, 0x4012_e206_a8ac_8c9d),
    (0x3fdc_7fff_ffff_ffff, 0xbfe9_e327_eb6a_c2c5),
    (0x3fdc_8000_0000_0000, 0xbfe9_e327_eb6a_c2c3),
    (0x3fdc_9000_0000_0000, 0xbfe9_d135_effe_6c5c),
    (0x3fec_7fff_ffff_ffff, 0xbfbd_a727_6384_46ab),
    (0x3fec_8000_0000_0000, 0xbfbd_a727_6384_46a2),
    (0x3fec_9000_0000_0000, 0xbfbd_1797_8821_9364),
    (0x3ffc_7fff_ffff_ffff, 0x3fe2_795e_1289_b11a),
    (0x3ffc_8000_0000_0000, 0x3fe2_795e_1289_b11b),
    (0x3ffc_9000_0000_0000, 0x3fe2_8b50_0df6_0783),
    (0x405c_7fff_ffff_ffff, 0x4012_f1de_018c_e197),
    (0x405c_8000_0000_0000, 0x4012_f1de_018c_e197),
    (0x405c_9000_0000_0000, 0x4012_f41c_40fa_6c64),
    (0x3fdc_ffff_ffff_ffff, 0xbfe9_54ae_caa5_6321),
    (0x3fdd_0000_0000_0000, 0xbfe9_54ae_caa5_6320),
    (0x3fdd_1000_0000_0000, 0xbfe9_430b_ee4c_7574),
    (0x3fec_ffff_ffff_ffff, 0xbfb9_335e_5d59_4992),
    (0x3fed_0000_0000_0000, 0xbfb9_335e_5d59_4989),
    (0x3fed_1000_0000_0000, 0xbfb8_a647_7a91_dc29),
    (0x3ffc_ffff_ffff_ffff, 0x3fe3_07d7_334f_10bd),
    (0x3ffd_0000_0000_0000, 0x3fe3_07d7_334f_10be),
    (0x3ffd_1000_0000_0000, 0x3fe3_197a_0fa7_fe6a),
    (0x405c_ffff_ffff_ffff, 0x4013_03ad_25a5_8d8b),
    (0x405d_0000_0000_0000, 0x4013_03ad_25a5_8d8b),
    (0x405d_1000_0000_0000, 0x4013_05e1_8130_ab41),
    (0x3fdd_7fff_ffff_ffff, 0xbfe8_c8a5_2a9e_49c6),
    (0x3fdd_8000_0000_0000, 0xbfe8_c8a5_2a9e_49c5),
    (0x3fdd_9000_0000_0000, 0xbfe8_b74e_bf75_b5e5),
    (0x3fed_7fff_ffff_ffff, 0xbfb4_d311_5d20_7eb5),
    (0x3fed_8000_0000_0000, 0xbfb4_d311_5d20_7eac),
    (0x3fed_9000_0000_0000, 0xbfb4_485e_03db_dfad),
    (0x3ffd_7fff_ffff_ffff, 0x3fe3_93e0_d356_2a19),
    (0x3ffd_8000_0000_0000, 0x3fe3_93e0_d356_2a1a),
    (0x3ffd_9000_0000_0000, 0x3fe3_a537_3e7e_bdfa),
    (0x405d_7fff_ffff_ffff, 0x4013_152e_59a6_70b6),
    (0x405d_8000_0000_0000, 0x4013_152e_59a6_70b7),
    (0x405d_9000_0000_0000, 0x4013_1759_270b_8333),
    (0x3fdd_ffff_ffff_ffff, 0xbfe8_3ef6_15ae_0131),
    (0x3fde_0000_0000_0000, 0xbfe8_3ef6_15ae_0130),
    (0x3fde_1000_0000_0000, 0xbfe8_2de9_9014_f31f),
    (0x3fed_ffff_ffff_ffff, 0xbfb0_8598_b59e_3a0f),
    (0x3fee_0000_0000_0000, 0xbfb0_8598_b59e_3a07),
    (0x3fee_1000_0000_0000, 0xbfaf_fa69_11ab_9301),
    (0x3ffd_ffff_ffff_ffff, 0x3fe4_1d8f_e846_72ad),
    (0x3ffe_0000_0000_0000, 0x3fe4_1d8f_e846_72ae),
    (0x3ffe_1000_0000_0000, 0x3fe4_2e9c_6ddf_80bf),
    (0x405d_ffff_ffff_ffff, 0x4013_2664_3c44_79c9),
    (0x405e_0000_0000_0000, 0x4013_2664_3c44_79c9),
    (0x405e_1000_0000_0000, 0x4013_2885_ccf7_9b8b),
    (0x3fde_7fff_ffff_ffff, 0xbfe7_b78d_a044_3524),
    (0x3fde_8000_0000_0000, 0xbfe7_b78d_a044_3523),
    (0x3fde_9000_0000_0000, 0xbfe7_a6c8_949d_916b),
    (0x3fee_7fff_ffff_ffff, 0xbfa8_94aa_149f_b354),
    (0x3fee_8000_0000_0000, 0xbfa8_94aa_149f_b343),
    (0x3fee_9000_0000_0000, 0xbfa7_8859_5a35_77ba),
    (0x3ffe_7fff_ffff_ffff, 0x3fe4_a4f8_5db0_3eba),
    (0x3ffe_8000_0000_0000, 0x3fe4_a4f8_5db0_3ebb),
    (0x3ffe_9000_0000_0000, 0x3fe4_b5bd_6956_e274),
    (0x405e_7fff_ffff_ffff, 0x4013_3751_4af1_b34b),
    (0x405e_8000_0000_0000, 0x4013_3751_4af1_b34b),
    (0x405e_9000_0000_0000, 0x4013_3969_ec66_87c2),
    (0x3fde_ffff_ffff_ffff, 0xbfe7_3258_d798_ae35),
    (0x3fdf_0000_0000_0000, 0xbfe7_3258_d798_ae33),
    (0x3fdf_1000_0000_0000, 0xbfe7_21d8_f83a_d862),
    (0x3fee_ffff_ffff_ffff, 0xbfa0_415d_89e7_4455),
    (0x3fef_0000_0000_0000, 0xbfa0_415d_89e7_4444),
    (0x3fef_1000_0000_0000, 0xbf9e_72bf_2813_ce51),
    (0x3ffe_ffff_ffff_ffff, 0x3fe5_2a2d_265b_c5aa),
    (0x3fff_0000_0000_0000, 0x3fe5_2a2d_265b_c5ab),
    (0x3fff_1000_0000_0000, 0x3fe5_3aad_05b9_9b7d),
    (0x405e_ffff_ffff_ffff, 0x4013_47f7_e407_2429),
    (0x405f_0000_0000_0000, 0x4013_47f7_e407_2429),
    (0x405f_1000_0000_0000, 0x4013_4a07_dff2_dee3),
    (0x3fdf_7fff_ffff_ffff, 0xbfe6_af45_b1be_d4b2),
    (0x3fdf_8000_0000_0000, 0xbfe6_af45_b1be_d4b1),
    (0x3fdf_9000_0000_0000, 0xbfe6_9f08_cd0d_576b),
    (0x3fef_7fff_ffff_ffff, 0xbf90_2056_5893_5868),
    (0x3fef_8000_0000_0000, 0xbf90_2056_5893_5847),
    (0x3fef_9000_0000_0000, 0xbf8c_3173_84c7_5f06),
    (0x3fff_7fff_ffff_ffff, 0x3fe5_ad40_4c35_9f2c),
    (0x3fff_8000_0000_0000, 0x3fe5_ad40_4c35_9f2d),
    (0x3fff_9000_0000_0000, 0x3fe5_bd7d_30e7_1c73),
    (0x405f_7fff_ffff_ffff, 0x4013_585a_48c2_5f59),
    (0x405f_8000_0000_0000, 0x4013_585a_48c2_5f59),
    (0x405f_9000_0000_0000, 0x4013_5a61_e558_8f02),
    (0x3fdf_ffff_ffff_ffff, 0xbfe6_2e42_fefa_39f0),
    (0x3fe0_0000_0000_0000, 0xbfe6_2e42_fefa_39ef),
    (0x3fe0_1000_0000_0000, 0xbfe6_0e52_f457_88e3),
    (0x3fef_ffff_ffff_ffff, 0xbca0_0000_0000_0000),
    (0x3ff0_0000_0000_0000, 0x0000_0000_0000_0000),
    (0x3ff0_1000_0000_0000, 0x3f6f_f00a_a2b1_0bc0),
    (0x3fff_ffff_ffff_ffff, 0x3fe6_2e42_fefa_39ee),
    (0x4000_0000_0000_0000, 0x3fe6_2e42_fefa_39ef),
    (0x4000_1000_0000_0000, 0x3fe6_4e33_099c_eafb),
    (0x405f_ffff_ffff_ffff, 0x4013_687a_9f1a_f2b1),
    (0x4060_0000_0000_0000, 0x4013_687a_9f1a_f2b1),
    (0x4060_1000_0000_0000, 0x4013_6c78_a06f_48d3),
    (0x3fe0_7fff_ffff_ffff, 0xbfe5_322e_2686_7859),
    (0x3fe0_8000_0000_0000, 0xbfe5_322e_2686_7857),
    (0x3fe0_9000_0000_0000, 0xbfe5_1335_6667_fc57),
    (0x3ff0_7fff_ffff_ffff, 0x3f9f_829b_0e78_32c2),
    (0x3ff0_8000_0000_0000, 0x3f9f_829b_0e78_3300),
    (0x3ff0_9000_0000_0000, 0x3fa1_b0d9_8923_d980),
    (0x4000_7fff_ffff_ffff, 0x3fe7_2a57_d76d_fb85),
    (0x4000_8000_0000_0000, 0x3fe7_2a57_d76d_fb87),
    (0x4000_9000_0000_0000, 0x3fe7_4950_978c_7787),
    (0x4060_7fff_ffff_ffff, 0x4013_87fd_3a29_6ae4),
    (0x4060_8000_0000_0000, 0x4013_87fd_3a29_6ae4),
    (0x4060_9000_0000_0000, 0x4013_8bdc_522d_3a64),
    (0x3fe0_ffff_ffff_ffff, 0xbfe4_3d9f_f2f9_23c7),
    (0x3fe1_0000_0000_0000, 0xbfe4_3d9f_f2f9_23c5),
    (0x3fe1_1000_0000_0000, 0xbfe4_1f8f_f847_1d61),
    (0x3ff0_ffff_ffff_ffff, 0x3faf_0a30_c011_6288),
    (0x3ff1_0000_0000_0000, 0x3faf_0a30_c011_62a6),
    (0x3ff1_1000_0000_0000, 0x3fb0_7598_3598_e471),
    (0x4000_ffff_ffff_ffff, 0x3fe8_1ee6_0afb_5018),
    (0x4001_0000_0000_0000, 0x3fe8_1ee6_0afb_501a),
    (0x4001_1000_0000_0000, 0x3fe8_3cf6_05ad_567d),
    (0x4060_ffff_ffff_ffff, 0x4013_a68f_009b_1576),
    (0x4061_0000_0000_0000, 0x4013_a68f_009b_1577),
    (0x4061_1000_0000_0000, 0x4013_aa50_fff1_5643),
    (0x3fe1_7fff_ffff_ffff, 0xbfe3_5028_ad9d_8c88),
    (0x3fe1_8000_0000_0000, 0xbfe3_5028_ad9d_8c86),
    (0x3fe1_9000_0000_0000, 0xbfe3_32f4_314a_d796),
    (0x3ff1_7fff_ffff_ffff, 0x3fb6_f0d2_8ae5_6b3d),
    (0x3ff1_8000_0000_0000, 0x3fb6_f0d2_8ae5_6b4c),
    (0x3ff1_9000_0000_0000, 0x3fb7_da76_6d7b_12cd),
    (0x4001_7fff_ffff_ffff, 0x3fe9_0c5d_5056_e757),
    (0x4001_8000_0000_0000, 0x3fe9_0c5d_5056_e759),
    (0x4001_9000_0000_0000, 0x3fe9_2991_cca9_9c49),
    (0x4061_7fff_ffff_ffff, 0x4013_c43d_e946_885e),
    (0x4061_8000_0000_0000, 0x4013_c43d_e946_885e),
    (0x4061_9000_0000_0000, 0x4013_c7e4_78d0_defd),
    (0x3fe1_ffff_ffff_ffff, 0xbfe2_6962_1134_db94),
    (0x3fe2_0000_0000_0000, 0xbfe2_6962_1134_db92),
    (0x3fe2_1000_0000_0000, 0xbfe2_4cfc_e6f8_0d9a),
    (0x3ff1_ffff_ffff_ffff, 0x3fbe_2707_6e2a_f2d8),
    (0x3ff2_0000_0000_0000, 0x3fbe_2707_6e2a_f2e6),
    (0x3ff2_1000_0000_0000, 0x3fbf_0a30_c011_62a6),
    (0x4001_ffff_ffff_ffff, 0x3fe9_f323_ecbf_984a),
    (0x4002_0000_0000_0000, 0x3fe9_f323_ecbf_984c),
    (0x4002_1000_0000_0000, 0x3fea_0f89_16fc_6644),
    (0x4061_ffff_ffff_ffff, 0x4013_e116_bcd3_9e7d),
    (0x4062_0000_0000_0000, 0x4013_e116_bcd3_9e7d),
    (0x4062_1000_0000_0000, 0x4013_e4a3_621b_383c),
    (0x3fe2_7fff_ffff_ffff, 0xbfe1_88ee_40f2_3ca8),
    (0x3fe2_8000_0000_0000, 0xbfe1_88ee_40f2_3ca6),
    (0x3fe2_9000_0000_0000, 0xbfe1_6d4d_38c1_19fa),
    (0x3ff2_7fff_ffff_ffff, 0x3fc2_9552_f81f_f51c),
    (0x3ff2_8000_0000_0000, 0x3fc2_9552_f81f_f523),
    (0x3ff2_9000_0000_0000, 0x3fc3_03d7_18e4_7fd3),
    (0x4002_7fff_ffff_ffff, 0x3fea_d397_bd02_3736),
    (0x4002_8000_0000_0000, 0x3fea_d397_bd02_3738),
    (0x4002_9000_0000_0000, 0x3fea_ef38_c533_59e4),
    (0x4062_7fff_ffff_ffff, 0x4013_fd25_36db_f25a),
    (0x4062_8000_0000_0000, 0x4013_fd25_36db_f25a),
    (0x4062_9000_0000_0000, 0x4014_0099_57e2_16b0),
    (0x3fe2_ffff_ffff_ffff, 0xbfe0_ae76_e2d0_54fc),
    (0x3fe3_0000_0000_0000, 0xbfe0_ae76_e2d0_54fa),
    (0x3fe3_1000_0000_0000, 0xbfe0_938f_ae5d_8e9b),
    (0x3ff2_ffff_ffff_ffff, 0x3fc5_ff30_70a7_93cd),
    (0x3ff3_0000_0000_0000, 0x3fc5_ff30_70a7_93d4),
    (0x3ff3_1000_0000_0000, 0x3fc6_6acd_4272_ad51),
    (0x4002_ffff_ffff_ffff, 0x3feb_ae0f_1b24_1ee2),
    (0x4003_0000_0000_0000, 0x3feb_ae0f_1b24_1ee4),
    (0x4003_1000_0000_0000, 0x3feb_c8f6_4f96_e543),
    (0x4062_ffff_ffff_ffff, 0x4014_1874_22a0_2f50),
    (0x4063_0000_0000_0000, 0x4014_1874_22a0_2f50),
    (0x4063_1000_0000_0000, 0x4014_1bd1_092e_881c),
    (0x3fe3_7fff_ffff_ffff, 0xbfdf_b358_af7a_4887),
    (0x3fe3_8000_0000_0000, 0xbfdf_b358_af7a_4884),
    (0x3fe3_9000_0000_0000, 0xbfdf_7eea_e6b5_761d),
    (0x3ff3_7fff_ffff_ffff, 0x3fc9_525a_9cf4_56ae),
    (0x3ff3_8000_0000_0000, 0x3fc9_525a_9cf4_56b4),
    (0x3ff3_9000_0000_0000, 0x3fc9_bb36_2e7d_fb83),
    (0x4003_7fff_ffff_ffff, 0x3fec_82d9_a637_4f9b),
    (0x4003_8000_0000_0000, 0x3fec_82d9_a637_4f9c),
    (0x4003_9000_0000_0000, 0x3fec_9d10_8a99_b8d0),
    (0x4063_7fff_ffff_ffff, 0x4014_330d_7402_9567),
    (0x4063_8000_0000_0000, 0x4014_330d_7402_9567),
    (0x4063_9000_0000_0000, 0x4014_3654_508e_e28d),
    (0x3fe3_ffff_ffff_ffff, 0xbfde_148a_1a27_26d1),
    (0x3fe4_0000_0000_0000, 0xbfde_148a_1a27_26ce),
    (0x3fe4_1000_0000_0000, 0xbfdd_e16b_56ef_90f0),
    (0x3ff3_ffff_ffff_ffff, 0x3fcc_8ff7_c79a_9a1b),
    (0x3ff4_0000_0000_0000, 0x3fcc_8ff7_c79a_9a22),
    (0x3ff4_1000_0000_0000, 0x3fcc_f635_4e09_c5dc),
    (0x4003_ffff_ffff_ffff, 0x3fed_5240_f0e0_e076),
    (0x4004_0000_0000_0000, 0x3fed_5240_f0e0_e078),
    (0x4004_1000_0000_0000, 0x3fed_6bd0_527c_ab66),
    (0x4063_ffff_ffff_ffff, 0x4014_4cfa_5d57_c782),
    (0x4064_0000_0000_0000, 0x4014_4cfa_5d57_c782),
    (0x4064_1000_0000_0000, 0x4014_502c_498b_40e0),
    (0x3fe4_7fff_ffff_ffff, 0xbfdc_7ff9_c745_54cc),
    (0x3fe4_8000_0000_0000, 0xbfdc_7ff9_c745_54c9),
    (0x3fe4_9000_0000_0000, 0xbfdc_4e19_b847_23c2),
    (0x3ff4_7fff_ffff_ffff, 0x3fcf_b918_6d5e_3e24),
    (0x3ff4_8000_0000_0000, 0x3fcf_b918_6d5e_3e2b),
    (0x3ff4_9000_0000_0000, 0x3fd0_0e6c_45ad_501d),
    (0x4004_7fff_ffff_ffff, 0x3fee_1c89_1a51_c978),
    (0x4004_8000_0000_0000, 0x3fee_1c89_1a51_c97a),
    (0x4004_9000_0000_0000, 0x3fee_3579_21d0_e1fe),
    (0x4064_7fff_ffff_ffff, 0x4014_6643_6285_e4a2),
    (0x4064_8000_0000_0000, 0x4014_6643_6285_e4a3),
    (0x4064_9000_0000_0000, 0x4014_6961_6375_c7b3),
    (0x3fe4_ffff_ffff_ffff, 0xbfda_f529_5248_cdd3),
    (0x3fe5_0000_0000_0000, 0xbfda_f529_5248_cdd0),
    (0x3fe5_1000_0000_0000, 0xbfda_c478_d020_506f),
    (0x3ff4_ffff_ffff_ffff, 0x3fd1_675c_abab_a60b),
    (0x3ff5_0000_0000_0000, 0x3fd1_675c_abab_a60e),
    (0x3ff5_1000_0000_0000, 0x3fd1_980d_2dd4_236f),
    (0x4004_ffff_ffff_ffff, 0x3fee_e1f1_54d0_0cf5),
    (0x4005_0000_0000_0000, 0x3fee_e1f1_54d0_0cf6),
    (0x4005_1000_0000_0000, 0x3fee_fa49_95e4_4ba7),
    (0x4064_ffff_ffff_ffff, 0x4014_7ef0_69d5_ad12),
    (0x4065_0000_0000_0000, 0x4014_7ef0_69d5_ad12),
    (0x4065_1000_0000_0000, 0x4014_81fb_71f8_34e8),
    (0x3fe5_7fff_ffff_ffff, 0xbfd9_73a3_4313_56b1),
    (0x3fe5_8000_0000_0000, 0xbfd9_73a3_4313_56ae),
    (0x3fe5_9000_0000_0000, 0xbfd9_4414_34a0_3259),
    (0x3ff5_7fff_ffff_ffff, 0x3fd2_e8e2_bae1_1d2e),
    (0x3ff5_8000_0000_0000, 0x3fd2_e8e2_bae1_1d31),
    (0x3ff5_9000_0000_0000, 0x3fd3_1871_c954_4185),
    (0x4005_7fff_ffff_ffff, 0x3fef_a2b4_5c6a_c886),
    (0x4005_8000_0000_0000, 0x3fef_a2b4_5c6a_c888),
    (0x4005_9000_0000_0000, 0x3fef_ba7b_e3a4_5ab2),
    (0x4065_7fff_ffff_ffff, 0x4014_9708_cac9_0484),
    (0x4065_8000_0000_0000, 0x4014_9708_cac9_0484),
    (0x4065_9000_0000_0000, 0x4014_9a01_bbb0_36ca),
    (0x5c4b_77ae_0bf3_4dad, 0x4073_a893_d087_63c9),
    (0x40bb_3521_84d3_0d0c, 0x4021_b285_1856_079b),
    (0x7b17_ce91_e590_6136, 0x4084_80ea_bdf3_cdd2),
    (0x4079_8269_5c10_e571, 0x4018_0bea_71ec_39c9),
    (0x2cfb_16e0_a1c5_4aec, 0xc06a_4616_0a29_b42d),
    (0x40f9_6d5f_efe4_4378, 0x4027_1b6f_cf11_a7f5),
    (0x1b02_e144_d6e8_f2cf, 0xc079_97c0_6542_508c),
    (0x414c_eacd_25ce_74a0, 0x402e_4bbe_94cc_713c),
    (0x5dda_4e85_b0d6_e28b, 0x4074_bd25_39c2_f44f),
    (0x40f0_f55a_1907_1518, 0x4026_4c0c_195e_202d),
    (0x0904_74ff_b8e8_ab15, 0xc083_083e_bd08_c644),
    (0x4077_4816_0280_aaed, 0x4017_ae56_6649_9533),
    (0x55cc_79f8_ada7_11fd, 0x406e_4f83_ee1c_137a),
    (0x4050_12aa_b5c7_8c20, 0x4010_a75a_35e2_f409),
    (0x3951_99e8_3f5a_101f, 0xc052_5834_cd4d_c347),
    (0x4133_703b_e64a_7381, 0x402c_1d7e_8bf7_7552),
    (0x354c_fc38_7dfa_e6b8, 0xc05d_7bc6_29f7_7151),
    (0x4108_73fc_ad00_8c4e, 0x4028_6a53_a128_0589),
    (0x7c86_39b1_6b71_4b4f, 0x4084_ffe7_f6a0_e487),
    (0x40f4_666d_5acc_bb29, 0x4026_aaa7_1e8e_4abd),
    (0x545b_0ec7_6d00_616d, 0x406c_4fb9_42dc_ba1e),
    (0x4128_4583_7d7a_4d47, 0x402b_2c4b_4fbf_f34a),
    (0x0f2a_50d5_9c0a_a21a, 0xc080_e6cd_8e23_3aa4),
    (0x40de_646c_a479_47e2, 0x4024_b0fa_6a94_7771),
    (0x0e2e_cd02_ed7c_0cbd, 0xc081_3e44_4d11_c474),
    (0x404e_507d_81a0_2900, 0x4010_6b48_f6e9_b101),
    (0x5cb6_b3d3_cdbd_f613, 0x4073_f329_5135_027d),
    (0x40c5_0d57_a34c_ac18, 0x4022_9216_39de_bc0c),
    (0x3691_da7f_6993_082d, 0xc059_f732_a407_e707),
    (0x40b0_68fc_93ce_349b, 0x4020_afa7_7c4f_d41b),
    (0x6c81_6e1e_6ced_8137, 0x407e_e4ca_f7a6_3e25),
    (0x413c_c25c_5992_ae1e, 0x402c_e60c_6682_3839),
    (0x1f37_b27a_7886_9b5a, 0xc076_ad0f_ca80_223e),
    (0x4119_65a1_5550_00b2, 0x4029_e09c_25b2_a828),
    (0x475b_4c36_d0db_7fed, 0x4054_94d6_5395_fd8a),
    (0x4081_3c20_bc9b_4ece, 0x4019_402c_c7b2_43ed),
    (0x7ad7_8fb3_73ff_bff6, 0x4084_6aa7_3e8a_c86c),
    (0x40ef_908b_5b53_2dfb, 0x4026_273f_76a2_e34f),
    (0x59b6_9ba1_26cd_29b3, 0x4071_dec1_f262_bd29),
    (0x412c_a2c9_370b_3f39, 0x402b_80f4_e12d_8285),
    (0x2d2c_e288_56d2_0e5e, 0xc06a_017d_8333_5c0a),
    (0x40a9_df2f_0d16_edca, 0x4020_35da_b70c_dbeb),
    (0x32c9_1149_9417_aab9, 0xc062_39c3_2329_ef83),
    (0x405a_e3d0_9895_a13a, 0x4012_b651_796b_1064),
    (0x0cd8_8eab_2f9a_d4bb, 0xc081_b487_1cff_0595),
    (0x4127_9e7f_b90c_553c, 0x402b_1e57_f9f0_6f42),
    (0x6f1f_3414_c47c_9c0d, 0x4080_5a68_4581_fe9d),
    (0x415d_dbbe_91b5_512f, 0x402f_bf08_e2f3_7d61),
    (0x6377_4cf8_41ee_8ab9, 0x4078_a155_fb58_a580),
    (0x4158_8707_7042_4023, 0x402f_5a56_a9ff_ca66),
    (0x579e_b22e_1ea5_a35f, 0x4070_6a94_2fd0_4a00),
    (0x40a0_a1e7_b029_6ce2, 0x401e_a74e_7dfb_536f),
    (0x73e3_63e9_3829_5a26, 0x4082_0194_75b0_4ce5),
    (0x4076_b912_bef6_c46c, 0x4017_9577_8978_3d43),
    (0x3839_d78e_2a2f_9b10, 0xc055_5e22_33bf_4f5b),
    (0x4094_a2e8_1321_f470, 0x401c_be66_5c08_f4fd),
    (0x0977_b5fe_fda6_afa6, 0xc082_e03f_79fb_509f),
    (0x4099_bef0_971d_cc5f, 0x401d_a0ed_bad2_5a4a),
    (0x4000_273b_10a6_d4af, 0x3fe6_7c59_8b99_bdad),
    (0x4164_90f4_76b0_bd76, 0x4030_3185_bb9c_e110),
    (0x3c1a_45ad_6d01_75e3, 0xc045_3d56_89b3_196c),
    (0x40b0_b915_4d35_2efd, 0x4020_b952_ff43_ebe9),
    (0x107b_c2dd_a0eb_c917, 0xc080_71ed_2c1c_6b35),
    (0x4094_0f1e_3207_25e3, 0x401c_a158_62fe_1430),
    (0x5923_0b16_630d_2b73, 0x4071_7832_f540_2735),
    (0x40ca_2bc1_fe3d_5601, 0x4023_0185_c94e_966f),
    (0x544b_14bc_79e2_1fbe, 0x406c_3992_0ab3_a2ac),
    (0x411d_cac5_9e9d_32c0, 0x402a_3254_c6d6_101b),
    (0x195a_5514_fae8_13a9, 0xc07a_bdde_332f_e1a5),
    (0x40bc_2a52_e52c_d5fb, 0x4021_c43b_da4f_6573),
    (0x5713_572b_fb80_5a5d, 0x4070_0a77_124f_7882),
    (0x4170_45ef_d345_40bd, 0x4030_a707_ca58_2ff7),
    (0x2867_793e_9e8a_d732, 0xc070_4eee_61fa_4c9b),
    (0x40a2_779d_1cb2_6e25, 0x401f_1276_1bdd_6b3b),
    (0x4dda_1d57_ff03_f180, 0x4063_4bcb_6a03_795e),
    (0x4097_946d_99fa_f76e, 0x401d_46ef_9a3a_21d3),
    (0x1626_6c76_ad45_818f, 0xc07c_f60c_0544_be1e),
    (0x413a_dccc_13b8_d022, 0x402c_c31d_ab8e_cadf),
    (0x2183_5587_1886_f75e, 0xc075_15f9_6db9_f780),
    (0x4070_cced_76e3_c632, 0x4016_6040_d269_d792),
    (0x075c_31b6_d9ef_a2ea, 0xc083_9b66_070f_c20b),
    (0x412b_168b_afd7_c1ec, 0x402b_6481_9337_7b98),
    (0x792d_0016_351a_c3e1, 0x4083_d698_5943_36b1),
    (0x4072_5380_8523_3a27, 0x4016_b942_ec16_a3b3),
    (0x4fb7_9455_2d7c_87fa, 0x4065_e1f2_b0b5_11f2),
    (0x40c3_4677_3b27_5b7d, 0x4022_64f0_6f31_4dce),
    (0x3108_38d4_f456_58b5, 0xc064_a7eb_8ca5_5983),
    (0x4168_d50d_accf_da19, 0x4030_61c6_c510_20c6),
    (0x3501_bf49_868f_c4b6, 0xc05e_4c9d_8f48_4c2e),
    (0x40dc_0ad5_10f0_f8ff, 0x4024_87c6_823a_3860),
    (0x1b0f_073c_a7e2_4f12, 0xc079_8fcd_82f8_958d),
    (0x412b_7186_a163_0731, 0x402b_6b2e_09b5_d8fc),
    (0x790a_ff4a_b7e1_c412, 0x4083_caee_a2d8_616b),
    (0x4087_854b_b69e_6dc8, 0x401a_7e95_3fc6_3d75),
    (0x61e6_cc3f_ce8a_571c, 0x4077_8bba_5a88_31f1),
    (0x40f9_bfec_ab04_994d, 0x4027_21e3_91a5_4e72),
    (0x7896_37bd_bb04_623b, 0x4083_a28e_a38c_40e8),
    (0x40d3_c33a_4447_27be, 0x4023_d49d_69ad_8556),
    (0x7644_dc40_37d1_ccf7, 0x4082_d4e1_9c6d_eef9),
    (0x4112_ff11_ac04_161c, 0x4029_4bef_09ae_5979),
    (0x108d_b970_f61e_c64b, 0xc080_6bd5_ab96_bd4f),
    (0x410f_894e_e794_6f9d, 0x4028_ec92_68fe_eed9),
    (0x42f8_7faa_ebb9_a0d5, 0x4040_d93a_71b1_6dd7),
    (0x40d8_8a9b_e0d7_c3f6, 0x4024_437f_df57_4849),
    (0x13e4_1155_7b1e_1b59, 0xc07e_8713_6921_6b7c),
    (0x405a_2b78_e516_bd99, 0x4012_9a85_c74d_f9cf),
    (0x1d7e_b56c_c3fe_cd4d, 0xc077_df71_d073_c7c2),
    (0x4101_4e35_ed17_d35a, 0x4027_b94f_fa96_89a4),
    (0x1417_f09c_7699_5dd0, 0xc07e_62fb_5844_eac1),
    (0x408e_19a6_7eaa_90d8, 0x401b_7b27_6ec6_7677),
    (0x7c40_536a_3934_3f9d, 0x4084_e741_eca1_e4f5),
    (0x4073_7458_9f33_3563, 0x4016_f671_2321_1a32),
    (0x328d_e04b_5365_8403, 0xc062_8cde_97f0_b619),
    (0x4097_0e65_8107_bb9b, 0x401d_2ff1_6aeb_47f3),
    (0x2a49_ef48_de09_d554, 0xc06e_0140_212d_13c5),
    (0x4127_7bb5_4543_f85b, 0x402b_1b63_a02d_b1b8),
    (0x0174_0cfd_5e7e_0059, 0xc085_a75f_3d0d_5108),
    (0x4066_4635_5f3b_7c57, 0x4014_bb43_0a8c_1555),
    (0x3a89_dbbf_218e_9bcd, 0xc04d_e970_eb2d_e681),
    (0x4096_9876_8999_b65f, 0x401d_1b46_9631_1a48),
    (0x0f81_80ea_42ce_3691, 0xc080_c8cb_42d1_1d29),
    (0x4062_455b_f692_ab57, 0x4013_f063_1b2d_72fe),
    (0x3e04_865f_060e_d9e1, 0xc035_3d0f_329a_6db7),
    (0x4101_4a7f_5049_63a5, 0x4027_b8e2_1204_9961),
    (0x68d2_9c22_e6ec_81aa, 0x407c_5782_812b_91a2),
    (0x4106_b275_4972_f1ab, 0x4028_442c_50ee_6ca2),
    (0x153c_6175_be7d_148d, 0xc07d_98a2_0001_8b02),
    (0x408c_75be_5867_e216, 0x401b_41c6_5b7b_d4f4),
    (0x3918_620e_fee2_ae3f, 0xc052_f4cb_0273_9ed0),
    (0x40c0_8cdd_6939_98e7, 0x4022_16e6_54ed_afb2),
    (0x7fbf_4d50_b83a_266a, 0x4086_1d73_2258_d224),
    (0x4082_2dc7_354d_b6bd, 0x4019_76c6_e772_a1d6),
    (0x7446_a02a_b71e_e437, 0x4082_2415_e262_e0b1),
    (0x40e1_6fa4_b639_52a7, 0x4024_f761_07da_13fb),
    (0x195c_b64c_fdf7_b997, 0xc07a_bc7b_cf8f_c1da),
    (0x4137_2de8_2204_a58c, 0x402c_779c_748b_d58a),
    (0x646d_2dce_235d_ab82, 0x4079_4b4a_66a7_1825),
    (0x40de_2a5f_82f1_f3f7, 0x4024_ad24_cba4_6a9b),
    (0x1985_31f7_eedc_5275, 0xc07a_a011_bce2_8ec0),
    (0x4047_b7b4_b51d_dc15, 0x400e_dffa_8e5f_677a),
    (0x73f9_caff_b024_e07e, 0x4082_0968_6183_cd11),
    (0x4161_7ace_dbc1_76b2, 0x4030_07e4_fb16_f479),
    (0x5346_1012_dddd_2752, 0x406a_d01e_fc61_771f),
    (0x4148_43df_adbc_d301, 0x402d_f1f1_16ab_74a6),
    (0x0d84_97b6_e7e3_148f, 0xc081_78f0_7f1e_c3a8),
    (0x403e_3c70_26be_2c13, 0x400b_45b4_bae3_59db),
    (0x750b_a3db_8471_e0c4, 0x4082_683a_a47c_4d58),
    (0x4109_f1ce_3e37_55ae, 0x4028_88a3_d86f_427d),
    (0x58e6_8ff5_2d13_b421, 0x4071_4e8c_fa23_2e60),
    (0x40d7_eac3_c517_1036, 0x4024_364d_f0b7_1208),
    (0x1910_9052_e585_3c3f, 0xc07a_f1a5_8ce1_b187),
    (0x4123_e07c_3cef_16d3, 0x402a_c606_28f1_e2fa),
    (0x0444_9ea8_330d_49f4, 0xc084_ad9d_7bf7_f998),
    (0x4066_8d21_ae54_09df, 0x4014_c7eb_6ec4_b6cb),
    (0x2df1_5b82_7533_44fb, 0xc068_f170_4427_da9e),
    (0x40c1_84ee_be8d_38ff, 0x4022_3408_5038_f79b),
    (0x72ab_fdea_5375_f6cb, 0x4081_959d_0ec8_2b7b),
    (0x4173_85f9_9f49_f710, 0x4030_d5a5_59a5_2fc2),
    (0x4b95_228e_e7b1_81f9, 0x4060_2684_d972_1dba),
    (0x408f_4f8c_d516_a218, 0x401b_a387_a6dd_9ac2),
    (0x0000_0000_0000_0001, 0xc087_4385_446d_71c3),
    (0x000f_ffff_ffff_ffff, 0xc086_232b_dd7a_bcd2),
    (0x0010_0000_0000_0000, 0xc086_232b_dd7a_bcd2),
    (0x7fef_ffff_ffff_ffff, 0x4086_2e42_fefa_39ef),
    (0x3ff0_0000_0000_0000, 0x0000_0000_0000_0000),
    (0x3ff0_0000_0000_0001, 0x3caf_ffff_ffff_ffff),
    (0x3fef_ffff_ffff_ffff, 0xbca0_0000_0000_0000),
    (0x4000_0000_0000_0000, 0x3fe6_2e42_fefa_39ef),
    (0x3fe0_0000_0000_0000, 0xbfe6_2e42_fefa_39ef),
    (0x417c_9c38_0000_0000, 0x4031_377a_2be9_7aa3),
];
// END GENERATED TEST DATA
