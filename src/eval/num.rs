//! Serde for report numbers that may be NaN or infinite (a median of nothing, a failed prediction ranked as
//! infinitely wrong): JSON has no such numbers and serde_json would write `null`, which reads back as an
//! error. Non-finite values are written as the strings "NaN", "inf" and "-inf" instead, so a summary renders
//! the same report after a round trip; everything else stays a plain JSON number (exact with float_roundtrip).

use serde::de::{Deserializer, Visitor};
use serde::ser::Serializer;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Real(pub f64);

impl Serialize for Real {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let v = self.0;
        if v.is_finite() {
            s.serialize_f64(v)
        } else if v.is_nan() {
            s.serialize_str("NaN")
        } else if v > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_str("-inf")
        }
    }
}

struct RealVisitor;

impl Visitor<'_> for RealVisitor {
    type Value = Real;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a number, or \"NaN\", \"inf\", \"-inf\"")
    }

    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Real, E> {
        Ok(Real(v))
    }

    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Real, E> {
        Ok(Real(v as f64))
    }

    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Real, E> {
        Ok(Real(v as f64))
    }

    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Real, E> {
        match v {
            "NaN" => Ok(Real(f64::NAN)),
            "inf" => Ok(Real(f64::INFINITY)),
            "-inf" => Ok(Real(f64::NEG_INFINITY)),
            other => Err(E::custom(format!("expected a number, or \"NaN\", \"inf\", \"-inf\", got \"{other}\""))),
        }
    }
}

impl<'de> Deserialize<'de> for Real {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Real, D::Error> {
        d.deserialize_any(RealVisitor)
    }
}

/// `#[serde(with = "num::real")]` on an `f64`.
pub mod real {
    use super::*;

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        Real(*v).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Real::deserialize(d).map(|r| r.0)
    }
}

/// `#[serde(with = "num::reals")]` on a `Vec<f64>`.
pub mod reals {
    use super::*;

    pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(v.iter().map(|x| Real(*x)))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        Ok(Vec::<Real>::deserialize(d)?.into_iter().map(|r| r.0).collect())
    }
}

/// `#[serde(with = "num::opt")]` on an `Option<f64>`.
pub mod opt {
    use super::*;

    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        v.map(Real).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        Ok(Option::<Real>::deserialize(d)?.map(|r| r.0))
    }
}

/// `#[serde(with = "num::opt_pair")]` on an `Option<(f64, f64)>`.
pub mod opt_pair {
    use super::*;

    pub fn serialize<S: Serializer>(v: &Option<(f64, f64)>, s: S) -> Result<S::Ok, S::Error> {
        v.map(|(a, b)| (Real(a), Real(b))).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<(f64, f64)>, D::Error> {
        Ok(Option::<(Real, Real)>::deserialize(d)?.map(|(a, b)| (a.0, b.0)))
    }
}

/// `#[serde(with = "num::points")]` on a `Vec<(f64, f64)>`.
pub mod points {
    use super::*;

    pub fn serialize<S: Serializer>(v: &[(f64, f64)], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(v.iter().map(|(x, y)| (Real(*x), Real(*y))))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<(f64, f64)>, D::Error> {
        Ok(Vec::<(Real, Real)>::deserialize(d)?.into_iter().map(|(x, y)| (x.0, y.0)).collect())
    }
}

/// `#[serde(with = "num::triples")]` on a `Vec<[f64; 3]>`.
pub mod triples {
    use super::*;

    pub fn serialize<S: Serializer>(v: &[[f64; 3]], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(v.iter().map(|t| t.map(Real)))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 3]>, D::Error> {
        Ok(Vec::<[Real; 3]>::deserialize(d)?.into_iter().map(|t| t.map(|r| r.0)).collect())
    }
}

/// `#[serde(with = "num::quad")]` on a `[f64; 4]` (one value per TRADYN variant).
pub mod quad {
    use super::*;

    pub fn serialize<S: Serializer>(v: &[f64; 4], s: S) -> Result<S::Ok, S::Error> {
        v.map(Real).serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 4], D::Error> {
        Ok(<[Real; 4]>::deserialize(d)?.map(|r| r.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct T {
        #[serde(with = "reals")]
        v: Vec<f64>,
        #[serde(with = "opt")]
        o: Option<f64>,
    }

    #[test]
    fn non_finite_values_round_trip_and_finite_ones_stay_exact() {
        let t = T { v: vec![0.1 + 0.2, f64::INFINITY, f64::NEG_INFINITY, 1e-300], o: Some(-0.0) };
        let text = serde_json::to_string(&t).unwrap();
        assert_eq!(serde_json::from_str::<T>(&text).unwrap(), t);
        let nan: T = serde_json::from_str(r#"{"v": ["NaN"], "o": null}"#).unwrap();
        assert!(nan.v[0].is_nan() && nan.o.is_none());
        assert!(serde_json::from_str::<T>(r#"{"v": [null], "o": null}"#).is_err());
        assert!(serde_json::from_str::<T>(r#"{"v": ["nan"], "o": null}"#).is_err());
    }
}
