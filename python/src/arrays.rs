//! numpy in and out: anything array-like in (a float64 array is read in place, other inputs
//! through `numpy.asarray(x, dtype=float64)`), checked for shape and finiteness with the
//! argument's name in the message; float64 arrays out.

use dem::math::Tensor;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::errors::input;

fn as_float_array<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    np.getattr("asarray")?
        .call1((obj, np.getattr("float64")?))
        .map_err(|e| input(format!("`{name}`: not an array of numbers ({e})")))
}

/// A 1-D array of numbers as a vector (`name` is the argument's, for messages).
pub fn vec1(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<f64>> {
    let arr = as_float_array(obj, name)?;
    let ndim: usize = arr.getattr("ndim")?.extract()?;
    if ndim != 1 {
        return Err(input(format!(
            "`{name}`: a 1-D array is expected, got {ndim} dimensions"
        )));
    }
    let a: PyReadonlyArray1<'_, f64> = arr
        .cast_into::<PyArray1<f64>>()
        .map_err(|e| input(format!("`{name}`: {e}")))?
        .readonly();
    Ok(a.as_array().iter().copied().collect())
}

/// [`vec1`] with every value finite.
pub fn finite1(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<f64>> {
    let v = vec1(obj, name)?;
    check_finite(&v, name)?;
    Ok(v)
}

/// Refuses a NaN or infinite value, naming its index.
pub fn check_finite(v: &[f64], name: &str) -> PyResult<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(input(format!("`{name}`[{i}] is not finite ({})", v[i]))),
        None => Ok(()),
    }
}

/// An `(n, 2)` array of finite numbers as rows.
pub fn rows2(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<[f64; 2]>> {
    let arr = as_float_array(obj, name)?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    let arr = if shape.len() == 1 && shape[0] == 2 {
        arr.call_method1("reshape", ((1usize, 2usize),))?
    } else {
        arr
    };
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.len() != 2 || shape[1] != 2 {
        return Err(input(format!(
            "`{name}`: an (n, 2) array is expected, got shape {shape:?}"
        )));
    }
    let a: PyReadonlyArray2<'_, f64> = arr
        .cast_into::<PyArray2<f64>>()
        .map_err(|e| input(format!("`{name}`: {e}")))?
        .readonly();
    let view = a.as_array();
    let rows: Vec<[f64; 2]> = view.rows().into_iter().map(|r| [r[0], r[1]]).collect();
    for (i, r) in rows.iter().enumerate() {
        if !(r[0].is_finite() && r[1].is_finite()) {
            return Err(input(format!(
                "`{name}`[{i}] is not finite ({}, {})",
                r[0], r[1]
            )));
        }
    }
    Ok(rows)
}

/// A vector as a 1-D float64 array.
pub fn out1(py: Python<'_>, v: Vec<f64>) -> Bound<'_, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

/// Rows of `K` numbers as an `(n, K)` float64 array.
pub fn out2<'py, const K: usize>(py: Python<'py>, rows: &[[f64; K]]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = rows.iter().flat_map(|r| r.iter().copied()).collect();
    Array2::from_shape_vec((rows.len(), K), flat)
        .expect("rows of K values fill an (n, K) array")
        .into_pyarray(py)
}

/// 2×2 tensors as an `(n, 2, 2)` float64 array, `a[k, i, j] = T_k[i, j]`.
pub fn out_tensors<'py>(py: Python<'py>, ts: &[Tensor]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f64> = ts
        .iter()
        .flat_map(|t| [t[(0, 0)], t[(0, 1)], t[(1, 0)], t[(1, 1)]])
        .collect();
    PyArray1::from_vec(py, flat)
        .reshape([ts.len(), 2, 2])
        .map(|a| a.into_any())
}

/// One 2×2 tensor as a `(2, 2)` float64 array.
pub fn out_tensor<'py>(py: Python<'py>, t: &Tensor) -> PyResult<Bound<'py, PyAny>> {
    out_tensors(py, std::slice::from_ref(t))?.get_item(0)
}
