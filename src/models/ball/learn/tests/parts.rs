//! Pieces of the learner on their own.

use super::super::device::{tensor, training_device, values};

#[test]
fn scratch_matmul() {
    let device = training_device();
    let b = 4;
    let a: Vec<f64> = (0..b * 3).map(|i| i as f64 * 0.37 + 1.0).collect();
    let m: Vec<f64> = (0..b * 3 * 5).map(|i| (i as f64 * 0.11).sin()).collect();
    let ta = tensor(a.clone(), [b, 1, 3], &device);
    let tm = tensor(m.clone(), [b, 3, 5], &device);
    let out = values(&ta.matmul(tm));
    for s in 0..b {
        for j in 0..5 {
            let e: f64 = (0..3).map(|k| a[3 * s + k] * m[15 * s + 5 * k + j]).sum();
            println!("{s} {j} {} {}", out[5 * s + j], e);
        }
    }
}
