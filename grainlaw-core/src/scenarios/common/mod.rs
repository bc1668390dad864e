//! What several scenarios share. Here: the pieces every scenario runner uses (phases with
//! progress and honest solver and numerics accounting, VTK frames at a fixed simulated-time
//! interval, the solver keys of `summary.json`); in the submodules, the shared pieces of the
//! configurations ([`config`]: grains, friction, solver, cell control; [`deposit`]; [`laws`],
//! the laws a plan fits and the data each needs) and of the worlds ([`build`]: walls, the
//! rained column of `janssen` and `stick-slip`, rough beds, the loose biperiodic cell).

pub mod build;
pub mod config;
pub mod deposit;
pub mod laws;

use dem::{StepReport, World};
use serde::{Deserialize, Serialize};

use super::{PhaseEnv, RunOutcome};
pub use crate::checkpoint::Stop;
use crate::error::{CliError, Result};
use crate::output::vtk::VtkSeries;
use crate::output::{OutputDir, Summary};
use crate::progress::{warn, Phase};
use crate::scenarios::phases::{
    continue_steps, continue_until_rest, PhaseProgress, PhaseStats, ENERGY_GROWTH_TOLERANCE,
    PENETRATION_LIMIT,
};

impl RunOutcome {
    /// The outcome of a run that averaged over windows: the summary `s` with the solver keys of
    /// all its phases `all` ([`solver_keys`]) and then the numerics of its windows
    /// (`window_*`, [`crate::verdict::WindowStats::keys`]), the `headline` and the `verdict`.
    pub fn windowed(
        mut s: Summary,
        all: &PhaseStats,
        windows: &crate::verdict::WindowStats,
        headline: Vec<String>,
        verdict: crate::verdict::RunVerdict,
    ) -> Self {
        solver_keys(&mut s, all);
        windows.keys(&mut s, "window");
        Self {
            summary: s,
            headline,
            verdict,
        }
    }
}

/// Runs `world` through one phase with a progress bar, from `progress` (default for a new
/// phase; kept up to date, so that a checkpoint can save it). `each` is called after every step
/// with the updated progress; its error stops the phase and is returned (the run driver's
/// Ctrl-C stop is one). At the end, one line on stderr per problem the phase met: steps whose
/// contact solve did not converge, steps whose energy grew, overlaps beyond the limit, a rest
/// not reached; each names the first step concerned.
pub fn run_phase(
    ctx: &PhaseEnv,
    name: &str,
    world: &mut World,
    stop: Stop,
    progress: &mut PhaseProgress,
    mut each: impl FnMut(&World, &StepReport, &PhaseProgress) -> Result<()>,
) -> Result<PhaseStats> {
    let dt = world.params.dt;
    let len = match stop {
        Stop::UntilRest(r) => (r.max_time / dt).ceil() as u64,
        Stop::Steps(n) => n,
    };
    let bar = Phase::new(ctx.verbosity, name, len);
    bar.set(progress.steps());
    let mut failure: Option<CliError> = None;
    world.record_problems = ctx.dump.is_some();
    let mut cb = |w: &World, r: &StepReport, p: &PhaseProgress| -> bool {
        if let Some(d) = ctx.dump.as_deref().filter(|d| d.wants(r)) {
            if let Err(e) = d.write(name, w, r) {
                failure = Some(e);
                return false;
            }
        }
        if p.steps().is_multiple_of(25) {
            bar.set(p.steps());
            bar.message(format!(
                "t={:.3}s sweeps={} err={:.1e}",
                w.time, r.solver.iterations, r.solver.error
            ));
        }
        if let Err(e) = each(w, r, p) {
            failure = Some(e);
            return false;
        }
        true
    };
    let stats = match stop {
        Stop::UntilRest(r) => continue_until_rest(world, &r, progress, &mut cb)?,
        Stop::Steps(n) => continue_steps(world, n, progress, &mut cb)?,
    };
    if let Some(e) = failure {
        bar.finish("stopped");
        return Err(e);
    }
    let rest = match stop {
        Stop::UntilRest(_) if stats.at_rest => ", at rest",
        Stop::UntilRest(_) => ", NOT at rest at the time limit",
        Stop::Steps(_) => "",
    };
    let sub = if stats.subdivided_steps > 0 {
        format!(
            " ({} subdivided, up to {} sub-steps)",
            stats.subdivided_steps,
            1u64 << stats.max_halvings_used
        )
    } else {
        String::new()
    };
    bar.finish(&format!(
        "{} steps of {:.2e} s{sub}, {:.3} s simulated, {:.0} sweeps/step on average{rest}",
        stats.steps,
        dt,
        stats.simulated_time,
        stats.mean_sweeps()
    ));
    for line in phase_warnings(name, &stats, world, matches!(stop, Stop::UntilRest(_))) {
        warn(&line);
    }
    Ok(stats)
}

/// The warnings of a finished phase (one line each): non-converged steps, energy growth,
/// overlaps beyond [`PENETRATION_LIMIT`], rest not reached (`looks_for_rest`).
pub fn phase_warnings(
    name: &str,
    stats: &PhaseStats,
    world: &World,
    looks_for_rest: bool,
) -> Vec<String> {
    let mut lines = Vec::new();
    let solver = &world.params.solver;
    let first = |s: Option<u64>| s.map_or_else(|| "?".to_string(), |s| s.to_string());
    if stats.unconverged_steps > 0 {
        lines.push(format!(
            "{name}: {} of {} steps stopped at the sweep cap ({}{}) above the tolerance {:.0e}, first at step {}; worst error {:.2e}",
            stats.unconverged_steps,
            stats.steps,
            solver.max_iterations,
            match (stats.max_halvings_used, stats.paused_steps) {
                (0, 0) => String::new(),
                (l, 0) => format!(", in up to {} sub-steps", 1u64 << l),
                (l, p) => format!(
                    ", in up to {} sub-steps; {p} steps done whole while the subdivision paused",
                    1u64 << l
                ),
            },
            solver.tolerance,
            first(stats.first_unconverged_step),
            stats.worst_error
        ));
    }
    if stats.energy_growth_steps > 0 {
        lines.push(format!(
            "{name}: the mechanical energy grew in {} of {} steps, first at step {}; worst growth {:.2e} of the load energy E_load (tolerance {ENERGY_GROWTH_TOLERANCE:.0e})",
            stats.energy_growth_steps,
            stats.steps,
            first(stats.first_energy_growth_step),
            stats.worst_energy_growth
        ));
    }
    if stats.penetration_flagged_steps > 0 {
        lines.push(format!(
            "{name}: overlap above {:.0} % of the smallest radius in {} of {} steps, first at step {}; largest {:.2e} m ({:.1} % of the smallest radius)",
            100.0 * PENETRATION_LIMIT,
            stats.penetration_flagged_steps,
            stats.steps,
            first(stats.first_penetration_step),
            stats.max_penetration,
            100.0 * stats.max_penetration_ratio
        ));
    }
    if looks_for_rest && !stats.at_rest {
        lines.push(format!(
            "{name}: not at rest after {:.3} s (kinetic energy / E_load = {:.2e})",
            stats.simulated_time, stats.final_energy_ratio
        ));
    }
    lines
}

/// Solver and numerics keys of `summary.json`: `solver_steps`, `solver_unconverged_steps`,
/// `solver_first_unconverged_step`, `solver_worst_error`, `solver_worst_error_without_gap_shifts`
/// (the same residuals over a scale that leaves out the gap-closing shifts of open pairs:
/// what the error is on the loaded contacts, docs/physics.md §1.6), `solver_mean_sweeps`,
/// `solver_max_sweeps`; `max_penetration_m`,
/// `max_penetration_over_radius` (over the smallest grain radius), `penetration_flagged_steps`
/// (overlap above [`PENETRATION_LIMIT`] of it) and `penetration_first_step`;
/// `energy_growth_steps` (energy residual above [`ENERGY_GROWTH_TOLERANCE`] of the load energy
/// scale), `energy_growth_first_step` and `energy_growth_worst` (largest residual over the
/// scale); `position_corrected_steps` (steps where the position correction moved something),
/// `position_correction_energy_J` (the potential energy it added, `−Σ f·Δq_c`) and
/// `max_corrected_overlap_over_radius` (the largest overlap it removed, over the smallest grain
/// radius); `solver_subdivided_steps` (steps redone in sub-steps because their solve did not
/// converge, `dem::step_control::step_subdivided`), `solver_substeps` (sub-steps kept),
/// `solver_max_halvings_used`, `solver_discarded_sweeps` (sweeps of the undone attempts,
/// included in the mean) and `solver_paused_steps` (steps done whole while the subdivision
/// paused after repeated failures at its largest level), `solver_polished_steps` (converged
/// steps whose energy grew, solved again at a tenth of the tolerance). A first step is the world's step index, `null` when there is none.
pub fn solver_keys(s: &mut Summary, stats: &PhaseStats) {
    let step = |v: Option<u64>| v.map_or(serde_json::Value::Null, serde_json::Value::from);
    s.int("solver_steps", stats.steps)
        .int("solver_unconverged_steps", stats.unconverged_steps)
        .set(
            "solver_first_unconverged_step",
            step(stats.first_unconverged_step),
        )
        .num("solver_worst_error", stats.worst_error)
        .num(
            "solver_worst_error_without_gap_shifts",
            stats.worst_error_without_gap_shifts,
        )
        .num("solver_mean_sweeps", stats.mean_sweeps())
        .int("solver_max_sweeps", stats.max_sweeps as u64)
        .num("max_penetration_m", stats.max_penetration)
        .num("max_penetration_over_radius", stats.max_penetration_ratio)
        .int("penetration_flagged_steps", stats.penetration_flagged_steps)
        .set("penetration_first_step", step(stats.first_penetration_step))
        .int("energy_growth_steps", stats.energy_growth_steps)
        .set(
            "energy_growth_first_step",
            step(stats.first_energy_growth_step),
        )
        .num("energy_growth_worst", stats.worst_energy_growth)
        .int("position_corrected_steps", stats.position_corrected_steps)
        .num(
            "position_correction_energy_J",
            stats.position_correction_energy,
        )
        .num(
            "max_corrected_overlap_over_radius",
            stats.max_corrected_overlap_ratio,
        )
        .int("solver_subdivided_steps", stats.subdivided_steps)
        .int("solver_substeps", stats.substeps)
        .int(
            "solver_max_halvings_used",
            u64::from(stats.max_halvings_used),
        )
        .int("solver_discarded_sweeps", stats.discarded_sweeps)
        .int("solver_paused_steps", stats.paused_steps)
        .int("solver_polished_steps", stats.polished_steps);
}

/// VTK frames every `interval` seconds of simulated time, at most `max_frames` (the final
/// state is added by [`VtkFrames::finish`]). Serialisable, for run checkpoints.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct VtkFrames {
    series: VtkSeries,
    #[serde(with = "dem::serde_float")]
    interval: f64,
    #[serde(with = "dem::serde_float")]
    next: f64,
    max_frames: usize,
}

impl VtkFrames {
    /// Frames every `interval` s, at most `max_frames` including the final one.
    pub fn new(interval: f64, max_frames: usize) -> Self {
        Self {
            series: VtkSeries::new(),
            interval,
            next: 0.0,
            max_frames,
        }
    }

    /// Like [`VtkFrames::new`] with file names prefixed by `prefix`.
    pub fn with_prefix(prefix: &str, interval: f64, max_frames: usize) -> Self {
        Self {
            series: VtkSeries::with_prefix(prefix),
            interval,
            next: 0.0,
            max_frames,
        }
    }

    /// Writes a frame if one is due.
    pub fn maybe(&mut self, out: &mut OutputDir, world: &World) -> Result<()> {
        if self.series.len() + 1 < self.max_frames && world.time + 1e-12 >= self.next {
            self.series.add_frame(out, &world.snapshot())?;
            self.next = world.time + self.interval;
        }
        Ok(())
    }

    /// Writes the final frame and the `.pvd` collections.
    pub fn finish(mut self, out: &mut OutputDir, world: &World) -> Result<usize> {
        self.series.add_frame(out, &world.snapshot())?;
        self.series.finish(out)?;
        Ok(self.series.len())
    }
}

/// Weight of the grains `Σ m |g|` (N per metre of thickness... for unit thickness, N).
pub fn grain_weight(world: &World) -> f64 {
    let g = world.params.gravity.norm();
    world
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .map(|b| b.mass * g)
        .sum()
}

/// Mean grain diameter (m).
pub fn mean_diameter(world: &World) -> f64 {
    let (s, n) = world
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .fold((0.0, 0usize), |(s, n), b| (s + 2.0 * b.radius, n + 1));
    if n > 0 {
        s / n as f64
    } else {
        0.0
    }
}

/// Pointwise confidence band of a fitted curve by the delta method: for each `x`, the value
/// `f(p, x)`, and `f ∓ t √(gᵀ C g)` with `g = ∂f/∂p` by central differences (relative step 1e-6)
/// and `C` the parameters' covariance. Returns `(x, f, lo, hi)`.
pub fn delta_band(
    p: &[f64],
    cov: &[Vec<f64>],
    t: f64,
    xs: &[f64],
    f: impl Fn(&[f64], f64) -> f64,
) -> Vec<(f64, f64, f64, f64)> {
    xs.iter()
        .map(|&x| {
            let y = f(p, x);
            let mut g = vec![0.0; p.len()];
            for k in 0..p.len() {
                let h = 1e-6 * p[k].abs().max(1e-12);
                let mut a = p.to_vec();
                let mut b = p.to_vec();
                a[k] += h;
                b[k] -= h;
                g[k] = (f(&a, x) - f(&b, x)) / (2.0 * h);
            }
            let mut var = 0.0;
            for i in 0..p.len() {
                for j in 0..p.len() {
                    var += g[i] * cov.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0) * g[j];
                }
            }
            let e = t * var.max(0.0).sqrt();
            (x, y, y - e, y + e)
        })
        .collect()
}

/// Summary keys of a fit's parameters: `{prefix}_{name}` with `_ci_low` / `_ci_high` (95 %).
pub fn fit_keys(s: &mut Summary, prefix: &str, parameters: &[identify::Estimate]) {
    for e in parameters {
        s.num(&format!("{prefix}_{}", e.name), e.value)
            .num(&format!("{prefix}_{}_ci_low", e.name), e.ci_low)
            .num(&format!("{prefix}_{}_ci_high", e.name), e.ci_high);
    }
}

/// The printed lines of a fit: `title (R² = …)`, then one line per parameter with its 95 %
/// interval, so that no fitted number reaches stdout without its interval.
pub fn parameter_lines(
    title: &str,
    r_squared: f64,
    parameters: &[identify::Estimate],
) -> Vec<String> {
    let mut lines = vec![format!("{title} (R² = {r_squared:.3})")];
    let width = parameters
        .iter()
        .map(|e| e.name.chars().count())
        .max()
        .unwrap_or(0);
    for e in parameters {
        lines.push(format!(
            "  {:<width$} = {}  (95 % CI {} … {}){}",
            e.name,
            short_number(e.value),
            short_number(e.ci_low),
            short_number(e.ci_high),
            if e.unit == "1" || e.unit.is_empty() {
                String::new()
            } else {
                format!(" {}", e.unit)
            }
        ));
    }
    lines
}

/// Four significant digits: fixed notation between 10⁻² and 10⁴, scientific elsewhere.
pub fn short_number(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-2..1e4).contains(&a) {
        let digits = if a == 0.0 {
            3
        } else {
            (3 - a.log10().floor() as i32).clamp(0, 6) as usize
        };
        format!("{x:.digits$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Adds a fitted curve and its 95 % confidence band (from [`delta_band`]) to `plot`.
pub fn add_fitted_curve(
    plot: &mut crate::plot::xy::XyPlot,
    label: &str,
    band_color: plotters::style::RGBColor,
    line_color: plotters::style::RGBColor,
    band: &[(f64, f64, f64, f64)],
) {
    use crate::plot::xy::{Band, Series, Style};
    plot.bands.push(Band::between(
        "95 % confidence band",
        band_color,
        &band.iter().map(|b| (b.0, b.2, b.3)).collect::<Vec<_>>(),
    ));
    plot.series.push(Series::new(
        label,
        Style::Line,
        line_color,
        band.iter().map(|b| (b.0, b.1)).collect(),
    ));
}

/// Means of the columns `cols` of a history (typed rows, [`super::rows`]) over consecutive bins
/// of `width` of its column `axis` (a strain growing along the rows; the first bin starts at 0):
/// one array of means per bin with at least one row that `keep` accepts, in the order of `cols`.
/// The means are of the step values; what is derived from them (a stress ratio of mean
/// stresses, a peak) is the caller's.
pub fn strain_bins<R, const N: usize>(
    history: &[R],
    axis: impl Fn(&R) -> f64,
    width: f64,
    cols: [fn(&R) -> f64; N],
    keep: impl Fn(&R) -> bool,
) -> Vec<[f64; N]> {
    let mut out = Vec::new();
    let mut acc = [0.0; N];
    let mut n = 0usize;
    let mut current = 0i64;
    let mut flush = |acc: &mut [f64; N], n: &mut usize| {
        if *n > 0 {
            out.push(acc.map(|v| v / *n as f64));
        }
        acc.iter_mut().for_each(|v| *v = 0.0);
        *n = 0;
    };
    for r in history {
        let b = (axis(r) / width).floor() as i64;
        if b != current {
            flush(&mut acc, &mut n);
            current = b;
        }
        if keep(r) {
            for (a, col) in acc.iter_mut().zip(cols) {
                *a += col(r);
            }
            n += 1;
        }
    }
    flush(&mut acc, &mut n);
    out
}

/// Gain of the implicit cell control of the cell scenarios (`dem::cell_coupling`), in units of
/// `ε̇_max/p`: a cell without contacts closes at most at `(1 + K) ε̇_max`, and a jammed packing's
/// stress misses its target by `p ΔL/(K ε̇_max)`, `ΔL` the change of the rate it can follow over
/// one step. Measured (`biaxial`, 100 disks, μ = 0.5, p₀ = 1 kPa, 5 % axial strain): K = 1, 10,
/// 30 give a lateral stress of −p₀ ± 6 %, ± 1.8 %, ± 1.0 % (standard deviation over the steps)
/// and 151, 119, 246 of 475 steps at a sweep cap of 1000 (a lighter cell slows Gauss–Seidel;
/// measured before the grains followed the cell's change at the end of each step, which cut the
/// sweeps 5-fold).
pub const IMPLICIT_GAIN: f64 = 10.0;

/// The implicit cell control of a cell scenario (`dem::cell::CellControl::implicit_law`):
/// `g = K ε̇_max/pressure` with [`IMPLICIT_GAIN`] and the rate cap `cap` (1/s); while a loose
/// packing is compressed isotropically (`compressing`) the reference rate is capped at
/// `cap/(1 + K)`, so that it closes at most at `cap` until it jams.
pub fn implicit_cell_control(
    xx: dem::Imposed,
    yy: dem::Imposed,
    xy: dem::Imposed,
    cap: f64,
    pressure: f64,
    compressing: bool,
) -> dem::CellControl {
    let max_rate = if compressing {
        cap / (1.0 + IMPLICIT_GAIN)
    } else {
        cap
    };
    dem::CellControl::implicit_law(xx, yy, xy, IMPLICIT_GAIN * max_rate / pressure, max_rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_parameters_print_with_their_intervals() {
        let e = identify::Estimate::new("mu_s", "1", 0.3812, 0.01, 2.0);
        let lines = parameter_lines("μ(I)", 0.9, &[e]);
        assert_eq!(lines[0], "μ(I) (R² = 0.900)");
        assert_eq!(lines[1], "  mu_s = 0.3812  (95 % CI 0.3612 … 0.4012)");
        assert_eq!(short_number(1.2345e-5), "1.234e-5");
        assert_eq!(short_number(1234.5), "1234");
    }
}
