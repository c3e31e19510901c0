//! What a resumed run needs of a method trained with our Adam: the live parameters and the optimizer's
//! moments and step count, as named tensors (`live.<name>`, `adam.exp_avg.<name>`, `adam.exp_avg_sq.<name>`,
//! `adam.step`), for f32 networks and f64 gray-box models alike.

use super::tensors::{StoredTensor, TensorData};
use crate::error::{Error, Result};
use crate::nn::params::ParamScalar;
use crate::nn::{Adam, ParamSet};

/// Element types a checkpoint stores.
pub trait StoredScalar: ParamScalar {
    fn stored(name: String, shape: Vec<usize>, values: Vec<Self>) -> StoredTensor;
    fn values(data: &TensorData) -> Option<&Vec<Self>>;
}

impl StoredScalar for f32 {
    fn stored(name: String, shape: Vec<usize>, values: Vec<Self>) -> StoredTensor {
        StoredTensor::f32(name, shape, values)
    }

    fn values(data: &TensorData) -> Option<&Vec<Self>> {
        match data {
            TensorData::F32(v) => Some(v),
            TensorData::F64(_) => None,
        }
    }
}

impl StoredScalar for f64 {
    fn stored(name: String, shape: Vec<usize>, values: Vec<Self>) -> StoredTensor {
        StoredTensor::f64(name, shape, values)
    }

    fn values(data: &TensorData) -> Option<&Vec<Self>> {
        match data {
            TensorData::F64(v) => Some(v),
            TensorData::F32(_) => None,
        }
    }
}

/// The parameters as stored weights, under their own names.
pub fn weights<T: StoredScalar>(params: &ParamSet<T>) -> Vec<StoredTensor> {
    params.tensors.iter().map(|t| T::stored(t.name.clone(), t.shape.clone(), t.values.clone())).collect()
}

pub fn save<T: StoredScalar>(params: &ParamSet<T>, adam: &Adam<T>) -> Vec<StoredTensor> {
    let mut out = Vec::with_capacity(3 * params.len() + 1);
    for (k, t) in params.tensors.iter().enumerate() {
        out.push(T::stored(format!("live.{}", t.name), t.shape.clone(), t.values.clone()));
        out.push(T::stored(format!("adam.exp_avg.{}", t.name), t.shape.clone(), adam.exp_avg[k].clone()));
        out.push(T::stored(format!("adam.exp_avg_sq.{}", t.name), t.shape.clone(), adam.exp_avg_sq[k].clone()));
    }
    out.push(StoredTensor::f64("adam.step", vec![1], vec![adam.step as f64]));
    out
}

/// Puts a saved state back into `params` and `adam`, checking every tensor's presence, type and size.
pub fn restore<T: StoredScalar>(state: &[StoredTensor], params: &mut ParamSet<T>, adam: &mut Adam<T>) -> Result<()> {
    let find = |name: &str, n: usize| -> Result<Vec<T>> {
        match state.iter().find(|t| t.name == name).and_then(|t| T::values(&t.data)) {
            Some(v) if v.len() == n => Ok(v.clone()),
            _ => Err(Error::config(format!(
                "training state lacks the tensor '{name}' with {n} values of the model's type"
            ))),
        }
    };
    for k in 0..params.len() {
        let (name, n) = (params.tensors[k].name.clone(), params.tensors[k].values.len());
        params.tensors[k].values = find(&format!("live.{name}"), n)?;
        adam.exp_avg[k] = find(&format!("adam.exp_avg.{name}"), n)?;
        adam.exp_avg_sq[k] = find(&format!("adam.exp_avg_sq.{name}"), n)?;
    }
    adam.step = match state.iter().find(|t| t.name == "adam.step").map(|t| &t.data) {
        Some(TensorData::F64(v)) if v.len() == 1 && v[0] >= 0.0 && v[0].fract() == 0.0 => v[0] as u64,
        _ => return Err(Error::config("training state lacks a valid 'adam.step'")),
    };
    Ok(())
}
