//! Homogenisation of a snapshot (`homogenise`, docs/physics.md §2): per-grain and region mean
//! stress with its contact and inertia parts, solid fraction, coordination, fabric. Stresses in
//! Pa, tension positive, tensors as (2, 2) arrays `[[xx, xy], [yx, yy]]`.

use dem::math::Vector;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use homogenise::state::ContactCounting;
use homogenise::Region;

use crate::arrays::{out1, out2, out_tensor, out_tensors};
use crate::errors::{homogenise_err, input};
use crate::world::Snapshot;

/// `region` = None (the whole sample: the grains' bounding box) or `(x_min, y_min, x_max,
/// y_max)` (m); `y_slice` = `(y_min, y_max)`: the horizontal slice across the sample.
fn region_of(
    region: Option<(f64, f64, f64, f64)>,
    y_slice: Option<(f64, f64)>,
) -> PyResult<Region> {
    match (region, y_slice) {
        (None, None) => Ok(Region::Whole),
        (Some((x0, y0, x1, y1)), None) => Ok(Region::Rectangle {
            min: Vector::new(x0, y0),
            max: Vector::new(x1, y1),
        }),
        (None, Some((y_min, y_max))) => Ok(Region::Slice { y_min, y_max }),
        (Some(_), Some(_)) => Err(input("give `region` or `y_slice`, not both")),
    }
}

fn counting(
    force_threshold: f64,
    count_wall_contacts: bool,
    min_contacts: usize,
) -> ContactCounting {
    ContactCounting {
        force_threshold,
        count_wall_contacts,
        min_contacts,
    }
}

/// grain_stresses(snapshot)
/// --
///
/// Per-grain mean stress Σ_p = Σ_c + Σ_i of every disk (Pa, tension positive;
/// docs/physics.md §2.1): the contact (Love–Weber) term Σ_c = (1/V_p) Σ_α r_α ⊗ (x_α − c_p) and
/// the inertia term Σ_i = (I/(2 V_p)) (−ω̇ j + ω² 𝟙) of a rigid disk (Nicot et al. 2013).
///
/// Returns a dict of arrays over the disks, in body order: ``body`` (int64 index),
/// ``position`` (n, 2) m, ``radius`` (n,) m, ``volume`` (n,) m³, and ``contact``,
/// ``inertia``, ``total`` (n, 2, 2) Pa.
#[pyfunction]
pub fn grain_stresses<'py>(py: Python<'py>, snapshot: &Snapshot) -> PyResult<Bound<'py, PyDict>> {
    let g = homogenise::grain_stresses(&snapshot.inner).map_err(homogenise_err)?;
    let d = PyDict::new(py);
    d.set_item(
        "body",
        PyArray1::from_vec(py, g.iter().map(|s| s.body as i64).collect()),
    )?;
    let pos: Vec<[f64; 2]> = g.iter().map(|s| [s.position.x, s.position.y]).collect();
    d.set_item("position", out2(py, &pos))?;
    d.set_item("radius", out1(py, g.iter().map(|s| s.radius).collect()))?;
    d.set_item("volume", out1(py, g.iter().map(|s| s.volume).collect()))?;
    let c: Vec<_> = g.iter().map(|s| s.contact).collect();
    let i: Vec<_> = g.iter().map(|s| s.inertia).collect();
    let t: Vec<_> = g.iter().map(|s| s.total).collect();
    d.set_item("contact", out_tensors(py, &c)?)?;
    d.set_item("inertia", out_tensors(py, &i)?)?;
    d.set_item("total", out_tensors(py, &t)?)?;
    Ok(d)
}

/// mean_stress(snapshot, region=None, y_slice=None)
/// --
///
/// Region mean stress Σ = (1/A_R) Σ_p w_p A_p Σ_p (Pa, tension positive; the paper's
/// Σ = (1/V) Σ_p V_p Σ_p, docs/physics.md §2.2), w_p the exact fraction of disk p inside the
/// region.
///
/// region: None (the whole sample) or (x_min, y_min, x_max, y_max) in m; y_slice: (y_min, y_max)
/// in m, a horizontal slice across the sample.
///
/// Returns a dict: ``total``, ``contact``, ``inertia`` (2, 2) Pa; ``area`` (m², voids
/// included), ``grain_area`` (m²), ``grains`` (weighted count); ``pressure`` P = −tr Σ/2 (Pa,
/// compressive positive), ``shear_stress`` τ (Pa) and ``stress_ratio`` τ/P (None if P ≤ 0).
#[pyfunction]
#[pyo3(signature = (snapshot, region=None, y_slice=None))]
pub fn mean_stress<'py>(
    py: Python<'py>,
    snapshot: &Snapshot,
    region: Option<(f64, f64, f64, f64)>,
    y_slice: Option<(f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    let region = region_of(region, y_slice)?;
    let g = homogenise::grain_stresses(&snapshot.inner).map_err(homogenise_err)?;
    let s = homogenise::mean_stress(&snapshot.inner, &g, &region).map_err(homogenise_err)?;
    let inv = homogenise::invariants::stress_invariants(&s.total);
    let d = PyDict::new(py);
    d.set_item("total", out_tensor(py, &s.total)?)?;
    d.set_item("contact", out_tensor(py, &s.contact)?)?;
    d.set_item("inertia", out_tensor(py, &s.inertia)?)?;
    d.set_item("area", s.area)?;
    d.set_item("grain_area", s.grain_area)?;
    d.set_item("grains", s.grains)?;
    d.set_item("pressure", inv.pressure)?;
    d.set_item("shear_stress", inv.shear_stress)?;
    d.set_item("stress_ratio", inv.friction)?;
    Ok(d)
}

/// solid_fraction(snapshot, region=None, y_slice=None)
/// --
///
/// Solid fraction φ = Σ_p w_p π R_p² / A_R of the region (dimensionless); region as in
/// ``mean_stress``.
#[pyfunction]
#[pyo3(signature = (snapshot, region=None, y_slice=None))]
pub fn solid_fraction(
    snapshot: &Snapshot,
    region: Option<(f64, f64, f64, f64)>,
    y_slice: Option<(f64, f64)>,
) -> PyResult<f64> {
    let region = region_of(region, y_slice)?;
    homogenise::state::solid_fraction(&snapshot.inner, &region).map_err(homogenise_err)
}

/// coordination(snapshot, region=None, y_slice=None, force_threshold=0.0,
///              count_wall_contacts=True, min_contacts=2)
/// --
///
/// Coordination numbers of the grains in the region: a contact counts when f_n exceeds
/// `force_threshold` (N); a grain with fewer than `min_contacts` such contacts is a rattler.
/// Returns a dict: ``z`` (mean contacts per grain Z), ``z_without_rattlers`` (Z*),
/// ``rattler_fraction``, ``grains`` (weighted count).
#[pyfunction]
#[pyo3(signature = (snapshot, region=None, y_slice=None, force_threshold=0.0, count_wall_contacts=true, min_contacts=2))]
pub fn coordination<'py>(
    py: Python<'py>,
    snapshot: &Snapshot,
    region: Option<(f64, f64, f64, f64)>,
    y_slice: Option<(f64, f64)>,
    force_threshold: f64,
    count_wall_contacts: bool,
    min_contacts: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let region = region_of(region, y_slice)?;
    let c = homogenise::state::coordination(
        &snapshot.inner,
        &region,
        &counting(force_threshold, count_wall_contacts, min_contacts),
    )
    .map_err(homogenise_err)?;
    let d = PyDict::new(py);
    d.set_item("z", c.z)?;
    d.set_item("z_without_rattlers", c.z_without_rattlers)?;
    d.set_item("rattler_fraction", c.rattler_fraction)?;
    d.set_item("grains", c.grains)?;
    Ok(d)
}

/// fabric(snapshot, region=None, y_slice=None, force_threshold=0.0, count_wall_contacts=True,
///        min_contacts=2)
/// --
///
/// Fabric tensor F = (1/N_c) Σ n ⊗ n of the force-carrying contacts in the region (trace 1;
/// Satake 1982). Returns a dict: ``tensor`` (2, 2), ``contacts`` N_c, ``anisotropy``
/// a = 2 (λ₁ − λ₂) ∈ [0, 2], ``major_angle`` (rad from x, in [0, π)).
#[pyfunction]
#[pyo3(signature = (snapshot, region=None, y_slice=None, force_threshold=0.0, count_wall_contacts=true, min_contacts=2))]
pub fn fabric<'py>(
    py: Python<'py>,
    snapshot: &Snapshot,
    region: Option<(f64, f64, f64, f64)>,
    y_slice: Option<(f64, f64)>,
    force_threshold: f64,
    count_wall_contacts: bool,
    min_contacts: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let region = region_of(region, y_slice)?;
    let f = homogenise::state::fabric(
        &snapshot.inner,
        &region,
        &counting(force_threshold, count_wall_contacts, min_contacts),
    )
    .map_err(homogenise_err)?;
    let d = PyDict::new(py);
    d.set_item("tensor", out_tensor(py, &f.tensor)?)?;
    d.set_item("contacts", f.contacts)?;
    d.set_item("anisotropy", f.anisotropy)?;
    d.set_item("major_angle", f.major_angle)?;
    Ok(d)
}
