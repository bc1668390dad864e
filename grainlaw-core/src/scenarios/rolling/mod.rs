//! The `rolling` scenario: one homogeneous disk released from rest on a slope
//! (`docs/physics.md` §2.3, the seed paper's eq. 13–14), the exact check of the mean stress
//! with inertia. Its files and `summary.json` keys: `docs/outputs.md` §3.1.
//!
//! In the slope frame (e₁ down the slope, e₂ the outward normal), for μ ≥ tan φ / 3 the disk
//! rolls without slipping with acceleration `(2/3) g sin φ`, and when its centre has travelled L
//!
//! `Σ_p = ρ g a [[0, sin φ/6], [sin φ/6, −cos φ]] + (ρ g L sin φ / 3) 𝟙`,
//! `Σ_c = ρ g a [[0, sin φ/3], [0, −cos φ]]` (the contact part alone, not symmetric).
//!
//! For μ < tan φ / 3 it rolls while sliding, acceleration `g (sin φ − μ cos φ)`; the exact stress
//! then follows from the same formula with the friction force μ m g cos φ (also reported).

pub mod build;
pub mod config;

use dem::math::Vector;
use homogenise::tensor::{frobenius, in_frame, skew_ratio, Tensor2};
use serde::{Deserialize, Serialize};

use super::common::{solver_keys, Stop, VtkFrames};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::PhaseStats;
use super::rows::{self, serde_csv_table, table_row};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::{CliError, Result};
use crate::output::{OutputDir, Summary};
use crate::plot::xy::{draw_row, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use build::rolling;
use config::RollingConfig;

/// Exact acceleration along the slope (m/s²), friction force over m g (up the slope), and
/// whether the disk rolls without slipping.
pub fn exact_motion(slope_rad: f64, mu: f64, g: f64) -> (f64, f64, bool) {
    let (s, c) = slope_rad.sin_cos();
    if mu >= slope_rad.tan() / 3.0 {
        (2.0 / 3.0 * g * s, s / 3.0, true)
    } else {
        (g * (s - mu * c), mu * c, false)
    }
}

/// Exact slope-frame mean stress `(Σ_p, Σ_c)` (Pa) of the disk (radius a, density ρ) after it
/// travelled `l` with angular velocity `omega` and angular acceleration `omega_dot`, friction
/// force `f m g` up the slope: contact term `(1/V)[(−f m g) e₁ + m g cos φ e₂] ⊗ (−a e₂)`, inertia
/// term `(I/2V)(−ω̇ j + ω² 𝟙)` (the slope frame is a rotation of the world frame, so `j` keeps
/// its components).
pub fn exact_stress(
    rho: f64,
    g: f64,
    a: f64,
    slope_rad: f64,
    f: f64,
    omega: f64,
    omega_dot: f64,
) -> (Tensor2, Tensor2) {
    let c = slope_rad.cos();
    let contact = Tensor2::new(0.0, rho * g * a * f, 0.0, -rho * g * a * c);
    let k = 0.25 * rho * a * a; // I/(2V) = (m a²/2)/(2 π a²) = ρ a²/4
    let inertia = Tensor2::new(
        k * omega * omega,
        k * omega_dot,
        -k * omega_dot,
        k * omega * omega,
    );
    (contact + inertia, contact)
}

/// The single phase: the disk rolls for `duration`.
struct Roll<'a> {
    c: &'a RollingConfig,
}

/// What the rolling phase collects.
#[derive(Serialize, Deserialize)]
struct RollState {
    /// Slope frame: down the slope, outward normal.
    e1: Vector,
    e2: Vector,
    /// Initial centre (m).
    c0: Vector,
    /// One row per step: `history.csv`.
    #[serde(with = "serde_csv_table")]
    hist: Vec<RollStep>,
    vtk: VtkFrames,
    stats: PhaseStats,
}

table_row! {
    /// One step of the rolling disk: a row of `history.csv` (slope frame).
    struct RollStep {
        /// Time (s).
        t: "time_s",
        /// Distance travelled down the slope L (m).
        travelled: "travelled_m",
        /// Velocity down the slope (m/s).
        velocity: "velocity_m_s",
        /// Angular velocity (rad/s, counter-clockwise).
        omega: "omega_rad_s",
        /// Slip velocity of the contact point `v + ω a` (m/s).
        slip: "slip_velocity_m_s",
        /// Mean stress with inertia Σ_p, xx (Pa).
        sxx: "stress_xx_Pa",
        /// Σ_p, xy (Pa).
        sxy: "stress_xy_Pa",
        /// Σ_p, yx (Pa).
        syx: "stress_yx_Pa",
        /// Σ_p, yy (Pa).
        syy: "stress_yy_Pa",
        /// Contact part Σ_c, xx (Pa).
        cxx: "contact_stress_xx_Pa",
        /// Σ_c, xy (Pa).
        cxy: "contact_stress_xy_Pa",
        /// Σ_c, yx (Pa).
        cyx: "contact_stress_yx_Pa",
        /// Σ_c, yy (Pa).
        cyy: "contact_stress_yy_Pa",
    }
}

impl RollStep {
    /// The mean stress with inertia Σ_p (slope frame, Pa).
    fn total(&self) -> Tensor2 {
        Tensor2::new(self.sxx, self.sxy, self.syx, self.syy)
    }

    /// The contact part Σ_c (slope frame, Pa).
    fn contact(&self) -> Tensor2 {
        Tensor2::new(self.cxx, self.cxy, self.cyx, self.cyy)
    }
}

impl PhasedRun for Roll<'_> {
    type State = RollState;

    fn enter(&self, _st: &mut RollState, _at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let c = self.c;
        Ok(Some(PhasePlan::new(
            "roll",
            Stop::Steps((c.duration / c.dt).round().max(1.0) as u64),
        )))
    }

    fn step(&self, st: &mut RollState, at: Step<'_>) -> Result<()> {
        let (out, w) = (at.out, at.world);
        let snap = w.snapshot();
        let gs = homogenise::grain_stresses(&snap)?;
        let gr = gs
            .first()
            .ok_or_else(|| CliError::Usage("no grain".into()))?;
        let (e1, e2) = (st.e1, st.e2);
        let tot = in_frame(&gr.total, &e1, &e2);
        let con = in_frame(&gr.contact, &e1, &e2);
        let b = &w.bodies[1];
        let v = b.velocity.dot(&e1);
        // Slip velocity of the contact point along e₁: v + ω a (ω counter-clockwise, the
        // contact point is at −a e₂ from the centre: ω e_z × (−a e₂) = ω a e₁).
        let slip = v + b.omega * self.c.radius;
        st.hist.push(RollStep {
            t: w.time,
            travelled: (b.position - st.c0).dot(&e1),
            velocity: v,
            omega: b.omega,
            slip,
            sxx: tot[(0, 0)],
            sxy: tot[(0, 1)],
            syx: tot[(1, 0)],
            syy: tot[(1, 1)],
            cxx: con[(0, 0)],
            cxy: con[(0, 1)],
            cyx: con[(1, 0)],
            cyy: con[(1, 1)],
        });
        st.vtk.maybe(out, w)
    }

    fn leave(&self, st: &mut RollState, at: Leave<'_>) -> Result<()> {
        let stats = at.stats;
        st.stats = *stats;
        Ok(())
    }
}

/// Stages "build" and "run": the disk released on the slope (or resumed from a checkpoint).
fn simulate(
    c: &RollingConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<(dem::World, RollState)> {
    let fresh = || -> Result<(dem::World, RollState)> {
        let (world, e1, e2) = build::rolling(c)?;
        let c0 = world.bodies[1].position;
        let state = RollState {
            e1,
            e2,
            c0,
            hist: Vec::new(),
            vtk: VtkFrames::new(c.duration / 20.0, 21),
            stats: PhaseStats::default(),
        };
        Ok((world, state))
    };
    drive(ctx, ctl, &Roll { c }, fresh)
}

/// The exact answers the figures compare with ([`exact_motion`]).
#[derive(Debug, Clone, Copy)]
struct Exact {
    /// Acceleration down the slope (m/s²).
    a_exact: f64,
    /// Friction force over the disk's weight term of the contact stress.
    f: f64,
    /// Whether the disk rolls without slipping.
    rolls: bool,
}

/// Stage "report": `stress_vs_travel.png`, the stress components against the distance
/// travelled `l` (m), DEM against the exact formulas, on a slope of `phi` (rad) under gravity
/// `g` (m/s²).
fn stress_figures(
    out: &mut OutputDir,
    c: &RollingConfig,
    hist: &[RollStep],
    (g, phi, l): (f64, f64, f64),
    exact: Exact,
) -> Result<()> {
    let Exact { f, rolls, .. } = exact;
    let rho_g_a = c.density * g * c.radius;
    let mut p1 = XyPlot::new(
        "Mean stress with inertia Σ_p (slope frame)",
        Axis::new("distance travelled L (m)"),
        Axis::new("stress / (ρ g a)"),
    );
    let mut p2 = XyPlot::new(
        "Contact part alone Σ_c (not symmetric)",
        Axis::new("distance travelled L (m)"),
        Axis::new("stress / (ρ g a)"),
    );
    let every = (hist.len() / 25).max(1);
    let pts = |tensor: fn(&RollStep) -> Tensor2, ij: (usize, usize)| -> Vec<(f64, f64)> {
        hist.iter()
            .step_by(every)
            .map(|r| (r.travelled, tensor(r)[ij] / rho_g_a))
            .collect()
    };
    let components = [(0, 0), (0, 1), (1, 0), (1, 1)];
    let lmax = l.max(1e-12);
    let line = |v0: f64, slope: f64| vec![(0.0, v0), (lmax, v0 + slope * lmax)];
    let (sn, cs) = (phi.sin(), phi.cos());
    let iso = if rolls {
        sn / (3.0 * c.radius)
    } else {
        f64::NAN
    };
    let fxy = f;
    let names = ["xx", "xy", "yx", "yy"];
    let exact_total = [(0.0, iso), (fxy / 2.0, 0.0), (fxy / 2.0, 0.0), (-cs, iso)];
    let exact_contact = [(0.0, 0.0), (fxy, 0.0), (0.0, 0.0), (-cs, 0.0)];
    for (k, name) in names.iter().enumerate() {
        let col = PALETTE[k];
        p1.series.push(Series::new(
            &format!("Σ_{name} exact"),
            Style::Line,
            col,
            line(exact_total[k].0, if rolls { exact_total[k].1 } else { 0.0 }),
        ));
        p1.series.push(Series::new(
            &format!("Σ_{name} DEM"),
            if k == 2 {
                Style::Circles
            } else {
                Style::Points
            },
            col,
            pts(RollStep::total, components[k]),
        ));
        p2.series.push(Series::new(
            &format!("Σc_{name} exact"),
            Style::Line,
            col,
            line(exact_contact[k].0, 0.0),
        ));
        p2.series.push(Series::new(
            &format!("Σc_{name} DEM"),
            if k == 2 {
                Style::Circles
            } else {
                Style::Points
            },
            col,
            pts(RollStep::contact, components[k]),
        ));
    }
    p1.legend = LegendAt::MiddleRight;
    p2.legend = LegendAt::MiddleRight;
    if !rolls {
        p1.notes
            .push("μ < tan φ/3: rolls while sliding (isotropic term from ω² only)".into());
    }
    draw_row(out, "stress_vs_travel.png", &[p1, p2], (1800, 700))?;
    Ok(())
}

/// Stage "report": `motion.png`, the distance travelled against the exact motion and the slip
/// velocity of the contact point.
fn motion_figures(
    out: &mut OutputDir,
    c: &RollingConfig,
    hist: &[RollStep],
    exact: Exact,
) -> Result<()> {
    let Exact { a_exact, rolls, .. } = exact;
    let every = (hist.len() / 25).max(1);
    let mut m = XyPlot::new(
        "Motion of the centre",
        Axis::new("time t (s)"),
        Axis::new("distance travelled L (m)"),
    );
    m.series.push(Series::new(
        &format!("exact ½ a t², a = {a_exact:.4} m/s²"),
        Style::Line,
        PALETTE[1],
        (0..=50)
            .map(|k| {
                let t = c.duration * k as f64 / 50.0;
                (t, 0.5 * a_exact * t * t)
            })
            .collect(),
    ));
    m.series.push(Series::new(
        "DEM",
        Style::Points,
        PALETTE[0],
        hist.iter()
            .step_by(every)
            .map(|r| (r.t, r.travelled))
            .collect(),
    ));
    m.legend = LegendAt::UpperLeft;
    // Rolling without slipping: the slip is round-off (1e-16 m/s); show it on a ±1 μm/s scale.
    let slip_axis = if rolls {
        Axis::new("slip velocity v + ω a (m/s)").range(-1e-6, 1e-6)
    } else {
        Axis::new("slip velocity v + ω a (m/s)")
    };
    let mut sv = XyPlot::new(
        "Slip velocity of the contact point",
        Axis::new("time t (s)"),
        slip_axis,
    );
    sv.series.push(Series::new(
        "DEM",
        Style::Line,
        PALETTE[2],
        hist.iter().map(|r| (r.t, r.slip)).collect(),
    ));
    draw_row(out, "motion.png", &[m, sv], (1600, 600))?;
    Ok(())
}

/// Runs the scenario: build and run (`simulate`), measure (the acceleration, the stress
/// at the end), compare with the exact answers, report.
pub fn run(c: &RollingConfig, ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    let phi = c.slope_deg.to_radians();
    let (
        world,
        RollState {
            hist, vtk, stats, ..
        },
    ) = simulate(c, ctx, ctl)?;
    let g = world.params.gravity.norm();
    let frames = vtk.finish(&mut ctx.out, &world)?;
    let last = hist.last().copied().unwrap_or_default();
    // Measured acceleration: least squares of v(t) = a t.
    let (svt, stt) = hist.iter().fold((0.0, 0.0), |(a, b), r| {
        (a + r.velocity * r.t, b + r.t * r.t)
    });
    let accel = svt / stt;
    let (a_exact, f, rolls) = exact_motion(phi, c.friction, g);
    let b = &world.bodies[1];
    let (s_exact, c_exact) = exact_stress(
        c.density,
        g,
        c.radius,
        phi,
        f,
        b.omega,
        b.angular_acceleration,
    );
    let tot = last.total();
    let con = last.contact();
    let l = last.travelled;
    let paper = Tensor2::new(0.0, phi.sin() / 6.0, phi.sin() / 6.0, -phi.cos())
        * (c.density * g * c.radius)
        + Tensor2::identity() * (c.density * g * l * phi.sin() / 3.0);

    let mut s = Summary::new();
    s.num("slope_deg", c.slope_deg)
        .num("radius", c.radius)
        .num("density", c.density)
        .num("friction", c.friction)
        .num("duration", c.duration)
        .num("dt", c.dt)
        .flag("rolls_without_slipping", rolls)
        .num("acceleration", accel)
        .num("expected_acceleration", a_exact)
        .num(
            "acceleration_rel_error",
            (accel - a_exact).abs() / a_exact.abs().max(1e-300),
        )
        .num("travelled", l);
    for (name, t) in [("stress", &tot), ("contact_stress", &con)] {
        s.num(&format!("{name}_xx"), t[(0, 0)])
            .num(&format!("{name}_xy"), t[(0, 1)])
            .num(&format!("{name}_yx"), t[(1, 0)])
            .num(&format!("{name}_yy"), t[(1, 1)]);
    }
    for (name, t) in [
        ("expected_stress", &s_exact),
        ("expected_contact_stress", &c_exact),
    ] {
        s.num(&format!("{name}_xx"), t[(0, 0)])
            .num(&format!("{name}_xy"), t[(0, 1)])
            .num(&format!("{name}_yx"), t[(1, 0)])
            .num(&format!("{name}_yy"), t[(1, 1)]);
    }
    s.num(
        "stress_rel_error",
        frobenius(&(tot - s_exact)) / frobenius(&s_exact),
    )
    .num(
        "contact_stress_rel_error",
        frobenius(&(con - c_exact)) / frobenius(&c_exact),
    )
    .num(
        "stress_rel_error_vs_paper_formula",
        if rolls {
            frobenius(&(tot - paper)) / frobenius(&paper)
        } else {
            f64::NAN
        },
    )
    .num("stress_skew_ratio", skew_ratio(&tot))
    .num("contact_stress_skew_ratio", skew_ratio(&con))
    .int("vtk_frames", frames as u64);
    solver_keys(&mut s, &stats);
    rows::table(&hist).write(&mut ctx.out, "history.csv")?;

    let exact = Exact { a_exact, f, rolls };
    stress_figures(&mut ctx.out, c, &hist, (g, phi, l), exact)?;
    motion_figures(&mut ctx.out, c, &hist, exact)?;

    let headline = vec![
        format!("report: {}/", ctx.out.path().display()),
        format!(
            "acceleration {accel:.5} m/s² (exact {a_exact:.5}), travelled L = {l:.4} m, {}",
            if rolls { "rolling without slipping" } else { "rolling while sliding" }
        ),
        format!(
            "Σ_p (slope frame) = [[{:.3}, {:.3}], [{:.3}, {:.3}]] Pa, exact [[{:.3}, {:.3}], [{:.3}, {:.3}]]",
            tot[(0, 0)], tot[(0, 1)], tot[(1, 0)], tot[(1, 1)],
            s_exact[(0, 0)], s_exact[(0, 1)], s_exact[(1, 0)], s_exact[(1, 1)]
        ),
        format!(
            "Σ_c = [[{:.3}, {:.3}], [{:.3}, {:.3}]] Pa (not symmetric); skew ratio of Σ_p {:.1e}",
            con[(0, 0)], con[(0, 1)], con[(1, 0)], con[(1, 1)], skew_ratio(&tot)
        ),
    ];
    // Verdict: the comparison with the exact answers (crate::verdict).
    let mut checks = crate::verdict::Checks::new();
    for key in ["acceleration_rel_error", "stress_rel_error"] {
        let e = s.get_f64(key).unwrap_or(f64::NAN);
        checks.at_most(
            &format!("rolling.{key}"),
            e,
            ROLLING_REL_ERROR_SUSPECT,
            Some(ROLLING_REL_ERROR_REFUSED),
            |t| format!("{key} = {e:.2e} against the exact answer (limit {t:.0e})"),
        );
    }
    Ok(RunOutcome::without_laws(s, headline, checks))
}

/// Relative error of the acceleration, or of the mean stress, against the exact answer above
/// which the run is suspect (1); the θ = 1 scheme is exact for uniform acceleration, so the
/// defaults stay far below it.
pub const ROLLING_REL_ERROR_SUSPECT: f64 = 1e-3;
/// The same, above which it is refused (1).
pub const ROLLING_REL_ERROR_REFUSED: f64 = 1e-2;

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for RollingConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "rolling"
    }

    fn grains(&self) -> usize {
        1
    }

    fn build_first(&self) -> datasets::Result<()> {
        rolling(self).map(drop)
    }
}
