//! exp(x) for x ≤ 0 in straight-line arithmetic, so that a loop over a slice vectorizes (libm's exp is a
//! call per value and was half of a DLGPD planning step). Cody–Waite reduction x = k ln 2 + r with
//! |r| ≤ ln 2 / 2, a degree-13 Taylor polynomial for e^r, and 2^k assembled in the exponent bits; relative
//! error below 2e-15. Arguments below −700 give exp(−700) ≈ 1e-304 instead of smaller numbers, which is
//! zero to every kernel sum it feeds.

const LOG2_E: f64 = std::f64::consts::LOG2_E;
#[allow(clippy::excessive_precision)] // the split of ln 2 must be exact to the last bit
const LN2_HI: f64 = 6.931_471_803_691_238_2e-1;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
/// 1.5 · 2^52: adding it rounds to an integer held in the low mantissa bits.
const ROUNDER: f64 = 6_755_399_441_055_744.0;
const FLOOR: f64 = -700.0;

#[inline(always)]
pub fn exp_nonpositive(x: f64) -> f64 {
    let x = x.clamp(FLOOR, 0.0);
    let shifted = x * LOG2_E + ROUNDER;
    let k = shifted - ROUNDER;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut p = 1.0 / 6_227_020_800.0;
    for c in [
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        p = p * r + c;
    }
    // The low bits of `shifted` hold k (two's complement, wrapping); k + 1023 in the exponent field is 2^k.
    let k_bits = shifted.to_bits().wrapping_sub(ROUNDER.to_bits()).wrapping_add(1023);
    p * f64::from_bits(k_bits << 52)
}

/// `values[i] = scale · exp(values[i])` for non-positive values.
#[inline(always)]
pub fn scaled_exp_in_place(values: &mut [f64], scale: f64) {
    for v in values.iter_mut() {
        *v = scale * exp_nonpositive(*v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_libm_to_a_few_ulps_over_the_kernel_range() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let x = -700.0 * (i as f64 / 200_000.0).powi(3);
            let (got, want) = (exp_nonpositive(x), x.exp());
            worst = worst.max(((got - want) / want).abs());
        }
        assert!(worst < 2e-15, "worst relative error {worst:e}");
        assert_eq!(exp_nonpositive(0.0), 1.0);
        assert!(exp_nonpositive(-1e6) < 1e-300 && exp_nonpositive(-1e6) >= 0.0);
        assert!(exp_nonpositive(f64::NEG_INFINITY) < 1e-300);
    }
}
