//! The pendulum variants a user can name on the command line (`pendulum:<variant>`).

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::params::{PendulumParams, QuadrantActuator};
use crate::error::{Error, Result};
use crate::util::domain::Domain;
use crate::util::suggest::did_you_mean;

#[derive(Clone, Debug, PartialEq)]
pub enum PendulumVariant {
    Standard,
    /// Pendulum mass changed (thesis 3.5.3 uses 0.2 and 1.5).
    Mass(f64),
    /// Actions multiplied by −1.
    Inverted,
    /// Per-quadrant gains α_i ∼ U[0.5, 2] and signs s_i ∈ {−1, 1}, drawn per instance, action repeat 2
    /// (thesis 4.5.3).
    Quadrant,
}

pub const VARIANT_HELP: &str = "light (m=0.2), heavy (m=1.5), mass=<m>, inverted, quadrant";

/// The named variants (all but `mass=<m>`), as `pendulum:<name>` takes them.
/// A gram to a tonne (the thesis' family spans 0.2-1.5 kg). The torque's effect scales as 1/m: far below a gram
/// it overflows (and a zero action then gives NaN), far above a tonne the actuator moves nothing.
const MASS: Domain = Domain::closed(1e-3, 1e3).in_unit("kg");

pub const VARIANT_NAMES: [&str; 4] = ["light", "heavy", "inverted", "quadrant"];

impl PendulumVariant {
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            let hint = did_you_mean(text, VARIANT_NAMES.into_iter().chain(["standard"]));
            Error::config(format!("unknown pendulum variant '{text}'{hint}; expected one of: {VARIANT_HELP}"))
        };
        match text {
            "" | "standard" => Ok(PendulumVariant::Standard),
            "light" => Ok(PendulumVariant::Mass(0.2)),
            "heavy" => Ok(PendulumVariant::Mass(1.5)),
            "inverted" => Ok(PendulumVariant::Inverted),
            "quadrant" => Ok(PendulumVariant::Quadrant),
            other => {
                let value = other.strip_prefix("mass=").ok_or_else(bad)?;
                let mass: f64 = value.parse().map_err(|_| {
                    Error::config(format!("pendulum variant 'mass={value}': expected a number, the mass in kg"))
                })?;
                let mass = MASS
                    .check("mass", mass)
                    .map_err(|e| Error::config(format!("pendulum variant 'mass={value}': {e}")))?;
                Ok(PendulumVariant::Mass(mass))
            }
        }
    }

    pub fn env_name(&self) -> String {
        match self {
            PendulumVariant::Standard => "pendulum".into(),
            PendulumVariant::Mass(m) if *m == 0.2 => "pendulum:light".into(),
            PendulumVariant::Mass(m) if *m == 1.5 => "pendulum:heavy".into(),
            PendulumVariant::Mass(m) => format!("pendulum:mass={m}"),
            PendulumVariant::Inverted => "pendulum:inverted".into(),
            PendulumVariant::Quadrant => "pendulum:quadrant".into(),
        }
    }

    /// Parameters before any per-instance draw (the quadrant family starts with unit gains).
    pub fn fixed_params(&self) -> PendulumParams {
        let base = PendulumParams::default();
        match self {
            PendulumVariant::Standard => base,
            PendulumVariant::Mass(m) => PendulumParams { mass: *m, ..base },
            PendulumVariant::Inverted => PendulumParams { action_factor: -1.0, ..base },
            PendulumVariant::Quadrant => PendulumParams {
                quadrants: Some([QuadrantActuator { gain: 1.0, sign: 1.0 }; 4]),
                action_repeat: 2,
                ..base
            },
        }
    }

    pub fn sample_params(&self, rng: &mut ChaCha8Rng) -> PendulumParams {
        let mut params = self.fixed_params();
        if let Some(quadrants) = params.quadrants.as_mut() {
            for q in quadrants.iter_mut() {
                q.gain = rng.random_range(0.5..2.0);
                q.sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            }
        }
        params
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn parses_named_and_numeric_variants() {
        assert_eq!(PendulumVariant::parse("light").unwrap(), PendulumVariant::Mass(0.2));
        assert_eq!(PendulumVariant::parse("mass=0.7").unwrap(), PendulumVariant::Mass(0.7));
        assert_eq!(PendulumVariant::parse("inverted").unwrap().fixed_params().action_factor, -1.0);
    }

    #[test]
    fn rejects_unknown_and_nonfinite_variants() {
        let err = PendulumVariant::parse("wobbly").unwrap_err().to_string();
        assert!(err.contains("wobbly") && err.contains("quadrant"), "{err}");
        assert!(PendulumVariant::parse("mass=nan").is_err());
        assert!(PendulumVariant::parse("mass=-1").is_err());
    }

    #[test]
    fn quadrant_instances_draw_gains_in_range() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut signs = Vec::new();
        for _ in 0..20 {
            let p = PendulumVariant::Quadrant.sample_params(&mut rng);
            for q in p.quadrants.unwrap() {
                assert!((0.5..2.0).contains(&q.gain));
                signs.push(q.sign);
            }
        }
        assert!(signs.contains(&1.0) && signs.contains(&-1.0));
    }
}
