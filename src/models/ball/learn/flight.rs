//! Batched free flight g_free(z, Δt) (eq. 6.21) and its Jacobians J_z (eq. C.1-C.5) and J_Δt (eq. C.6), the
//! tensor counterpart of `models::ball::flight`.

use burn::tensor::{Device, Tensor};

use super::device::{eye, tensor, zeros};
use super::linalg::{cross_matrix, cross_matrix_map};
use crate::models::ball::BallPhysics;

/// Constant tensors of one batch size, built once per forward pass.
pub struct Consts {
    pub batch: usize,
    cross: Tensor<2>,
    eye3: Tensor<3>,
    /// Rows of p in J_z: the identity, and Δt at (i, 3 + i) per unit Δt \[B, 3, 11\] each.
    p_rows_eye: Tensor<3>,
    p_rows_dt: Tensor<3>,
    /// Columns v … a_m of the identity's v rows \[B, 3, 8\].
    v_rows_eye: Tensor<3>,
    /// Rows of ω, a_d, a_m in J_z: the identity's \[B, 5, 11\].
    rest_rows: Tensor<3>,
    zeros_3x3: Tensor<3>,
    zeros_5: Tensor<2>,
    gravity: Tensor<2>,
}

impl Consts {
    pub fn new(batch: usize, physics: &BallPhysics, device: &Device) -> Self {
        let mut pv = vec![0.0; 33];
        for i in 0..3 {
            pv[11 * i + 3 + i] = 1.0;
        }
        let eye11 = eye(11, device).unsqueeze::<3>().repeat_dim(0, batch);
        Consts {
            batch,
            cross: cross_matrix_map(device),
            eye3: eye(3, device).unsqueeze(),
            p_rows_eye: eye11.clone().slice([0..batch, 0..3, 0..11]),
            p_rows_dt: tensor(pv, [1, 3, 11], device).repeat_dim(0, batch),
            v_rows_eye: eye11.clone().slice([0..batch, 3..6, 3..11]),
            rest_rows: eye11.slice([0..batch, 6..11, 0..11]),
            zeros_3x3: zeros([batch, 3, 3], device),
            zeros_5: zeros([batch, 5], device),
            gravity: tensor(vec![0.0, 0.0, -physics.gravity], [1, 3], device),
        }
    }
}

/// A step length: the camera period for every sample, or one per sample \[B, 1\] (the pieces of an impact step).
#[derive(Clone)]
pub enum StepLen {
    Fixed(f64),
    PerSample(Box<Tensor<2>>),
}

impl StepLen {
    fn scale_rows(&self, x: Tensor<2>) -> Tensor<2> {
        match self {
            StepLen::Fixed(dt) => x.mul_scalar(*dt),
            StepLen::PerSample(dt) => x * (**dt).clone(),
        }
    }

    fn scale_matrices(&self, x: Tensor<3>) -> Tensor<3> {
        match self {
            StepLen::Fixed(dt) => x.mul_scalar(*dt),
            StepLen::PerSample(dt) => x * (**dt).clone().unsqueeze_dim::<3>(2),
        }
    }
}

/// The quantities of one state that g_free and its Jacobians share.
pub struct Flight {
    v: Tensor<2>,
    speed: Tensor<2>,
    ad: Tensor<2>,
    am: Tensor<2>,
    kd: Tensor<2>,
    km: Tensor<2>,
    w_cross: Tensor<3>,
    v_cross: Tensor<3>,
    w_x_v: Tensor<2>,
    /// ż = (v, a, 0, 0, 0), which is also J_Δt (eq. C.6) \[B, 11\].
    pub rate: Tensor<2>,
}

/// Evaluates the flight quantities at states x \[B, 11\].
pub fn flight(x: &Tensor<2>, k: &Consts, physics: &BallPhysics) -> Flight {
    let b = k.batch;
    let v = x.clone().slice([0..b, 3..6]);
    let w = x.clone().slice([0..b, 6..9]);
    let ad = x.clone().slice([0..b, 9..10]);
    let am = x.clone().slice([0..b, 10..11]);
    let speed = v.clone().square().sum_dim(1).sqrt();
    let kd = ad.clone().square().add_scalar(physics.coeff_offset);
    let km = am.clone().square().add_scalar(physics.coeff_offset);
    let w_cross = cross_matrix(w, &k.cross);
    let v_cross = cross_matrix(v.clone(), &k.cross);
    let w_x_v = w_cross.clone().matmul(v.clone().unsqueeze_dim(2)).reshape([b, 3]);
    // v̇ = −k_d ‖v‖ v + k_m ω × v + g (eq. 6.18).
    let accel = (kd.clone() * speed.clone()).neg() * v.clone() + km.clone() * w_x_v.clone() + k.gravity.clone();
    let rate = Tensor::cat(vec![v.clone(), accel, k.zeros_5.clone()], 1);
    Flight { v, speed, ad, am, kd, km, w_cross, v_cross, w_x_v, rate }
}

/// g_free(x, Δt) for the state the flight quantities were evaluated at.
pub fn free_step(x: &Tensor<2>, f: &Flight, dt: &StepLen) -> Tensor<2> {
    x.clone() + dt.scale_rows(f.rate.clone())
}

/// J_z(x, Δt) \[B, 11, 11\], assembled row block by row block: on \[B, 11, 11\] every operation costs several times
/// more than on the \[B, 3, ·\] blocks, forward and backward, so the full matrix is formed once.
pub fn free_jacobian(f: &Flight, dt: &StepLen, k: &Consts) -> Tensor<3> {
    let b = k.batch;
    let v_col = f.v.clone().unsqueeze_dim::<3>(2);
    let speed = f.speed.clone().unsqueeze_dim::<3>(2);
    // ∂(‖v‖v)/∂v = ‖v‖ I + v vᵀ/‖v‖; the clamp only keeps 0/0 out at v = 0, where the outer product is 0 anyway.
    let d_norm_v = speed.clone() * k.eye3.clone()
        + v_col.clone().matmul(v_col.swap_dims(1, 2)) / speed.clamp_min(f64::MIN_POSITIVE);
    let kd = f.kd.clone().unsqueeze_dim::<3>(2);
    let km = f.km.clone().unsqueeze_dim::<3>(2);
    // ω × v = [ω]ₓ v = −[v]ₓ ω.
    let d_v = d_norm_v * kd.neg() + f.w_cross.clone() * km.clone();
    let d_w = f.v_cross.clone() * km.neg();
    let d_ad = (f.v.clone() * f.speed.clone() * f.ad.clone()).mul_scalar(-2.0).reshape([b, 3, 1]);
    let d_am = (f.w_x_v.clone() * f.am.clone()).mul_scalar(2.0).reshape([b, 3, 1]);
    let v_rows = Tensor::cat(vec![d_v, d_w, d_ad, d_am], 2);
    let v_rows = Tensor::cat(vec![k.zeros_3x3.clone(), k.v_rows_eye.clone() + dt.scale_matrices(v_rows)], 2);
    let p_rows = k.p_rows_eye.clone() + dt.scale_matrices(k.p_rows_dt.clone());
    Tensor::cat(vec![p_rows, v_rows, k.rest_rows.clone()], 1)
}
