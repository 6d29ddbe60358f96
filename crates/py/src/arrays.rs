//! numpy arrays in: any real dtype is taken (converted to float32 in a new array when it is not
//! float32 already, so the caller's array is never modified), and a wrong dtype or shape is a
//! `ShapeError` that names the shape expected (`rotations: shape [5, 2, 3]; expected [T, J, 4]`).

use crate::errors::shape;
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// A float32 copy of `value` with `dims` (fixed sizes as numbers, free ones as names: `"T"`).
/// Returns the array and its shape.
pub fn f32_array(name: &str, value: &Bound<'_, PyAny>, dims: &[Dim]) -> PyResult<(Vec<f32>, Vec<usize>)> {
    let want = format!("[{}]", dims.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", "));
    let py = value.py();
    let arr: Bound<'_, PyArrayDyn<f32>> = match value.cast::<PyArrayDyn<f32>>() {
        Ok(a) => a.clone(),
        Err(_) => {
            let np = py.import("numpy")?;
            let any = np
                .call_method1("asarray", (value,))
                .map_err(|e| shape(format!("{name}: not an array ({e}); expected float32 {want}")))?;
            let kind: String = any.getattr("dtype")?.getattr("kind")?.extract()?;
            if !"fiu".contains(kind.as_str()) || kind.is_empty() {
                let dtype = any.getattr("dtype")?.str()?.to_string();
                return Err(shape(format!("{name}: dtype {dtype}; expected float32 {want}")));
            }
            any.call_method1("astype", ("float32",))?
                .cast_into::<PyArrayDyn<f32>>()
                .map_err(|e| shape(e.to_string()))?
        }
    };
    let got = arr.shape().to_vec();
    let mismatch = got.len() != dims.len()
        || got.iter().zip(dims).any(|(g, d)| matches!(d, Dim::Fixed(n) | Dim::Sized(_, n) if n != g));
    if mismatch {
        let sizes: Vec<String> = dims
            .iter()
            .filter_map(|d| match d {
                Dim::Sized(s, n) => Some(format!("{s} = {n}")),
                _ => None,
            })
            .collect();
        let with = if sizes.is_empty() { String::new() } else { format!(" with {}", sizes.join(", ")) };
        return Err(shape(format!("{name}: shape {got:?}; expected {want}{with}")));
    }
    let data = arr.to_vec().unwrap_or_else(|_| arr.readonly().as_array().iter().copied().collect());
    Ok((data, got))
}

/// One axis of an expected shape.
#[derive(Clone, Copy, Debug)]
pub enum Dim {
    Fixed(usize),
    Named(&'static str),
    /// A named size that is known already (the frames of another array).
    Sized(&'static str, usize),
}

impl std::fmt::Display for Dim {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Dim::Fixed(n) => write!(f, "{n}"),
            Dim::Named(s) | Dim::Sized(s, _) => f.write_str(s),
        }
    }
}
