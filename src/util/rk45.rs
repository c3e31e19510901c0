//! Adaptive Dormand-Prince RK45 for small autonomous systems, with the step control of scipy's `solve_ivp`
//! (RMS error norm, safety 0.9, step factor within [0.2, 10], no growth right after a rejection, Hairer's
//! initial step): the integrator the thesis' simulators were run with, so the same tolerances give the same
//! accuracy.
//!
//! (The `ode_solvers` crate's Dopri5 was tried first: with its default dense output it returned diverged
//! values for starts at rest, and with sparse output it stepped over the unicycle's friction kink at v = 0
//! without a rejection, off by up to 0.3 m/s; scipy's controller rejects those steps.)

/// Butcher tableau (the nodes c are not needed for autonomous systems).
const A: [[f64; 5]; 6] = [
    [0.0; 5],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0],
];
/// Fifth-order weights (the solution carried on).
const B: [f64; 6] = [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0];
/// Error weights over the six stages and the first-same-as-last seventh.
const E: [f64; 7] =
    [-71.0 / 57600.0, 0.0, 71.0 / 16695.0, -71.0 / 1920.0, 17253.0 / 339200.0, -22.0 / 525.0, 1.0 / 40.0];
const SAFETY: f64 = 0.9;
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 10.0;
/// Steps per call before giving up (a stiff stretch can need thousands; this bounds a call's time).
const MAX_STEPS: usize = 1_000_000;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rk45Error {
    /// The step size fell below what the time variable can resolve.
    StepUnderflow {
        t: f64,
    },
    TooManySteps {
        t: f64,
    },
    /// The right-hand side returned a non-finite value.
    NonFinite {
        t: f64,
    },
}

fn rms<const N: usize>(values: impl Iterator<Item = f64>) -> f64 {
    (values.map(|v| v * v).sum::<f64>() / N as f64).sqrt()
}

/// y(duration) of dy/dt = f(y) from y(0) = y0, with relative and absolute tolerances `rtol`, `atol`.
pub fn solve<const N: usize, F>(f: F, y0: [f64; N], duration: f64, rtol: f64, atol: f64) -> Result<[f64; N], Rk45Error>
where
    F: Fn(&[f64; N]) -> [f64; N],
{
    solve_with_regions(f, y0, duration, rtol, atol, |_: &[f64; N]| 1)
}

/// As [`solve`], for right-hand sides that are smooth inside each region `region(y)` names and may change
/// sharply between regions (a kink: give it a narrow region of its own). An embedded error estimate cannot
/// see a kink that falls between a step's stages: a step may jump over it with a small estimated error and a
/// large true one. So a step that ends in another region is cut just over the edge of its own (bisection on
/// its length: no stage before the edge looks past it), and the step control starts afresh there; inside the
/// kink's region steps stay inside it, small enough to resolve it.
pub fn solve_with_regions<const N: usize, F, S>(
    f: F,
    y0: [f64; N],
    duration: f64,
    rtol: f64,
    atol: f64,
    region: S,
) -> Result<[f64; N], Rk45Error>
where
    F: Fn(&[f64; N]) -> [f64; N],
    S: Fn(&[f64; N]) -> i32,
{
    let mut t = 0.0;
    let mut y = y0;
    let mut k0 = f(&y);
    if y.iter().chain(&k0).any(|v| !v.is_finite()) {
        return Err(Rk45Error::NonFinite { t });
    }
    if duration <= 0.0 {
        return Ok(y);
    }
    let mut h = initial_step(&f, &y, &k0, rtol, atol).min(duration);
    for _ in 0..MAX_STEPS {
        let min_step = 10.0 * (next_up(t) - t);
        let mut rejected = false;
        loop {
            if h < min_step {
                return Err(Rk45Error::StepUnderflow { t });
            }
            let last = t + h >= duration;
            let h_step = if last { duration - t } else { h };
            let (y_new, k_new, error) = dormand_prince_step(&f, &y, &k0, h_step);
            if y_new.iter().chain(&k_new).any(|v| !v.is_finite()) {
                return Err(Rk45Error::NonFinite { t: t + h_step });
            }
            let norm = rms::<N>((0..N).map(|i| error[i] / (atol + rtol * y[i].abs().max(y_new[i].abs()))));
            if norm >= 1.0 {
                h = h_step * (SAFETY * norm.powf(-0.2)).max(MIN_FACTOR);
                rejected = true;
                continue;
            }
            let start_region = region(&y);
            if region(&y_new) != start_region {
                let inside = |y: &[f64; N]| region(y) == start_region;
                let cut = leaving_step(&f, &y, &k0, h_step, inside);
                let (y_cut, k_cut, _) = dormand_prince_step(&f, &y, &k0, cut);
                t += cut;
                y = y_cut;
                k0 = k_cut;
                h = initial_step(&f, &y, &k0, rtol, atol).min(duration - t);
                break;
            }
            let factor = if norm == 0.0 { MAX_FACTOR } else { (SAFETY * norm.powf(-0.2)).min(MAX_FACTOR) };
            let factor = if rejected { factor.min(1.0) } else { factor };
            t = if last { duration } else { t + h_step };
            y = y_new;
            k0 = k_new;
            h = h_step * factor;
            if last {
                return Ok(y);
            }
            break;
        }
        if t >= duration {
            return Ok(y);
        }
    }
    Err(Rk45Error::TooManySteps { t })
}

/// The shortest step length (to 1e-9 of `h`) that evaluates the right-hand side outside the start's
/// region: the step just over the edge, all but a 1e-9 sliver of it computed inside.
fn leaving_step<const N: usize, F, S>(f: &F, y: &[f64; N], k0: &[f64; N], h: f64, inside: S) -> f64
where
    F: Fn(&[f64; N]) -> [f64; N],
    S: Fn(&[f64; N]) -> bool,
{
    let (mut clean, mut crossing) = (0.0, h);
    while crossing - clean > 1e-9 * h {
        let mid = 0.5 * (clean + crossing);
        if stages_inside(f, y, k0, mid, &inside) {
            clean = mid;
        } else {
            crossing = mid;
        }
    }
    crossing
}

/// Whether every point where a step of length `h` evaluates `f`, and its end, satisfy `inside`.
fn stages_inside<const N: usize, F, S>(f: &F, y: &[f64; N], k0: &[f64; N], h: f64, inside: &S) -> bool
where
    F: Fn(&[f64; N]) -> [f64; N],
    S: Fn(&[f64; N]) -> bool,
{
    let mut k = [[0.0; N]; 6];
    k[0] = *k0;
    for s in 1..6 {
        let ys = stage_point(y, &k, s, h);
        if !inside(&ys) {
            return false;
        }
        k[s] = f(&ys);
    }
    inside(&fifth_order_end(y, &k, h))
}

/// y + h·Σ B_s k_s over the six stages.
fn fifth_order_end<const N: usize>(y: &[f64; N], k: &[[f64; N]], h: f64) -> [f64; N] {
    let mut y_new = *y;
    for (s, b) in B.iter().enumerate() {
        for i in 0..N {
            y_new[i] += h * b * k[s][i];
        }
    }
    y_new
}

fn stage_point<const N: usize>(y: &[f64; N], k: &[[f64; N]], s: usize, h: f64) -> [f64; N] {
    let mut ys = *y;
    for (j, a) in A[s][..s].iter().enumerate() {
        for i in 0..N {
            ys[i] += h * a * k[j][i];
        }
    }
    ys
}

fn next_up(t: f64) -> f64 {
    f64::from_bits(t.to_bits() + 1).max(f64::MIN_POSITIVE)
}

/// One step: the fifth-order solution, the derivative there (the next step's first stage) and the error
/// estimate h·Σ E_i k_i.
fn dormand_prince_step<const N: usize, F>(f: &F, y: &[f64; N], k0: &[f64; N], h: f64) -> ([f64; N], [f64; N], [f64; N])
where
    F: Fn(&[f64; N]) -> [f64; N],
{
    let mut k = [[0.0; N]; 7];
    k[0] = *k0;
    for s in 1..6 {
        k[s] = f(&stage_point(y, &k, s, h));
    }
    let y_new = fifth_order_end(y, &k, h);
    k[6] = f(&y_new);
    let mut error = [0.0; N];
    for (s, e) in E.iter().enumerate() {
        for i in 0..N {
            error[i] += h * e * k[s][i];
        }
    }
    (y_new, k[6], error)
}

/// Hairer, Nørsett & Wanner's starting step (what scipy uses), for order 4 error estimates.
fn initial_step<const N: usize, F>(f: &F, y0: &[f64; N], f0: &[f64; N], rtol: f64, atol: f64) -> f64
where
    F: Fn(&[f64; N]) -> [f64; N],
{
    let scale: Vec<f64> = y0.iter().map(|v| atol + v.abs() * rtol).collect();
    let d0 = rms::<N>((0..N).map(|i| y0[i] / scale[i]));
    let d1 = rms::<N>((0..N).map(|i| f0[i] / scale[i]));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 { 1e-6 } else { 0.01 * d0 / d1 };
    let mut y1 = *y0;
    for i in 0..N {
        y1[i] += h0 * f0[i];
    }
    let f1 = f(&y1);
    let d2 = rms::<N>((0..N).map(|i| (f1[i] - f0[i]) / scale[i])) / h0;
    let h1 = if d1 <= 1e-15 && d2 <= 1e-15 { (h0 * 1e-3).max(1e-6) } else { (0.01 / d1.max(d2)).powf(1.0 / 5.0) };
    (100.0 * h0).min(h1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_decay_to_tolerance() {
        let y = solve(|y: &[f64; 1]| [-y[0]], [1.0], 2.0, 1e-8, 1e-10).unwrap();
        assert!((y[0] - (-2.0f64).exp()).abs() < 1e-8, "{}", y[0]);
    }

    #[test]
    fn harmonic_oscillator_over_a_period() {
        let y = solve(|y: &[f64; 2]| [y[1], -y[0]], [1.0, 0.0], std::f64::consts::TAU, 1e-9, 1e-12).unwrap();
        assert!((y[0] - 1.0).abs() < 1e-7 && y[1].abs() < 1e-7, "{y:?}");
    }

    #[test]
    fn polynomials_of_low_degree_are_exact() {
        // Constant acceleration: RK is exact, whatever the steps.
        let y = solve(|y: &[f64; 2]| [y[1], 3.0], [0.5, 0.0], 0.01, 1e-3, 1e-6).unwrap();
        assert!((y[0] - (0.5 + 1.5e-4)).abs() < 1e-15 && (y[1] - 0.03).abs() < 1e-15, "{y:?}");
    }

    #[test]
    fn a_kink_between_stages_is_cut_out_and_resolved() {
        // dv/dt = −395 while v > 0, −235 after a smoothed switch at v = 0 (Coulomb friction reversing).
        let f = |y: &[f64; 1]| [-315.0 - 80.0 * (1000.0 * y[0]).tanh()];
        let mut fine = 2.75;
        let h = 0.01 / 200_000.0;
        for _ in 0..200_000 {
            let k1 = f(&[fine])[0];
            let k2 = f(&[fine + h / 2.0 * k1])[0];
            let k3 = f(&[fine + h / 2.0 * k2])[0];
            let k4 = f(&[fine + h * k3])[0];
            fine += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        let band =
            |y: &[f64; 1]| if y[0].abs() > 0.01 { 100 * y[0].signum() as i32 } else { (y[0] / 0.002).floor() as i32 };
        let cut = solve_with_regions(f, [2.75], 0.01, 1e-3, 1e-6, band).unwrap()[0];
        assert!((cut - fine).abs() < 1e-5, "{cut} vs {fine}");
    }

    #[test]
    fn non_finite_derivatives_are_an_error() {
        assert!(matches!(solve(|_: &[f64; 1]| [f64::NAN], [1.0], 1.0, 1e-3, 1e-6), Err(Rk45Error::NonFinite { .. })));
    }
}
