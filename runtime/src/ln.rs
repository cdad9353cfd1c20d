//! Natural logarithm of an `f64`, table-driven: the design of ARM
//! optimized-routines' `log` (Szabolcs Nagy; glibc's `log` since 2.28), with the
//! table built by Gal's accurate-tables method. log x = k·ln 2 + log c +
//! log1p(z/c − 1) for x = 2^k·z, c from a 128-entry table: no division, ~40
//! instructions, ≤ 0.55 ulp, where `libm::log` (fdlibm) takes ~60 with a
//! division. x near 1 (where log c and z/c − 1 would cancel) has its own
//! polynomial, subnormals are scaled into the table path, and x ≤ 0, NaN and ∞
//! are answered directly: no call at all, so a caller's values need not be saved
//! around one (the generated control law is ~5 instructions cheaper for it).

/// f32's `Real::ln` stays `libm::logf`; `real_impl!` (lib.rs) calls both through here.
pub(crate) use libm::logf;

/// bits(x) − OFF puts z = x/2^k in [OFF, 2·OFF) = [0.6875, 1.375), split into
/// 128 subintervals by the next 7 bits.
const OFF: u64 = 0x3fe6_0000_0000_0000;
/// [1 − 2^-4, 1 + 0x1.09p-4), where |log x| < 2^-4, takes [`near_one`].
const NEAR1_LO: u64 = 0x3fee_0000_0000_0000;
const NEAR1_HI: u64 = 0x3ff1_0900_0000_0000;
/// f64::MIN_POSITIVE and +∞: the table path takes normal positive finite x.
const MIN_NORMAL: u64 = 0x0010_0000_0000_0000;
const INF: u64 = 0x7ff0_0000_0000_0000;
/// 2^52, which makes a subnormal normal.
const TWO52: u64 = 0x4330_0000_0000_0000;

/// log1p(r) = r − r²/2 + r³·(B1 + B2 r + … + B10 r⁹) on [−2^-4, 0x1.09p-4]:
/// minimax of the relative error (weighted Remez at 200 bits, mpmath), coefficients
/// rounded to double; max relative error after rounding 2^-61.9.
const B: [u64; 10] = [
    0x3fd5_5555_5555_5577, // 0.3333333333333352
    0xbfcf_ffff_ffff_fdb3, // -0.24999999999998365
    0x3fc9_9999_9995_deb2, // 0.199999999993215
    0xbfc5_5555_5567_c849, // -0.16666666670022526
    0x3fc2_4924_a342_f230, // 0.1428571507621128
    0xbfbf_ffff_a24a_aa99, // -0.12499997818182819
    0x3fbc_7184_2927_5e69, // 0.11110712055903495
    0xbfb9_99ec_e453_429c, // -0.10000496458384095
    0x3fb7_8183_5f93_2037, // 0.0918199642502494
    0xbfb5_5196_0fba_ad11, // -0.08327615627301933
];

/// ln x, ≤ 0.55 ulp (ln 1 = +0, ln ±0 = −∞, ln ∞ = ∞, NaN for x < 0 and NaN).
/// Always inlined, with its rare paths: no call is left in the caller.
#[inline(always)]
pub(crate) fn ln(x: f64) -> f64 {
    let mut ix = x.to_bits();
    // Two range checks on the top 32 bits (the bounds' low 32 bits are zero).
    let top = ix >> 32;
    if top.wrapping_sub(NEAR1_LO >> 32) < (NEAR1_HI - NEAR1_LO) >> 32 {
        return near_one(x);
    }
    if top.wrapping_sub(MIN_NORMAL >> 32) >= (INF - MIN_NORMAL) >> 32 {
        if let Some(y) = special(x) {
            return y;
        }
        // Subnormal: x·2^52 is normal; taking 52 off its exponent field (which
        // wraps below zero, on purpose) gives k − 52 in the table path below.
        ix = (x * f64::from_bits(TWO52)).to_bits().wrapping_sub(52 << 52);
    }
    // x = 2^k·z, z in subinterval i of [OFF, 2·OFF). The subtraction wraps for
    // x < OFF (k < 0), on purpose: `tmp as i64` is then the negative difference.
    let tmp = ix.wrapping_sub(OFF);
    // Exact: < 128.
    let i = ((tmp >> (52 - 7)) & 127) as usize;
    // Bit reinterpretation (intended), then an arithmetic shift: k in [−1075, 1024].
    let k = (tmp as i64) >> 52;
    let z = f64::from_bits(ix.wrapping_sub(tmp & (0xfff << 52)));
    let Some(&[c, invc, logc]) = TABLE.get(i) else {
        return f64::NAN; // unreachable: i < 128 (and the check is optimised out)
    };
    let (c, invc, logc) = (
        f64::from_bits(c),
        f64::from_bits(invc),
        f64::from_bits(logc),
    );
    // z − c is exact (Sterbenz), so r = z/c − 1 within 2^-61.2; |r| < 0.00390.
    let r = (z - c) * invc;
    // Exact: |k| ≤ 1075.
    let kd = k as f64;
    // log x = w + t: w = k·ln2_hi + log c is exact (both multiples of 2^-43,
    // |w| < 2^10); t = r + (log1p(r) − r) + k·ln2_lo, |t| < 2^-8, so the errors of
    // r and t (< 2^-60.3 all told) stay below 0.05 ulp of |log x| ≥ 2^-4.
    let w = kd * f64::from_bits(LN2_HI) + logc;
    let (a0, a1, a2) = (f64::from_bits(A0), f64::from_bits(A1), f64::from_bits(A2));
    let (a3, a4) = (f64::from_bits(A3), f64::from_bits(A4));
    // Horner: the fewest instructions on SSE2 (no register copies); Estrin would
    // shorten the dependency chain (~2 ns) for ~5 more instructions.
    let p = r * (r * (a0 + r * (a1 + r * (a2 + r * (a3 + r * a4)))));
    w + (r + (p + kd * f64::from_bits(LN2_LO)))
}

/// log x for x in [1 − 2^-4, 1 + 0x1.09p-4): with r = x − 1 (exact, Sterbenz),
/// log x = r − r²/2 + r³·B(r). r − r²/2 is summed in double-double: r = rhi + rlo
/// with rhi on 26 bits, so rhi² is exact and r² = rhi² + rlo·(rhi + r); the
/// rounding error of r + w (|w| ≤ |r|/32, so Fast2Sum) is kept in `lo`. The
/// polynomial term is below 2^-9.5 of the result, so its rounding errors
/// hardly count: the result is within about 0.52 ulp.
// Inlined (a call would make every caller save its live values around it on
// the hot path too); the branch to it is rarely taken.
#[cold]
#[inline(always)]
fn near_one(x: f64) -> f64 {
    let r = x - 1.0;
    let rhi = f64::from_bits(r.to_bits() & 0xffff_ffff_f800_0000);
    let rlo = r - rhi;
    let w = -0.5 * (rhi * rhi);
    let hi = r + w;
    let lo = (r - hi) + w - 0.5 * rlo * (rhi + r);
    let b = |k: usize| B.get(k).map_or(0.0, |&c| f64::from_bits(c));
    let mut p = b(9);
    for k in (0..9).rev() {
        p = b(k) + r * p;
    }
    let r3 = r * r * r;
    hi + (lo + r3 * p)
}

/// ln of x ≤ 0, ∞, NaN; `None` for a subnormal x > 0 (the table path takes it).
#[cold]
#[inline(always)]
fn special(x: f64) -> Option<f64> {
    let ix = x.to_bits();
    if ix << 1 == 0 {
        Some(f64::NEG_INFINITY) // ±0
    } else if ix == INF {
        Some(x)
    } else if ix >> 63 != 0 || ix & INF == INF {
        Some(f64::NAN) // x < 0, −∞, NaN
    } else {
        None
    }
}

// BEGIN GENERATED TABLE (runtime/tools/ln_table.py)
// Generated by runtime/tools/ln_table.py; do not edit by hand. Regenerate with
// `python3 runtime/tools/ln_table.py --write` (from the repository root).
// Max |log(c) - logc| = 2^-64.0; max |invc*c - 1| = 2^-54.6;
// max |r| = 0.00389128; max |log1p(r) - r - r^2 A(r)| = 2^-64.1.

/// ln 2 rounded to 42 significant bits, so `k * LN2_HI` is exact for |k| < 2^11.
const LN2_HI: u64 = 0x3fe6_2e42_fefa_3800; // 0.6931471805598903
/// ln 2 - LN2_HI.
const LN2_LO: u64 = 0x3d2e_f357_93c7_6730; // 5.497923018708371e-14
/// log1p(r) - r = r² (A0 + A1 r + A2 r² + A3 r³ + A4 r⁴) (minimax on |r| ≤ max |r|).
const A0: u64 = 0xbfe0_0000_0000_0001; // -0.5000000000000001
const A1: u64 = 0x3fd5_5555_5550_b2a5; // 0.33333333331646947
const A2: u64 = 0xbfcf_ffff_ffeb_c173; // -0.24999999996317576
const A3: u64 = 0x3fc9_99b4_9d3c_02ad; // 0.20000322034322462
const A4: u64 = 0xbfc5_5576_1a8c_45a7; // -0.1666705731991389

/// [c, 1/c rounded, log c (a multiple of 2^-43)] of the 128 subintervals, as bits.
#[rustfmt::skip]
const TABLE: [[u64; 3]; 128] = [
    [0x3fe6_0fff_830d_b3f9, 0x3ff7_34f1_48af_4fc2, 0xbfd7_cc80_e827_e000],
    [0x3fe6_2fff_c196_7aa3, 0x3ff7_1378_ae85_dea9, 0xbfd7_6fef_7f9b_b800],
    [0x3fe6_5000_5785_c390, 0x3ff6_f25f_bcef_afd8, 0xbfd7_13e2_3f3b_2000],
    [0x3fe6_7000_5aa6_7c53, 0x3ff6_d1a5_ca50_c9d3, 0xbfd6_b85a_4a6e_3800],
    [0x3fe6_8fff_c7b2_5d4c, 0x3ff6_b149_4343_cd34, 0xbfd6_5d56_2d02_1800],
    [0x3fe6_afff_c4a7_2224, 0x3ff6_9147_7591_5223, 0xbfd6_02d1_325a_b000],
    [0x3fe6_d000_5786_7484, 0x3ff6_719e_dfe5_0e1a, 0xbfd5_a8c9_e632_0800],
    [0x3fe6_efff_c4a1_bf87, 0x3ff6_524f_bf01_67a6, 0xbfd5_4f43_c121_e800],
    [0x3fe7_0fff_c4a7_8306, 0x3ff6_3356_f1ab_6d30, 0xbfd4_f638_906a_c800],
    [0x3fe7_3000_5a8f_31e1, 0x3ff6_14b3_11f4_ec9b, 0xbfd4_9da6_f9c8_a800],
    [0x3fe7_4fff_8310_f628, 0x3ff5_f664_a9dc_14b2, 0xbfd4_4593_374e_f000],
    [0x3fe7_6fff_8308_812c, 0x3ff5_d868_3867_2137, 0xbfd3_edf5_b8ff_8800],
    [0x3fe7_8fff_8309_a164, 0x3ff5_babd_3985_a66e, 0xbfd3_96cf_8907_6000],
    [0x3fe7_afff_831d_b72f, 0x3ff5_9d62_6318_99f4, 0xbfd3_401f_6419_a000],
    [0x3fe7_d000_1c26_bd0b, 0x3ff5_8055_e7ec_c0b9, 0xbfd2_e9e2_7137_d800],
    [0x3fe7_f000_1f48_9b60, 0x3ff5_6397_9e88_5723, 0xbfd2_941a_a774_6000],
    [0x3fe8_1000_190d_f0c3, 0x3ff5_4725_d093_cf69, 0xbfd2_3ec5_567b_5000],
    [0x3fe8_3000_18fd_bd12, 0x3ff5_2aff_40c8_f81f, 0xbfd1_e9e1_2568_3800],
    [0x3fe8_4fff_c4ab_dd02, 0x3ff5_0f23_1475_823a, 0xbfd1_956d_d7c8_e000],
    [0x3fe8_6fff_c193_a746, 0x3ff4_f38f_9861_ff1e, 0xbfd1_4168_92b1_d000],
    [0x3fe8_9000_5da8_d140, 0x3ff4_d843_6f60_6ddd, 0xbfd0_edcf_6cad_9000],
    [0x3fe8_b000_1900_df27, 0x3ff4_bd3e_c8a5_60fd, 0xbfd0_9aa5_3215_2000],
    [0x3fe8_d000_5db9_839c, 0x3ff4_a27f_5f84_5713, 0xbfd0_47e5_1b1e_f800],
    [0x3fe8_f000_5dac_3729, 0x3ff4_8804_d4e2_1a43, 0xbfcf_eb20_531b_a000],
    [0x3fe9_1000_1c19_066a, 0x3ff4_6dce_1d72_340e, 0xbfcf_474a_83cd_8000],
    [0x3fe9_3000_578a_a032, 0x3ff4_53d9_9c20_ff60, 0xbfce_a442_e224_7000],
    [0x3fe9_4fff_c19a_46e9, 0x3ff4_3a27_6288_7f7f, 0xbfce_020e_01ab_2000],
    [0x3fe9_6fff_c199_4ad9, 0x3ff4_20b5_57be_8d97, 0xbfcd_60a2_b990_0000],
    [0x3fe9_9000_1f36_e98d, 0x3ff4_0782_b899_2a92, 0xbfcc_c000_2d8e_1000],
    [0x3fe9_b000_1c21_d6f2, 0x3ff3_ee8f_2cd1_8335, 0xbfcc_2028_1ee9_7000],
    [0x3fe9_cfff_cad3_dae6, 0x3ff3_d5d9_ba86_9319, 0xbfcb_8118_3864_9000],
    [0x3fe9_f000_5db9_2cb5, 0x3ff3_bd60_91cf_2313, 0xbfca_e2c8_a0e2_5000],
    [0x3fea_1000_5dbc_03c3, 0x3ff3_a523_f1d3_5a47, 0xbfca_453e_b68b_c000],
    [0x3fea_3000_1f4a_159e, 0x3ff3_8d22_bc09_c9f3, 0xbfc9_a876_f4fb_c000],
    [0x3fea_5000_5db3_87f7, 0x3ff3_755b_8c7e_3064, 0xbfc9_0c6b_f22a_d000],
    [0x3fea_7000_1f3e_5bd1, 0x3ff3_5dce_48bc_1464, 0xbfc8_7120_a00c_0000],
    [0x3fea_8fff_831b_c3b0, 0x3ff3_467a_0780_fe9a, 0xbfc7_d692_9683_f000],
    [0x3fea_b000_5a8e_806b, 0x3ff3_2f5c_ac50_c4e2, 0xbfc7_3cb7_54fa_b000],
    [0x3fea_d000_5daa_359c, 0x3ff3_1877_1634_e777, 0xbfc6_a398_1b96_7000],
    [0x3fea_f000_1c24_fb99, 0x3ff3_01c8_16e8_3606, 0xbfc6_0b30_7af4_6000],
    [0x3feb_1000_546e_481c, 0x3ff2_eb4e_66f8_74b4, 0xbfc5_737b_39aa_8000],
    [0x3feb_2fff_c7bb_42a9, 0x3ff2_d50a_2827_29ae, 0xbfc4_dc7c_9265_f000],
    [0x3feb_5000_5a95_d69d, 0x3ff2_bef9_502d_d225, 0xbfc4_4629_f542_9000],
    [0x3feb_7000_5db4_af9a, 0x3ff2_a91c_5338_bf4f, 0xbfc3_b089_b231_3000],
    [0x3feb_8fff_8c5f_7080, 0x3ff2_9372_a9a5_8dc5, 0xbfc3_1b9b_6633_1000],
    [0x3feb_b000_1c19_9509, 0x3ff2_7dfa_25dd_4fd6, 0xbfc2_8753_3a29_9000],
    [0x3feb_cfff_8309_799e, 0x3ff2_68b3_cf8c_6af9, 0xbfc1_f3bb_650e_b000],
    [0x3feb_efff_8c5d_a697, 0x3ff2_539d_ca6c_367e, 0xbfc1_60ca_1416_f000],
    [0x3fec_0fff_c493_baf0, 0x3ff2_3eb7_bdb9_b7f5, 0xbfc0_ce7f_dcd7_b000],
    [0x3fec_3000_5da6_4b25, 0x3ff2_2a00_e646_fe1d, 0xbfc0_3cda_610e_3000],
    [0x3fec_5000_1f43_5b8d, 0x3ff2_1579_6c50_655a, 0xbfbf_57bb_62e2_2000],
    [0x3fec_6fff_8635_1b90, 0x3ff2_0120_5f1d_291f, 0xbfbe_370c_3696_e000],
    [0x3fec_9000_1f48_bfe7, 0x3ff1_ecf4_28dd_7dd8, 0xbfbd_1796_6fbc_c000],
    [0x3fec_b000_5aa8_31b0, 0x3ff1_d8f5_2ec7_aadf, 0xbfbb_f965_4d9f_c000],
    [0x3fec_cfff_c7a8_e6bb, 0x3ff1_c523_1edc_4d25, 0xbfba_dc79_e2f0_a000],
    [0x3fec_f000_546b_fe38, 0x3ff1_b17c_3454_7992, 0xbfb9_c0c0_4273_6000],
    [0x3fed_1000_1c23_dd9e, 0x3ff1_9e01_08d1_3499, 0xbfb8_a646_82b1_e000],
    [0x3fed_3000_5dbc_acc3, 0x3ff1_8ab0_4b3a_1dc3, 0xbfb7_8cfe_f015_a000],
    [0x3fed_4fff_8639_74d1, 0x3ff1_778a_61ac_5cab, 0xbfb6_74f4_b0bc_8000],
    [0x3fed_7000_1f35_f80a, 0x3ff1_648d_3e8b_6bf6, 0xbfb5_5e0e_f5a2_2000],
    [0x3fed_9000_1f48_b94f, 0x3ff1_51b9_91a9_e954, 0xbfb4_485c_f4f3_6000],
    [0x3fed_afff_830d_2854, 0x3ff1_3f0e_d5ca_5a1c, 0xbfb3_33dc_2d8b_e000],
    [0x3fed_d000_1f45_d851, 0x3ff1_2c8b_77e9_d916, 0xbfb2_207a_4fee_2000],
    [0x3fed_efff_c4a7_e490, 0x3ff1_1a30_3b8e_0711, 0xbfb1_0e47_af40_e000],
    [0x3fee_0fff_831e_df9f, 0x3ff1_07fc_04c0_6842, 0xbfaf_fa71_6083_c000],
    [0x3fee_3000_1c17_1000, 0x3ff0_f5ed_eaea_e486, 0xbfad_da88_fffa_c000],
    [0x3fee_5000_15f9_fc4c, 0x3ff0_e406_4943_772c, 0xbfab_bcea_8936_0000],
    [0x3fee_6fff_c18a_200c, 0x3ff0_d244_78ba_75f0, 0xbfa9_a18b_d01f_4000],
    [0x3fee_9000_5aa3_4006, 0x3ff0_c0a7_54dc_9b85, 0xbfa7_8853_6bcb_c000],
    [0x3fee_b000_1f35_6c25, 0x3ff0_af2f_6137_332a, 0xbfa5_715a_4351_c000],
    [0x3fee_d000_5a8d_b20b, 0x3ff0_9ddb_75da_0a22, 0xbfa3_5c86_19ef_8000],
    [0x3fee_efff_830e_711f, 0x3ff0_8cab_f64b_89c1, 0xbfa1_49eb_f7c1_4000],
    [0x3fef_0fff_c497_1c03, 0x3ff0_7b9f_493f_4fba, 0xbf9e_72c6_ce91_0000],
    [0x3fef_3000_5dbe_97f3, 0x3ff0_6ab5_6b20_6bf5, 0xbf9a_55e9_42cc_0000],
    [0x3fef_4fff_c183_8ccd, 0x3ff0_59ee_c113_c29f, 0xbf96_3d69_73de_8000],
    [0x3fef_6fff_8310_d1ed, 0x3ff0_494a_0ccf_5ef1, 0xbf92_290b_0558_8000],
    [0x3fef_9000_5a9f_4705, 0x3ff0_38c6_88ee_d776, 0xbf8c_315c_8c91_0000],
    [0x3fef_afff_8951_fdc2, 0x3ff0_2865_38fb_463a, 0xbf84_1947_efd1_0000],
    [0x3fef_d000_15fd_a2a5, 0x3ff0_1824_2b31_61ab, 0xbf78_1207_04f0_0000],
    [0x3fef_efff_c180_9921, 0x3ff0_0804_2160_0b60, 0xbf60_043f_f48c_0000],
    [0x3ff0_0fff_c18c_f51d, 0x3fef_e020_5c0d_a05d, 0x3f6f_ef8e_3904_0000],
    [0x3ff0_3000_1f41_49dd, 0x3fef_a11c_6cef_f87c, 0x3f87_dc56_d1cf_0000],
    [0x3ff0_4fff_8632_1040, 0x3fef_6311_96fe_3988, 0x3f93_ce86_6521_0000],
    [0x3ff0_6fff_c49b_8bb9, 0x3fef_25f6_b4ae_c5f4, 0x3f9b_9fb1_b3be_0000],
    [0x3ff0_9000_5781_8ed4, 0x3fee_e9c7_54f2_014b, 0x3fa1_b0e4_1a3b_c000],
    [0x3ff0_b000_1f45_ca92, 0x3fee_ae80_413a_8e67, 0x3fa5_8a5f_6f47_c000],
    [0x3ff0_cfff_c18f_2080, 0x3fee_741b_16b1_b8ba, 0x3fa9_5c7b_a13d_0000],
    [0x3ff0_f000_5da4_f31b, 0x3fee_3a90_d2ba_fdc0, 0x3fad_2776_999c_0000],
    [0x3ff1_0fff_c7ba_37d9, 0x3fee_01e0_80f8_e9b7, 0x3fb0_7594_e94d_6000],
    [0x3ff1_3000_1f2f_8c05, 0x3fed_ca01_a693_2a8f, 0x3fb2_53f7_ff89_6000],
    [0x3ff1_5000_190c_8350, 0x3fed_92f1_f854_59a5, 0x3fb4_2ede_310c_2000],
    [0x3ff1_7000_5775_941f, 0x3fed_5cab_ed30_ee43, 0x3fb6_065d_ad34_c000],
    [0x3ff1_9000_5dbc_cbfa, 0x3fed_272c_0862_ad37, 0x3fb7_da7b_c3d8_a000],
    [0x3ff1_b000_5daa_551e, 0x3fec_f26d_c2fa_519b, 0x3fb9_ab47_91ca_8000],
    [0x3ff1_cfff_c7c3_f0bc, 0x3fec_be6d_f0c0_9567, 0x3fbb_78c5_037d_c000],
    [0x3ff1_efff_c499_5965, 0x3fec_8b26_b981_8ed0, 0x3fbd_4310_86aa_c000],
    [0x3ff2_0fff_c193_c4bc, 0x3fec_5895_3303_8c07, 0x3fbf_0a2d_4b59_6000],
    [0x3ff2_2fff_8313_909c, 0x3fec_26b5_fa8b_0045, 0x3fc0_6711_a39a_6000],
    [0x3ff2_5000_5779_1cff, 0x3feb_f583_68f9_5854, 0x3fc1_4787_e7d1_c000],
    [0x3ff2_7000_1915_1d59, 0x3feb_c4fd_3fc1_228d, 0x3fc2_266f_c72c_2000],
    [0x3ff2_8fff_830f_4bdb, 0x3feb_951e_e4bf_e6d2, 0x3fc3_03d3_bb5a_0000],
    [0x3ff2_afff_c18c_8816, 0x3feb_65e3_3f4e_6019, 0x3fc3_dfc1_052a_a000],
    [0x3ff2_d000_1f2d_30e2, 0x3feb_3748_1dbd_ae0d, 0x3fc4_ba37_c7ba_4000],
    [0x3ff2_efff_c19a_172f, 0x3feb_094b_8aee_71e6, 0x3fc5_9337_33d7_4000],
    [0x3ff3_1000_1f48_6bb2, 0x3fea_dbe8_5380_b83c, 0x3fc6_6ace_1481_4000],
    [0x3ff3_3000_1f2d_031e, 0x3fea_af1d_042c_bc85, 0x3fc7_40f9_c539_a000],
    [0x3ff3_4fff_c199_c70d, 0x3fea_82e6_a6d9_932a, 0x3fc8_15bf_03b0_e000],
    [0x3ff3_7000_1917_5d65, 0x3fea_5740_e567_e1e3, 0x3fc8_e929_83c3_a000],
    [0x3ff3_9000_5772_472d, 0x3fea_2c2a_12c6_af22, 0x3fc9_bb38_6aaa_5000],
    [0x3ff3_afff_c4a8_84f5, 0x3fea_01a0_6864_ed96, 0x3fca_8beb_7ab7_7000],
    [0x3ff3_d000_1f34_e9df, 0x3fe9_d79e_eeb7_2260, 0x3fcb_5b52_682c_a000],
    [0x3ff3_f000_5da9_acb9, 0x3fe9_ae24_71b0_ed32, 0x3fcc_296a_aede_4000],
    [0x3ff4_0fff_c190_71f4, 0x3fe9_852f_5cfa_6fb5, 0x3fcc_f633_bfb1_b000],
    [0x3ff4_2fff_c4a3_af79, 0x3fe9_5cbb_5677_1b79, 0x3fcd_c1bb_284a_d000],
    [0x3ff4_5000_1c1f_cd9a, 0x3fe9_34c6_5cb4_cef0, 0x3fce_8c03_03e4_3000],
    [0x3ff4_6fff_c18c_f31f, 0x3fe9_0d4f_5e8e_42d9, 0x3fcf_5508_cf2c_a000],
    [0x3ff4_9000_1c22_069c, 0x3fe8_e652_58e0_15ec, 0x3fd0_0e6c_9d3d_5800],
    [0x3ff4_b000_5da7_6149, 0x3fe8_bfce_1058_5805, 0x3fd0_71b9_8188_e800],
    [0x3ff4_d000_5a98_9926, 0x3fe8_99c0_8aeb_a463, 0x3fd0_d46c_6e31_b000],
    [0x3ff4_efff_8312_ab33, 0x3fe8_7428_4ea8_d7ef, 0x3fd1_3685_84b5_c800],
    [0x3ff5_1000_5db2_cd7d, 0x3fe8_4f00_5654_6fa2, 0x3fd1_980e_4a89_d800],
    [0x3ff5_3000_5a9f_0760, 0x3fe8_2a49_9a27_3a9d, 0x3fd1_f900_b004_c000],
    [0x3ff5_5000_5da8_8ebb, 0x3fe8_0601_16cd_b6ab, 0x3fd2_5961_2a1f_7000],
    [0x3ff5_6fff_c188_29fa, 0x3fe7_e225_96f2_b6ef, 0x3fd2_b92f_803a_3800],
    [0x3ff5_8fff_8631_11d1, 0x3fe7_beb4_1851_190c, 0x3fd3_1870_5fc9_b000],
    [0x3ff5_afff_894d_8796, 0x3fe7_9baa_eceb_a021, 0x3fd3_7725_0479_1800],
    [0x3ff5_cfff_8949_870d, 0x3fe7_7908_915a_74e9, 0x3fd3_d54e_4971_5800],
    [0x3ff5_efff_8310_9bc9, 0x3fe7_56cb_46ec_331a, 0x3fd4_32ed_bd89_3800],
];
// END GENERATED TABLE
