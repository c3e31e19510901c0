//! Mean, sample standard deviation and the 95 % Student's t interval of a cell's values. Seeds are few
//! (3 to 10), so the normal interval would be far too narrow; the t quantile with n − 1 degrees of freedom
//! is the textbook answer for the mean of a small sample.

use statrs::distribution::{ContinuousCDF, StudentsT};

pub const LEVEL: f64 = 0.95;

#[derive(Clone, Debug, PartialEq)]
pub struct Interval {
    /// Finite values the figures are of.
    pub n: usize,
    /// Values left out because they are NaN or infinite (a diverged run).
    pub non_finite: usize,
    pub mean: Option<f64>,
    /// Sample standard deviation (n − 1); none below two values.
    pub sd: Option<f64>,
    /// Half the width of the 95 % t interval around the mean; none below two values.
    pub half_width: Option<f64>,
}

impl Interval {
    pub fn of(values: &[f64]) -> Interval {
        let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
        let n = finite.len();
        let non_finite = values.len() - n;
        let mean = (n > 0).then(|| finite.iter().sum::<f64>() / n as f64);
        let sd = mean.filter(|_| n > 1).map(|m| {
            let squares: f64 = finite.iter().map(|v| (v - m) * (v - m)).sum();
            (squares / (n - 1) as f64).sqrt()
        });
        let half_width = sd.and_then(|s| t_quantile(n).map(|t| t * s / (n as f64).sqrt()));
        Interval { n, non_finite, mean, sd, half_width }
    }

    pub fn low(&self) -> Option<f64> {
        self.mean.zip(self.half_width).map(|(m, h)| m - h)
    }

    pub fn high(&self) -> Option<f64> {
        self.mean.zip(self.half_width).map(|(m, h)| m + h)
    }
}

/// The two-sided 95 % quantile of Student's t with n − 1 degrees of freedom.
pub fn t_quantile(n: usize) -> Option<f64> {
    if n < 2 {
        return None;
    }
    let t = StudentsT::new(0.0, 1.0, (n - 1) as f64).ok()?;
    Some(t.inverse_cdf(0.5 + LEVEL / 2.0)).filter(|q| q.is_finite())
}

/// A figure for the markdown report: four significant digits, scientific outside 0.001..100000; whole
/// numbers (counts) as they are.
pub fn short(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x.fract() == 0.0 && x.abs() < 1e5 {
        return format!("{x:.0}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    if (-3..5).contains(&magnitude) {
        let decimals = (3 - magnitude).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_known_sample_gets_the_textbook_interval() {
        let i = Interval::of(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!((i.n, i.mean), (4, Some(2.5)));
        assert!((i.sd.unwrap() - 1.290_994_448_735_805_6).abs() < 1e-12, "{:?}", i.sd);
        assert!((t_quantile(4).unwrap() - 3.182_446_305_284_263).abs() < 1e-6, "{:?}", t_quantile(4));
        assert!((i.half_width.unwrap() - 2.054_260_26).abs() < 1e-5, "{:?}", i.half_width);
        assert!((i.low().unwrap() - 0.445_739_74).abs() < 1e-5);
    }

    #[test]
    fn one_value_has_no_spread_and_non_finite_values_are_counted_apart() {
        let one = Interval::of(&[7.0, f64::NAN]);
        assert_eq!((one.n, one.non_finite, one.mean, one.sd, one.half_width), (1, 1, Some(7.0), None, None));
        assert_eq!(Interval::of(&[]).mean, None);
    }

    #[test]
    fn short_figures_keep_four_digits() {
        assert_eq!(short(2.054_260_26), "2.054");
        assert_eq!(short(146.964_62), "147.0");
        assert_eq!(short(0.012_345_6), "0.01235");
        assert_eq!(short(-0.000_123_4), "-1.234e-4");
        assert_eq!(short(123_456.0), "1.235e5");
        assert_eq!(short(0.0), "0");
        assert_eq!(short(-441.0), "-441");
    }
}
