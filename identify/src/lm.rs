//! Box-constrained Levenberg–Marquardt as an [`argmin`] solver.
//!
//! Why our own: argmin 0.11 has no Levenberg–Marquardt (its Gauss–Newton has no damping, so it
//! diverges from poor starts and cannot respect bounds), and the `levenberg-marquardt` crate is
//! built on another nalgebra than the workspace's 0.34 and has no bounds either. The fits here
//! need physical bounds (`K > 0`, `0 < μ_w ≤ μ_wall`, `I₀ > 0`) and must *detect* a parameter
//! ending on its bound, so we implement the method as an argmin [`Solver`]: argmin's
//! [`Executor`](argmin::core::Executor) drives the iterations, counts evaluations and keeps the
//! best state; the step is ours.
//!
//! Minimises `F(x) = ½ ‖r(x)‖²` over the box `l ≤ x ≤ u`. One iteration:
//! 1. `J = ∂r/∂x`, gradient `g = Jᵀ r`, Gauss–Newton matrix `A = JᵀJ`.
//! 2. Active set: components on a bound whose descent direction `−g_i` points outside are
//!    frozen; the others are free (projected-gradient test for convergence:
//!    `‖P(x − g) − x‖_∞ ≤ gtol · max(1, ‖g‖_∞ at start)` on the free set).
//! 3. Damped step on the free set, Marquardt scaling: `(A_ff + λ diag(A_ff)) δ_f = −g_f`;
//!    trial point `x⁺ = P(x + δ)` (projection onto the box).
//! 4. Gain ratio `ρ = (F(x) − F(x⁺)) / (−gᵀs − ½ sᵀ A s)`, `s = x⁺ − x`. Accept when `ρ > 10⁻⁴`
//!    and update `λ ← λ max(1/3, 1 − (2ρ − 1)³)` (Nielsen's rule); otherwise `λ ← λν`, `ν ← 2ν`.
//! 5. Stop when the relative decrease of `F` is below `ftol`, the relative step below `xtol`,
//!    or no damping gives a decrease (a minimum to rounding).

use argmin::core::{
    Error as ArgminError, IterState, Jacobian, Operator, Problem, Solver, State, TerminationReason,
    TerminationStatus, KV,
};
use nalgebra::{DMatrix, DVector};

/// argmin state used by [`BoundedLevenbergMarquardt`]: parameters, Jacobian and residuals are
/// nalgebra dynamic vectors/matrices, the cost is `½‖r‖²`.
pub type LmState = IterState<DVector<f64>, (), DMatrix<f64>, (), DVector<f64>, f64>;

/// Box-constrained Levenberg–Marquardt solver (see the module documentation).
#[derive(Debug, Clone)]
pub struct BoundedLevenbergMarquardt {
    lower: DVector<f64>,
    upper: DVector<f64>,
    lambda: f64,
    nu: f64,
    /// Relative decrease of the cost below which the iteration stops.
    pub ftol: f64,
    /// Relative step below which the iteration stops.
    pub xtol: f64,
    /// Projected-gradient tolerance.
    pub gtol: f64,
    g0: f64,
    status: Option<TerminationReason>,
}

impl BoundedLevenbergMarquardt {
    /// A solver for the box `lower ≤ x ≤ upper` (use ±∞ for unbounded components).
    pub fn new(lower: DVector<f64>, upper: DVector<f64>) -> Self {
        BoundedLevenbergMarquardt {
            lower,
            upper,
            lambda: 1e-3,
            nu: 2.0,
            ftol: 1e-15,
            xtol: 1e-13,
            gtol: 1e-14,
            g0: 1.0,
            status: None,
        }
    }

    /// Projection onto the box.
    pub fn project(&self, x: &DVector<f64>) -> DVector<f64> {
        DVector::from_fn(x.len(), |i, _| x[i].clamp(self.lower[i], self.upper[i]))
    }
}

fn cost_of(r: &DVector<f64>) -> f64 {
    0.5 * r.norm_squared()
}

impl<O> Solver<O, LmState> for BoundedLevenbergMarquardt
where
    O: Operator<Param = DVector<f64>, Output = DVector<f64>>
        + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    fn name(&self) -> &str {
        "bounded Levenberg-Marquardt"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), ArgminError> {
        let x0 = state
            .take_param()
            .ok_or_else(|| ArgminError::msg("Levenberg-Marquardt needs an initial parameter"))?;
        let x0 = self.project(&x0);
        let r = problem.apply(&x0)?;
        if r.iter().any(|v| !v.is_finite()) {
            return Err(ArgminError::msg(
                "residuals are not finite at the initial parameters",
            ));
        }
        let j = problem.jacobian(&x0)?;
        self.g0 = j.tr_mul(&r).amax().max(1.0);
        let cost = cost_of(&r);
        Ok((state.param(x0).residuals(r).cost(cost), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: LmState,
    ) -> Result<(LmState, Option<KV>), ArgminError> {
        let x = state
            .get_param()
            .ok_or_else(|| ArgminError::msg("LM: parameters not set"))?
            .clone();
        let r = state
            .get_residuals()
            .ok_or_else(|| ArgminError::msg("LM: residuals not set"))?
            .clone();
        let cost = cost_of(&r);
        if cost == 0.0 {
            self.status = Some(TerminationReason::SolverConverged);
            return Ok((state.cost(cost), None));
        }
        let j = problem.jacobian(&x)?;
        let g = j.tr_mul(&r);
        let a = j.tr_mul(&j);
        let n = x.len();

        let free: Vec<usize> = (0..n)
            .filter(|&i| {
                let at_lower = x[i] <= self.lower[i] && g[i] > 0.0;
                let at_upper = x[i] >= self.upper[i] && g[i] < 0.0;
                !(at_lower || at_upper)
            })
            .collect();
        let projected_gradient = free.iter().map(|&i| g[i].abs()).fold(0.0, f64::max);
        if free.is_empty() || projected_gradient <= self.gtol * self.g0 {
            self.status = Some(TerminationReason::SolverConverged);
            return Ok((state.cost(cost), None));
        }

        let nf = free.len();
        let max_diag = (0..n).map(|i| a[(i, i)]).fold(0.0, f64::max).max(1e-300);
        for _attempt in 0..60 {
            let mut m = DMatrix::zeros(nf, nf);
            let mut rhs = DVector::zeros(nf);
            for (p, &i) in free.iter().enumerate() {
                rhs[p] = -g[i];
                for (q, &k) in free.iter().enumerate() {
                    m[(p, q)] = a[(i, k)];
                }
                m[(p, p)] += self.lambda * a[(i, i)].max(1e-12 * max_diag);
            }
            let delta = match m.cholesky() {
                Some(ch) => ch.solve(&rhs),
                None => {
                    self.lambda *= self.nu;
                    self.nu *= 2.0;
                    continue;
                }
            };
            let mut trial = x.clone();
            for (p, &i) in free.iter().enumerate() {
                trial[i] += delta[p];
            }
            let trial = self.project(&trial);
            let s = &trial - &x;
            if s.norm() <= self.xtol * (x.norm() + self.xtol) {
                self.status = Some(TerminationReason::SolverConverged);
                return Ok((state.cost(cost), None));
            }
            let r_new = problem.apply(&trial)?;
            let cost_new = cost_of(&r_new);
            let predicted = -(g.dot(&s) + 0.5 * s.dot(&(&a * &s)));
            let rho = if predicted > 0.0 {
                (cost - cost_new) / predicted
            } else {
                -1.0
            };
            if cost_new.is_finite() && cost_new < cost && rho > 1e-4 {
                self.lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                self.lambda = self.lambda.max(1e-15);
                self.nu = 2.0;
                if cost - cost_new <= self.ftol * cost {
                    self.status = Some(TerminationReason::SolverConverged);
                }
                return Ok((
                    state
                        .param(trial)
                        .residuals(r_new)
                        .jacobian(j)
                        .cost(cost_new),
                    None,
                ));
            }
            self.lambda *= self.nu;
            self.nu *= 2.0;
            if self.lambda > 1e30 {
                break;
            }
        }
        // No damping decreases the cost: we are at a minimum to rounding.
        self.status = Some(TerminationReason::SolverConverged);
        Ok((state.cost(cost), None))
    }

    fn terminate(&mut self, _state: &LmState) -> TerminationStatus {
        match self.status.take() {
            Some(reason) => TerminationStatus::Terminated(reason),
            None => TerminationStatus::NotTerminated,
        }
    }
}

/// Outcome of [`minimise`].
#[derive(Debug, Clone)]
pub struct LmOutcome {
    /// Best parameters.
    pub x: DVector<f64>,
    /// Residuals there.
    pub residuals: DVector<f64>,
    /// Iterations used.
    pub iterations: u64,
}

/// Runs [`BoundedLevenbergMarquardt`] through argmin's `Executor` from `x0`.
/// Errors (as text) when argmin fails or the iteration limit is reached.
pub fn minimise<O>(
    problem: O,
    x0: DVector<f64>,
    lower: DVector<f64>,
    upper: DVector<f64>,
    max_iters: u64,
) -> Result<LmOutcome, String>
where
    O: Operator<Param = DVector<f64>, Output = DVector<f64>>
        + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    let solver = BoundedLevenbergMarquardt::new(lower, upper);
    let result = argmin::core::Executor::new(problem, solver)
        .configure(|s| s.param(x0).max_iters(max_iters))
        .timer(false)
        .run()
        .map_err(|e| e.to_string())?;
    let state = result.state();
    if let Some(TerminationReason::MaxItersReached) = state.get_termination_reason() {
        return Err(format!("iteration limit {max_iters} reached"));
    }
    let x = state
        .get_best_param()
        .ok_or_else(|| "no parameters returned".to_string())?
        .clone();
    // Residuals at the best point (the state keeps those of the last accepted point, which is
    // the best one since every accepted step decreases the cost).
    let residuals = state
        .get_residuals()
        .cloned()
        .ok_or_else(|| "no residuals returned".to_string())?;
    Ok(LmOutcome {
        x,
        residuals,
        iterations: state.get_iter(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock as least squares: r = (10 (y − x²), 1 − x), minimum (1, 1).
    struct Rosenbrock;
    impl Operator for Rosenbrock {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, ArgminError> {
            Ok(DVector::from_vec(vec![
                10.0 * (p[1] - p[0] * p[0]),
                1.0 - p[0],
            ]))
        }
    }
    impl Jacobian for Rosenbrock {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, ArgminError> {
            Ok(DMatrix::from_row_slice(
                2,
                2,
                &[-20.0 * p[0], 10.0, -1.0, 0.0],
            ))
        }
    }

    #[test]
    fn rosenbrock_unconstrained_reaches_minimum() {
        let inf = f64::INFINITY;
        let out = minimise(
            Rosenbrock,
            DVector::from_vec(vec![-1.2, 1.0]),
            DVector::from_element(2, -inf),
            DVector::from_element(2, inf),
            500,
        )
        .unwrap();
        assert!((out.x[0] - 1.0).abs() < 1e-10 && (out.x[1] - 1.0).abs() < 1e-10);
    }

    #[test]
    fn rosenbrock_with_active_bound_stops_on_it() {
        // With x ≤ 0.5 the constrained minimum is x = 0.5, y = 0.25 (r₁ = 0 there).
        let inf = f64::INFINITY;
        let out = minimise(
            Rosenbrock,
            DVector::from_vec(vec![-1.2, 1.0]),
            DVector::from_element(2, -inf),
            DVector::from_vec(vec![0.5, inf]),
            500,
        )
        .unwrap();
        assert_eq!(out.x[0], 0.5);
        // Stopping on the relative cost decrease (1e-15) leaves y accurate to ~1e-8.
        assert!((out.x[1] - 0.25).abs() < 1e-7);
    }
}
