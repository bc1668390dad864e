//! The `biaxial` scenario: a representative volume without walls or gravity, a biperiodic
//! deformable cell (`dem::cell`). For each confining pressure p₀ (lowest first) the same loose
//! packing (same seed) is compressed isotropically under stress control, σ_xx = σ_yy = −p₀ with
//! L_xy = 0 (tension positive), with the grain–grain friction switched to 0 for a `dense`
//! preparation or kept for a `loose` one; then it is compressed along y at the constant axial
//! strain rate `ε̇_a = I √(p₀/ρ)/d` (L_yy = −ε̇_a imposed) with σ_xx = −p₀ held and L_xy = 0,
//! to `max_axial_strain` (`docs/physics.md` §8).
//!
//! Per pressure, the whole-cell state (`homogenise::cell`) of every step of the axial
//! compression is written to `history_p{k}.csv`. With compression positive, as in soil
//! mechanics: axial strain `ε_a = −ln(H/H₀)`, volumetric strain `ε_v = −ln(V/V₀)` (positive
//! in contraction), `p = (σ₁ + σ₃)/2 = −tr Σ/2`, `q = (σ₁ − σ₃)/2`, `sin φ_mob = q/p`. Over bins
//! of `bin_strain` of axial strain: the peak `sin φ_peak` (largest bin mean of q/p). Over
//! consecutive windows of [`DILATANCY_WINDOW_BINS`] bins: the 2D dilatancy angle
//! `sin ψ = −ε̇_v/ε̇_γ` of the window's mean strain-rate tensor ([`dilatancy_ratio`]), reported
//! only where it lies in [−1, 1] and judged ([`DILATANCY_SE_SUSPECT`]). Over the last
//! `critical_strain`: the critical state, means and block-averaged standard errors of q/p, φ,
//! p, Z (of one sample: the critical-state law states its intervals from the pressures as
//! replicas, `identify::critical_state::IntervalKind`), and the plateau's dilatancy.
//!
//! Identification: Mohr–Coulomb (2D Drucker–Prager) over the peak Mohr circles
//! (`identify::mohr_coulomb`, Clarabel), the critical state (`identify::critical_state`) and a
//! stress–dilatancy relation `sin φ_mob = sin φ_cv + β sin ψ` fitted over the hardening phase
//! (dilatancy windows before the peak) of every pressure.

pub mod build;
pub mod config;

use dem::cell::{CellControl, Imposed};
use dem::math::Tensor as Mat;
use homogenise::averaging::block_average;
use homogenise::cell::cell_state;
use identify::critical_state::{
    fit_critical_state, fit_stress_dilatancy, PlateauMeasure, StressDilatancyData,
};
use identify::law::Provenance;
use identify::mohr_coulomb::{fit_mohr_coulomb_supported, YieldData};
use identify::CalibratedLaw;
use serde::{Deserialize, Serialize};

use super::cell_base::{cell_history_row, CellRecord, ControlPlan, GAIN_FRACTION, MIN_BLOCKS};
use super::common::laws::LawNeed;
use super::common::{
    fit_keys, mean_diameter, parameter_lines, short_number, strain_bins, Stop, VtkFrames,
};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::PhaseStats;
use super::rows::{self, serde_rows, table_row};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::{OutputDir, Summary};
use crate::plot::xy::{draw_row, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::progress::warn;
use crate::verdict::{
    export_law, max_solid_fraction, remove_stale_law, Checks, RunVerdict, Verdict, WindowStats,
};
use config::{BiaxialConfig, Preparation};

cell_history_row! {
    /// One step of the axial compression: a row of `history_p{k}.csv`.
    struct HistoryRow {
        head {
            /// Time (s).
            t: "t_s",
            /// `ε_a = −ln(H/H₀)` (compression positive).
            axial_strain: "axial_strain",
            /// `ε_v = −ln(V/V₀)` (positive in contraction).
            volumetric_strain: "volumetric_strain",
        }
        tail {
            /// q/p of the step.
            sin_phi_mob: "sin_phi_mob",
            /// Solid fraction.
            phi: "phi",
            /// Coordination over force-carrying contacts.
            z: "Z",
            /// Fabric anisotropy `a = 2 (F₁ − F₂)`.
            fabric_anisotropy: "fabric_anisotropy",
            /// Inertial number of the step (NaN without pressure).
            inertial: "I",
            /// Re-solves of the step by the cell control.
            cell_corrections: "cell_corrections",
            /// Major direction of the fabric from x (degrees).
            fabric_angle_deg: "fabric_angle_deg",
            /// `q_a = (Σ_xx − Σ_yy)/2` (Pa).
            q_axial: "q_axial_Pa",
            /// The imposed lateral stress after the outer correction (Pa).
            target_sxx: "target_sigma_xx_Pa",
        }
    }
}

table_row! {
    /// One step of the isotropic compression: a row of `compression_p{k}.csv`.
    struct CompressionRow {
        /// Time (s).
        t: "t_s",
        /// Σ_xx (Pa, tension positive).
        sxx: "sigma_xx_Pa",
        /// Σ_yy (Pa).
        syy: "sigma_yy_Pa",
        /// Solid fraction.
        phi: "phi",
        /// Coordination.
        z: "Z",
        /// Re-solves of the step by the cell control.
        cell_corrections: "cell_corrections",
        /// The imposed target (Pa).
        target: "target_sigma_Pa",
    }
}

/// Gain of the lateral control in the axial compression, as a fraction of `Δt/(ρ d²)`: lower
/// than in the isotropic compression, so that the step-to-step noise of Σ_xx (tens of % of p₀
/// for rigid grains) does not drive the lateral rate.
const AXIAL_GAIN_FRACTION: f64 = 0.05;
/// Cap of the lateral rate in the axial compression, in units of ε̇_a.
const AXIAL_RATE_CAP: f64 = 3.0;
/// Filter time of the lateral control in the axial compression, in time steps.
const AXIAL_FILTER_STEPS: f64 = 10.0;
/// About this many axial steps per pressure, evenly spread, are solved again to
/// [`crate::verdict::SENSITIVITY_TOLERANCE`] and the cell's stress taken both ways: the solver
/// sensitivity of the axial compression ([`crate::verdict::Sensitivity`] with the axial
/// deviator `q_a = (Σ_xx − Σ_yy)/2` as the shear stress and the mean stress as the normal one,
/// so its μ is `sin φ_mob = Σ q_a / Σ p`, the ratio of means the analysis takes, and its
/// pressure `p`), judged by the window's checks (`solver.sensitivity_mu` on sin φ,
/// `solver.sensitivity_pressure` on p). A re-solve of these quasi-static steps takes one to
/// two seconds at 200 grains (the default run, 2026-12-03: 479 s with 80 samples, 390 s
/// without, both alone; 914 s with one step in 25, 581 samples, beside other work), so their
/// number is fixed rather than their rate: every `⌊steps / SENSITIVITY_SAMPLES⌋`-th axial step (at least every
/// step), 20 samples per pressure, twice the verdict's minimum.
const SENSITIVITY_SAMPLES: u64 = 20;
/// Fraction of the isotropic compression (its last steps) over which the reached stress is
/// averaged and compared with −p₀.
const COMPRESSION_TAIL: f64 = 0.2;
/// Axial strain of a segment of the axial compression: after each, the lateral target moves
/// by the mean error of Σ_xx over it, `σ* ← σ* − (⟨Σ_xx⟩ + p₀)` (an outer integral
/// correction, which removes the bias of the proportional control of a packing that carries
/// compression only).
const SEGMENT_STRAIN: f64 = 0.005;
/// Relative error `max(|⟨Σ_xx⟩ + p₀|, |⟨Σ_yy⟩ + p₀|)/p₀` of the stress reached by the isotropic
/// compression (means over its last `COMPRESSION_TAIL`) above which the sample is suspect.
/// The explicit control of a massless cell on rigid grains holds the stress of a jammed
/// packing only through the impulses of its deformation (`dem::cell`): the stress of a step
/// scatters by tens of % of p₀ and its mean sits 10–15 % on the tensile side of the target
/// (measured: 14 % for 100 disks at p₀ = 1 kPa); the axial compression then brings the lateral
/// stress to −p₀ (its own check).
pub const COMPRESSION_ERROR_SUSPECT: f64 = 0.1;
/// The same, above which it is refused.
pub const COMPRESSION_ERROR_REFUSED: f64 = 0.25;
/// Relative error `|⟨Σ_xx⟩ + p₀|/p₀` of the lateral stress over the axial compression (mean of
/// every step, after the outer correction of each segment) above which the results are
/// suspect.
pub const LATERAL_ERROR_SUSPECT: f64 = 0.05;
/// The same, above which they are refused.
pub const LATERAL_ERROR_REFUSED: f64 = 0.15;
/// Bound of a quasi-static test: the inertial number of the axial compression
/// `I = ε̇_a d/√(⟨p⟩/ρ)` (with the mean pressure of the axial compression) must stay at or below
/// it; suspect above (1).
pub const QUASI_STATIC_I: f64 = 1e-3;
/// Above this the axial compression is refused as not quasi-static (1).
pub const QUASI_STATIC_I_REFUSED: f64 = 1e-2;
/// Difference of the plateau halves of q/p that matters (absolute; `verdict::halves_drift`).
pub const STEADY_SIN_PHI_TOLERANCE: f64 = 0.02;
/// Difference of the plateau halves of φ that matters (absolute).
pub const STEADY_PHI_TOLERANCE: f64 = 0.005;

table_row! {
    /// One dilatancy window ([`dilatancy_windows`]): a row of `dilatancy.csv`.
    struct DilatancyRow {
        /// p₀ (Pa) in the CSV; the pressure's index while the run collects them.
        p0: "p0_Pa",
        /// ε_a at the window's centre.
        axial_strain: "axial_strain",
        /// `q_a/p` of the window's mean stresses.
        sin_phi_mob: "sin_phi_mob",
        /// `sin ψ` (NaN outside [−1, 1]).
        sin_psi: "sin_psi",
        /// Its block standard error.
        sin_psi_std_error: "sin_psi_std_error",
        /// `−ε̇_v/ε̇_γ`, in range or not.
        dilatancy_ratio: "dilatancy_ratio",
        /// 1 for a window whose centre comes before the peak, else 0.
        hardening: "hardening",
    }
}

table_row! {
    /// The result of one pressure ([`State::rows`], `biaxial.csv`).
    struct PressureRow {
        /// Confining pressure (Pa).
        p0: "p0_Pa",
        /// Largest bin mean of q/p.
        sin_phi_peak: "sin_phi_peak",
        /// ε_a of the peak bin.
        axial_strain_peak: "axial_strain_peak",
        /// p at the peak (Pa).
        p_peak: "p_peak_Pa",
        /// q_a at the peak (Pa).
        q_peak: "q_peak_Pa",
        /// Plateau q/p (ratio of means).
        sin_phi_critical: "sin_phi_critical",
        /// Its block standard error.
        sin_phi_critical_se: "sin_phi_critical_std_error",
        /// Plateau solid fraction.
        phi_critical: "phi_critical",
        /// Its block standard error.
        phi_critical_se: "phi_critical_std_error",
        /// Plateau pressure (Pa).
        p_critical: "p_critical_Pa",
        /// Plateau coordination.
        z_critical: "Z_critical",
        /// Largest window `sin ψ`.
        sin_psi_max: "sin_psi_max",
        /// ε_a of that window.
        axial_strain_psi_max: "axial_strain_psi_max",
        /// The plateau's `sin ψ`.
        sin_psi_critical: "sin_psi_critical",
        /// `|⟨Σ_xx⟩ + p₀|/p₀` over the axial compression.
        lateral_stress_error: "lateral_stress_error",
        /// Inertial number with the mean pressure of the axial compression.
        i_mean: "I_mean",
        /// Error of the stress reached by the isotropic compression.
        compression_stress_error: "compression_stress_error",
        /// Solid fraction reached by the isotropic compression.
        phi_compressed: "phi_compressed",
        /// Coordination reached by the isotropic compression.
        z_compressed: "Z_compressed",
        /// ε̇_a (1/s).
        axial_rate: "axial_rate_1_s",
        /// Time step (s).
        dt: "dt_s",
        /// Steps of the plateau.
        critical_samples: "critical_samples",
        /// Mean re-solves per axial step.
        cell_corrections_per_step: "cell_corrections_per_step",
        /// Plateau fabric anisotropy.
        fabric_anisotropy_critical: "fabric_anisotropy_critical",
        /// Solid fraction at the first axial step.
        phi_initial_axial: "phi_initial_axial",
        /// Block standard error of [`Self::sin_psi_max`].
        sin_psi_max_se: "sin_psi_max_std_error",
        /// Block standard error of [`Self::sin_psi_critical`].
        sin_psi_critical_se: "sin_psi_critical_std_error",
        /// The plateau's `−ε̇_v/ε̇_γ`, in range or not.
        dilatancy_ratio_critical: "dilatancy_ratio_critical",
        /// Dilatancy windows.
        dilatancy_windows: "dilatancy_windows",
        /// Windows without a dilatancy angle.
        dilatancy_undefined_windows: "dilatancy_undefined_windows",
    }
}

table_row! {
    /// A point of a finished pressure's binned curves ([`bin_history`]), kept for the figures.
    struct BinPoint {
        /// Index of the pressure.
        pressure: "pressure_index",
        /// ε_a (bin mean).
        axial_strain: "axial_strain",
        /// `q_a/p` of the bin's mean stresses.
        sin_phi: "sin_phi",
        /// ε_v (bin mean).
        volumetric_strain: "volumetric_strain",
    }
}

/// What the isotropic compression reached (means over its last `COMPRESSION_TAIL`), kept
/// until the axial compression closes the pressure's row.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
struct Compressed {
    /// `max(|⟨Σ_xx⟩ + p₀|, |⟨Σ_yy⟩ + p₀|)/p₀`.
    #[serde(with = "dem::serde_float")]
    error: f64,
    /// Solid fraction.
    #[serde(with = "dem::serde_float")]
    phi: f64,
    /// Coordination.
    #[serde(with = "dem::serde_float")]
    z: f64,
}

/// The plan of the current phase.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
struct RunPlan {
    #[serde(with = "dem::serde_float")]
    rate: f64,
    #[serde(with = "dem::serde_float")]
    dt: f64,
    steps: u64,
    n: u64,
    /// Height and volume of the cell when the axial compression starts (m, m²).
    #[serde(with = "dem::serde_float")]
    h0: f64,
    #[serde(with = "dem::serde_float")]
    v0: f64,
}

/// What the checks of one pressure need.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct PressureCheck {
    #[serde(with = "dem::serde_float")]
    p0: f64,
    /// Numerics of the axial compression.
    window: WindowStats,
    /// q/p and φ over the critical-state plateau.
    #[serde(with = "crate::floats::vec")]
    sin_phi: Vec<f64>,
    #[serde(with = "crate::floats::vec")]
    phi: Vec<f64>,
}

/// What the phases collect.
#[derive(Serialize, Deserialize)]
struct State {
    /// Solver statistics, one row per finished pressure, the current axial compression's
    /// history, the frames of the last pressure's sample, the numerics of the current axial
    /// compression.
    #[serde(flatten)]
    cell: CellRecord<HistoryRow, PressureRow>,
    /// What the current pressure's isotropic compression reached, until its row is closed.
    #[serde(default)]
    compressed: Option<Compressed>,
    /// The steps of the current isotropic compression.
    #[serde(with = "serde_rows")]
    compression: Vec<CompressionRow>,
    /// Binned curves of the finished pressures.
    #[serde(with = "serde_rows")]
    bins: Vec<BinPoint>,
    /// Dilatancy windows of the finished pressures ([`dilatancy_windows`]), with the
    /// pressure's index in place of p₀.
    #[serde(default, with = "serde_rows")]
    dilatancy: Vec<DilatancyRow>,
    run: RunPlan,
    checks: Vec<PressureCheck>,
    /// The imposed stress target of the current phase (Pa), after the outer correction.
    #[serde(with = "dem::serde_float")]
    target: f64,
    /// Sums of Σ_xx, Σ_yy (Σ_xx twice in the axial compression) and steps of the current
    /// phase, for the outer correction.
    seg: (f64, f64, u64),
}

/// `[q_a, −p] = [(Σ_xx − Σ_yy)/2, (Σ_xx + Σ_yy)/2]` of a cell stress (Pa, tension positive):
/// the pair the solver-sensitivity measure takes as shear and normal stress
/// ([`SENSITIVITY_SAMPLES`]).
fn axial_pair(s: &Mat) -> [f64; 2] {
    [0.5 * (s[(0, 0)] - s[(1, 1)]), 0.5 * (s[(0, 0)] + s[(1, 1)])]
}

/// One bin of a history ([`bin_history`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bin {
    /// Mean ε_a.
    axial_strain: f64,
    /// `q_a/p` of the mean stresses.
    sin_phi: f64,
    /// Mean ε_v.
    volumetric_strain: f64,
    /// Mean p (Pa).
    p: f64,
    /// `q_a = (⟨Σ_xx⟩ − ⟨Σ_yy⟩)/2` (Pa).
    q_axial: f64,
}

/// Bins of a history: per bin of `width` in ε_a (the first starting at ε_a = 0, bins with at
/// least one sample), the means of ε_a, ε_v, I, Σ_xx, Σ_yy, p, and from the mean tensor the
/// mobilised friction `sin φ = q_a/p`, `q_a = (⟨Σ_xx⟩ − ⟨Σ_yy⟩)/2` (σ₁ axial, σ₃ lateral, the
/// shear stress averaging 0 under L_xy = 0). The mean of the tensor, not of the step's q/p,
/// which the noise of the step biases upward.
fn bin_history(history: &[HistoryRow], width: f64) -> Vec<Bin> {
    let cols: [fn(&HistoryRow) -> f64; 6] = [
        |r| r.axial_strain,
        |r| r.volumetric_strain,
        |r| r.inertial,
        |r| r.sxx,
        |r| r.syy,
        |r| r.p,
    ];
    strain_bins(
        history,
        |r| r.axial_strain,
        width,
        cols,
        |r| r.inertial.is_finite(),
    )
    .into_iter()
    .map(|[ea, ev, _inertial, sxx, syy, p]| {
        let qa = 0.5 * (sxx - syy);
        Bin {
            axial_strain: ea,
            sin_phi: qa / p,
            volumetric_strain: ev,
            p,
            q_axial: qa,
        }
    })
    .collect()
}

/// Mean of `num/den` as the ratio of the means `⟨num⟩/⟨den⟩`, with its block-averaged standard
/// error by the delta method: the error of the mean of `(num_t − r den_t)/⟨den⟩`.
fn ratio_of_means(num: &[f64], den: &[f64]) -> (f64, f64) {
    let n = num.len().max(1) as f64;
    let (mn, md) = (num.iter().sum::<f64>() / n, den.iter().sum::<f64>() / n);
    let r = mn / md;
    let y: Vec<f64> = num.iter().zip(den).map(|(a, b)| (a - r * b) / md).collect();
    let se = block_average(&y, MIN_BLOCKS).map_or(f64::NAN, |a| a.std_error);
    (r, se)
}

/// Axial-strain bins of `bin_strain` per window of the dilatancy: the windows of the dilatancy
/// (and of the stress–dilatancy points) are consecutive and do not overlap, 0.02 of axial strain
/// with the default bins. Measured (100 grains, dense, p₀ = 1 and 4 kPa, seed 5): over one bin
/// (0.005) a burst of contraction gives `ε̇_v/ε̇_γ` down to −7.9 and the former ratio of bin
/// differences `d/(2 + d)` −2.1 to −2.5 (and +1.66 in a run of the default scenario, where
/// `2 + d < 0`); over windows of 0.025 every window lies within ±0.25, the largest
/// `sin ψ` 0.23 ± 0.03 and 0.25 ± 0.02 (block standard errors).
pub const DILATANCY_WINDOW_BINS: usize = 4;
/// Block standard error of the largest window dilatancy above which it is suspect (absolute):
/// its 95 % interval then spans more than ±0.1, half the dilatancy of a dense packing (measured
/// 0.02–0.03 at 100 grains; windows of a contraction burst reach 0.2–0.3).
pub const DILATANCY_SE_SUSPECT: f64 = 0.05;

/// The ratio `−ε̇_v/ε̇_γ = tr D / (D₁ − D₂)` of a mean strain rate `D = [D_xx, D_yy, D_xy]`
/// (tension positive, 1/s), with `ε̇_v = −tr D` the volumetric rate (compression positive) and
/// `ε̇_γ = D₁ − D₂ = √((D_xx − D_yy)² + 4 D_xy²)` the difference of its principal rates: the
/// 2D dilatancy angle `sin ψ` when it lies in `[−1, 1]`, which it does exactly when the principal
/// rates have opposite signs (a shear with a change of volume; Vermeer & de Borst, Heron 29,
/// 1984). Outside, the cell contracted (or dilated) along both principal directions: no
/// dilatancy angle describes that deformation. NaN without any shear rate.
pub fn dilatancy_ratio(d: [f64; 3]) -> f64 {
    let g = ((d[0] - d[1]).powi(2) + 4.0 * d[2] * d[2]).sqrt();
    if g > 0.0 {
        (d[0] + d[1]) / g
    } else {
        f64::NAN
    }
}

/// The dilatancy of a run of steps of the axial compression.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Dilatancy {
    /// `sin ψ` of the mean strain rate of the steps ([`dilatancy_ratio`]), NaN when it is not
    /// in `[−1, 1]` (no dilatancy angle) or there are no steps.
    sin_psi: f64,
    /// Its block-averaged standard error (delta method; NaN with too few steps).
    std_error: f64,
    /// The ratio itself, in range or not.
    ratio: f64,
}

/// The dilatancy of the steps `rows` of a history ([`HISTORY`]): [`dilatancy_ratio`] of their
/// mean strain rate `D̄` (the cell's deformation over them: `tr D̄` times their duration is
/// their `−Δ ln V`), with the block-averaged standard error of the ratio of means
/// ([`ratio_of_means`] with `tr D_t` over the shear rate of step `t` along `D̄`'s principal
/// axes, `((D_xx − D_yy)(D̄_xx − D̄_yy) + 4 D_xy D̄_xy)/ε̇_γ`, whose mean is `ε̇_γ`).
fn dilatancy_over(rows: &[&HistoryRow]) -> Dilatancy {
    let nan = Dilatancy {
        sin_psi: f64::NAN,
        std_error: f64::NAN,
        ratio: f64::NAN,
    };
    if rows.is_empty() {
        return nan;
    }
    let n = rows.len() as f64;
    let mean = |f: fn(&HistoryRow) -> f64| rows.iter().map(|r| f(r)).sum::<f64>() / n;
    let (a, b, c) = (mean(|r| r.dxx), mean(|r| r.dyy), mean(|r| r.dxy));
    let ratio = dilatancy_ratio([a, b, c]);
    let g = ((a - b).powi(2) + 4.0 * c * c).sqrt();
    if !ratio.is_finite() {
        return nan;
    }
    let num: Vec<f64> = rows.iter().map(|r| r.dxx + r.dyy).collect();
    let den: Vec<f64> = rows
        .iter()
        .map(|r| ((r.dxx - r.dyy) * (a - b) + 4.0 * r.dxy * c) / g)
        .collect();
    let (_, se) = ratio_of_means(&num, &den);
    Dilatancy {
        sin_psi: if ratio.abs() <= 1.0 { ratio } else { f64::NAN },
        std_error: se,
        ratio,
    }
}

/// The dilatancy windows of a history: consecutive windows of `width` of axial strain from
/// ε_a = 0, each with at least one step, the last one only if whole: `(ε_a at its centre, sin φ
/// as the ratio of its mean stresses, its dilatancy)`.
fn dilatancy_windows(history: &[HistoryRow], width: f64) -> Vec<(f64, f64, Dilatancy)> {
    let end = history.last().map_or(0.0, |r| r.axial_strain);
    let mut out = Vec::new();
    let mut k = 0.0;
    while (k + 1.0) * width <= end * (1.0 + 1e-9) {
        let (lo, hi) = (k * width, (k + 1.0) * width);
        let rows: Vec<&HistoryRow> = history
            .iter()
            .filter(|r| r.axial_strain >= lo && r.axial_strain < hi && r.inertial.is_finite())
            .collect();
        if !rows.is_empty() {
            let n = rows.len() as f64;
            let m = |f: fn(&HistoryRow) -> f64| rows.iter().map(|r| f(r)).sum::<f64>() / n;
            let sin_phi = 0.5 * (m(|r| r.sxx) - m(|r| r.syy)) / m(|r| r.p);
            out.push((0.5 * (lo + hi), sin_phi, dilatancy_over(&rows)));
        }
        k += 1.0;
    }
    out
}

struct Biaxial<'a> {
    c: &'a BiaxialConfig,
    pressures: Vec<f64>,
}

impl Biaxial<'_> {
    /// The control of the cell at confining pressure `p0`, time step `dt`, mean diameter `d`:
    /// the isotropic compression (`axial_rate` None) or the axial compression at that rate.
    fn control(
        &self,
        p0: f64,
        target: f64,
        dt: f64,
        d: f64,
        axial_rate: Option<f64>,
    ) -> CellControl {
        let rho = self.c.grain.density;
        let cap = self.c.control_inertial_number * (p0 / rho).sqrt() / d;
        let (yy, max_rate, gain_fraction, filter_steps) = match axial_rate {
            None => (Imposed::Stress(target), cap, GAIN_FRACTION, 0.0),
            // the lateral expansion of a dilating sample runs at ε̇_a (1 + d), d ≲ 1
            Some(r) => (
                Imposed::Rate(-r),
                AXIAL_RATE_CAP * r,
                AXIAL_GAIN_FRACTION,
                AXIAL_FILTER_STEPS,
            ),
        };
        ControlPlan {
            mode: self.c.cell_control,
            xx: Imposed::Stress(target),
            yy,
            xy: Imposed::Rate(0.0),
            max_rate,
            pressure: p0,
            compressing: axial_rate.is_none(),
            gain_fraction,
            filter_steps,
            affine: false,
        }
        .control(dt, rho, d)
    }

    /// Closes an axial compression: the result row, the binned curves, the check data.
    fn close_axial(&self, i: usize, st: &mut State, world: &dem::World) -> Result<()> {
        let c = self.c;
        let p0 = self.pressures[i];
        let h = &st.cell.history;
        let bins = bin_history(h, c.bin_strain);
        // the peak: the largest bin mean of q/p
        let (kpeak, peak) =
            bins.iter()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |(k, m), (j, b)| {
                    if b.sin_phi > m {
                        (j, b.sin_phi)
                    } else {
                        (k, m)
                    }
                });
        let (eps_peak, p_peak, q_peak) =
            bins.get(kpeak).map_or((f64::NAN, f64::NAN, f64::NAN), |b| {
                (b.axial_strain, b.p, b.q_axial)
            });
        for b in &bins {
            st.bins.push(BinPoint {
                pressure: i as f64,
                axial_strain: b.axial_strain,
                sin_phi: b.sin_phi,
                volumetric_strain: b.volumetric_strain,
            });
        }
        // dilatancy over windows of DILATANCY_WINDOW_BINS bins; the largest defined one
        let windows = dilatancy_windows(h, DILATANCY_WINDOW_BINS as f64 * c.bin_strain);
        let mut psi_max = (f64::NAN, f64::NAN, f64::NAN);
        let mut undefined = 0usize;
        for (x, sin_phi, dl) in &windows {
            if dl.ratio.is_finite() && dl.sin_psi.is_nan() {
                undefined += 1;
            }
            if dl.sin_psi.is_finite() && (psi_max.0.is_nan() || dl.sin_psi > psi_max.0) {
                psi_max = (dl.sin_psi, *x, dl.std_error);
            }
            // the hardening phase: windows whose centre comes before the peak
            st.dilatancy.push(DilatancyRow {
                p0: i as f64,
                axial_strain: *x,
                sin_phi_mob: *sin_phi,
                sin_psi: dl.sin_psi,
                sin_psi_std_error: dl.std_error,
                dilatancy_ratio: dl.ratio,
                hardening: if *x <= eps_peak { 1.0 } else { 0.0 },
            });
        }
        let p_mean = h.iter().map(|r| r.p).sum::<f64>() / h.len().max(1) as f64;
        let i_mean = st.run.rate * mean_diameter(world) / (p_mean / c.grain.density).sqrt();
        // the critical-state plateau
        let start = c.max_axial_strain - c.critical_strain;
        let tail: Vec<&HistoryRow> = h.iter().filter(|r| r.axial_strain >= start).collect();
        let col = |f: fn(&HistoryRow) -> f64| -> Vec<f64> { tail.iter().map(|r| f(r)).collect() };
        let avg = |f: fn(&HistoryRow) -> f64| -> (f64, f64) {
            block_average(&col(f), MIN_BLOCKS)
                .map_or((f64::NAN, f64::NAN), |a| (a.mean, a.std_error))
        };
        let qa: Vec<f64> = tail.iter().map(|r| 0.5 * (r.sxx - r.syy)).collect();
        let (sphi, sphi_se) = ratio_of_means(&qa, &col(|r| r.p));
        let (phi, phi_se) = avg(|r| r.phi);
        let (pc, _) = avg(|r| r.p);
        let (zc, _) = avg(|r| r.z);
        let (ac, _) = avg(|r| r.fabric_anisotropy);
        // the dilatancy of the plateau, from its mean strain rate
        let psi_c = dilatancy_over(&tail);
        let sxx_mean = h.iter().map(|r| r.sxx).sum::<f64>() / h.len().max(1) as f64;
        let lateral = (sxx_mean + p0).abs() / p0;
        let corr = h.iter().map(|r| r.cell_corrections).sum::<f64>() / h.len().max(1) as f64;
        let comp = st.compressed.take().unwrap_or(Compressed {
            error: f64::NAN,
            phi: f64::NAN,
            z: f64::NAN,
        });
        st.cell.rows.push(PressureRow {
            p0,
            sin_phi_peak: peak,
            axial_strain_peak: eps_peak,
            p_peak,
            q_peak,
            sin_phi_critical: sphi,
            sin_phi_critical_se: sphi_se,
            phi_critical: phi,
            phi_critical_se: phi_se,
            p_critical: pc,
            z_critical: zc,
            sin_psi_max: psi_max.0,
            axial_strain_psi_max: psi_max.1,
            sin_psi_critical: psi_c.sin_psi,
            lateral_stress_error: lateral,
            i_mean,
            compression_stress_error: comp.error,
            phi_compressed: comp.phi,
            z_compressed: comp.z,
            axial_rate: st.run.rate,
            dt: st.run.dt,
            critical_samples: tail.len() as f64,
            cell_corrections_per_step: corr,
            fabric_anisotropy_critical: ac,
            phi_initial_axial: h.first().map_or(f64::NAN, |r| r.phi),
            sin_psi_max_se: psi_max.2,
            sin_psi_critical_se: psi_c.std_error,
            dilatancy_ratio_critical: psi_c.ratio,
            dilatancy_windows: windows.len() as f64,
            dilatancy_undefined_windows: undefined as f64,
        });
        st.checks.push(PressureCheck {
            p0,
            window: st.cell.window,
            sin_phi: qa.iter().zip(col(|r| r.p)).map(|(q, p)| q / p).collect(),
            phi: col(|r| r.phi),
        });
        Ok(())
    }
}

/// What phase `k` of a run is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Part {
    /// The isotropic compression of pressure `i`.
    Compress,
    /// Segment `j` of the axial compression.
    Axial(usize),
}

impl Biaxial<'_> {
    /// Segments of the axial compression.
    fn segments(&self) -> usize {
        (self.c.max_axial_strain / SEGMENT_STRAIN).ceil().max(1.0) as usize
    }

    /// Phases per pressure.
    fn per_pressure(&self) -> usize {
        1 + self.segments()
    }

    /// Pressure index and part of phase `k`.
    fn part(&self, k: usize) -> (usize, Part) {
        let (i, j) = (k / self.per_pressure(), k % self.per_pressure());
        let part = if j == 0 {
            Part::Compress
        } else {
            Part::Axial(j - 1)
        };
        (i, part)
    }

    /// The outer integral correction at the end of a phase: the target moves by the mean
    /// error of the controlled stress over the phase, `σ* ← σ* − (⟨σ⟩ − (−p₀))`, within
    /// `[−3 p₀, −p₀/3]`.
    fn corrected_target(st: &State, p0: f64) -> f64 {
        if st.seg.2 == 0 {
            return st.target;
        }
        let mean = 0.5 * (st.seg.0 + st.seg.1) / st.seg.2 as f64;
        (st.target - (mean + p0)).clamp(-3.0 * p0, -p0 / 3.0)
    }
}

impl PhasedRun for Biaxial<'_> {
    type State = State;

    fn phase_count(&self) -> usize {
        self.per_pressure() * self.pressures.len()
    }

    fn enter(&self, st: &mut State, at: Enter<'_>) -> Result<Option<PhasePlan>> {
        let (k, world) = (at.k, at.world);
        let c = self.c;
        let (i, part) = self.part(k);
        let p0 = self.pressures[i];
        let d = mean_diameter(world);
        let dt = match part {
            Part::Compress => c.compression_dt(),
            Part::Axial(_) => c.axial_dt(p0),
        };
        let target = match part {
            Part::Compress | Part::Axial(0) => -p0,
            Part::Axial(_) => Self::corrected_target(st, p0),
        };
        st.target = target;
        st.seg = (0.0, 0.0, 0);
        match part {
            Part::Compress => {
                // the same initial packing for every pressure
                *world = build::biaxial(c)?;
                if c.preparation == Preparation::Dense {
                    world.laws.set_friction(0, 0, 0.0);
                }
                st.compression.clear();
                let d = mean_diameter(world);
                world.params.dt = dt;
                world.cell_control = Some(self.control(p0, target, dt, d, None));
                world.validate(1e-9)?;
                st.run = RunPlan {
                    dt,
                    steps: c.compression_step_count(),
                    ..Default::default()
                };
                Ok(Some(PhasePlan::new(
                    format!("compress p0={p0}"),
                    Stop::Steps(st.run.steps),
                )))
            }
            Part::Axial(j) => {
                let rate = c.axial_rate(p0);
                let total = (c.max_axial_strain / (rate * dt)).ceil() as u64;
                let per = total.div_ceil(self.segments() as u64);
                if j == 0 {
                    world.laws.set_friction(0, 0, c.friction.grain_grain);
                    let cell = *world.cell().ok_or_else(|| dem::DemError::Parameter {
                        name: "cell".into(),
                        reason: "the biaxial world has no biperiodic cell".into(),
                    })?;
                    world.params.dt = dt;
                    // the lateral rate starts at rest (not at the compression's last value)
                    world.set_velocity_gradient(Mat::new(0.0, 0.0, 0.0, -rate));
                    st.run = RunPlan {
                        rate,
                        dt,
                        steps: total,
                        n: 0,
                        h0: cell.h[(1, 1)],
                        v0: cell.volume(),
                    };
                    st.cell.history.clear();
                    st.cell.window.reset();
                }
                world.cell_control = Some(self.control(p0, target, dt, d, Some(rate)));
                let steps = per.min(total.saturating_sub(st.run.n));
                if steps == 0 {
                    return Ok(None);
                }
                Ok(Some(PhasePlan::new(
                    format!("axial p0={p0} ({}/{})", j + 1, self.segments()),
                    Stop::Steps(steps),
                )))
            }
        }
    }

    fn step(&self, st: &mut State, at: Step<'_>) -> Result<()> {
        let (k, out, w, r, p) = (at.k, at.out, at.world, at.report, at.progress);
        let (i, part) = self.part(k);
        if i + 1 == self.pressures.len() && matches!(part, Part::Axial(_)) {
            st.cell.frames.maybe(out, w)?;
        }
        let snap = w.snapshot();
        let cs = cell_state(&snap)?;
        let s = cs.stress;
        if !matches!(part, Part::Axial(_)) {
            st.seg = (st.seg.0 + s[(0, 0)], st.seg.1 + s[(1, 1)], st.seg.2 + 1);
            st.compression.push(CompressionRow {
                t: w.time,
                sxx: s[(0, 0)],
                syy: s[(1, 1)],
                phi: cs.solid_fraction,
                z: cs.coordination,
                cell_corrections: r.cell_corrections as f64,
                target: st.target,
            });
            return Ok(());
        }
        st.seg = (st.seg.0 + s[(0, 0)], st.seg.1 + s[(0, 0)], st.seg.2 + 1);
        st.run.n += 1;
        st.cell.window.step(true, w, r, &p.stats);
        if st
            .run
            .n
            .is_multiple_of((st.run.steps / SENSITIVITY_SAMPLES).max(1))
        {
            st.cell.resolve_sample(w, axial_pair(&s), |snap| {
                Some(axial_pair(&cell_state(snap).ok()?.stress))
            });
        }
        let Some(cell) = w.cell().copied() else {
            return Ok(());
        };
        let d = mean_diameter(w);
        let pm = cs.pressure;
        let inertial = if pm > 0.0 {
            st.run.rate * d / (pm / self.c.grain.density).sqrt()
        } else {
            f64::NAN
        };
        let f = cs.fabric;
        let aniso = 2.0 * ((f[(0, 0)] - f[(1, 1)]).powi(2) + 4.0 * f[(0, 1)].powi(2)).sqrt();
        let angle = 0.5 * (2.0 * f[(0, 1)]).atan2(f[(0, 0)] - f[(1, 1)]);
        st.cell.history.push(HistoryRow {
            t: w.time,
            axial_strain: -(cell.h[(1, 1)] / st.run.h0).ln(),
            volumetric_strain: -(cell.volume() / st.run.v0).ln(),
            sin_phi_mob: if pm > 0.0 { cs.deviator / pm } else { f64::NAN },
            phi: cs.solid_fraction,
            z: cs.coordination,
            fabric_anisotropy: aniso,
            inertial,
            cell_corrections: r.cell_corrections as f64,
            fabric_angle_deg: angle.to_degrees(),
            q_axial: 0.5 * (s[(0, 0)] - s[(1, 1)]),
            target_sxx: st.target,
            ..HistoryRow::of_cell(&cs)
        });
        Ok(())
    }

    fn settle(&self, st: &mut State) {
        st.cell.settle();
    }

    fn leave(&self, st: &mut State, at: Leave<'_>) -> Result<()> {
        let (k, out, world, stats) = (at.k, at.out, at.world, at.stats);
        st.cell.all.merge(stats);
        let (i, part) = self.part(k);
        let p0 = self.pressures[i];
        match part {
            Part::Compress => {
                // the stress reached: means over the last COMPRESSION_TAIL of the steps
                let n = st.compression.len();
                let m = ((n as f64 * COMPRESSION_TAIL).ceil() as usize).clamp(1, n.max(1));
                let tail = &st.compression[n.saturating_sub(m)..];
                let mean = |f: fn(&CompressionRow) -> f64| {
                    tail.iter().map(f).sum::<f64>() / tail.len().max(1) as f64
                };
                let err = (mean(|r| r.sxx) + p0)
                    .abs()
                    .max((mean(|r| r.syy) + p0).abs())
                    / p0;
                // kept until the axial compression closes the row
                st.compressed = Some(Compressed {
                    error: err,
                    phi: mean(|r| r.phi),
                    z: mean(|r| r.z),
                });
                let mut table = rows::table(&st.compression);
                table.comments.push(format!(
                    "isotropic compression to p0 = {p0} Pa ({} preparation: grain friction {} during it): whole-cell mean stress (tension positive), solid fraction, coordination over force-carrying contacts, re-solves of the step by the cell control, the imposed target",
                    self.c.preparation.as_str(),
                    match self.c.preparation {
                        Preparation::Dense => 0.0,
                        Preparation::Loose => self.c.friction.grain_grain,
                    }
                ));
                table.write(out, &format!("compression_p{}.csv", i + 1))?;
                Ok(())
            }
            Part::Axial(_) => {
                if st.run.n < st.run.steps {
                    return Ok(());
                }
                let mut table = rows::table(&st.cell.history);
                table.comments.push(format!(
                    "biaxial compression at confining pressure p0 = {p0} Pa ({} preparation), axial rate {:.6e} 1/s along y with sigma_xx = -p0 held: whole-cell mean stress (tension positive, kinetic stress of the fluctuations included), strain rate D of the cell (1/s); compression positive for the strains: axial_strain = -ln(H/H0), volumetric_strain = -ln(V/V0) (positive in contraction); p = -tr(sigma)/2, q = sqrt(((sigma_xx - sigma_yy)/2)^2 + sigma_xy^2), sin_phi_mob = q/p of the step (noisy: the analysis uses means of the tensor), q_axial = (sigma_xx - sigma_yy)/2; phi solid fraction, Z coordination and fabric over force-carrying contacts, fabric_anisotropy a = 2 (F1 - F2) of the fabric tensor F (Rothenburg & Bathurst 1989), fabric_angle_deg its major direction from x; I = rate d / sqrt(p/rho); cell_corrections counts the re-solves of the step by the cell control; target_sigma_xx the imposed lateral stress after the outer correction",
                    self.c.preparation.as_str(),
                    st.run.rate
                ));
                table.write(out, &format!("history_p{}.csv", i + 1))?;
                self.close_axial(i, st, world)
            }
        }
    }
}

/// Runs the scenario.
pub fn run(c: &BiaxialConfig, ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    let mut pressures = c.confining_pressures.clone();
    pressures.sort_by(f64::total_cmp);
    let bx = Biaxial { c, pressures };
    let fresh = || -> Result<(dem::World, State)> {
        let world = build::biaxial(c)?;
        let p_last = *bx.pressures.last().unwrap_or(&1.0);
        let t_last = c.compression_time + c.max_axial_strain / c.axial_rate(p_last);
        Ok((
            world,
            State {
                // frames of the last (highest) pressure's sample
                cell: CellRecord::new(VtkFrames::new(t_last / 40.0, 41)),
                compressed: None,
                compression: Vec::new(),
                bins: Vec::new(),
                dilatancy: Vec::new(),
                run: RunPlan::default(),
                checks: Vec::new(),
                target: 0.0,
                seg: (0.0, 0.0, 0),
            },
        ))
    };
    let (world, state) = drive(ctx, ctl, &bx, fresh)?;
    let State {
        cell: CellRecord {
            all, rows, frames, ..
        },
        bins,
        dilatancy,
        checks,
        ..
    } = state;
    frames.finish(&mut ctx.out, &world)?;
    analyse(
        c,
        &bx.pressures,
        ctx,
        ctl,
        &world,
        &all,
        &rows,
        &bins,
        &dilatancy,
        &checks,
    )
}

/// The checks of one pressure's dilatancy (its row `r` of [`ROW`]): the largest window
/// dilatancy must exist (some window has a dilatancy angle) and be resolved (block standard
/// error at most [`DILATANCY_SE_SUSPECT`]); the plateau's must be an angle (its mean strain
/// rate shears the cell). Suspect otherwise: the value is then not reported (NaN), never a
/// `sin ψ` outside [−1, 1].
fn judge_dilatancy(k: &mut Checks, label: &str, r: &PressureRow) {
    let (max, max_se, crit, crit_ratio, windows, undefined) = (
        r.sin_psi_max,
        r.sin_psi_max_se,
        r.sin_psi_critical,
        r.dilatancy_ratio_critical,
        r.dilatancy_windows,
        r.dilatancy_undefined_windows,
    );
    if max.is_nan() {
        k.fail(
            "biaxial.dilatancy_undefined",
            Verdict::Suspect,
            undefined,
            windows,
            format!(
                "{label}: none of the {windows} dilatancy windows has a dilatancy angle ({undefined} contracted or dilated along both principal directions): no largest sin ψ"
            ),
        );
    } else {
        k.at_most(
            "biaxial.dilatancy_resolution",
            max_se,
            DILATANCY_SE_SUSPECT,
            None,
            |t| {
                format!(
                    "{label}: the largest window dilatancy sin ψ = {max:.3} has a block standard error {max_se:.3} (limit {t})"
                )
            },
        );
    }
    if crit.is_nan() {
        k.fail(
            "biaxial.dilatancy_critical_undefined",
            Verdict::Suspect,
            crit_ratio,
            1.0,
            format!(
                "{label}: the plateau's mean strain rate has -ε̇_v/ε̇_γ = {crit_ratio:.3}, no dilatancy angle (|·| > 1 or no shear): sin ψ_c not reported"
            ),
        );
    }
}

/// The checks of a finished run ([`judge`]): per law, the checks it is judged by.
struct Judged {
    /// The numerics and stresses of every pressure (all laws).
    common: Checks,
    /// `common` and the plateaus (the critical state).
    critical: Checks,
    /// `common` and the dilatancy (the stress–dilatancy relation).
    dilat: Checks,
    /// The run's own checks: the critical state's and the dilatancy's.
    run: Checks,
    /// The numerics of all axial compressions.
    windows: WindowStats,
}

/// Stage "measure → verdict": the checks of every pressure (`crate::verdict`).
fn judge(c: &BiaxialConfig, rows: &[PressureRow], checks: &[PressureCheck]) -> Judged {
    let mut common = Checks::new();
    let mut critical = Checks::new();
    let mut dilat = Checks::new();
    let mut windows = WindowStats::default();
    let phi_bound = max_solid_fraction(c.grain.radius_spread);
    for (r, pc) in rows.iter().zip(checks) {
        let label = format!("p0 = {} Pa", pc.p0);
        common.window(&format!("{label}, axial compression"), &pc.window);
        windows.merge(&pc.window);
        common.at_most(
            "biaxial.compression_stress_error",
            r.compression_stress_error,
            COMPRESSION_ERROR_SUSPECT,
            Some(COMPRESSION_ERROR_REFUSED),
            |t| {
                format!(
                    "{label}: the isotropic compression ended {:.2} % away from -p0 (means over its last {:.0} %; limit {:.0} %)",
                    100.0 * r.compression_stress_error,
                    100.0 * COMPRESSION_TAIL,
                    100.0 * t
                )
            },
        );
        common.at_most(
            "biaxial.lateral_stress_error",
            r.lateral_stress_error,
            LATERAL_ERROR_SUSPECT,
            Some(LATERAL_ERROR_REFUSED),
            |t| {
                format!(
                    "{label}: the mean lateral stress of the axial compression is {:.2} % away from -p0 (limit {:.0} %)",
                    100.0 * r.lateral_stress_error,
                    100.0 * t
                )
            },
        );
        common.at_most(
            "biaxial.quasi_static",
            r.i_mean,
            QUASI_STATIC_I,
            Some(QUASI_STATIC_I_REFUSED),
            |t| {
                format!(
                    "{label}: the inertial number of the axial compression is {:.2e} (with its mean pressure; limit {t:.0e})",
                    r.i_mean
                )
            },
        );
        critical.steady(
            "biaxial.steady_sin_phi",
            &format!("{label}: q/p on the plateau"),
            &pc.sin_phi,
            STEADY_SIN_PHI_TOLERANCE,
        );
        critical.steady(
            "biaxial.steady_phi",
            &format!("{label}: φ on the plateau"),
            &pc.phi,
            STEADY_PHI_TOLERANCE,
        );
        critical.solid_fraction("biaxial.solid_fraction", &label, r.phi_critical, phi_bound);
        judge_dilatancy(&mut dilat, &label, r);
    }
    let critical = {
        let mut k = critical;
        k.extend(&common);
        k
    };
    // the dilatancy is reported per pressure whatever is fitted: judged with the run
    let mut run_checks = critical.clone();
    run_checks.extend(&dilat);
    let dilat = {
        let mut k = common.clone();
        k.extend(&dilat);
        k
    };
    Judged {
        common,
        critical,
        dilat,
        run: run_checks,
        windows,
    }
}

/// What the fits of a finished run write into: the output directory, the summary, the
/// headline and the verdict.
struct Report<'a> {
    out: &'a mut OutputDir,
    s: Summary,
    headline: Vec<String>,
    verdict: RunVerdict,
}

impl Report<'_> {
    /// Its parts, borrowed apart: output directory, summary, headline, verdict.
    fn parts(
        &mut self,
    ) -> (
        &mut OutputDir,
        &mut Summary,
        &mut Vec<String>,
        &mut RunVerdict,
    ) {
        (self.out, &mut self.s, &mut self.headline, &mut self.verdict)
    }
}

/// Whether the plan leaves the law `law` out (said at the start).
fn left_out(c: &BiaxialConfig, law: &str) -> bool {
    c.leave_out.iter().any(|l| l == law)
}

/// Stage "report": `biaxial.csv` (one row per pressure) and `dilatancy.csv` (one row per
/// dilatancy window), with `d` the mean grain diameter (m).
fn write_tables(
    c: &BiaxialConfig,
    pressures: &[f64],
    out: &mut OutputDir,
    d: f64,
    rows: &[PressureRow],
    dilatancy: &[DilatancyRow],
) -> Result<()> {
    let mut table = rows::table(rows);
    table.comments.push(format!(
        "biaxial compression ({} preparation) at each confining pressure p0: peak = largest mean of sin_phi_mob = q/p over axial-strain bins of {}, p and q at the peak (means over its bin); critical = means over the last {} of axial strain with block-averaged standard errors (of this sample alone: they understate the scatter between samples, summary.json gives the replica intervals); sin_psi = -rate_v/rate_gamma = tr D/(D1 - D2) of the mean strain rate D over consecutive windows of {} of axial strain (dilatancy.csv), empty where it is outside [-1, 1] (the cell contracted or dilated along both principal directions: no dilatancy angle), sin_psi_max the largest window with its block standard error, sin_psi_critical over the plateau; lateral_stress_error = |<sigma_xx> + p0|/p0 over the axial compression, compression_stress_error the largest of |<sigma_xx> + p0|/p0 and |<sigma_yy> + p0|/p0 over the last 20 % of the isotropic compression; I_mean = rate d / sqrt(<p>/rho) over the axial compression",
        c.preparation.as_str(),
        c.bin_strain,
        c.critical_strain,
        DILATANCY_WINDOW_BINS as f64 * c.bin_strain
    ));
    table.metadata = vec![
        ("grain_diameter_m".into(), d),
        ("grain_density_kg_m3".into(), c.grain.density),
        ("grain_friction".into(), c.friction.grain_grain),
    ];
    table.write(out, "biaxial.csv")?;
    let with_p0: Vec<DilatancyRow> = dilatancy
        .iter()
        .map(|w| DilatancyRow {
            p0: pressures.get(w.p0 as usize).copied().unwrap_or(f64::NAN),
            ..*w
        })
        .collect();
    let mut dt = rows::table(&with_p0);
    dt.comments.push(format!(
        "dilatancy of the axial compression over consecutive windows of {} of axial strain ({DILATANCY_WINDOW_BINS} bins): axial_strain at the window's centre, sin_phi_mob = q_a/p of its mean stresses, dilatancy_ratio = -rate_v/rate_gamma = tr D/(D1 - D2) of its mean strain rate D (tension positive), sin_psi the same where it lies in [-1, 1] (empty: the cell contracted or dilated along both principal directions, no dilatancy angle), with its block standard error; hardening = 1 for windows whose centre comes before the peak (the points of the stress-dilatancy fit)",
        DILATANCY_WINDOW_BINS as f64 * c.bin_strain
    ));
    dt.write(out, "dilatancy.csv")?;
    Ok(())
}

/// Stage "report": the summary keys and headline lines of the run and of each pressure.
fn pressure_summary(
    c: &BiaxialConfig,
    d: f64,
    rows: &[PressureRow],
    report_dir: &std::path::Path,
) -> (Summary, Vec<String>) {
    let mut s = Summary::new();
    let mut headline = vec![format!("report: {}/", report_dir.display())];
    s.int("grains", c.grains as u64)
        .text("preparation", c.preparation.as_str())
        .text("cell_control", c.cell_control.as_str())
        .num("grain_friction", c.friction.grain_grain)
        .num("mean_diameter_m", d)
        .int("pressures", rows.len() as u64)
        .num("inertial_number_target", c.inertial_number)
        .num("quasi_static_bound_I", QUASI_STATIC_I);
    let deg = |x: f64| x.asin().to_degrees();
    for (k, r) in rows.iter().enumerate() {
        let pre = format!("p{}", k + 1);
        s.num(&format!("{pre}_confining_pressure_Pa"), r.p0)
            .num(
                &format!("{pre}_compression_stress_error"),
                r.compression_stress_error,
            )
            .num(&format!("{pre}_phi_compressed"), r.phi_compressed)
            .num(&format!("{pre}_Z_compressed"), r.z_compressed)
            .num(&format!("{pre}_friction_peak_sin_phi"), r.sin_phi_peak)
            .num(
                &format!("{pre}_friction_peak_angle_deg"),
                deg(r.sin_phi_peak),
            )
            .num(&format!("{pre}_axial_strain_peak"), r.axial_strain_peak)
            .num(
                &format!("{pre}_friction_critical_sin_phi"),
                r.sin_phi_critical,
            )
            .num(
                &format!("{pre}_friction_critical_sin_phi_std_error"),
                r.sin_phi_critical_se,
            )
            .num(
                &format!("{pre}_friction_critical_angle_deg"),
                deg(r.sin_phi_critical),
            )
            .num(&format!("{pre}_solid_fraction_critical"), r.phi_critical)
            .num(
                &format!("{pre}_solid_fraction_critical_std_error"),
                r.phi_critical_se,
            )
            .num(&format!("{pre}_Z_critical"), r.z_critical)
            .num(
                &format!("{pre}_fabric_anisotropy_critical"),
                r.fabric_anisotropy_critical,
            )
            .num(&format!("{pre}_dilatancy_max_sin_psi"), r.sin_psi_max)
            .num(
                &format!("{pre}_dilatancy_max_sin_psi_std_error"),
                r.sin_psi_max_se,
            )
            .num(
                &format!("{pre}_dilatancy_max_angle_deg"),
                deg(r.sin_psi_max),
            )
            .num(
                &format!("{pre}_axial_strain_dilatancy_max"),
                r.axial_strain_psi_max,
            )
            .num(
                &format!("{pre}_dilatancy_critical_sin_psi"),
                r.sin_psi_critical,
            )
            .num(
                &format!("{pre}_dilatancy_critical_sin_psi_std_error"),
                r.sin_psi_critical_se,
            )
            .num(
                &format!("{pre}_dilatancy_critical_ratio"),
                r.dilatancy_ratio_critical,
            )
            .int(
                &format!("{pre}_dilatancy_windows"),
                r.dilatancy_windows as u64,
            )
            .int(
                &format!("{pre}_dilatancy_undefined_windows"),
                r.dilatancy_undefined_windows as u64,
            )
            .num(
                &format!("{pre}_lateral_stress_error"),
                r.lateral_stress_error,
            )
            .num(&format!("{pre}_I"), r.i_mean)
            .num(&format!("{pre}_axial_rate_1_s"), r.axial_rate);
        headline.push(format!(
            "p0 = {} Pa: peak sin φ = {:.4} at ε_a = {:.3}; critical sin φ = {:.4} ± {:.4}, φ = {:.4} ± {:.4} (block s.e. of this sample alone); max sin ψ = {} ± {} (block s.e., windows of {} of ε_a)",
            r.p0,
            r.sin_phi_peak,
            r.axial_strain_peak,
            r.sin_phi_critical,
            r.sin_phi_critical_se,
            r.phi_critical,
            r.phi_critical_se,
            short_number(r.sin_psi_max),
            short_number(r.sin_psi_max_se),
            DILATANCY_WINDOW_BINS as f64 * c.bin_strain
        ));
    }
    (s, headline)
}

/// Stage "fit": Mohr–Coulomb over the peak Mohr circles; the envelope `(φ, c)` when fitted.
fn fit_peaks(
    c: &BiaxialConfig,
    rows: &[PressureRow],
    common: &Checks,
    provenance: &Provenance,
    rep: &mut Report,
) -> Result<Option<(f64, f64)>> {
    let (out, s, headline, verdict) = rep.parts();
    let n = rows.len();
    let peaks = YieldData::Circles {
        p_pa: rows.iter().map(|r| r.p_peak).collect(),
        q_pa: rows.iter().map(|r| r.q_peak).collect(),
    };
    // A free cohesion with 4 pressures or more, else (or when the data do not identify it:
    // rigid cohesionless grains have none) the envelope through the origin.
    let left = |law: &str| left_out(c, law);
    let fitted = fit_mohr_coulomb_supported(&peaks, 0.95).map(|(f, fixed, refusal)| {
        if let Some(e) = refusal {
            warn(&format!(
                "Mohr–Coulomb with a free cohesion refused ({e}); fitted the cohesionless form q = p sin φ"
            ));
            s.text("friction_peak_free_cohesion_error", &e.to_string());
        }
        (f, fixed)
    });
    let mut mc_line = None;
    match (!left("mohr-coulomb")).then_some(fitted) {
        // left out by the plan (said at the start)
        None => remove_stale_law(out, "mohr_coulomb")?,
        Some(Ok((f, cohesion_fixed_zero))) => {
            fit_keys(s, "friction_peak", &f.report.parameters);
            fit_keys(
                s,
                "friction_peak",
                std::slice::from_ref(&f.friction_angle_deg),
            );
            s.num("friction_peak_r_squared", f.report.r_squared)
                .flag("friction_peak_cohesion_fixed_zero", cohesion_fixed_zero)
                // the scatter of the peaks, one independent sample per pressure, about the line
                .text("friction_peak_interval", "replicas");
            mc_line = Some((f.law.friction_angle_rad, f.law.cohesion_pa));
            let law = CalibratedLaw::from_mohr_coulomb(&f, provenance.clone());
            let exported = export_law(out, verdict, "mohr_coulomb", &law, common.clone())?;
            headline.extend(exported.heading(&law.law));
            headline.extend(parameter_lines(
                "Mohr–Coulomb over the peaks, q = p sin φ + c cos φ",
                f.report.r_squared,
                &[f.friction_angle_deg.clone(), f.cohesion.clone()],
            ));
        }
        Some(Err(e)) => {
            warn(&format!("Mohr–Coulomb fit over the peaks refused: {e}"));
            s.text("friction_peak_fit_error", &e.to_string());
            remove_stale_law(out, "mohr_coulomb")?;
            verdict.run.fail(
                "biaxial.mohr_coulomb_fit",
                Verdict::Refused,
                n as f64,
                f64::NAN,
                format!("no Mohr–Coulomb envelope over the peaks: {e}"),
            );
        }
    }
    Ok(mc_line)
}

/// Stage "fit": the critical state over the plateaus of the pressures (as replicas).
fn fit_critical(
    c: &BiaxialConfig,
    rows: &[PressureRow],
    critical: &Checks,
    provenance: &Provenance,
    rep: &mut Report,
) -> Result<()> {
    let (out, s, headline, verdict) = rep.parts();
    let n = rows.len();
    let left = |law: &str| left_out(c, law);
    let plateaus: Vec<PlateauMeasure> = rows
        .iter()
        .map(|r| PlateauMeasure {
            pressure_pa: r.p_critical,
            sin_phi: r.sin_phi_critical,
            sin_phi_std_error: r.sin_phi_critical_se,
            solid_fraction: r.phi_critical,
            solid_fraction_std_error: r.phi_critical_se,
            blocks: MIN_BLOCKS,
        })
        .collect();
    match (!left("critical-state")).then(|| fit_critical_state(&plateaus, 0.95)) {
        None => remove_stale_law(out, "critical_state")?,
        Some(Ok(f)) => {
            fit_keys(
                s,
                "friction_critical",
                &[
                    f.friction_angle.clone(),
                    f.friction_angle_deg.clone(),
                    f.sin_phi.clone(),
                ],
            );
            fit_keys(
                s,
                "solid_fraction_critical",
                std::slice::from_ref(&f.solid_fraction),
            );
            s.num("friction_critical_sin_phi_value", f.sin_phi.value)
                .num("solid_fraction_critical", f.solid_fraction.value)
                .int("critical_state_replicas", f.replicas as u64)
                .text("friction_critical_interval", f.sin_phi_interval.as_str())
                .text(
                    "solid_fraction_critical_interval",
                    f.solid_fraction_interval.as_str(),
                )
                .num("friction_critical_sin_phi_replica_sd", f.sin_phi_replica_sd)
                .num(
                    "solid_fraction_critical_replica_sd",
                    f.solid_fraction_replica_sd,
                );
            // each pressure's plateau value with the interval of one sample among replicas
            for (k, r) in rows.iter().enumerate() {
                let pre = format!("p{}", k + 1);
                let (lo, hi) = f.sample_interval(r.sin_phi_critical, f.sin_phi_replica_sd);
                s.num(
                    &format!("{pre}_friction_critical_sin_phi_replica_ci_low"),
                    lo,
                )
                .num(
                    &format!("{pre}_friction_critical_sin_phi_replica_ci_high"),
                    hi,
                );
                let (lo, hi) = f.sample_interval(r.phi_critical, f.solid_fraction_replica_sd);
                s.num(&format!("{pre}_solid_fraction_critical_replica_ci_low"), lo)
                    .num(
                        &format!("{pre}_solid_fraction_critical_replica_ci_high"),
                        hi,
                    );
            }
            let law = CalibratedLaw::from_critical_state(&f, provenance.clone());
            let exported = export_law(out, verdict, "critical_state", &law, critical.clone())?;
            headline.extend(exported.heading(&law.law));
            headline.extend(parameter_lines(
                &format!(
                    "critical state (plateau means over the {} pressures as replicas)",
                    f.replicas
                ),
                f.report.r_squared,
                &[
                    f.friction_angle_deg.clone(),
                    f.sin_phi.clone(),
                    f.solid_fraction.clone(),
                ],
            ));
            headline.push(format!(
                "  intervals: sin φ_c from {}; φ_c from {}",
                f.sin_phi_interval.describe(f.replicas),
                f.solid_fraction_interval.describe(f.replicas)
            ));
            if f.replicas >= 2 {
                headline.push(format!(
                    "  one pressure's plateau, as one sample among replicas: sin φ ± {}, φ ± {} (95 %)",
                    short_number(f.replica_t * f.sin_phi_replica_sd),
                    short_number(f.replica_t * f.solid_fraction_replica_sd)
                ));
            }
        }
        Some(Err(e)) => {
            warn(&format!("critical state refused: {e}"));
            s.text("friction_critical_fit_error", &e.to_string());
            remove_stale_law(out, "critical_state")?;
            verdict.run.fail(
                "biaxial.critical_state_fit",
                Verdict::Refused,
                n as f64,
                f64::NAN,
                format!("no critical state: {e}"),
            );
        }
    }
    Ok(())
}

/// Stage "fit": the stress–dilatancy relation over the hardening windows of every pressure;
/// its data and the line `(sin φ_cv, β)` when fitted.
fn fit_dilatancy(
    c: &BiaxialConfig,
    dilatancy: &[DilatancyRow],
    dilat: &Checks,
    provenance: &Provenance,
    rep: &mut Report,
) -> Result<(StressDilatancyData, Option<(f64, f64)>)> {
    let (out, s, headline, verdict) = rep.parts();
    let left = |law: &str| left_out(c, law);
    // the dilatancy windows of the hardening phases
    let hard: Vec<&DilatancyRow> = dilatancy
        .iter()
        .filter(|w| w.hardening > 0.5 && w.sin_psi.is_finite() && w.sin_phi_mob.is_finite())
        .collect();
    let sd_data = StressDilatancyData {
        sin_psi: hard.iter().map(|w| w.sin_psi).collect(),
        sin_phi: hard.iter().map(|w| w.sin_phi_mob).collect(),
        // each pressure's test is an independent sample: intervals over them
        sample: Some(hard.iter().map(|w| w.p0 as usize).collect()),
    };
    let mut sd_line = None;
    match (!left("stress-dilatancy"))
        .then(|| fit_stress_dilatancy(&sd_data, &identify::FitOptions::default()))
    {
        None => remove_stale_law(out, "stress_dilatancy")?,
        Some(Ok(f)) => {
            fit_keys(s, "stress_dilatancy", &f.report.parameters);
            s.num("stress_dilatancy_r_squared", f.report.r_squared)
                .int("stress_dilatancy_points", f.report.n as u64)
                .int("stress_dilatancy_samples", f.samples as u64)
                // cluster-robust over the pressures when wider, else least squares over the
                // windows (several per sample)
                .text(
                    "stress_dilatancy_interval",
                    if f.clustered { "replicas" } else { "windows" },
                );
            sd_line = Some((f.law.sin_phi_c, f.law.beta));
            let law = CalibratedLaw::from_stress_dilatancy(&f, provenance.clone());
            let exported = export_law(out, verdict, "stress_dilatancy", &law, dilat.clone())?;
            headline.extend(exported.heading(&law.law));
            headline.extend(parameter_lines(
                "stress–dilatancy over the hardening phases, sin φ = sin φ_cv + β sin ψ",
                f.report.r_squared,
                &f.report.parameters,
            ));
        }
        Some(Err(e)) => {
            warn(&format!("stress–dilatancy fit refused: {e}"));
            s.text("stress_dilatancy_fit_error", &e.to_string());
            remove_stale_law(out, "stress_dilatancy")?;
            verdict.run.fail(
                "biaxial.stress_dilatancy_fit",
                Verdict::Refused,
                sd_data.sin_psi.len() as f64,
                f64::NAN,
                format!("no stress–dilatancy relation: {e}"),
            );
        }
    }
    Ok((sd_data, sd_line))
}

/// Stage "report": `biaxial.png` (the binned curves of every pressure) and `biaxial_fits.png`
/// (the Mohr circles with the envelope, the stress–dilatancy points with the line).
fn figures(
    out: &mut OutputDir,
    pressures: &[f64],
    rows: &[PressureRow],
    bins: &[BinPoint],
    mc_line: Option<(f64, f64)>,
    sd: (&StressDilatancyData, Option<(f64, f64)>),
) -> Result<()> {
    let (sd_data, sd_line) = sd;
    let mut pq = XyPlot::new(
        "Mobilised friction",
        Axis::new("axial strain ε_a"),
        Axis::new("sin φ_mob = q/p"),
    );
    let mut pv = XyPlot::new(
        "Volumetric strain (positive in contraction)",
        Axis::new("axial strain ε_a"),
        Axis::new("ε_v = −ln(V/V₀)"),
    );
    for (k, p0) in pressures.iter().enumerate().take(rows.len()) {
        let pts = |f: fn(&BinPoint) -> f64| -> Vec<(f64, f64)> {
            bins.iter()
                .filter(|b| b.pressure as usize == k && f(b).is_finite())
                .map(|b| (b.axial_strain, f(b)))
                .collect()
        };
        let colour = PALETTE[k % PALETTE.len()];
        pq.series.push(Series::new(
            &format!("p₀ = {p0} Pa"),
            Style::Line,
            colour,
            pts(|b| b.sin_phi),
        ));
        pv.series.push(Series::new(
            &format!("p₀ = {p0} Pa"),
            Style::Line,
            colour,
            pts(|b| b.volumetric_strain),
        ));
    }
    pq.legend = LegendAt::LowerRight;
    pv.legend = LegendAt::UpperLeft;
    let circles: Vec<(f64, f64, f64)> = pressures
        .iter()
        .zip(rows.iter())
        .map(|(p0, r)| (*p0, r.p_peak, r.q_peak))
        .collect();
    let pmc = mohr_plot(&circles, mc_line);
    let mut psd = XyPlot::new(
        "Stress–dilatancy (hardening phases)",
        Axis::new("sin ψ = −ε̇_v / ε̇_γ"),
        Axis::new("sin φ_mob"),
    );
    psd.series.push(Series::new(
        "dilatancy windows before the peak",
        Style::Points,
        PALETTE[2],
        sd_data
            .sin_psi
            .iter()
            .copied()
            .zip(sd_data.sin_phi.iter().copied())
            .collect(),
    ));
    if let Some((a, b)) = sd_line {
        let (lo, hi) = sd_data
            .sin_psi
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(*x), h.max(*x)));
        psd.series.push(Series::new(
            "sin φ_cv + β sin ψ",
            Style::Line,
            PALETTE[1],
            vec![(lo, a + b * lo), (hi, a + b * hi)],
        ));
    }
    if sd_line.is_none() {
        psd.notes
            .push("no stress–dilatancy relation fitted (stress_dilatancy_fit_error)".into());
    }
    psd.legend = LegendAt::UpperLeft;
    draw_row(out, "biaxial.png", &[pq, pv], (1300, 650))?;
    draw_row(out, "biaxial_fits.png", &[pmc, psd], (1300, 650))?;
    Ok(())
}

/// The checks, fits, laws, table, figures and summary of a finished run.
#[allow(clippy::too_many_arguments)]
fn analyse(
    c: &BiaxialConfig,
    pressures: &[f64],
    ctx: &mut RunContext,
    ctl: &RunControl,
    world: &dem::World,
    all: &PhaseStats,
    rows: &[PressureRow],
    bins: &[BinPoint],
    dilatancy: &[DilatancyRow],
    checks: &[PressureCheck],
) -> Result<RunOutcome> {
    let judged = judge(c, rows, checks);
    let d = mean_diameter(world);
    write_tables(c, pressures, &mut ctx.out, d, rows, dilatancy)?;
    let (s, headline) = pressure_summary(c, d, rows, ctx.out.path());
    let provenance = ctl.law_provenance(ctx, "biaxial", c.seed);
    let mut rep = Report {
        out: &mut ctx.out,
        s,
        headline,
        verdict: RunVerdict {
            run: judged.run,
            allow_suspect: ctl.allow_suspect,
            ..Default::default()
        },
    };
    let mc_line = fit_peaks(c, rows, &judged.common, &provenance, &mut rep)?;
    fit_critical(c, rows, &judged.critical, &provenance, &mut rep)?;
    let (sd_data, sd_line) = fit_dilatancy(c, dilatancy, &judged.dilat, &provenance, &mut rep)?;
    figures(rep.out, pressures, rows, bins, mc_line, (&sd_data, sd_line))?;
    let Report {
        s,
        headline,
        verdict,
        ..
    } = rep;
    Ok(RunOutcome::windowed(
        s,
        all,
        &judged.windows,
        headline,
        verdict,
    ))
}

/// The figures of one biaxial benchmark row ([`bench_rve`]).
#[derive(Debug, Clone, Copy)]
pub struct BiaxialBench {
    /// Grains.
    pub grains: usize,
    /// Steps of the isotropic compression and its wall seconds.
    pub compress_steps: usize,
    /// Wall seconds of the compression.
    pub compress_seconds: f64,
    /// Timed steps of the axial compression.
    pub axial_steps: usize,
    /// Axial strain of one step `ε̇_a Δt` (1).
    pub strain_per_step: f64,
    /// Wall seconds per axial step.
    pub seconds_per_step: f64,
    /// Wall seconds per percent of axial strain, `0.01 / (ε̇_a Δt)` steps.
    pub seconds_per_percent: f64,
    /// Mean contacts, sweeps and re-solves (cell control) per axial step.
    pub contacts: f64,
    /// Mean sweeps per solve.
    pub sweeps: f64,
    /// Mean re-solves of a step by the cell control.
    pub corrections: f64,
    /// Axial steps stopped at the sweep cap.
    pub unconverged: usize,
}

/// The overrides of the built-in `biaxial` scenario for a benchmark row of `grains` grains
/// ([`bench_rve`]): p₀ = 1 kPa, nothing fitted, the sweeps on all of rayon's threads
/// (`solver.parallel`).
pub fn bench_sets(grains: usize) -> Vec<String> {
    vec![
        format!("grains={grains}"),
        "confining_pressures=[1000.0]".to_string(),
        // a benchmark of the engine: nothing is fitted
        r#"leave_out=["mohr-coulomb", "critical-state", "stress-dilatancy"]"#.to_string(),
        // the sweeps on all of rayon's threads (the same numbers on any thread count)
        "solver.parallel=true".to_string(),
    ]
}

/// The biaxial benchmark row: the built-in `biaxial` scenario loaded with [`bench_sets`],
/// `compress_steps` steps of isotropic compression (not timed per step), then `axial_steps`
/// timed steps of the axial compression (the scenario's own control and solver settings;
/// rayon's global pool).
pub fn bench_rve(
    c: &BiaxialConfig,
    compress_steps: usize,
    axial_steps: usize,
) -> Result<BiaxialBench> {
    let grains = c.grains;
    let bx = Biaxial {
        c,
        pressures: vec![1000.0],
    };
    let p0 = 1000.0;
    let mut w = build::biaxial(c)?;
    if c.preparation == Preparation::Dense {
        w.laws.set_friction(0, 0, 0.0);
    }
    let d = mean_diameter(&w);
    let dt = c.compression_dt();
    w.params.dt = dt;
    w.cell_control = Some(bx.control(p0, -p0, dt, d, None));
    let t0 = std::time::Instant::now();
    for _ in 0..compress_steps {
        w.step()?;
    }
    let compress_seconds = t0.elapsed().as_secs_f64();
    w.laws.set_friction(0, 0, c.friction.grain_grain);
    let rate = c.axial_rate(p0);
    let dt = c.axial_dt(p0);
    w.params.dt = dt;
    w.set_velocity_gradient(Mat::new(0.0, 0.0, 0.0, -rate));
    w.cell_control = Some(bx.control(p0, -p0, dt, d, Some(rate)));
    let (mut contacts, mut sweeps, mut corrections, mut unconverged) = (0usize, 0usize, 0u64, 0);
    let t1 = std::time::Instant::now();
    for _ in 0..axial_steps {
        let r = w.step()?;
        contacts += r.contacts;
        sweeps += r.solver.iterations;
        corrections += u64::from(r.cell_corrections);
        unconverged += usize::from(!r.solver.converged);
    }
    let secs = t1.elapsed().as_secs_f64() / axial_steps.max(1) as f64;
    let k = axial_steps.max(1) as f64;
    Ok(BiaxialBench {
        grains,
        compress_steps,
        compress_seconds,
        axial_steps,
        strain_per_step: rate * dt,
        seconds_per_step: secs,
        seconds_per_percent: secs * 0.01 / (rate * dt),
        contacts: contacts as f64 / k,
        sweeps: sweeps as f64 / k,
        corrections: corrections as f64 / k,
        unconverged,
    })
}

/// Points per drawn half circle.
const CIRCLE_SEGMENTS: usize = 90;

/// The figure of the peak Mohr circles: for each pressure `(p₀, p, q)` the upper half of the
/// circle of centre `σ = p` and radius `q` in the plane of normal stress `σ` (compression
/// positive) and shear stress `τ`, drawn at equal scales so that circles look round; with
/// `envelope = (φ, c)`, the Mohr–Coulomb line `τ = c + σ tan φ`, tangent to the circle
/// `(p, q)` at `σ_t = p − q sin φ`, `τ_t = q cos φ` when `q = p sin φ + c cos φ`: solid between
/// the circles' tangent points (the data), dashed from `σ = 0` (its cohesion intercept, an
/// extrapolation) to the first of them.
pub(crate) fn mohr_plot(circles: &[(f64, f64, f64)], envelope: Option<(f64, f64)>) -> XyPlot {
    let mut plot = XyPlot::new(
        "Peak Mohr circles (compression positive)",
        Axis::new("normal stress σ (Pa)"),
        Axis::new("shear stress τ (Pa)"),
    );
    plot.equal_aspect = true;
    for (k, &(p0, p, q)) in circles.iter().enumerate() {
        plot.series.push(Series::new(
            &format!("peak at p₀ = {p0} Pa"),
            Style::Line,
            PALETTE[k % PALETTE.len()],
            (0..=CIRCLE_SEGMENTS)
                .map(|j| {
                    let a = std::f64::consts::PI * j as f64 / CIRCLE_SEGMENTS as f64;
                    (p + q * a.cos(), q * a.sin())
                })
                .collect(),
        ));
    }
    if let Some((phi, c)) = envelope {
        let tangents: Vec<f64> = circles
            .iter()
            .map(|&(_, p, q)| p - q * phi.sin())
            .filter(|x| x.is_finite())
            .collect();
        let lo = tangents.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = tangents.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() {
            let tau = |x: f64| c + x * phi.tan();
            plot.series.push(Series::new(
                &format!(
                    "Mohr–Coulomb τ = c + σ tan φ (φ = {:.1}°, c = {c:.0} Pa)",
                    phi.to_degrees()
                ),
                Style::Line,
                PALETTE[6],
                vec![(lo, tau(lo)), (hi, tau(hi))],
            ));
            if lo > 0.0 {
                plot.series.push(Series::new(
                    "the same, extrapolated to σ = 0",
                    Style::Dashed,
                    PALETTE[6],
                    vec![(0.0, tau(0.0)), (lo, tau(lo))],
                ));
            }
        }
    }
    plot.legend = LegendAt::UpperLeft;
    plot
}

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for BiaxialConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "biaxial"
    }

    fn law_needs(&self) -> Vec<LawNeed> {
        BiaxialConfig::law_needs(self)
    }

    fn leave_out(&self) -> &[String] {
        &self.leave_out
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> datasets::Result<()> {
        build::biaxial(self).map(drop)
    }
}

#[cfg(test)]
mod figure_tests {
    use super::*;

    /// The circles are circles: every drawn point of the circle `(p, q)` is at distance `q`
    /// from `(p, 0)` (to 1e-9 relative), with τ ≥ 0, at equal scales; the envelope is the
    /// line τ = c + σ tan φ, solid only between the tangent points `p − q sin φ` of the
    /// circles (the smallest and the largest), dashed below, and tangent to a circle that
    /// satisfies `q = p sin φ + c cos φ` (its distance to the centre equals the radius).
    #[test]
    fn mohr_circles_are_circles_and_the_envelope_spans_its_data() {
        let (phi, c) = (26.5f64.to_radians(), 50.0);
        let circles: Vec<(f64, f64, f64)> = [1000.0, 2000.0, 4000.0]
            .iter()
            .map(|&p| (p, 1.8 * p, 1.8 * p * phi.sin() + c * phi.cos()))
            .collect();
        let plot = mohr_plot(&circles, Some((phi, c)));
        assert!(plot.equal_aspect);
        for (k, &(_, p, q)) in circles.iter().enumerate() {
            let s = &plot.series[k];
            assert_eq!(s.xy.len(), CIRCLE_SEGMENTS + 1);
            for &(x, y) in &s.xy {
                let r = ((x - p).powi(2) + y * y).sqrt();
                assert!((r - q).abs() <= 1e-9 * q, "radius {r} vs {q}");
                assert!(y >= -1e-9 * q);
            }
        }
        let line = &plot.series[3];
        assert_eq!(line.style, Style::Line);
        let (lo, hi) = (line.xy[0].0, line.xy[1].0);
        let t = |k: usize| circles[k].1 - circles[k].2 * phi.sin();
        assert!(
            (lo - t(0)).abs() < 1e-9 && (hi - t(2)).abs() < 1e-9,
            "{lo} {hi}"
        );
        for &(x, y) in &line.xy {
            assert!((y - (c + x * phi.tan())).abs() < 1e-9);
        }
        // tangent: distance from each centre to the line equals its radius
        for &(_, p, q) in &circles {
            let d = (p * phi.tan() + c) / (1.0 + phi.tan().powi(2)).sqrt();
            assert!((d - q).abs() <= 1e-9 * q, "{d} vs {q}");
        }
        let ext = &plot.series[4];
        assert_eq!(ext.style, Style::Dashed);
        assert_eq!(ext.xy[0].0, 0.0);
        assert!((ext.xy[1].0 - lo).abs() < 1e-12);
    }
}
