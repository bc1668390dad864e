//! One time step as named stages ([`World::step_plain`]):
//!
//! ```text
//! detect → free velocities → solve → integrate (positions, the cell) → correct → control the cell → finish
//! ```
//!
//! [`World::detect`] finds the contacts at `q⁻` and warm-starts them from the previous step;
//! [`World::free_velocities`] gives `v_free = v⁻ + h M⁻¹ f_ext` and each contact's shift;
//! [`World::solve_contacts`] solves the contact problem (in natural order,
//! [`World::solve_natural`], or in the parallel sweep's block-contiguous copy,
//! [`World::solve_blocked`]); [`World::integrate`] moves the bodies with the θ-method and
//! [`World::deform_cell`] the deformable cell; [`World::correct`] projects the positions out of
//! their overlaps ([`crate::stabilise`]); [`World::control_cell`] measures the cell's stress and
//! sets its next velocity gradient; [`World::finish`] checks what the cell's change did and
//! writes the step's report. The stages read the state ([`WorldState`]) and the previous
//! stage's results, and work in the work space.
//!
//! [`WorldState`]: super::WorldState

use crate::body::external_loads;
use crate::body::Dof;
use crate::cell::ComponentValues;
use crate::cell_coupling::CellCoupling;
use crate::error::DemError;
use crate::math::{Tensor, Vector};
use crate::snapshot::BodyKind;
use crate::solver::{self, SolveReport, SweepOrder};
use crate::stabilise::CorrectionReport;

use super::{cell_inverse, LastCellStep, StepReport, World, BLOCKED_MIN_CONTACTS, SWEEP_BLOCKS};

/// What the solve leaves to the stages after it.
struct Solved {
    /// The solver's report.
    report: SolveReport,
    /// The change `δ` of the cell's velocity gradient found with the impulses (zero without an
    /// implicit cell control).
    delta: Tensor,
    /// Whether each body follows the cell's change within the step ([`World::follows_cell`];
    /// empty when none does).
    follows: Vec<bool>,
}

impl World {
    /// Advance one time step (see the module documentation). Non-convergence of the contact
    /// solver is reported in the returned [`StepReport`], never hidden; a non-finite state is an
    /// error.
    ///
    /// Called from outside the rayon pool, a step that will fork runs on one of its workers
    /// (one hand-over per step), so that the many short parallel kernels of the solve fork and
    /// join between workers instead of each waking the pool from the outside and blocking on
    /// it. A step that will not fork (the sweeps in natural order and every chunked pass one
    /// task's worth, [`crate::parallel::runs_inline`]) stays on the calling thread: handed over,
    /// it kept a second worker spinning beside it for nothing (the poured 2000-grain column,
    /// 4614 sub-steps: about 15 % slower on two cores, same bits).
    pub fn step(&mut self) -> Result<StepReport, DemError> {
        self.work.unconverged_problem = None;
        let forks = self.state.params.solver.parallel
            || !crate::parallel::runs_inline(
                self.state.contacts.len().div_ceil(crate::parallel::CHUNK),
            );
        if forks && rayon::current_thread_index().is_none() {
            rayon::scope(|_| self.step_in_pool())
        } else {
            self.step_in_pool()
        }
    }

    /// A step, with the implicit correction of a stress-controlled cell
    /// ([`CellControl::tolerance`](crate::cell::CellControl::tolerance)): when the step ends with a mean stress error beyond the
    /// tolerance (more compressive: typically a rigid packing asked to deform faster than it
    /// can, whose impulses then grow without bound; or more tensile), the step is done again
    /// from its start with the stress-controlled components of `L` changed by a common `δ`,
    /// found by bracketing and bisection on the mean signed error `Σ (σ_ij − σ*_ij)/n` (which
    /// grows with `δ`), until that error is within the tolerance or
    /// [`CellControl::max_corrections`](crate::cell::CellControl::max_corrections) re-solves are spent. On the tensile side `δ ≥ −ε̇_max`
    /// (a loose packing cannot be brought to its stress within one step).
    fn step_in_pool(&mut self) -> Result<StepReport, DemError> {
        let (Some(ctl), Some(_)) = (self.state.cell_control, self.state.cell) else {
            return self.step_plain();
        };
        if ctl.implicit || ctl.tolerance <= 0.0 || ctl.max_corrections == 0 {
            return self.step_plain();
        }
        // State only: every re-solve starts from it ([`World::undo_point`]).
        let backup = self.undo_point();
        let first = self.step_plain()?;
        let f0 = ctl.signed_error(&self.state.cell_stress.unwrap_or_else(Tensor::zeros));
        if f0.abs() <= ctl.tolerance {
            return Ok(first);
        }
        let l0 = backup.cell.map_or_else(Tensor::zeros, |c| c.l);
        let mut tries = 0u32;
        let attempt = |w: &mut World, delta: f64, tries: &mut u32| -> Result<f64, DemError> {
            w.undo_to(&backup);
            let e = w.set_velocity_gradient(l0 + ctl.direction() * delta);
            let mut r = w.step_plain()?;
            r.cell_work += e;
            *tries += 1;
            r.cell_corrections = *tries;
            w.last = r;
            Ok(ctl.signed_error(&w.state.cell_stress.unwrap_or_else(Tensor::zeros)))
        };
        // Bracket the root of f(δ) (f grows with δ): [lo, hi] with f(lo) < 0 < f(hi).
        let (mut lo, mut hi);
        if f0 < 0.0 {
            // Too compressive: open faster, doubling the step (a rigid packing can need it).
            lo = 0.0;
            hi = ctl.max_rate;
            let mut f = attempt(self, hi, &mut tries)?;
            while f < -ctl.tolerance && (tries as usize) < ctl.max_corrections / 2 {
                lo = hi;
                hi *= 2.0;
                f = attempt(self, hi, &mut tries)?;
            }
            if f.abs() <= ctl.tolerance || f < 0.0 {
                return Ok(self.state.last);
            }
        } else {
            // Too tensile: close, but no component faster than ε̇_max (a loose packing cannot
            // be brought to its stress within one step; no rigidity to overcome this way).
            let dir = ctl.direction();
            let l_min = (0..2)
                .flat_map(|i| (0..2).map(move |j| (i, j)))
                .filter(|&ij| dir[ij] != 0.0)
                .map(|ij| l0[ij])
                .fold(f64::INFINITY, f64::min);
            hi = 0.0;
            lo = -(ctl.max_rate + l_min);
            if lo.is_nan() || lo >= 0.0 {
                return Ok(first);
            }
            let f = attempt(self, lo, &mut tries)?;
            if f >= -ctl.tolerance {
                return Ok(self.state.last);
            }
        }
        let mut last_ok = true;
        while (tries as usize) < ctl.max_corrections {
            let mid = 0.5 * (lo + hi);
            let f = attempt(self, mid, &mut tries)?;
            if f.abs() <= ctl.tolerance {
                return Ok(self.state.last);
            }
            if f < 0.0 {
                lo = mid;
                last_ok = false;
            } else {
                hi = mid;
                last_ok = true;
            }
        }
        // Out of re-solves: end on the bracket's side that is not too compressive.
        if !last_ok {
            attempt(self, hi, &mut tries)?;
        }
        Ok(self.state.last)
    }

    /// One step as its stages (module documentation); a step that fails leaves the error of
    /// the stage that found it.
    fn step_plain(&mut self) -> Result<StepReport, DemError> {
        self.refresh_inverse_mass();
        // The contacts are about to change: a step that fails before its solve leaves no
        // problem behind.
        self.forget_last_step_problem();
        let free_change = self.detect()?;
        let max_pen = self.free_velocities();
        let solved = self.solve_contacts(free_change);
        self.integrate(&solved)?;
        let (mut cell_work, gap_shift) = self.deform_cell(&solved);
        let correction = self.correct(&gap_shift);
        cell_work += self.work.wrap_energy;
        let active = self.refresh_body_forces();
        self.control_cell(solved.delta, &mut cell_work);
        self.finish(solved.report, max_pen, correction, cell_work, active)
    }

    /// Stage 1: detection at `q⁻`, warm start from the previous step's impulses (rescaled when
    /// the time step changed, `R = h r`). Returns the impulse-free change of an implicit cell
    /// over the step ([`World::implicit_free_change`]): its images' drift widens the swept
    /// margins, and the contact problem starts from it.
    fn detect(&mut self) -> Result<Option<ComponentValues>, DemError> {
        let h = self.state.params.dt;
        std::mem::swap(&mut self.state.contacts, &mut self.work.previous);
        let free_change = self.implicit_free_change();
        self.detect_step_contacts(free_change)?;
        let scale = if self.work.previous.dt > 0.0 {
            h / self.work.previous.dt
        } else {
            1.0
        };
        self.state
            .contacts
            .warm_start_from(&self.work.previous, scale);
        self.state.contacts.dt = h;
        Ok(free_change)
    }

    /// Stage 2: the free velocities `v_free = v⁻ + h M⁻¹ f_ext` (imposed degrees of freedom keep
    /// their velocity) in `work.vel`, and each contact's shift (an open gap closing within the
    /// step, or Newton's restitution on an impact). Returns the largest overlap at the start of
    /// the step (m, 0 if none).
    fn free_velocities(&mut self) -> f64 {
        let (h, theta, g) = (
            self.state.params.dt,
            self.state.params.theta,
            self.state.params.gravity,
        );
        self.work.vel.clear();
        for b in &self.state.bodies {
            self.work.vel.push([b.velocity.x, b.velocity.y, b.omega]);
        }
        let mut max_pen = 0.0f64;
        for (row, geo) in self.state.contacts.rows_with_geometry_mut() {
            let open_gap = if geo.gap > geo.closed_gap {
                geo.gap
            } else {
                0.0
            };
            let mut shift = open_gap / (h * theta);
            max_pen = max_pen.max(-geo.gap);
            if geo.restitution > 0.0 {
                // Detection leaves the shift at zero, so this is u_n⁻.
                let un = row.velocity(
                    &self.work.vel[row.a as usize],
                    &self.work.vel[row.b as usize],
                )[0];
                // An impact during this step (closed gap, or one that closes within the step
                // at the approach velocity): Newton's law u_n⁺ ≥ −e u_n⁻ from now on.
                if un < 0.0 && open_gap + h * un <= 0.0 {
                    shift = geo.restitution * un;
                }
            }
            row.shift = shift;
        }
        for (i, b) in self.state.bodies.iter().enumerate() {
            let inv = &self.state.last_step.inv[i];
            let f = external_loads(b, g);
            for d in 0..3 {
                if b.dofs[d] == Dof::Free {
                    self.work.vel[i][d] += h * inv[d] * f[d];
                }
            }
        }
        max_pen
    }

    /// Stage 3: the contact solve, `v⁺ = v_free + M⁻¹ Hᵀ R` with the impulses extremal for the
    /// bipotential (with the cell's stress-controlled components as unknowns under an implicit
    /// control, [`crate::cell_coupling`]). Keeps the free velocities (and the problem, when
    /// problems are recorded) for after the step, and the contacts' statuses.
    fn solve_contacts(&mut self, free_change: Option<ComponentValues>) -> Solved {
        let h = self.state.params.dt;
        let q_norms = solver::free_velocity_norms(&self.state.contacts.rows, &self.work.vel);
        let thickness = self.grain_thickness();
        let follows = self.follows_cell();
        let mut coupling = match (self.state.cell_control, self.state.cell, free_change) {
            (Some(ctl), Some(cell), Some(delta0)) => CellCoupling::new(
                &ctl,
                &cell,
                &mut self.state.contacts.rows,
                &self.state.contacts.geometry,
                &follows,
                h,
                thickness,
                delta0,
            ),
            _ => None,
        };
        let approach_limit = self.approach_limit();
        // Emptied at the start of the step (`forget_last_step_problem`).
        self.state
            .last_step
            .v_free
            .extend_from_slice(&self.work.vel);
        self.state.last_step.problem = self.state.record_problems.then(|| {
            crate::assemble::contact_problem_with(
                &self.state.contacts.rows,
                &self.state.last_step.v_free,
                &self.state.last_step.inv,
                coupling.as_ref(),
            )
        });
        // Without a contact across the boundary the cell's change is δ⁰ whatever the impulses.
        // In parallel the coupled contacts are swept after the others, on one thread
        // (`CellCoupling::sweep_coupled`).
        let coupled = coupling.as_mut().filter(|c| c.coupled_contacts() > 0);
        // The back-off of `auto` is state; the solver keeps it in its work space during the solve.
        self.work.solver.backoff = self.state.newton_backoff;
        let report = if self.state.params.solver.parallel {
            self.solve_blocked(q_norms, approach_limit, coupled)
        } else {
            self.solve_natural(q_norms, approach_limit, coupled)
        };
        self.state.newton_backoff = self.work.solver.backoff;
        solver::classify(&self.state.contacts.rows, &mut self.state.contacts.status);
        // The images moved with L⁺ h k = (L⁻ + δ) h k during the solve: the cell deforms with
        // L⁺ (`deform_cell`), the grains follow δ at the end of the step (`control_cell`).
        let delta = coupling.as_ref().map_or_else(Tensor::zeros, |c| c.delta());
        self.work.image_outran = delta.abs().sum() > self.work.detector.image_rate();
        self.state.last_step.cell_step = match (self.state.cell, self.state.cell_control) {
            (Some(_), Some(ctl)) if !ctl.implicit => None,
            (Some(_), _) => Some(LastCellStep {
                coupling: coupling.take(),
            }),
            (None, _) => None,
        };
        Solved {
            report,
            delta,
            follows,
        }
    }

    /// The solve in the contacts' natural order, on the calling thread's sweep.
    fn solve_natural(
        &mut self,
        q_norms: [f64; 2],
        approach_limit: f64,
        coupled: Option<&mut CellCoupling>,
    ) -> SolveReport {
        self.work.order.clear();
        self.work.order.extend(0..self.state.contacts.len() as u32);
        let order = SweepOrder::Natural(&mut self.work.order);
        solver::rebuild_velocities(
            &self.state.contacts.rows,
            &mut self.work.vel,
            &self.state.last_step.v_free,
            &self.state.last_step.inv,
            &order,
        );
        solver::solve(
            &mut self.state.contacts.rows,
            order,
            &mut self.work.vel,
            &self.state.last_step.v_free,
            &self.state.last_step.inv,
            q_norms,
            approach_limit,
            &self.state.params.solver,
            &mut self.work.solver,
            coupled,
        )
    }

    /// The parallel solve: in a block-contiguous copy of the problem (no two threads on one
    /// cache line, [`crate::blocked`]), coloured by spatial blocks
    /// ([`crate::colouring::ContactColouring::build_blocked`]), scattered back after it.
    fn solve_blocked(
        &mut self,
        q_norms: [f64; 2],
        approach_limit: f64,
        coupled: Option<&mut CellCoupling>,
    ) -> SolveReport {
        self.work.mobile.clear();
        self.work.mobile.extend(
            self.state
                .last_step
                .inv
                .iter()
                .map(|i| i.iter().any(|&x| x != 0.0)),
        );
        self.work.pos.clear();
        self.work.pos.extend(
            self.state
                .bodies
                .iter()
                .map(|b| [b.position.x, b.position.y]),
        );
        let blocks = if self.state.contacts.len() >= BLOCKED_MIN_CONTACTS {
            SWEEP_BLOCKS
        } else {
            1
        };
        self.work.layout.gather(
            &self.state.contacts.rows,
            &self.work.vel,
            &self.state.last_step.v_free,
            &self.state.last_step.inv,
            &self.work.mobile,
            &self.work.pos,
            blocks,
        );
        let l = &mut self.work.layout;
        self.work
            .colouring
            .build_blocked(&l.rows, &l.mobile, &l.pos, blocks);
        let order = SweepOrder::Coloured {
            colouring: &mut self.work.colouring,
            mobile: &l.mobile,
        };
        solver::rebuild_velocities(&l.rows, &mut l.vel, &l.v_free, &l.inv, &order);
        // The coupling in the copy's numbering; its δ comes back with the impulses.
        let mut renumbered = coupled.as_deref().map(|c| c.renumbered(l.row_old()));
        let report = solver::solve(
            &mut l.rows,
            order,
            &mut l.vel,
            &l.v_free,
            &l.inv,
            q_norms,
            approach_limit,
            &self.state.params.solver,
            &mut self.work.solver,
            renumbered.as_mut(),
        );
        l.scatter(&mut self.state.contacts.rows, &mut self.work.vel);
        if let (Some(c), Some(solved)) = (coupled, &renumbered) {
            c.adopt(solved, &mut self.state.contacts.rows);
        }
        report
    }

    /// Stage 4: positions and accelerations, `q⁺ = q⁻ + h [(1 − θ) v⁻ + θ v⁺]`,
    /// `a = (v⁺ − v⁻)/h`, the displacements kept for the correction; the grains that follow the
    /// cell's change move with it over the step (their velocities take it in
    /// [`World::control_cell`]). A non-finite velocity is an error.
    fn integrate(&mut self, solved: &Solved) -> Result<(), DemError> {
        let (h, theta) = (self.state.params.dt, self.state.params.theta);
        let periodic = self.periodic();
        let (delta, follows) = (solved.delta, &solved.follows);
        let affine = !follows.is_empty();
        let drag_centre = self.state.cell.filter(|_| affine).map(|c| c.centre());
        self.work.displacement.clear();
        for (i, b) in self.state.bodies.iter_mut().enumerate() {
            let v = self.work.vel[i];
            for (d, x) in v.iter().enumerate() {
                if !x.is_finite() {
                    return Err(DemError::NonFinite {
                        step: self.state.step_index + 1,
                        body: i,
                        what: ["x velocity", "y velocity", "angular velocity"][d].into(),
                    });
                }
            }
            let vm = [b.velocity.x, b.velocity.y, b.omega];
            b.acceleration = Vector::new((v[0] - vm[0]) / h, (v[1] - vm[1]) / h);
            b.angular_acceleration = (v[2] - vm[2]) / h;
            let mut d = [
                h * ((1.0 - theta) * vm[0] + theta * v[0]),
                h * ((1.0 - theta) * vm[1] + theta * v[1]),
                h * ((1.0 - theta) * vm[2] + theta * v[2]),
            ];
            if let (Some(c), true) = (drag_centre, follows.get(i) == Some(&true)) {
                let a = delta * (b.position - c);
                d[0] += h * theta * a.x;
                d[1] += h * theta * a.y;
            }
            self.work.displacement.push(d);
            b.position.x += d[0];
            b.position.y += d[1];
            b.angle += d[2];
            b.velocity = Vector::new(v[0], v[1]);
            b.omega = v[2];
            if let Some(p) = periodic {
                if b.kind == BodyKind::Grain {
                    b.position.x = p.wrap(b.position.x);
                }
            }
        }
        Ok(())
    }

    /// Stage 4b, the deformable cell: `h ← exp(L h) h`, a basis change when it tilts beyond
    /// half a period, grains wrapped back with `v ← v + L h k`. Returns the work of the cell on
    /// the grains so far (the wraps, and the impulses against the images' affine velocities;
    /// J) and the gap change of each contact from the cell's deformation (empty without a
    /// cell).
    fn deform_cell(&mut self, solved: &Solved) -> (f64, Vec<f64>) {
        let h = self.state.params.dt;
        let (delta, affine) = (solved.delta, !solved.follows.is_empty());
        let mut cell_work = 0.0;
        let mut cell_gap_shift = Vec::new();
        if let Some(mut cell) = self.state.cell {
            // The grains moved with L⁻ (the images with L⁺ = L⁻ + δ under an implicit cell).
            let (h_old, l) = (cell.h, cell.l);
            // Affine part of the step's displacements, for the outran check.
            let c = cell.centre();
            self.work.fluct_displacement.clear();
            for (b, d) in self.state.bodies.iter().zip(&self.work.displacement) {
                let x_old = b.position - Vector::new(d[0], d[1]);
                let a = if affine {
                    (l + delta) * (x_old - c) * h
                } else {
                    l * (x_old - c) * h
                };
                self.work
                    .fluct_displacement
                    .push([d[0] - a.x, d[1] - a.y, d[2]]);
            }
            cell.advance_with(&(l + delta), h);
            // Gap change of each image contact from the cell's deformation, n·(Δh k).
            let dh = (cell.h - h_old) * cell_inverse(&h_old);
            for (row, geo) in self.state.contacts.rows_with_geometry() {
                if geo.image != [0.0, 0.0] {
                    let u = dh * Vector::new(geo.image[0], geo.image[1]);
                    cell_gap_shift.push(row.n[0] * u.x + row.n[1] * u.y);
                } else {
                    cell_gap_shift.push(0.0);
                }
            }
            cell.remap();
            // Until the grains follow δ (`control_cell`), the affine field of their velocities
            // stays L⁻: the wraps and the kinetic stress use it.
            self.state.cell = Some(cell);
            cell_work += self.wrap_grains();
            // Work of the impulses against the images' affine velocities.
            for row in &self.state.contacts.rows {
                cell_work -= row.r[0] * row.affine[0] + row.r[1] * row.affine[1];
            }
        }
        (cell_work, cell_gap_shift)
    }

    /// Stage 5: the position correction ([`World::correct_positions`]; velocities untouched
    /// but for the wraps), with the gaps of the image contacts moved by the cell's deformation
    /// (`gap_shift`, from [`World::deform_cell`]) while it predicts `g⁺ = g⁻ + H_n Δq`. The
    /// kinetic energy of its wraps is left in `work.wrap_energy`.
    fn correct(&mut self, gap_shift: &[f64]) -> CorrectionReport {
        self.work.wrap_energy = 0.0;
        if !self.state.params.position_correction {
            return CorrectionReport::default();
        }
        if gap_shift.is_empty() {
            return self.correct_positions();
        }
        let saved: Vec<f64> = self.state.contacts.geometry.iter().map(|g| g.gap).collect();
        for (g, s) in self.state.contacts.geometry.iter_mut().zip(gap_shift) {
            g.gap += s;
        }
        let r = self.correct_positions();
        for (g, s) in self.state.contacts.geometry.iter_mut().zip(saved) {
            g.gap = s;
        }
        r
    }

    /// Stage 6, the cell control: the mean stress of the step ([`World::cell_stress`]), then
    /// the new velocity gradient with the homogeneous change of the grains' velocities (under
    /// an implicit control they take the step's change `delta` too, from `L⁻` to the next `L`),
    /// whose kinetic energy is added to `cell_work` (J). Nothing without a cell.
    fn control_cell(&mut self, delta: Tensor, cell_work: &mut f64) {
        let h = self.state.params.dt;
        if let Some(cell) = self.state.cell {
            let sigma = self.measure_cell_stress(&cell);
            self.state.cell_stress = Some(sigma);
            if let Some(ctl) = self.state.cell_control {
                let l = if ctl.implicit {
                    ctl.implicit_next(&(cell.l + delta))
                } else {
                    ctl.update(&cell.l, &sigma, h)
                };
                if l != cell.l {
                    *cell_work += self.set_velocity_gradient(l);
                }
            }
        }
    }

    /// The end of the step: a cell whose control ran away (its rate ringing up against the
    /// packing, test `a_cell_control_that_runs_away_fails_its_run_at_the_step`) makes the
    /// grains' velocities non-finite only at [`World::control_cell`], through the grains
    /// following it: the step fails, not the measurement after it. Otherwise the step's index,
    /// time and report.
    fn finish(
        &mut self,
        report: SolveReport,
        max_pen: f64,
        correction: CorrectionReport,
        cell_work: f64,
        active: usize,
    ) -> Result<StepReport, DemError> {
        if let Some(cell) = &self.state.cell {
            if !cell.l.iter().chain(cell.h.iter()).all(|x| x.is_finite()) {
                return Err(DemError::NonFiniteCell {
                    step: self.state.step_index + 1,
                });
            }
            if let Some(i) = self.state.bodies.iter().position(|b| {
                !(b.position
                    .iter()
                    .chain(b.velocity.iter())
                    .all(|x| x.is_finite())
                    && b.omega.is_finite())
            }) {
                return Err(DemError::NonFinite {
                    step: self.state.step_index + 1,
                    body: i,
                    what: "position or velocity after the cell's change".into(),
                });
            }
        }
        self.state.step_index += 1;
        self.state.time += self.state.params.dt;
        self.state.last = StepReport {
            step: self.state.step_index,
            time: self.state.time,
            contacts: self.state.contacts.len(),
            active_contacts: active,
            solver: report,
            max_penetration: max_pen,
            position_correction: correction,
            cell_work,
            cell_corrections: 0,
        };
        Ok(self.state.last)
    }

    /// The projection of [`World::correct`] ([`crate::stabilise`]): projects the positions after the
    /// update so that no contact of the step overlaps by more than its slop, moving free degrees
    /// of freedom only and no velocity, and wraps moved grains into the periodic cell. Returns
    /// the projection's report with the work of gravity and the applied loads over it.
    fn correct_positions(&mut self) -> CorrectionReport {
        let mut report = self.work.projection.project(
            &self.state.contacts.rows,
            &self.state.contacts.geometry,
            &self.work.displacement,
            &self.state.last_step.inv,
        );
        if report.corrected_contacts > 0 {
            report.load_work = self.apply_correction();
        }
        // A disk that travelled beyond its swept margin plus half the detection gap, with the
        // correction, may overlap one that no contact of the step knew (`Detector::outran`):
        // detect again at the corrected positions (nothing moves now, so no swept
        // margin; pairs up to a quarter of the smallest radius apart, which the projection can
        // push into contact) and project the actual gaps.
        let moved = if self.state.cell.is_some() {
            &self.work.fluct_displacement
        } else {
            &self.work.displacement
        };
        // The correction that was applied (none when no contact kept a projection impulse).
        let correction = if report.corrected_contacts > 0 {
            self.work.projection.correction()
        } else {
            &[]
        };
        if self.work.image_outran
            || self
                .work
                .detector
                .outran(&self.state.colliders, moved, correction)
        {
            let mut fresh = std::mem::take(&mut self.work.fresh);
            let reach = 0.25 * self.smallest_radius().unwrap_or(0.0);
            // The second projection moves nothing unless a contact is violated: look for one
            // first (the same pairs and gaps, without making the contacts), and detect the
            // contacts only then. Without one, its report is the empty one it would return.
            let deep = self.state.cell.is_some()
                || self
                    .work
                    .detector
                    .finds_deep_overlap(
                        &self.state.bodies,
                        &self.state.last_step.inv,
                        &self.state.colliders,
                        &self.state.laws,
                        self.periodic(),
                        reach,
                        0.0,
                        0.0,
                    )
                    .unwrap_or(true);
            let detected = if deep {
                self.detect_into(reach, 0.0, 0.0, 0.0, &mut fresh)
            } else {
                Ok(())
            };
            if detected.is_ok() {
                let second = if deep {
                    let still = vec![[0.0; 3]; self.state.bodies.len()];
                    self.work.projection.project(
                        &fresh.rows,
                        &fresh.geometry,
                        &still,
                        &self.state.last_step.inv,
                    )
                } else {
                    CorrectionReport::default()
                };
                if second.corrected_contacts > 0 {
                    report.load_work += self.apply_correction();
                }
                report.violated_contacts += second.violated_contacts;
                report.corrected_contacts += second.corrected_contacts;
                report.sweeps += second.sweeps;
                report.capped |= second.capped;
                report.overlap_before = report.overlap_before.max(second.overlap_before);
                report.overlap_after = second.overlap_after;
                report.max_displacement = report.max_displacement.max(second.max_displacement);
            }
            self.work.fresh = fresh;
        }
        report
    }

    /// Moves the bodies by the last projection's correction (free degrees of freedom only,
    /// periodic wrap) and returns the work of gravity and the applied loads over it.
    fn apply_correction(&mut self) -> f64 {
        let g = self.state.params.gravity;
        let periodic = self.periodic();
        let mut work = 0.0;
        for ((b, dq), inv) in self
            .state
            .bodies
            .iter_mut()
            .zip(self.work.projection.correction())
            .zip(&self.state.last_step.inv)
        {
            if *dq == [0.0; 3] {
                continue;
            }
            b.position.x += dq[0];
            b.position.y += dq[1];
            b.angle += dq[2];
            let f = external_loads(b, g);
            for d in 0..3 {
                if inv[d] != 0.0 {
                    work += f[d] * dq[d];
                }
            }
            if let Some(p) = periodic {
                if b.kind == BodyKind::Grain {
                    b.position.x = p.wrap(b.position.x);
                }
            }
        }
        if self.state.cell.is_some() {
            // A correction is a few 10⁻⁴ R: a grain it moves across a face keeps the velocity
            // of its image, as in the step.
            self.work.wrap_energy += self.wrap_grains();
        }
        work
    }
}
