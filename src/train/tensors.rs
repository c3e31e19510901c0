//! Named tensors on disk as safetensors: f32 for networks, f64 for gray-box parameters. Layout and names are
//! what PyTorch's `safetensors.torch.load_file` returns, so a PyTorch user can load our weights directly.

use std::collections::HashMap;
use std::path::Path;

use safetensors::tensor::{Dtype, TensorView};
use safetensors::SafeTensors;

use crate::error::{Error, Result};
use crate::nn::{NamedTensor, ParamSet};
use crate::util::domain::Domain;

/// Checkpoint files larger than this are refused before reading (the largest preset is a few MB).
pub const MAX_TENSOR_FILE_BYTES: u64 = 1 << 31;

/// The one metadata entry we write: safetensors keeps metadata in a hash map, so a second entry would make the
/// header's byte order (and the file's bytes) vary from run to run.
const METADATA_KEY: &str = "format";
const METADATA_VALUE: &str = "mbrl";

#[derive(Clone, Debug, PartialEq)]
pub enum TensorData {
    F32(Vec<f32>),
    F64(Vec<f64>),
}

#[derive(Clone, Debug, PartialEq)]
pub struct StoredTensor {
    pub name: String,
    pub shape: Vec<usize>,
    pub data: TensorData,
}

impl StoredTensor {
    pub fn f32(name: impl Into<String>, shape: Vec<usize>, values: Vec<f32>) -> Self {
        StoredTensor { name: name.into(), shape, data: TensorData::F32(values) }
    }

    pub fn f64(name: impl Into<String>, shape: Vec<usize>, values: Vec<f64>) -> Self {
        StoredTensor { name: name.into(), shape, data: TensorData::F64(values) }
    }

    fn bytes(&self) -> Vec<u8> {
        match &self.data {
            TensorData::F32(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            TensorData::F64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        }
    }
}

/// Serializes tensors (names must be unique) to safetensors bytes.
pub fn to_bytes(tensors: &[StoredTensor]) -> Result<Vec<u8>> {
    let mut names = std::collections::HashSet::new();
    if let Some(t) = tensors.iter().find(|t| !names.insert(t.name.as_str())) {
        return Err(Error::config(format!(
            "two tensors are named '{}'; a safetensors file needs distinct names",
            t.name
        )));
    }
    let raw: Vec<(String, Dtype, Vec<usize>, Vec<u8>)> = tensors
        .iter()
        .map(|t| {
            let dtype = match t.data {
                TensorData::F32(_) => Dtype::F32,
                TensorData::F64(_) => Dtype::F64,
            };
            (t.name.clone(), dtype, t.shape.clone(), t.bytes())
        })
        .collect();
    let mut views = Vec::with_capacity(raw.len());
    for (name, dtype, shape, bytes) in &raw {
        let view = TensorView::new(*dtype, shape.clone(), bytes)
            .map_err(|e| Error::config(format!("tensor '{name}' {shape:?}: {e}")))?;
        views.push((name.clone(), view));
    }
    let metadata = HashMap::from([(METADATA_KEY.to_string(), METADATA_VALUE.to_string())]);
    safetensors::serialize(views, Some(metadata)).map_err(|e| Error::config(format!("safetensors: {e}")))
}

/// Reads every tensor of a safetensors file, checking dtypes and that each tensor's byte length matches its
/// shape (safetensors validates offsets against the buffer; we bound the buffer by the file's real size).
pub fn read(path: &Path) -> Result<Vec<StoredTensor>> {
    let bytes = super::checkpoint::read_bounded(path, MAX_TENSOR_FILE_BYTES)?;
    parse(path, &bytes)
}

pub fn parse(path: &Path, bytes: &[u8]) -> Result<Vec<StoredTensor>> {
    let file = SafeTensors::deserialize(bytes)
        .map_err(|e| Error::bad_file(path, format!("not a readable safetensors file: {e}")))?;
    let mut out = Vec::new();
    let mut entries = file.tensors();
    entries.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, view) in entries {
        let shape = view.shape().to_vec();
        let data = view.data();
        let elements = shape.iter().try_fold(1usize, |acc, d| acc.checked_mul(*d));
        let bad = |what: &str| Error::bad_file(path, format!("tensor '{name}': {what}"));
        let data = match view.dtype() {
            Dtype::F32 if elements.and_then(|n| n.checked_mul(4)) == Some(data.len()) => {
                TensorData::F32(data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
            }
            Dtype::F64 if elements.and_then(|n| n.checked_mul(8)) == Some(data.len()) => TensorData::F64(
                data.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8-byte chunk"))).collect(),
            ),
            Dtype::F32 | Dtype::F64 => return Err(bad("byte length does not match its shape")),
            other => return Err(bad(&format!("dtype {other:?}; expected F32 or F64"))),
        };
        let finite = match &data {
            TensorData::F32(v) => v.iter().all(|x| x.is_finite()),
            TensorData::F64(v) => v.iter().all(|x| x.is_finite()),
        };
        if !finite {
            return Err(bad("contains NaN or infinite values"));
        }
        out.push(StoredTensor { name, shape, data });
    }
    Ok(out)
}

/// Trained weights, biases and normalizer statistics of every model stay far inside this; a larger value
/// saturates or overflows the f32 activations it feeds (NaN predictions, degenerate evaluations).
const WEIGHT: Domain = Domain::closed(-1e6, 1e6);
/// A tensor named `*.std` holds standard deviations (normalizers, latent scales), which divide.
const STD: Domain = Domain { lo: 0.0, lo_open: true, ..WEIGHT };

/// The weights of a model file, each within its domain: the error names the tensor and element.
pub fn check_weights(path: &Path, tensors: &[StoredTensor]) -> Result<()> {
    for tensor in tensors {
        let domain = if tensor.name.ends_with(".std") { STD } else { WEIGHT };
        let values: Box<dyn Iterator<Item = f64>> = match &tensor.data {
            TensorData::F32(v) => Box::new(v.iter().map(|&x| x as f64)),
            TensorData::F64(v) => Box::new(v.iter().copied()),
        };
        if let Some((i, x)) = values.enumerate().find(|(_, x)| !domain.contains(*x)) {
            let e = domain.check(&format!("tensor '{}'[{i}]", tensor.name), x).unwrap_err();
            return Err(Error::bad_file(path, e.to_string()));
        }
    }
    Ok(())
}

/// The f32 tensors named in `layout`, in its order and with its shapes; anything missing, extra or differently
/// shaped is an error naming the tensor.
pub fn to_params(path: &Path, stored: &[StoredTensor], layout: &ParamSet) -> Result<ParamSet> {
    if stored.len() != layout.len() {
        return Err(
            Error::bad_shape("the tensor count", stored.len(), format!("{} (this model's)", layout.len())).at(path)
        );
    }
    let mut tensors = Vec::with_capacity(layout.len());
    for expected in &layout.tensors {
        let found = stored
            .iter()
            .find(|t| t.name == expected.name)
            .ok_or_else(|| Error::bad_file(path, format!("tensor '{}' is missing", expected.name)))?;
        let TensorData::F32(values) = &found.data else {
            return Err(Error::bad_file(path, format!("tensor '{}' is not F32", expected.name)));
        };
        if found.shape != expected.shape {
            let name = format!("the shape of tensor '{}'", expected.name);
            return Err(Error::bad_shape(name, format!("{:?}", found.shape), format!("{:?}", expected.shape)).at(path));
        }
        tensors.push(NamedTensor { name: expected.name.clone(), shape: found.shape.clone(), values: values.clone() });
    }
    Ok(ParamSet { tensors })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Finite but absurd weights (1e19 in a bias made evaluations print NaN) and a zero standard deviation are
    /// refused by name.
    #[test]
    fn weights_outside_their_domain_are_named() {
        let path = Path::new("m.safetensors");
        let ok = StoredTensor::f32("input_normalizer.std", vec![2], vec![0.5, 2.0]);
        assert!(check_weights(path, std::slice::from_ref(&ok)).is_ok());
        let big = StoredTensor::f32("hidden.bias", vec![3], vec![0.0, 1e19, 0.0]);
        let err = check_weights(path, &[ok, big]).unwrap_err().to_string();
        assert!(err.contains("m.safetensors") && err.contains("tensor 'hidden.bias'[1] = "), "{err}");
        assert!(err.contains("expected a finite number in [-1e6, 1e6]"), "{err}");
        let zero = StoredTensor::f64("latent_scale.std", vec![1], vec![0.0]);
        let err = check_weights(path, &[zero]).unwrap_err().to_string();
        assert!(err.contains("tensor 'latent_scale.std'[0] = 0: expected a finite number in (0, 1e6]"), "{err}");
    }

    #[test]
    fn round_trip_and_same_bytes() {
        let tensors = vec![
            StoredTensor::f32("b.weight", vec![2, 2], vec![1.0, 2.0, 3.0, 4.0]),
            StoredTensor::f64("a", vec![1], vec![0.5]),
        ];
        let bytes = to_bytes(&tensors).unwrap();
        assert_eq!(bytes, to_bytes(&tensors).unwrap());
        let back = parse(Path::new("x"), &bytes).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0].name, "a");
        assert_eq!(back[1], tensors[0]);
    }

    #[test]
    fn two_tensors_of_one_name_are_an_error_not_a_panic() {
        let step = || StoredTensor::f64("adam.step", vec![1], vec![3.0]);
        let e = to_bytes(&[step(), step()]).unwrap_err().to_string();
        assert!(e.contains("adam.step"), "{e}");
    }

    #[test]
    fn garbage_and_nan_are_errors() {
        assert!(parse(Path::new("x"), b"\xff\xff\xff\xff\xff\xff\xff\x7fjunk").is_err());
        let bytes = to_bytes(&[StoredTensor::f32("w", vec![1], vec![f32::NAN])]).unwrap();
        let err = parse(Path::new("w.safetensors"), &bytes).unwrap_err().to_string();
        assert!(err.contains("w.safetensors") && err.contains("NaN"), "{err}");
    }
}
