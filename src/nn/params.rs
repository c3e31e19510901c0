//! A module's parameters as plain named f32 buffers, in the module's own visiting order. Our optimizer,
//! checkpoints (safetensors), best-model snapshots and the fast inference path all work on these buffers; burn
//! is used for what it is best at, the forward pass and autodiff.

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::tensor::{DType, Device, Gradients, Tensor, TensorData};

use crate::error::{Error, Result};

/// The element types parameters are kept in: f32 for networks, f64 for gray-box models such as the ball EKF.
pub trait ParamScalar: burn::tensor::Element + num_traits::Float + Send + Sync + 'static {
    const DTYPE: DType;
}

impl ParamScalar for f32 {
    const DTYPE: DType = DType::F32;
}

impl ParamScalar for f64 {
    const DTYPE: DType = DType::F64;
}

fn tensor<T: ParamScalar, const D: usize>(values: Vec<T>, shape: [usize; D], device: &Device) -> Tensor<D> {
    Tensor::from_data(TensorData::new(values, shape), (device, T::DTYPE))
}

fn values<T: ParamScalar, const D: usize>(t: &Tensor<D>) -> Vec<T> {
    t.to_data().convert::<T>().try_to_vec::<T>().expect("float tensor data converts to the parameter type")
}

#[derive(Clone, Debug, PartialEq)]
pub struct NamedTensor<T = f32> {
    pub name: String,
    pub shape: Vec<usize>,
    pub values: Vec<T>,
}

/// Named tensors in a fixed order. Cloning is a deep copy: a snapshot never aliases live weights.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSet<T = f32> {
    pub tensors: Vec<NamedTensor<T>>,
}

impl<T> Default for ParamSet<T> {
    fn default() -> Self {
        ParamSet { tensors: Vec::new() }
    }
}

impl<T: ParamScalar> ParamSet<T> {
    /// Every float parameter of `module`, named by its path (`layer.0.weight`) after `rename`.
    pub fn from_module<M: Module>(module: &M, rename: impl Fn(&str) -> String) -> Self {
        let mut collector = Collector::<T> { path: Vec::new(), out: Vec::new() };
        module.visit(&mut collector);
        let tensors = collector
            .out
            .into_iter()
            .map(|(path, shape, values)| NamedTensor { name: rename(&path), shape, values })
            .collect();
        ParamSet { tensors }
    }

    /// Gradients of `module`'s parameters in the same order; zeros for parameters the loss did not reach.
    pub fn gradients<M: Module>(module: &M, grads: &Gradients) -> Vec<Vec<T>> {
        let mut collector = GradCollector::<T> { grads, out: Vec::new() };
        module.visit(&mut collector);
        collector.out
    }

    /// `module` with its parameters replaced by these values (same order and shapes as `from_module`).
    pub fn load_into<M: Module>(&self, module: M, device: &Device) -> Result<M> {
        let mut loader = Loader { source: &self.tensors, next: 0, device, error: None };
        let module = module.map(&mut loader);
        if let Some(e) = loader.error {
            return Err(e);
        }
        if loader.next != self.tensors.len() {
            return Err(Error::config(format!(
                "parameter set has {} tensors, the module {}",
                self.tensors.len(),
                loader.next
            )));
        }
        Ok(module)
    }

    pub fn get(&self, name: &str) -> Option<&NamedTensor<T>> {
        self.tensors.iter().find(|t| t.name == name)
    }

    pub fn len(&self) -> usize {
        self.tensors.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tensors.is_empty()
    }

    pub fn count(&self) -> usize {
        self.tensors.iter().map(|t| t.values.len()).sum()
    }

    /// Checks that `other` has the same names and shapes, in order (a checkpoint against a freshly built model).
    pub fn check_layout(&self, other: &ParamSet<T>, what: &str) -> Result<()> {
        if self.tensors.len() != other.tensors.len() {
            return Err(Error::config(format!(
                "{what}: {} tensors, expected {}",
                other.tensors.len(),
                self.tensors.len()
            )));
        }
        for (a, b) in self.tensors.iter().zip(&other.tensors) {
            if a.name != b.name || a.shape != b.shape {
                return Err(Error::config(format!(
                    "{what}: tensor '{}' {:?}, expected '{}' {:?}",
                    b.name, b.shape, a.name, a.shape
                )));
            }
        }
        Ok(())
    }

    pub fn values_mut(&mut self) -> Vec<&mut Vec<T>> {
        self.tensors.iter_mut().map(|t| &mut t.values).collect()
    }
}

struct Collector<T> {
    path: Vec<String>,
    out: Vec<(String, Vec<usize>, Vec<T>)>,
}

impl<T: ParamScalar> ModuleVisitor for Collector<T> {
    fn enter_module(&mut self, name: &str, _container_type: &str) {
        self.path.push(name.to_string());
    }

    fn exit_module(&mut self, _name: &str, _container_type: &str) {
        self.path.pop();
    }

    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let value = param.val();
        self.out.push((self.path.join("."), value.dims().to_vec(), values(&value)));
    }
}

struct GradCollector<'a, T> {
    grads: &'a Gradients,
    out: Vec<Vec<T>>,
}

impl<T: ParamScalar> ModuleVisitor for GradCollector<'_, T> {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let value = param.val();
        let grad = value.grad(self.grads).map(|g| values(&g));
        let n = value.dims().iter().product();
        self.out.push(grad.unwrap_or_else(|| vec![T::zero(); n]));
    }
}

struct Loader<'a, T> {
    source: &'a [NamedTensor<T>],
    next: usize,
    device: &'a Device,
    error: Option<Error>,
}

impl<T: ParamScalar> ModuleMapper for Loader<'_, T> {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        let index = self.next;
        self.next += 1;
        let dims = param.val().dims();
        let Some(source) = self.source.get(index) else {
            return param;
        };
        if source.shape != dims || source.values.len() != dims.iter().product::<usize>() {
            self.error.get_or_insert_with(|| {
                let name = format!("the shape of tensor '{}'", source.name);
                Error::bad_shape(name, format!("{:?}", source.shape), format!("{dims:?} (the module's)"))
            });
            return param;
        }
        Param::from_tensor(tensor(source.values.clone(), dims, self.device))
    }
}
