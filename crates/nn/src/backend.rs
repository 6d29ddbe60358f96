//! Device helpers: which backend runs the models, autodiff, seeding.
//!
//! burn 0.22 selects the backend at runtime through [`Device`]; a tensor's device decides where
//! it is computed and whether autodiff records it. Models in this crate take `&Device` in their
//! `init` functions and work on any device, so engines pick the device once:
//!
//! ```
//! use inbetween_nn::backend;
//! let infer = backend::cpu();             // flex, no gradients
//! let train = backend::cpu_autodiff();    // flex + autodiff for training
//! backend::seed(&train, 7);               // parameter init and random tensors become reproducible
//! # let _ = infer;
//! ```

pub use burn::tensor::{Device, Tensor};

/// The default CPU device: burn's pure-Rust flex backend.
pub fn cpu() -> Device {
    Device::flex()
}

/// The flex CPU device with autodiff enabled: parameters created on it are trainable.
pub fn cpu_autodiff() -> Device {
    Device::flex().autodiff()
}

/// The same device with autodiff enabled (idempotent).
pub fn with_autodiff(device: &Device) -> Device {
    device.clone().autodiff()
}

/// The same device without autodiff, for inference (idempotent).
pub fn without_autodiff(device: &Device) -> Device {
    device.clone().without_autodiff()
}

/// Seed the device's random number generator. Parameter initialisation and
/// [`Tensor::random`] draw from it, so two runs seeded alike start from bit-identical weights.
///
/// burn notes the seed may be global to the backend rather than per device; seed right before
/// building a model and do not share the device across threads while doing so.
pub fn seed(device: &Device, seed: u64) {
    device.seed(seed);
}

/// Serialises [`seeded`] sections: flex keeps one random generator for the whole process.
static SEED_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Seed the device and run `f` (e.g. build a model, draw random inputs) while holding a
/// process-wide lock, so other threads that also go through `seeded` cannot draw from the shared
/// generator in between. flex's generator is global to the process: a bare [`seed`] followed by
/// initialisation is only reproducible when no other thread uses random tensors meanwhile
/// (parallel tests do). Random draws outside any `seeded` section are not excluded.
pub fn seeded<T>(device: &Device, seed: u64, f: impl FnOnce() -> T) -> T {
    let _guard = SEED_LOCK.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    device.seed(seed);
    f()
}

// flex is built with its `rayon` and `simd` features (workspace Cargo.toml): one op may use every
// core of rayon's pool, and gives bit-identical results on any number of threads (see
// `train::tests::thread_count_does_not_change_the_result`).

/// Visitor that reads every float parameter once, which runs burn's lazy initialisers.
struct InitializeParams;

impl burn::module::ModuleVisitor for InitializeParams {
    fn visit_float<const D: usize>(&mut self, param: &burn::module::Param<Tensor<D>>) {
        if !param.is_initialized() {
            let _ = param.val();
        }
    }
}

/// Build a module with `build` inside [`seeded`] and run all its parameter initialisers before
/// the lock is released.
///
/// burn initialises parameters lazily, on first use: a model built inside `seeded` but first
/// used outside it would draw its weights later, from whatever state the shared generator is in
/// then. This forces the draws to happen under the seed.
pub fn seeded_module<M: burn::module::Module>(device: &Device, seed: u64, build: impl FnOnce(&Device) -> M) -> M {
    seeded(device, seed, || {
        let module = build(device);
        module.visit(&mut InitializeParams);
        module
    })
}

/// The CUDA device at `index` (only with the crate feature `cuda`, which does not build offline).
#[cfg(feature = "cuda")]
pub fn cuda(index: usize) -> Device {
    Device::cuda(index)
}

/// The CUDA device at `index` with autodiff (only with the crate feature `cuda`).
#[cfg(feature = "cuda")]
pub fn cuda_autodiff(index: usize) -> Device {
    Device::cuda(index).autodiff()
}

/// Human-readable name of the backend a device uses, for logs and bench tables.
pub fn describe(device: &Device) -> String {
    format!("{device:?}{}", if device.is_autodiff() { " (autodiff)" } else { "" })
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::nn::LinearConfig;
    use burn::tensor::Distribution;

    fn weights(linear: &burn::nn::Linear) -> Vec<f32> {
        linear.weight.val().into_data().try_to_vec::<f32>().unwrap()
    }

    #[test]
    fn seeded_module_draws_weights_under_the_seed() {
        let device = cpu();
        let a = seeded_module(&device, 5, |d| LinearConfig::new(4, 3).init(d));
        // Random draws between the builds must not leak into `a`'s (lazy) initialisation.
        let _noise = Tensor::<1>::random([100], Distribution::Default, &device);
        let b = seeded_module(&device, 5, |d| LinearConfig::new(4, 3).init(d));
        assert_eq!(weights(&a), weights(&b));
        let c = seeded_module(&device, 6, |d| LinearConfig::new(4, 3).init(d));
        assert_ne!(weights(&a), weights(&c));
    }

    #[test]
    fn autodiff_helpers_toggle_the_device() {
        let device = cpu();
        assert!(!device.is_autodiff());
        assert!(with_autodiff(&device).is_autodiff());
        assert!(!without_autodiff(&cpu_autodiff()).is_autodiff());
        assert!(describe(&cpu_autodiff()).ends_with("(autodiff)"));
    }
}
