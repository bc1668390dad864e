//! `grainlaw.World` and `grainlaw.Snapshot`: the engine (`dem::World`) from Python.

use dem::math::Vector;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use dem::fc::SolverMethod;
use dem::snapshot::BodyKind;
use dem::solver::ErrorScale;
use dem::{ContactLaws, SolverParams, WorldParams};

use crate::arrays::{finite1, out1, out2, rows2};
use crate::errors::{dem_err, input, one_line, panic_err, SolverError};

/// Largest overlap between two grains, or of a grain behind a wall, accepted when a world is
/// checked before its first step (m), as for the built-in scenarios.
const BUILD_TOLERANCE: f64 = 1e-12;

fn positive(name: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(input(format!("`{name}` must be finite and > 0, got {v}")))
    }
}

fn pair(v: (f64, f64), name: &str) -> PyResult<Vector> {
    if v.0.is_finite() && v.1.is_finite() {
        Ok(Vector::new(v.0, v.1))
    } else {
        Err(input(format!("`{name}` is not finite ({}, {})", v.0, v.1)))
    }
}

/// World(dt=1e-3, gravity=(0.0, -9.81), theta=1.0, materials=("grain", "wall"), friction=0.5,
///       restitution=0.0, tolerance=1e-6, max_iterations=10000, method="auto",
///       periodic_x=None, detection_gap=1e-4, position_correction=True, parallel=False,
///       error_scale="problem")
/// --
///
/// A 2D world of rigid disks and walls stepped by the Moreau–Jean θ-scheme with Coulomb
/// friction solved exactly per contact (Jean 1999; docs/physics.md §1). Quantities per metre
/// of thickness along z unless a disk is given another thickness.
///
/// Parameters
/// ----------
/// dt : float
///     Time step h (s).
/// gravity : (float, float)
///     Gravity (m/s²).
/// theta : float
///     θ of the θ-method in [1/2, 1]: 1 is dissipative, 1/2 integrates free flight exactly.
/// materials : sequence of str
///     Material names; disks and walls name one (default "grain" and "wall").
/// friction : float
///     Coulomb coefficient μ of every pair of materials (change one with ``set_friction``).
/// restitution : float
///     Newton restitution coefficient e of every pair (``set_restitution``).
/// tolerance : float
///     Tolerance of the contact solver on its error measure (dimensionless).
/// max_iterations : int
///     Largest number of Gauss–Seidel sweeps per step.
/// method : str
///     "nlgs", "newton" or "auto" (Gauss–Seidel, then Newton where it stalls).
/// periodic_x : (float, float) or None
///     Periodic cell [x_min, x_max) along x (m).
/// detection_gap : float
///     Pairs closer than this become contacts (m).
/// position_correction : bool
///     Remove overlaps deeper than the slop after each step without changing velocities.
/// parallel : bool
///     Solve on all rayon threads (same numbers on any thread count).
/// error_scale : str
///     "problem": the tolerance applies to the error measure of the step's problem, whose
///     scale the gap-closing shifts of open pairs inflate; "loaded": it holds on the loaded
///     contacts' scale too, and the step's ``error`` is the larger of the two
///     (docs/physics.md §1.6).
#[pyclass(module = "grainlaw")]
pub struct World {
    world: dem::World,
    checked: bool,
}

impl World {
    fn material(&self, name: &str) -> PyResult<u16> {
        self.world.laws.index(name).ok_or_else(|| {
            input(format!(
                "unknown material `{name}` (materials: {})",
                self.world.laws.names().join(", ")
            ))
        })
    }

    fn body(&self, id: i64) -> PyResult<usize> {
        usize::try_from(id)
            .ok()
            .filter(|&i| i < self.world.bodies.len())
            .ok_or_else(|| {
                input(format!(
                    "body {id} does not exist ({} bodies)",
                    self.world.bodies.len()
                ))
            })
    }

    fn grain_id(&self, id: i64) -> PyResult<usize> {
        let i = self.body(id)?;
        if self.world.bodies[i].kind != BodyKind::Grain {
            return Err(input(format!("body {id} is a wall, not a disk")));
        }
        Ok(i)
    }
}

#[pymethods]
impl World {
    #[new]
    #[pyo3(signature = (dt=1e-3, gravity=(0.0, -9.81), theta=1.0, materials=vec!["grain".to_string(), "wall".to_string()], friction=0.5, restitution=0.0, tolerance=1e-6, max_iterations=10_000, method="auto", periodic_x=None, detection_gap=1e-4, position_correction=true, parallel=false, error_scale="problem"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        dt: f64,
        gravity: (f64, f64),
        theta: f64,
        materials: Vec<String>,
        friction: f64,
        restitution: f64,
        tolerance: f64,
        max_iterations: usize,
        method: &str,
        periodic_x: Option<(f64, f64)>,
        detection_gap: f64,
        position_correction: bool,
        parallel: bool,
        error_scale: &str,
    ) -> PyResult<Self> {
        let error_scale = match error_scale {
            "problem" => ErrorScale::Problem,
            "loaded" => ErrorScale::Loaded,
            other => {
                return Err(input(format!(
                    "error_scale `{other}`: one of problem, loaded"
                )))
            }
        };
        let method = match method {
            "nlgs" => SolverMethod::Nlgs,
            "newton" => SolverMethod::Newton,
            "auto" => SolverMethod::Auto,
            "lemke" => SolverMethod::Lemke,
            other => {
                return Err(input(format!(
                    "method `{other}`: one of nlgs, newton, auto, lemke"
                )))
            }
        };
        if materials.is_empty() {
            return Err(input("`materials`: at least one material name"));
        }
        if !(friction.is_finite() && friction >= 0.0) {
            return Err(input(format!(
                "`friction` must be finite and ≥ 0, got {friction}"
            )));
        }
        let params = WorldParams {
            dt,
            theta,
            gravity: pair(gravity, "gravity")?,
            periodic_x: periodic_x.map(|(a, b)| [a, b]),
            detection_gap,
            position_correction,
            solver: SolverParams {
                tolerance,
                max_iterations,
                parallel,
                method,
                error_scale,
                ..SolverParams::default()
            },
            ..WorldParams::default()
        };
        let names: Vec<&str> = materials.iter().map(String::as_str).collect();
        let mut laws = ContactLaws::new(&names, friction);
        for a in 0..laws.len() as u16 {
            for b in a..laws.len() as u16 {
                laws.set_restitution(a, b, restitution);
            }
        }
        Ok(World {
            world: dem::World::new(params, laws),
            checked: false,
        })
    }

    /// set_friction(a, b, mu): Coulomb coefficient μ between materials `a` and `b`.
    fn set_friction(&mut self, a: &str, b: &str, mu: f64) -> PyResult<()> {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(input(format!("friction must be finite and ≥ 0, got {mu}")));
        }
        let (a, b) = (self.material(a)?, self.material(b)?);
        self.world.laws.set_friction(a, b, mu);
        self.checked = false;
        Ok(())
    }

    /// set_restitution(a, b, e): Newton restitution coefficient e between `a` and `b`.
    fn set_restitution(&mut self, a: &str, b: &str, e: f64) -> PyResult<()> {
        let (a, b) = (self.material(a)?, self.material(b)?);
        self.world.laws.set_restitution(a, b, e);
        self.checked = false;
        Ok(())
    }

    /// add_disks(positions, radii, masses=None, density=None, thickness=1.0, material="grain",
    ///           velocities=None)
    /// --
    ///
    /// Adds free rigid disks; returns their body indices (int64 array).
    ///
    /// positions: (n, 2) centres (m); radii: (n,) radii R (m); masses: (n,) masses m (kg), or
    /// density: ρ (kg/m³, one value or (n,)) with m = ρ π R² t; thickness: t (m);
    /// velocities: (n, 2) initial velocities (m/s). The moment of inertia is m R²/2.
    #[pyo3(signature = (positions, radii, masses=None, density=None, thickness=1.0, material="grain", velocities=None))]
    #[allow(clippy::too_many_arguments)]
    fn add_disks<'py>(
        &mut self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        radii: &Bound<'py, PyAny>,
        masses: Option<&Bound<'py, PyAny>>,
        density: Option<&Bound<'py, PyAny>>,
        thickness: f64,
        material: &str,
        velocities: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let x = rows2(positions, "positions")?;
        let r = finite1(radii, "radii")?;
        let n = x.len();
        let t = positive("thickness", thickness)?;
        let same = |v: &[f64], name: &str| {
            if v.len() == n {
                Ok(())
            } else {
                Err(input(format!(
                    "`{name}` has {} values for {n} positions",
                    v.len()
                )))
            }
        };
        same(&r, "radii")?;
        for (i, &ri) in r.iter().enumerate() {
            positive(&format!("radii[{i}]"), ri)?;
        }
        let rho: Vec<f64> = match (masses, density) {
            (Some(m), None) => {
                let m = finite1(m, "masses")?;
                same(&m, "masses")?;
                m.iter()
                    .zip(&r)
                    .enumerate()
                    .map(|(i, (&m, &r))| {
                        positive(&format!("masses[{i}]"), m)
                            .map(|m| m / (std::f64::consts::PI * r * r * t))
                    })
                    .collect::<PyResult<_>>()?
            }
            (None, Some(d)) => {
                let d = if let Ok(v) = d.extract::<f64>() {
                    vec![v; n]
                } else {
                    finite1(d, "density")?
                };
                same(&d, "density")?;
                for (i, &di) in d.iter().enumerate() {
                    positive(&format!("density[{i}]"), di)?;
                }
                d
            }
            _ => return Err(input("give exactly one of `masses` and `density`")),
        };
        let v = match velocities {
            Some(v) => {
                let v = rows2(v, "velocities")?;
                if v.len() != n {
                    return Err(input(format!(
                        "`velocities` has {} rows for {n} positions",
                        v.len()
                    )));
                }
                Some(v)
            }
            None => None,
        };
        let mat = self.material(material)?;
        let mut ids = Vec::with_capacity(n);
        for i in 0..n {
            let b = self.world.add_grain_with_thickness(
                Vector::new(x[i][0], x[i][1]),
                r[i],
                rho[i],
                t,
                mat,
            );
            if let Some(v) = &v {
                self.world.bodies[b as usize].velocity = Vector::new(v[i][0], v[i][1]);
            }
            ids.push(i64::from(b));
        }
        self.checked = false;
        Ok(PyArray1::from_vec(py, ids))
    }

    /// add_wall(point, normal, name="wall", material="wall", velocity=(0.0, 0.0))
    /// --
    ///
    /// Adds an infinite line wall through `point` (m) with unit `normal` pointing to the
    /// grains, moving at the imposed `velocity` (m/s); returns its body index.
    #[pyo3(signature = (point, normal, name="wall", material="wall", velocity=(0.0, 0.0)))]
    fn add_wall(
        &mut self,
        point: (f64, f64),
        normal: (f64, f64),
        name: &str,
        material: &str,
        velocity: (f64, f64),
    ) -> PyResult<i64> {
        let n = pair(normal, "normal")?;
        if n.norm() == 0.0 {
            return Err(input("`normal` must not be zero"));
        }
        let mat = self.material(material)?;
        let b = self
            .world
            .add_line_wall(name, pair(point, "point")?, n, mat);
        self.world.bodies[b as usize].velocity = pair(velocity, "velocity")?;
        self.checked = false;
        Ok(i64::from(b))
    }

    /// add_segment(a, b, name="wall", material="wall")
    /// --
    ///
    /// Adds a fixed segment wall from `a` to `b` (m); returns its body index.
    #[pyo3(signature = (a, b, name="wall", material="wall"))]
    fn add_segment(
        &mut self,
        a: (f64, f64),
        b: (f64, f64),
        name: &str,
        material: &str,
    ) -> PyResult<i64> {
        let mat = self.material(material)?;
        let id = self
            .world
            .add_segment_wall(name, pair(a, "a")?, pair(b, "b")?, mat);
        self.checked = false;
        Ok(i64::from(id))
    }

    /// set_velocities(ids, velocities, omegas=None): velocities (m/s, (n, 2)) and angular
    /// velocities (rad/s, (n,)) of the disks `ids`.
    #[pyo3(signature = (ids, velocities, omegas=None))]
    fn set_velocities(
        &mut self,
        ids: Vec<i64>,
        velocities: &Bound<'_, PyAny>,
        omegas: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let v = rows2(velocities, "velocities")?;
        if v.len() != ids.len() {
            return Err(input(format!(
                "`velocities` has {} rows for {} ids",
                v.len(),
                ids.len()
            )));
        }
        let w = match omegas {
            Some(o) => {
                let w = finite1(o, "omegas")?;
                if w.len() != ids.len() {
                    return Err(input(format!(
                        "`omegas` has {} values for {} ids",
                        w.len(),
                        ids.len()
                    )));
                }
                Some(w)
            }
            None => None,
        };
        let idx = ids
            .iter()
            .map(|&i| self.grain_id(i))
            .collect::<PyResult<Vec<_>>>()?;
        for (k, &i) in idx.iter().enumerate() {
            self.world.bodies[i].velocity = Vector::new(v[k][0], v[k][1]);
            if let Some(w) = &w {
                self.world.bodies[i].omega = w[k];
            }
        }
        Ok(())
    }

    /// set_wall_velocity(id, velocity): the imposed velocity (m/s) of wall `id`.
    fn set_wall_velocity(&mut self, id: i64, velocity: (f64, f64)) -> PyResult<()> {
        let i = self.body(id)?;
        if self.world.bodies[i].kind != BodyKind::Wall {
            return Err(input(format!("body {id} is a disk, not a wall")));
        }
        self.world.bodies[i].velocity = pair(velocity, "velocity")?;
        Ok(())
    }

    /// step(n=1)
    /// --
    ///
    /// Advances `n` time steps with the GIL released; returns the report of the last one:
    /// ``step``, ``time`` (s), ``contacts``, ``active_contacts``, ``iterations`` (sweeps),
    /// ``error`` (solver error measure), ``error_without_gap_shifts`` (the same residual over
    /// a scale without the open pairs' gap-closing shifts: the error on the loaded contacts),
    /// ``converged``, ``max_penetration`` (m). The world is
    /// checked (parameters, bodies, no initial overlap) before its first step and after a
    /// change. Raises InputError for a world that cannot be stepped, SolverError when a step
    /// fails (non-finite state).
    #[pyo3(signature = (n=1))]
    fn step<'py>(&mut self, py: Python<'py>, n: u64) -> PyResult<Bound<'py, PyDict>> {
        if !self.checked {
            self.world.validate(BUILD_TOLERANCE).map_err(dem_err)?;
            self.checked = true;
        }
        let world = &mut self.world;
        let result = py.detach(|| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                for _ in 0..n {
                    world.step()?;
                }
                Ok::<_, dem::DemError>(())
            }))
        });
        match result {
            Err(payload) => return Err(panic_err(payload)),
            Ok(Err(e)) => return Err(dem_err(e)),
            Ok(Ok(())) => {}
        }
        let r = self.world.last_report();
        let d = PyDict::new(py);
        d.set_item("step", r.step)?;
        d.set_item("time", r.time)?;
        d.set_item("contacts", r.contacts)?;
        d.set_item("active_contacts", r.active_contacts)?;
        d.set_item("iterations", r.solver.iterations)?;
        d.set_item("error", r.solver.error)?;
        d.set_item(
            "error_without_gap_shifts",
            r.solver.error_without_gap_shifts,
        )?;
        d.set_item("converged", r.solver.converged)?;
        d.set_item("max_penetration", r.max_penetration)?;
        Ok(d)
    }

    /// Current time (s).
    #[getter]
    fn time(&self) -> f64 {
        self.world.time
    }

    /// Steps done.
    #[getter]
    fn step_index(&self) -> u64 {
        self.world.step_index
    }

    /// Number of bodies (disks and walls).
    fn __len__(&self) -> usize {
        self.world.bodies.len()
    }

    /// Centres of every body (m), (n, 2).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let rows: Vec<[f64; 2]> = self
            .world
            .bodies
            .iter()
            .map(|b| [b.position.x, b.position.y])
            .collect();
        out2(py, &rows)
    }

    /// Velocities of every body (m/s), (n, 2).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let rows: Vec<[f64; 2]> = self
            .world
            .bodies
            .iter()
            .map(|b| [b.velocity.x, b.velocity.y])
            .collect();
        out2(py, &rows)
    }

    /// Angular velocities of every body (rad/s), (n,).
    #[getter]
    fn omegas<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.world.bodies.iter().map(|b| b.omega).collect())
    }

    /// Kinetic energy Σ ½ m v² + ½ I ω² (J per metre of thickness for unit thickness).
    fn kinetic_energy(&self) -> f64 {
        self.world.kinetic_energy()
    }

    /// Potential energy of gravity −Σ m g·x of the free degrees of freedom (J).
    fn potential_energy(&self) -> f64 {
        self.world.potential_energy()
    }

    /// The state after the last step (bodies, contacts with forces, walls) as a Snapshot.
    fn snapshot(&self) -> Snapshot {
        Snapshot {
            inner: self.world.snapshot(),
        }
    }

    /// resolved_snapshot(tolerance=1e-8)
    /// --
    ///
    /// The last step solved again, from the same state, to ``tolerance`` (the error measure of
    /// the step's problem): the Snapshot Moreau–Jean's update gives with those impulses
    /// (velocities ``v + M⁻¹Hᵀ(r' − r)``, mean accelerations, positions ``+ θ h Δv``, contact
    /// and wall forces ``r'/h``), the world itself unchanged. Comparing what a measurement
    /// gives on it and on ``snapshot()`` tells what the solver's residual does to the
    /// measurement (grainlaw's solver sensitivity). The re-solve is ``auto`` on the assembled
    /// problem: Gauss–Seidel, the proximal semismooth Newton method, then Lemke's method, exact
    /// in 2D. Raises InputError before a step or for a non-positive tolerance, SolverError when
    /// the re-solve does not reach the tolerance.
    #[pyo3(signature = (tolerance=1e-8))]
    fn resolved_snapshot(&self, py: Python<'_>, tolerance: f64) -> PyResult<Snapshot> {
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(input(format!(
                "tolerance must lie in (0, 1), got {tolerance}"
            )));
        }
        let Some((problem, r)) = self.world.last_step_problem() else {
            return Err(input(
                "no step to solve again: step the world first (the last step's problem is \
                 not kept across a resume, nor for a cell under an explicit control)",
            ));
        };
        let options = dem::fc::FcOptions {
            tolerance,
            initial_guess: Some(r),
            ..dem::fc::FcOptions::default()
        };
        let solved = py.detach(|| {
            dem::fc::solve_by(
                &problem,
                &options,
                dem::fc::SolverMethod::Auto,
                &dem::fc::NewtonParams::default(),
            )
        });
        let (solution, _) = solved.map_err(|e| SolverError::new_err(one_line(&e.to_string())))?;
        if !solution.converged {
            return Err(SolverError::new_err(format!(
                "the re-solve stopped at error {:.2e} above the tolerance {tolerance:.0e}",
                solution.error
            )));
        }
        let inner = self
            .world
            .snapshot_with_last_impulses(&solution.r)
            .map_err(dem_err)?;
        Ok(Snapshot { inner })
    }

    fn __repr__(&self) -> String {
        let grains = self
            .world
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .count();
        format!(
            "World({grains} disks, {} walls, t = {} s, step {})",
            self.world.bodies.len() - grains,
            self.world.time,
            self.world.step_index
        )
    }
}

/// The state of a world after a step (positions, velocities, contacts with their forces,
/// walls), as numpy arrays: the input of the homogenisation functions. Forces are the step's
/// impulses divided by the time step (N for the bodies' thickness).
#[pyclass(module = "grainlaw", frozen)]
pub struct Snapshot {
    pub inner: dem::Snapshot,
}

fn body_rows(
    s: &dem::Snapshot,
    f: impl Fn(&dem::snapshot::BodyState) -> [f64; 2],
) -> Vec<[f64; 2]> {
    s.bodies.iter().map(f).collect()
}

#[pymethods]
impl Snapshot {
    /// Step index.
    #[getter]
    fn step(&self) -> u64 {
        self.inner.step
    }
    /// Time (s).
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time
    }
    /// Time step (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt
    }
    /// Gravity (m/s²).
    #[getter]
    fn gravity(&self) -> (f64, f64) {
        (self.inner.gravity.x, self.inner.gravity.y)
    }
    /// Periodic cell along x ``(x_min, x_max)`` (m), or None.
    #[getter]
    fn periodic_x(&self) -> Option<(f64, f64)> {
        self.inner.periodic_x.map(|[a, b]| (a, b))
    }
    /// The biperiodic cell, or None: a dict with ``h`` (2, 2), the cell matrix whose columns
    /// are the cell's edges (m, corner at the origin), ``velocity_gradient`` (2, 2) L (1/s), and
    /// ``area`` det h (m²).
    #[getter]
    fn cell<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(c) = self.inner.cell else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("h", crate::arrays::out_tensor(py, &c.h)?)?;
        d.set_item("velocity_gradient", crate::arrays::out_tensor(py, &c.l)?)?;
        d.set_item("area", c.volume())?;
        Ok(Some(d))
    }
    /// Number of bodies.
    fn __len__(&self) -> usize {
        self.inner.bodies.len()
    }
    /// True for the disks (grains), False for the walls, (n,).
    #[getter]
    fn is_grain<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_vec(
            py,
            self.inner
                .bodies
                .iter()
                .map(|b| b.kind == BodyKind::Grain)
                .collect(),
        )
    }
    /// Body names (walls are named, disks have "").
    #[getter]
    fn names(&self) -> Vec<String> {
        self.inner.bodies.iter().map(|b| b.name.clone()).collect()
    }
    /// Centres (m), (n, 2).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        out2(
            py,
            &body_rows(&self.inner, |b| [b.position.x, b.position.y]),
        )
    }
    /// Velocities (m/s), (n, 2).
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        out2(
            py,
            &body_rows(&self.inner, |b| [b.velocity.x, b.velocity.y]),
        )
    }
    /// Accelerations over the last step (m/s²), (n, 2).
    #[getter]
    fn accelerations<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        out2(
            py,
            &body_rows(&self.inner, |b| [b.acceleration.x, b.acceleration.y]),
        )
    }
    /// Angles (rad), (n,).
    #[getter]
    fn angles<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.bodies.iter().map(|b| b.angle).collect())
    }
    /// Angular velocities (rad/s), (n,).
    #[getter]
    fn omegas<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.bodies.iter().map(|b| b.omega).collect())
    }
    /// Radii (m; 0 for walls), (n,).
    #[getter]
    fn radii<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.bodies.iter().map(|b| b.radius).collect())
    }
    /// Masses (kg; inf for walls), (n,).
    #[getter]
    fn masses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.bodies.iter().map(|b| b.mass).collect())
    }
    /// Number of contacts.
    #[getter]
    fn n_contacts(&self) -> usize {
        self.inner.contacts.len()
    }
    /// First body of each contact (int64), (m,).
    #[getter]
    fn contact_a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        PyArray1::from_vec(
            py,
            self.inner
                .contacts
                .iter()
                .map(|c| i64::from(c.body_a))
                .collect(),
        )
    }
    /// Second body of each contact (int64), (m,); the normal points from a to b.
    #[getter]
    fn contact_b<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        PyArray1::from_vec(
            py,
            self.inner
                .contacts
                .iter()
                .map(|c| i64::from(c.body_b))
                .collect(),
        )
    }
    /// Contact points (m), (m, 2).
    #[getter]
    fn contact_points<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let rows: Vec<[f64; 2]> = self
            .inner
            .contacts
            .iter()
            .map(|c| [c.point.x, c.point.y])
            .collect();
        out2(py, &rows)
    }
    /// Unit normals from body a to body b, (m, 2).
    #[getter]
    fn contact_normals<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let rows: Vec<[f64; 2]> = self
            .inner
            .contacts
            .iter()
            .map(|c| [c.normal.x, c.normal.y])
            .collect();
        out2(py, &rows)
    }
    /// Normal force on b (N, ≥ 0, compressive), (m,).
    #[getter]
    fn force_n<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.contacts.iter().map(|c| c.force_n).collect())
    }
    /// Tangential force on b along t = (−n_y, n_x) (N), (m,).
    #[getter]
    fn force_t<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.contacts.iter().map(|c| c.force_t).collect())
    }
    /// Force on body b, f_n n + f_t t (N), (m, 2).
    #[getter]
    fn contact_forces<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray2<f64>> {
        let rows: Vec<[f64; 2]> = self
            .inner
            .contacts
            .iter()
            .map(|c| {
                let f = c.force_on_b();
                [f.x, f.y]
            })
            .collect();
        out2(py, &rows)
    }
    /// Gaps at the start of the step (m; negative: overlap), (m,).
    #[getter]
    fn gaps<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.contacts.iter().map(|c| c.gap).collect())
    }
    /// Friction coefficient of each contact, (m,).
    #[getter]
    fn contact_mu<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out1(py, self.inner.contacts.iter().map(|c| c.mu).collect())
    }
    /// Status of each contact: "open", "stick" or "slide" (numpy array of str), (m,).
    #[getter]
    fn statuses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let names: Vec<&str> = self
            .inner
            .contacts
            .iter()
            .map(|c| c.status.name())
            .collect();
        py.import("numpy")?.getattr("asarray")?.call1((names, "U5"))
    }
    /// Walls: ``{name: {"body": index, "force": (fx, fy) N, "torque": N·m}}``, the force the
    /// grains exert on each wall.
    #[getter]
    fn walls<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for w in &self.inner.walls {
            let e = PyDict::new(py);
            e.set_item("body", w.body)?;
            e.set_item("force", (w.force.x, w.force.y))?;
            e.set_item("torque", w.torque)?;
            d.set_item(&w.name, e)?;
        }
        Ok(d)
    }
    fn __repr__(&self) -> String {
        format!(
            "Snapshot(step {}, t = {} s, {} bodies, {} contacts)",
            self.inner.step,
            self.inner.time,
            self.inner.bodies.len(),
            self.inner.contacts.len()
        )
    }
}
