//! The domains of numbers read from outside (files and flags). A reader declares, next to the field it reads,
//! the range the field may hold (its physical meaning: a time step in (0, 1] s, a count no larger than the
//! bytes could hold) and checks the value where it is read, so that a finite but absurd number never reaches an
//! allocation, a loop bound, an integrator or a plot range. The message names the field by its path
//! (`metadata.dt`, `instances[3].mass`) and the accepted range; the caller adds the file.

use std::fmt;

/// A closed or half-open interval of accepted values, optionally integers only, with the unit it is in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Domain {
    pub lo: f64,
    pub hi: f64,
    /// The lower end is excluded: (lo, hi].
    pub lo_open: bool,
    pub integer: bool,
    /// Appended to the range in messages ("s", "kg"); empty for plain numbers.
    pub unit: &'static str,
}

impl Domain {
    /// [lo, hi].
    pub const fn closed(lo: f64, hi: f64) -> Domain {
        Domain { lo, hi, lo_open: false, integer: false, unit: "" }
    }

    /// (lo, hi]: a positive quantity with an upper bound, e.g. a time step.
    pub const fn above(lo: f64, hi: f64) -> Domain {
        Domain { lo, hi, lo_open: true, integer: false, unit: "" }
    }

    /// The whole numbers lo..=hi.
    pub const fn count(lo: u64, hi: u64) -> Domain {
        Domain { lo: lo as f64, hi: hi as f64, lo_open: false, integer: true, unit: "" }
    }

    pub const fn in_unit(self, unit: &'static str) -> Domain {
        Domain { unit, ..self }
    }

    pub fn contains(&self, value: f64) -> bool {
        let above = if self.lo_open { value > self.lo } else { value >= self.lo };
        value.is_finite() && above && value <= self.hi && (!self.integer || value.fract() == 0.0)
    }

    /// `value` if it lies in the domain; else the one-line message `field = value: expected …`.
    pub fn check(&self, field: &str, value: f64) -> Result<f64, OutOfDomain> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(OutOfDomain { field: field.to_string(), value: number(value), domain: *self })
        }
    }

    /// A count read as an integer of any width (the field's value as the file holds it).
    pub fn check_count(&self, field: &str, value: u64) -> Result<u64, OutOfDomain> {
        if (value as f64) >= self.lo && (value as f64) <= self.hi {
            Ok(value)
        } else {
            Err(OutOfDomain { field: field.to_string(), value: value.to_string(), domain: *self })
        }
    }
}

impl fmt::Display for Domain {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let unit = if self.unit.is_empty() { String::new() } else { format!(" {}", self.unit) };
        if self.integer {
            write!(f, "a whole number in {}..={}{unit}", number(self.lo), number(self.hi))
        } else {
            let open = if self.lo_open { '(' } else { '[' };
            write!(f, "a finite number in {open}{}, {}]{unit}", number(self.lo), number(self.hi))
        }
    }
}

/// A number as a reader would write it: 1e300 rather than its 301 digits.
pub fn number(x: f64) -> String {
    if x.is_finite() && x != 0.0 && (x.abs() >= 1e6 || x.abs() < 1e-4) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// A value outside its field's domain.
#[derive(Clone, Debug, PartialEq)]
pub struct OutOfDomain {
    pub field: String,
    pub value: String,
    pub domain: Domain,
}

impl fmt::Display for OutOfDomain {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{} = {}: expected {}", self.field, self.value, self.domain)
    }
}

impl std::error::Error for OutOfDomain {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn domains_accept_their_range_only() {
        let dt = Domain::above(0.0, 1.0).in_unit("s");
        assert_eq!(dt.check("metadata.dt", 0.05), Ok(0.05));
        for bad in [0.0, -0.0, -1.0, 1.0000001, f64::MAX, f64::INFINITY, f64::NAN] {
            assert!(dt.check("metadata.dt", bad).is_err(), "{bad}");
        }
        let err = dt.check("metadata.dt", f64::INFINITY).unwrap_err();
        assert_eq!(err.to_string(), "metadata.dt = inf: expected a finite number in (0, 1] s");
        let n = Domain::count(1, 64);
        assert!(n.check("metadata.action_dim", 2.5).is_err());
        assert_eq!(n.check_count("metadata.action_dim", 3), Ok(3));
        let err = Domain::closed(-1e9, 1e9).check("messages[2].state[0]", -f64::MAX).unwrap_err();
        assert_eq!(
            err.to_string(),
            "messages[2].state[0] = -1.7976931348623157e308: expected a finite number in [-1e9, 1e9]"
        );
        let err = n.check_count("metadata.action_dim", u64::MAX).unwrap_err();
        assert_eq!(err.to_string(), "metadata.action_dim = 18446744073709551615: expected a whole number in 1..=64");
    }
}
