//! The trainable parameters Ψ of the ball EKF as a burn module, and the conversion to and from
//! [`BallModelParams`], which the fast nalgebra filter uses for filtering and prediction.

use burn::module::{Module, Param};
use burn::tensor::{Device, Tensor};

use super::device::{tensor, values};
use super::positive::{inverse_softplus, softplus, softplus_tensor};
use super::spin_net::SpinNet;
use crate::models::ball::{BallModelParams, BallPhysics};

/// Ψ without the physical constants. Variances are held as raw values x with variance \[x\]⊕ (Table C.1 lists
/// them as inv\[·\]⊕); C, a_d0 and a_m0 are unconstrained.
#[derive(Module, Debug)]
pub struct BallParamsModule {
    /// Impact matrix, row-major \[6, 6\].
    pub c: Param<Tensor<2>>,
    /// Raw diag(Q) \[11\].
    pub q: Param<Tensor<1>>,
    /// Raw diag(R) \[3\].
    pub r: Param<Tensor<1>>,
    /// Raw Σ_p, Σ_v \[3\] each.
    pub init_pos: Param<Tensor<1>>,
    pub init_vel: Param<Tensor<1>>,
    /// Raw σ_ω (broad spin prior) and σ_ω,ai (after the impact, launcher prior) \[3\] each.
    pub init_spin: Param<Tensor<1>>,
    pub init_spin_after_impact: Param<Tensor<1>>,
    /// Initial means of a_d and a_m \[1\] each.
    pub a_d0: Param<Tensor<1>>,
    pub a_m0: Param<Tensor<1>>,
    /// Raw initial variances of a_d and a_m \[1\] each.
    pub a_d_var: Param<Tensor<1>>,
    pub a_m_var: Param<Tensor<1>>,
    /// The launcher spin network of C.1.3; `None` trains with the broad spin prior.
    pub spin_net: Option<SpinNet>,
}

fn param<const D: usize>(v: Vec<f64>, shape: [usize; D], device: &Device) -> Param<Tensor<D>> {
    Param::from_tensor(tensor(v, shape, device))
}

fn raw(variances: &[f64], device: &Device) -> Param<Tensor<1>> {
    param(variances.iter().map(|&v| inverse_softplus(v)).collect(), [variances.len()], device)
}

fn read<const N: usize>(p: &Param<Tensor<1>>) -> [f64; N] {
    let v = values(&p.val());
    std::array::from_fn(|i| v[i])
}

fn read_variances<const N: usize>(p: &Param<Tensor<1>>) -> [f64; N] {
    read::<N>(p).map(softplus)
}

impl BallParamsModule {
    pub fn from_params(params: &BallModelParams, spin_net: Option<SpinNet>, device: &Device) -> Self {
        BallParamsModule {
            c: param(params.c.iter().flatten().copied().collect(), [6, 6], device),
            q: raw(&params.q_diag, device),
            r: raw(&params.r_diag, device),
            init_pos: raw(&params.init_pos_var, device),
            init_vel: raw(&params.init_vel_var, device),
            init_spin: raw(&params.init_spin_var, device),
            init_spin_after_impact: raw(&params.init_spin_var_after_impact, device),
            a_d0: param(vec![params.a_d0], [1], device),
            a_m0: param(vec![params.a_m0], [1], device),
            a_d_var: raw(&[params.a_d_var], device),
            a_m_var: raw(&[params.a_m_var], device),
            spin_net,
        }
    }

    /// The current values as parameters of the nalgebra model, with the given fixed physics.
    pub fn to_params(&self, physics: &BallPhysics) -> BallModelParams {
        let c = values(&self.c.val());
        BallModelParams {
            c: std::array::from_fn(|i| std::array::from_fn(|j| c[6 * i + j])),
            q_diag: read_variances(&self.q),
            r_diag: read_variances(&self.r),
            init_pos_var: read_variances(&self.init_pos),
            init_vel_var: read_variances(&self.init_vel),
            init_spin_var: read_variances(&self.init_spin),
            init_spin_var_after_impact: read_variances(&self.init_spin_after_impact),
            a_d0: read::<1>(&self.a_d0)[0],
            a_m0: read::<1>(&self.a_m0)[0],
            a_d_var: read_variances::<1>(&self.a_d_var)[0],
            a_m_var: read_variances::<1>(&self.a_m_var)[0],
            physics: physics.clone(),
        }
    }

    /// The constrained values as tensors, evaluated once per forward pass.
    pub fn resolve(&self) -> Resolved {
        Resolved {
            c: self.c.val(),
            q: softplus_tensor(self.q.val()),
            r: softplus_tensor(self.r.val()),
            init_pos: softplus_tensor(self.init_pos.val()),
            init_vel: softplus_tensor(self.init_vel.val()),
            init_spin: softplus_tensor(self.init_spin.val()),
            init_spin_after_impact: softplus_tensor(self.init_spin_after_impact.val()),
            a_d0: self.a_d0.val(),
            a_m0: self.a_m0.val(),
            a_d_var: softplus_tensor(self.a_d_var.val()),
            a_m_var: softplus_tensor(self.a_m_var.val()),
        }
    }
}

/// Ψ in the units the filter uses (variances, not raw values).
pub struct Resolved {
    pub c: Tensor<2>,
    pub q: Tensor<1>,
    pub r: Tensor<1>,
    pub init_pos: Tensor<1>,
    pub init_vel: Tensor<1>,
    pub init_spin: Tensor<1>,
    pub init_spin_after_impact: Tensor<1>,
    pub a_d0: Tensor<1>,
    pub a_m0: Tensor<1>,
    pub a_d_var: Tensor<1>,
    pub a_m_var: Tensor<1>,
}
