//! Joins free flight and table impacts into one propagator.
//!
//! The EKF (eq. 6.22) assumes exactly one impact per trajectory and locates it with a gravity-only quadratic.
//! The truth does what the physics gives instead: every downward crossing of the table plane by the ball's
//! lowest point while the centre is above the table rectangle is a bounce, located by bisection on the RK4
//! step itself (so the contact time is as accurate as the flight), and any number of bounces can occur.
//! A crossing outside the rectangle is no contact: the ball falls past the table.

use serde::{Deserialize, Serialize};

use super::flight::{BallState, FlightParams};
use super::impact::ImpactModel;

/// Internal RK4 step: ten per 1/180 s camera frame (brief: "e.g. 1/1800 s").
pub const SUBSTEP: f64 = 1.0 / 1800.0;

/// Below this rebound speed (m/s) the ball no longer bounces but rolls or rests; the linear impact map says
/// nothing meaningful there, so the trajectory ends (never the case for launcher shots, which hit at ~3 m/s).
pub const MIN_REBOUND_SPEED: f64 = 0.05;

/// Bisection halvings when locating a contact: enough to reach f64 resolution of a 1/1800 s step.
const BISECTION_STEPS: usize = 64;

/// Ground-truth physics of the simulated ball.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BallPhysics {
    pub flight: FlightParams,
    pub impact: ImpactModel,
    /// Upper bound on the internal RK4 step (s).
    pub substep: f64,
}

impl Default for BallPhysics {
    fn default() -> Self {
        BallPhysics { flight: FlightParams::default(), impact: ImpactModel::default(), substep: SUBSTEP }
    }
}

/// How an `advance` ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    Flying,
    /// The ball stopped bouncing (see `MIN_REBOUND_SPEED`); the returned state is on the table.
    Resting,
}

impl BallPhysics {
    /// First contact with the table within one RK4 step of length `h` from `s`: the time offset and the
    /// state just before contact (not yet mapped by C). `None` if the lowest point does not pass downwards
    /// through the table plane in this step, or passes it outside the table.
    pub fn locate_contact(&self, s: &BallState, h: f64) -> Option<(f64, BallState)> {
        let impact = &self.impact;
        if impact.gap(s) < 0.0 || impact.gap(&self.flight.rk4_step(s, h)) >= 0.0 {
            return None;
        }
        let (mut lo, mut hi) = (0.0, h);
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if impact.gap(&self.flight.rk4_step(s, mid)) >= 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let tau = 0.5 * (lo + hi);
        let contact = self.flight.rk4_step(s, tau);
        (impact.table.contains_xy(&contact) && contact[5] < 0.0).then_some((tau, contact))
    }

    /// Advances `state` by `duration` seconds. Each contact's time (`t0` + offset) is appended to `impacts`.
    pub fn advance(&self, state: &mut BallState, duration: f64, t0: f64, impacts: &mut Vec<f64>) -> Outcome {
        // The tolerance keeps a frame that is an exact multiple of the substep from gaining a sliver step.
        let steps = (duration / self.substep * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let h = duration / steps as f64;
        for step in 0..steps {
            let mut t = t0 + step as f64 * h;
            let mut remaining = h;
            // A step can hold a contact; after it the rest of the step is flown from the rebound state.
            loop {
                match self.locate_contact(state, remaining) {
                    Some((tau, contact)) => {
                        *state = self.impact.apply(&contact);
                        t += tau;
                        remaining -= tau;
                        impacts.push(t);
                        if state[5] < MIN_REBOUND_SPEED {
                            return Outcome::Resting;
                        }
                        if remaining <= 0.0 {
                            break;
                        }
                    }
                    None => {
                        *state = self.flight.rk4_step(state, remaining);
                        break;
                    }
                }
            }
        }
        Outcome::Flying
    }
}
