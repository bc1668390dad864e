//! Time step control from the contact solve, for runs whose only goal is a state (settling a
//! packing), not a trajectory at a fixed step.
//!
//! A step whose solve stops at the sweep cap leaves its closed contacts approaching at some
//! residual speed `u_a`, so the overlap grows by `h u_a` that step; over a transient of
//! `T / h` steps the overlap left behind scales as `T u_a`, with `u_a` itself of the order of the
//! unbalanced part of `g h`: halving `h` roughly halves the overlap a transient leaves, and it
//! makes each step's load change smaller. Once the packing is quiet the step can grow again.
//! A rule in the spirit of LMGC90's adaptive step on the NLGS iteration count:
//!
//! ```text
//! solve not converged                       →  h ← max(h / 2, h_min)
//! `calm_steps` steps in a row converged in
//! at most `calm_fraction` of the sweep cap  →  h ← min(h · grow, h_max)
//! ```
//!
//! Impulses are warm-started across a change of `h` by the ratio of the steps (the world does
//! it), so a change costs nothing.

use serde::{Deserialize, Serialize};

use crate::world::{StepReport, World};

/// The rule and its state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StepControl {
    /// Smallest time step (s).
    pub min_dt: f64,
    /// Largest time step (s).
    pub max_dt: f64,
    /// Growth factor after a calm run (> 1).
    pub grow: f64,
    /// Consecutive calm steps before the step grows.
    pub calm_steps: usize,
    /// A step is calm when it converged within this fraction of the sweep cap.
    pub calm_fraction: f64,
    calm: usize,
}

impl StepControl {
    /// Steps between `min_dt` and `max_dt` (s), growing by 2 after 5 calm steps (converged
    /// within a quarter of the sweep cap).
    pub fn new(min_dt: f64, max_dt: f64) -> Self {
        StepControl {
            min_dt,
            max_dt,
            grow: 2.0,
            calm_steps: 5,
            calm_fraction: 0.25,
            calm: 0,
        }
    }

    /// Adjust `w.params.dt` after a step that reported `report`; returns the new step (s).
    pub fn after(&mut self, w: &mut World, report: &StepReport) -> f64 {
        let h = w.params.dt;
        let cap = w.params.solver.max_iterations as f64;
        let new = if !report.solver.converged {
            self.calm = 0;
            (0.5 * h).max(self.min_dt)
        } else if (report.solver.iterations as f64) <= self.calm_fraction * cap {
            self.calm += 1;
            if self.calm >= self.calm_steps {
                self.calm = 0;
                (self.grow * h).min(self.max_dt)
            } else {
                h
            }
        } else {
            self.calm = 0;
            h
        };
        w.params.dt = new;
        new
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::SolveReport;
    use crate::{ContactLaws, WorldParams};

    fn report(converged: bool, iterations: usize) -> StepReport {
        StepReport {
            solver: SolveReport {
                iterations,
                converged,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// Halves on a capped step down to the floor, grows by 2 only after 5 calm steps in a row
    /// (a busy step resets the count), up to the ceiling.
    #[test]
    fn halves_on_failure_and_grows_after_a_calm_run() {
        let params = WorldParams {
            dt: 1e-3,
            ..Default::default()
        };
        let mut w = World::new(params, ContactLaws::new(&["m"], 0.5));
        w.params.solver.max_iterations = 100;
        let mut c = StepControl::new(1.25e-4, 1e-3);
        assert_eq!(c.after(&mut w, &report(false, 100)), 5e-4);
        assert_eq!(c.after(&mut w, &report(false, 100)), 2.5e-4);
        assert_eq!(c.after(&mut w, &report(false, 100)), 1.25e-4);
        assert_eq!(c.after(&mut w, &report(false, 100)), 1.25e-4);
        for _ in 0..4 {
            assert_eq!(c.after(&mut w, &report(true, 25)), 1.25e-4);
        }
        // a converged but busy step (more than a quarter of the cap) resets the count
        assert_eq!(c.after(&mut w, &report(true, 26)), 1.25e-4);
        for _ in 0..4 {
            assert_eq!(c.after(&mut w, &report(true, 3)), 1.25e-4);
        }
        assert_eq!(c.after(&mut w, &report(true, 3)), 2.5e-4);
        for _ in 0..20 {
            c.after(&mut w, &report(true, 0));
        }
        assert_eq!(w.params.dt, 1e-3);
    }
}
