//! GPyTorch's parametrization of positive hyperparameters: an unconstrained raw value mapped through
//! softplus plus a lower bound, so that plain gradient steps on the raw value can never leave the bound.

/// softplus(x) = ln(1 + eˣ), computed without overflow for large x.
pub fn softplus(x: f64) -> f64 {
    if x > 30.0 {
        x + (-x).exp().ln_1p()
    } else {
        x.exp().ln_1p()
    }
}

/// d softplus / dx.
pub fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

/// The raw value whose softplus is `y` (> 0).
pub fn inverse_softplus(y: f64) -> f64 {
    if y > 30.0 {
        y + (-(-y).exp_m1()).ln()
    } else {
        y.exp_m1().ln()
    }
}

/// `value = lower + softplus(raw)` (GPyTorch's `GreaterThan`; `Positive` is lower = 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GreaterThan {
    pub lower: f64,
}

impl GreaterThan {
    pub fn value(&self, raw: f64) -> f64 {
        self.lower + softplus(raw)
    }

    /// d value / d raw.
    pub fn slope(&self, raw: f64) -> f64 {
        sigmoid(raw)
    }

    /// The raw value for `value`; `None` unless `value` lies above the bound.
    pub fn raw_for(&self, value: f64) -> Option<f64> {
        (value.is_finite() && value > self.lower).then(|| inverse_softplus(value - self.lower))
    }
}

/// A Gamma(concentration, rate) prior's log density at x > 0 and its derivative in x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GammaPrior {
    pub concentration: f64,
    pub rate: f64,
}

impl GammaPrior {
    pub fn log_density(&self, x: f64) -> f64 {
        let (a, b) = (self.concentration, self.rate);
        a * b.ln() - ln_gamma(a) + (a - 1.0) * x.ln() - b * x
    }

    pub fn d_log_density(&self, x: f64) -> f64 {
        (self.concentration - 1.0) / x - self.rate
    }
}

fn ln_gamma(x: f64) -> f64 {
    statrs::function::gamma::ln_gamma(x)
}
