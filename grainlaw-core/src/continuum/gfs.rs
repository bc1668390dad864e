//! Gerris simulation files (`.gfs`) of the two continuum cases (`docs/continuum.md` §3).
//!
//! Every number is written out (no `Define` macros, which need `m4`), with comments giving the
//! units and the conversions, so that the file reruns by hand: `gerris2D column.gfs`.

use identify::expr::c_literal;

use super::rheology::{sanitize_comment, GerrisRheology, LightPhase};
use crate::error::Result;

/// Directory of a case's snapshots (created before Gerris runs: it opens, never creates, them).
pub const SNAPSHOT_DIR: &str = "snapshots";

/// The Gerris variables of a snapshot: the volume fraction of grains `T`, the velocity, the
/// pressure and the law's inertial number `Inertial` (0 outside the grains).
pub const SNAPSHOT_VARIABLES: &str = "T,U,V,P,Inertial";

/// One instant at which the profile is written (`snapshots/ref-LABEL.txt`).
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceInstant {
    /// Label (`t0.66`).
    pub label: String,
    /// Gerris time.
    pub time: f64,
}

/// The 2D column collapse (Lagrée, Staron & Popinet 2011): a column `0 ≤ x ≤ 1`,
/// `0 ≤ y ≤ a` (units of `R₀`) released on a no-slip floor, the symmetry plane `x = 0`, in a
/// square box of side `domain` with the light phase above.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnCase {
    /// The law and its units (length unit `R₀`).
    pub rheology: GerrisRheology,
    /// The light phase.
    pub light: LightPhase,
    /// Aspect ratio `a = H₀/R₀`.
    pub aspect_ratio: f64,
    /// Side of the square domain (units of `R₀`).
    pub domain: f64,
    /// Refinement level: the cells in and around the grains have the side `domain/2^level`.
    pub level: u32,
    /// End time (Gerris units).
    pub end: f64,
    /// Interval between two history snapshots (Gerris units).
    pub history_interval: f64,
    /// Instants of the reference profiles.
    pub references: Vec<ReferenceInstant>,
    /// Provenance lines written as comments at the top.
    pub comments: Vec<String>,
}

/// The provenance comments of a case, one `# ` line each.
fn comment_block(comments: &[String]) -> String {
    comments
        .iter()
        .map(|c| format!("# {}\n", sanitize_comment(c)))
        .collect()
}

impl ColumnCase {
    /// Side of the finest cells (units of `R₀`), `domain/2^level`.
    pub fn cell_size(&self) -> f64 {
        self.domain / f64::from(1u32 << self.level)
    }

    /// The `.gfs` text.
    pub fn to_gfs(&self) -> Result<String> {
        let r = &self.rheology;
        let l = &self.light;
        let lit = |v: f64| c_literal(v);
        let mut s = comment_block(&self.comments);
        s.push_str(&format!(
            "# Units (Gerris): length R0 = {r0:e} m, gravity g = {g} m/s^2, density rho_b = phi rho_s = {rb} kg/m^3;\n\
             # time sqrt(R0/g) = {ts:e} s, t* = t sqrt(g/H0) = t_Gerris/sqrt(a); pressure rho_b g R0 = {pu:e} Pa;\n\
             # viscosity rho_b sqrt(g R0^3) = {vu:e} Pa s. I = sqrt(2) D2 D/sqrt(phi P), D = d/R0 = {d:e}, phi = {phi}.\n\
             # Regularisation: eta in [{emin:e}, {emax}] (Gerris units). Light phase: density {lr} rho_b, viscosity {lv}.\n\
             # Rerun by hand in this directory: gerris2D column.gfs\n",
            r0 = r.units.length_m,
            g = r.units.gravity_m_s2,
            rb = r.units.bulk_density_kg_m3,
            ts = r.units.time_s(),
            pu = r.units.pressure_pa(),
            vu = r.units.viscosity_pa_s(),
            d = r.grain_diameter(),
            phi = r.packing_fraction,
            emin = r.regularisation.eta_min,
            emax = r.regularisation.eta_max,
            lr = l.density_ratio,
            lv = l.viscosity,
        ));
        let level = self.level;
        let coarse = level.min(6);
        s.push_str("1 0 GfsSimulation GfsBox GfsGEdge { x = 0.5 y = 0.5 } {\n");
        s.push_str(&format!(
            "  PhysicalParams {{ L = {} }}\n",
            lit(self.domain)
        ));
        s.push_str(&format!(
            "  Time {{ end = {} dtmax = 1e-2 }}\n",
            lit(self.end)
        ));
        s.push_str("  ApproxProjectionParams { tolerance = 1e-4 }\n  ProjectionParams { tolerance = 1e-4 }\n");
        s.push_str("  VariableTracerVOF T\n  Variable Inertial\n");
        s.push_str(&format!(
            "  SourceViscosity {{}} {} {{ beta = 1 tolerance = 1e-4 }}\n",
            indent(&r.source_viscosity_c(Some(l))?, "  ")
        ));
        s.push_str(&format!(
            "  AdaptGradient {{ istep = 1 }} {{ cmax = 0 maxlevel = {level} }} T\n  AdaptFunction {{ istep = 1 }} {{ cmax = 0 maxlevel = {level} }} T\n"
        ));
        s.push_str(&format!(
            "  PhysicalParams {{ alpha = 1./(T + {rho}*(1. - T)) }}\n  Source V -1\n",
            rho = lit(l.density_ratio)
        ));
        s.push_str(&format!(
            "  Refine {coarse}\n  InitFraction T (union({a} - y, 1. - x))\n  RemoveDroplets {{ istep = 1 }} T -1\n",
            a = lit(self.aspect_ratio)
        ));
        s.push_str(&format!(
            "  Init {{ istep = 1 }} {{ Inertial = (T > 0.999 && P > 0. && D2 > 0. ? {} : 0.) }}\n",
            r.inertial_number_c()
        ));
        s.push_str("  OutputTime { istep = 50 } stderr\n");
        s.push_str(&format!(
            "  OutputSimulation {{ step = {} }} {SNAPSHOT_DIR}/history-%ld.txt {{ format = text variables = T,Inertial }}\n",
            lit(self.history_interval)
        ));
        for ri in &self.references {
            s.push_str(&format!(
                "  OutputSimulation {{ start = {} }} {SNAPSHOT_DIR}/ref-{}.txt {{ format = text variables = {SNAPSHOT_VARIABLES} }}\n",
                lit(ri.time),
                ri.label
            ));
        }
        s.push_str(&format!(
            "  OutputSimulation {{ start = end }} {SNAPSHOT_DIR}/end.txt {{ format = text variables = {SNAPSHOT_VARIABLES} }}\n"
        ));
        s.push_str("}\nGfsBox {\n");
        s.push_str(&format!(
            "  top = Boundary {{ BcDirichlet P {} BcNeumann V 0 }}\n",
            lit(-l.density_ratio * self.domain)
        ));
        s.push_str("  bottom = Boundary { BcDirichlet U 0 }\n  left = Boundary\n  right = Boundary { BcDirichlet V 0 }\n}\n");
        Ok(s)
    }
}

/// Steady uniform flow down an inclined plane (Bagnold): a layer `0 ≤ y ≤ 1` (units of its
/// thickness `H`), periodic along the slope `x`, no slip at the base, a free surface `P = 0`
/// on top, gravity `(sin θ, −cos θ)`, inertia left out (the steady uniform flow has none).
#[derive(Debug, Clone, PartialEq)]
pub struct InclinedCase {
    /// The law and its units (length unit `H`).
    pub rheology: GerrisRheology,
    /// Slope angle `θ` (rad).
    pub slope_rad: f64,
    /// Refinement level (`2^level` cells across the layer).
    pub level: u32,
    /// Surface velocity of the initial parabolic profile `u = u_s y (2 − y)` (Gerris units).
    pub initial_surface_velocity: f64,
    /// The run stops when `U` changes by less than this over 10 steps (Gerris units).
    pub steady_tolerance: f64,
    /// Largest number of time steps.
    pub max_steps: u64,
    /// Provenance lines written as comments at the top.
    pub comments: Vec<String>,
}

impl InclinedCase {
    /// The `.gfs` text.
    pub fn to_gfs(&self) -> Result<String> {
        let r = &self.rheology;
        let lit = |v: f64| c_literal(v);
        let mut s = comment_block(&self.comments);
        s.push_str(&format!(
            "# Units (Gerris): length H = {h:e} m, gravity g = {g} m/s^2, density rho_b = phi rho_s = {rb} kg/m^3;\n\
             # velocity sqrt(g H) = {vu:e} m/s; pressure rho_b g H = {pu:e} Pa. I = sqrt(2) D2 D/sqrt(phi P), D = d/H = {d:e}, phi = {phi}.\n\
             # Regularisation: eta in [{emin:e}, {emax}] (Gerris units). Rerun by hand in this directory: gerris2D inclined.gfs\n",
            h = r.units.length_m,
            g = r.units.gravity_m_s2,
            rb = r.units.bulk_density_kg_m3,
            vu = r.units.velocity_m_s(),
            pu = r.units.pressure_pa(),
            d = r.grain_diameter(),
            phi = r.packing_fraction,
            emin = r.regularisation.eta_min,
            emax = r.regularisation.eta_max,
        ));
        let (sin, cos) = self.slope_rad.sin_cos();
        s.push_str("1 1 GfsSimulation GfsBox GfsGEdge { y = 0.5 } {\n");
        s.push_str(&format!(
            "  Time {{ iend = {} dtmax = 5 }}\n",
            self.max_steps
        ));
        s.push_str("  AdvectionParams { scheme = none }\n  ApproxProjectionParams { tolerance = 1e-8 }\n  ProjectionParams { tolerance = 1e-8 }\n");
        s.push_str("  Variable Inertial\n");
        s.push_str(&format!(
            "  SourceViscosity {{}} {} {{ beta = 1 }}\n",
            indent(&r.source_viscosity_c(None)?, "  ")
        ));
        s.push_str(&format!(
            "  Source V {}\n  Source U {}\n",
            lit(-cos),
            lit(sin)
        ));
        s.push_str(&format!(
            "  Refine {}\n  Init {{}} {{\n    U = {}*y*(2. - y)\n    P = (1. - y)*{}\n  }}\n",
            self.level,
            lit(self.initial_surface_velocity),
            lit(cos)
        ));
        s.push_str(&format!(
            "  Init {{ istep = 1 }} {{ Inertial = (P > 0. && D2 > 0. ? {} : 0.) }}\n",
            r.inertial_number_c()
        ));
        s.push_str("  OutputTime { istep = 10 } stderr\n");
        s.push_str(&format!(
            "  EventStop {{ istart = 10 istep = 10 }} U {} DU\n",
            lit(self.steady_tolerance)
        ));
        s.push_str(&format!(
            "  OutputSimulation {{ start = end }} {SNAPSHOT_DIR}/end.txt {{ format = text variables = U,P,Inertial }}\n"
        ));
        s.push_str("}\nGfsBox {\n  top = Boundary { BcNeumann V 0 BcDirichlet P 0 }\n  bottom = Boundary { BcDirichlet U 0 }\n}\n1 1 right\n");
        Ok(s)
    }
}

/// `text` with every line after the first indented by `pad`.
fn indent(text: &str, pad: &str) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                l.to_string()
            } else {
                format!("{pad}{l}")
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}
