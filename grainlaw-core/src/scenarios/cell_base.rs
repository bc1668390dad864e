//! The shared base of the cell scenarios, `biaxial` and `simple-shear`: a biperiodic
//! deformable cell (`dem::cell`) driven by a stress or rate on each component of the velocity
//! gradient. Both build their cell control from a [`ControlPlan`] (explicit law with the gains
//! and tolerances below, or the implicit law of [`implicit_cell_control`]), keep what every
//! phase collects in a [`CellRecord`], and take block-averaged standard errors over at least
//! [`MIN_BLOCKS`] blocks.

use dem::cell::{CellControl, Imposed};
use serde::{Deserialize, Serialize};

use super::common::{implicit_cell_control, VtkFrames};
use super::rows::{serde_rows, TableRow};
use super::sensitivity::{refuse_unsettled, PairOf, ResolveQueue};
use crate::scenarios::common::config::CellControlMode;
use crate::scenarios::phases::PhaseStats;
use crate::verdict::WindowStats;

/// Gain of the explicit cell control as a fraction of its stability limit `Δt/(ρ d²)`
/// (`dem::cell`).
pub const GAIN_FRACTION: f64 = 0.3;
/// Tolerance of the explicit law's correction of the cell control, as a fraction of the
/// scenario's pressure.
pub const CONTROL_TOLERANCE: f64 = 0.5;
/// Re-solves of a step at most by the correction.
pub const MAX_CORRECTIONS: usize = 8;
/// Blocks of the block-averaged standard errors (at least).
pub const MIN_BLOCKS: usize = 4;

/// What a cell scenario imposes on its cell in a phase: the three components of the velocity
/// gradient and the control's scales.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlPlan {
    /// Explicit or implicit law.
    pub mode: CellControlMode,
    /// What is imposed on xx, yy, xy.
    pub xx: Imposed,
    pub yy: Imposed,
    pub xy: Imposed,
    /// Cap of a controlled rate (1/s).
    pub max_rate: f64,
    /// The pressure the control's tolerance and implicit gain scale with (Pa, positive).
    pub pressure: f64,
    /// An isotropic compression of a loose packing (the implicit law caps its reference
    /// rate, [`implicit_cell_control`]).
    pub compressing: bool,
    /// Gain of the explicit law as a fraction of `Δt/(ρ d²)` ([`GAIN_FRACTION`] unless the
    /// phase needs a gentler one).
    pub gain_fraction: f64,
    /// Filter time of the explicit law, in time steps (0: none).
    pub filter_steps: f64,
    /// Whether the implicit law moves the grains with the cell's change (`dem::cell`).
    pub affine: bool,
}

impl ControlPlan {
    /// The cell control of the plan at time step `dt` (s), grain density `rho` (kg/m³) and mean
    /// diameter `d` (m).
    pub fn control(&self, dt: f64, rho: f64, d: f64) -> CellControl {
        if self.mode == CellControlMode::Implicit {
            return implicit_cell_control(
                self.xx,
                self.yy,
                self.xy,
                self.max_rate,
                self.pressure,
                self.compressing,
            )
            .with_affine(self.affine);
        }
        CellControl {
            xx: self.xx,
            yy: self.yy,
            xy: self.xy,
            gain: self.gain_fraction * dt / (rho * d * d),
            max_rate: self.max_rate,
            relaxation: self.filter_steps * dt,
            tolerance: CONTROL_TOLERANCE * self.pressure,
            max_corrections: MAX_CORRECTIONS,
            implicit: false,
            affine: false,
        }
    }
}

/// What the phases of a cell scenario collect in common (flattened into the scenario's
/// state, so a checkpoint stores the same keys as before): the solver statistics of all
/// phases, one result row `R` per finished run, the current run's history of rows `H`, the VTK
/// frames and the numerics of the current window.
#[derive(Serialize, Deserialize)]
pub struct CellRecord<H: TableRow, R: TableRow> {
    /// Solver statistics of all phases.
    pub all: PhaseStats,
    /// One row per finished run (pressure, inertial number).
    #[serde(with = "serde_rows")]
    pub rows: Vec<R>,
    /// The current run's history, one row per step.
    #[serde(with = "serde_rows")]
    pub history: Vec<H>,
    /// VTK frames.
    pub frames: VtkFrames,
    /// Numerics of the current window.
    #[serde(default)]
    pub window: WindowStats,
    /// The window's re-solves not yet recorded in `window.sensitivity` (never saved: the
    /// phases settle them before a checkpoint, [`super::phased::PhasedRun::settle`]; a
    /// checkpoint of a state with re-solves pending fails, [`refuse_unsettled`]).
    #[serde(
        skip_deserializing,
        skip_serializing_if = "ResolveQueue::is_settled",
        serialize_with = "refuse_unsettled"
    )]
    pub resolves: ResolveQueue,
}

impl<H: TableRow, R: TableRow> CellRecord<H, R> {
    /// An empty record with these frames.
    pub fn new(frames: VtkFrames) -> Self {
        Self {
            all: PhaseStats::default(),
            rows: Vec::new(),
            history: Vec::new(),
            frames,
            window: WindowStats::default(),
            resolves: ResolveQueue::default(),
        }
    }

    /// Re-solves the window's sample that `w` holds, whose stress pair as run is `run`
    /// ([`ResolveQueue::submit`]; recorded into `window.sensitivity` at once or by
    /// [`CellRecord::settle`]).
    pub fn resolve_sample(&mut self, w: &dem::World, run: [f64; 2], pair: PairOf) {
        self.resolves
            .submit(&mut self.window.sensitivity, w, run, pair);
    }

    /// Records the pending re-solves into `window.sensitivity`, in sample order.
    pub fn settle(&mut self) {
        self.resolves.settle(&mut self.window.sensitivity);
    }
}

/// Declares the per-step history row of a cell scenario ([`table_row!`](super::rows::table_row)):
/// the scenario's own leading columns (`head`), then the whole-cell columns every cell
/// scenario writes in this order — mean stress Σ_xx, Σ_yy, Σ_xy (Pa, tension positive), strain
/// rate of the cell D_xx, D_yy, D_xy (1/s), mean pressure `p = −tr Σ/2` and deviator `q` (Pa) —
/// then its own trailing columns (`tail`). The row gets `of_cell(cs)`: those whole-cell columns
/// from a [`homogenise::cell::CellState`], every other column 0 (fill them with
/// `HistoryRow { t, .., ..HistoryRow::of_cell(&cs) }`).
macro_rules! cell_history_row {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            head { $( $(#[$hmeta:meta])* $hfield:ident : $hheader:literal ),* $(,)? }
            tail { $( $(#[$tmeta:meta])* $tfield:ident : $theader:literal ),* $(,)? }
        }
    ) => {
        $crate::scenarios::rows::table_row! {
            $(#[$meta])*
            $vis struct $name {
                $( $(#[$hmeta])* $hfield: $hheader, )*
                /// Whole-cell mean stress Σ_xx (Pa, tension positive).
                sxx: "sigma_xx_Pa",
                /// Σ_yy (Pa).
                syy: "sigma_yy_Pa",
                /// Σ_xy (Pa).
                sxy: "sigma_xy_Pa",
                /// Strain rate of the cell D_xx (1/s).
                dxx: "D_xx_1_s",
                /// D_yy (1/s).
                dyy: "D_yy_1_s",
                /// D_xy (1/s).
                dxy: "D_xy_1_s",
                /// Mean pressure `p = −tr Σ/2` (Pa).
                p: "p_Pa",
                /// Deviator q (Pa).
                q: "q_Pa",
                $( $(#[$tmeta])* $tfield: $theader, )*
            }
        }

        impl $name {
            /// A row with the whole-cell columns of `cs` (stress, strain rate, p, q), every
            /// other column 0.
            fn of_cell(cs: &homogenise::cell::CellState) -> Self {
                let (s, d) = (cs.stress, cs.strain_rate);
                Self {
                    sxx: s[(0, 0)],
                    syy: s[(1, 1)],
                    sxy: s[(0, 1)],
                    dxx: d[(0, 0)],
                    dyy: d[(1, 1)],
                    dxy: d[(0, 1)],
                    p: cs.pressure,
                    q: cs.deviator,
                    ..Self::default()
                }
            }
        }
    };
}
pub(crate) use cell_history_row;
