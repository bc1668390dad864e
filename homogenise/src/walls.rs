//! Walls: contact forces by depth (wall stress profiles), the vertical stress across horizontal
//! planes of a column, and near-wall profiles of sheared flows.
//!
//! **Wall stress by depth bin** (bin length `ℓ` along the wall, grain thickness `t`):
//! - normal stress of the material at the wall `σ_nn = −Σ_bin f_n / (ℓ t)` (Pa, tension
//!   positive, so ≤ 0; Janssen's `σ_h = −σ_nn`);
//! - shear stress `τ = Σ_bin (force of the grains on the wall) · e_down / (ℓ t)` (Pa): positive
//!   when the grains drag the wall down the depth axis (Janssen's `τ_w`).
//!
//! **Vertical stress across a horizontal plane** `y = y₀` (method of planes): the force `T`
//! that the material below exerts on the material above is the sum of the forces of the
//! contacts whose branch crosses the plane (branch: from one body's end to the other's, a
//! grain's end is its centre, a wall's end is the contact point). With the sample width `W`:
//! `σ_yy(y₀) = −T_y / (W t)`, `σ_xy(y₀) = −T_x / (W t)` (tension positive). Exact in
//! equilibrium; in flows it leaves out the momentum flux of grains crossing the plane.
//! At the bottom of a column at rest, `−σ_yy W t` is the weight minus what the side walls carry.

use dem::math::{Twist, Vector};
use dem::snapshot::{BodyKind, Snapshot, WallGeometry, WallState};
use serde::{Deserialize, Serialize};

use crate::depth::DepthBins;
use crate::error::{positive, HomogeniseError, Result};
use crate::mobilisation::COULOMB_LIMIT;
use crate::region::grain_extent;
use crate::validate::{check_snapshot, unit_normal};

/// The wall of that name.
pub fn find_wall<'a>(snapshot: &'a Snapshot, name: &str) -> Result<&'a WallState> {
    snapshot
        .walls
        .iter()
        .find(|w| w.name == name)
        .ok_or_else(|| HomogeniseError::UnknownWall(name.to_string()))
}

/// One contact between a wall and a grain, seen from the grain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WallContact {
    /// Index in `Snapshot::contacts`.
    pub contact: usize,
    /// Index of the grain in `Snapshot::bodies`.
    pub grain: usize,
    /// Contact point (m).
    pub point: Vector,
    /// Unit normal from the wall into the grain.
    pub normal: Vector,
    /// Force of the wall on the grain (N).
    pub force_on_grain: Vector,
    /// Normal force `f_n ≥ 0` (N).
    pub force_n: f64,
    /// Tangential force magnitude `|f_t|` (N).
    pub force_t: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Mobilisation `|f_t| / (μ f_n)`, when defined.
    pub mobilisation: Option<f64>,
    /// Thickness of the grain (m).
    pub thickness: f64,
}

/// Contacts between the named wall and grains.
pub fn wall_contacts(snapshot: &Snapshot, wall: &str) -> Result<Vec<WallContact>> {
    check_snapshot(snapshot)?;
    let w = find_wall(snapshot, wall)?.body;
    let mut out = Vec::new();
    for (i, c) in snapshot.contacts.iter().enumerate() {
        let (grain, sign) = if c.body_a == w {
            (c.body_b, 1.0)
        } else if c.body_b == w {
            (c.body_a, -1.0)
        } else {
            continue;
        };
        let g = &snapshot.bodies[grain as usize];
        if g.kind != BodyKind::Grain {
            continue;
        }
        out.push(WallContact {
            contact: i,
            grain: grain as usize,
            point: c.point,
            normal: c.normal * sign,
            force_on_grain: c.force_on_b() * sign,
            force_n: c.force_n,
            force_t: c.force_t.abs(),
            mu: c.mu,
            mobilisation: c.mobilisation(),
            thickness: g.thickness,
        });
    }
    Ok(out)
}

/// Wall stresses in one depth bin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WallStressBin {
    /// Upper bound of the bin's depth (m).
    pub depth_min: f64,
    /// Lower bound of the bin's depth (m).
    pub depth_max: f64,
    /// Length of wall in the bin `ℓ` (m).
    pub length: f64,
    /// `σ_nn = −Σ f_n / (ℓ t)` (Pa, tension positive).
    pub normal_stress: f64,
    /// `τ = Σ (force on the wall) · e_down / (ℓ t)` (Pa).
    pub shear_stress: f64,
    /// Number of contacts with a normal force in the bin.
    pub contacts: usize,
    /// Mean mobilisation of those contacts (`None` if none has one).
    pub mean_mobilisation: Option<f64>,
    /// Share of those at the Coulomb limit `m ≥ 0.99` (`None` if none has a mobilisation).
    pub fraction_at_limit: Option<f64>,
}

impl WallStressBin {
    /// Depth of the bin's middle (m).
    pub fn depth(&self) -> f64 {
        0.5 * (self.depth_min + self.depth_max)
    }

    /// Mobilised wall friction `τ / (−σ_nn)` in the bin; `None` without normal stress.
    pub fn friction(&self) -> Option<f64> {
        (self.normal_stress < 0.0).then(|| self.shear_stress / -self.normal_stress)
    }
}

/// Unit direction of a wall, if it has one (lines and segments).
fn wall_direction(w: &WallState) -> Option<Vector> {
    match &w.geometry {
        WallGeometry::Line { normal, .. } => Some(Vector::new(-normal.y, normal.x)),
        WallGeometry::Segment { a, b } => {
            let d = b - a;
            let n = d.norm();
            (n > 0.0).then(|| d / n)
        }
        WallGeometry::Clump { .. } => None,
    }
}

/// Normal and shear stress on the named wall by depth bin (see the module documentation).
/// The bin length along the wall is `Δ / |e_wall · e_down|` for lines and segments, `Δ` for
/// clumps (taken parallel to the depth axis). Fails when the wall is nearly perpendicular to
/// the depth axis (`|e_wall · e_down| < 0.1`).
pub fn wall_stress_profile(
    snapshot: &Snapshot,
    wall: &str,
    bins: &DepthBins,
) -> Result<Vec<WallStressBin>> {
    let contacts = wall_contacts(snapshot, wall)?;
    let w = find_wall(snapshot, wall)?;
    let cos = wall_direction(w).map_or(1.0, |d| d.dot(&bins.axis.down).abs());
    if cos < 0.1 {
        return Err(HomogeniseError::InvalidParameter {
            name: "bins",
            reason: format!("wall `{wall}` is nearly perpendicular to the depth axis"),
        });
    }
    let length = bins.width / cos;
    let k = bins.count;
    let (mut fn_sum, mut ft_sum) = (vec![0.0; k], vec![0.0; k]);
    let (mut n, mut m_n, mut m_sum, mut m_lim) = (
        vec![0usize; k],
        vec![0usize; k],
        vec![0.0; k],
        vec![0usize; k],
    );
    for c in &contacts {
        let Some(b) = bins.bin_of(&c.point) else {
            continue;
        };
        fn_sum[b] += c.force_n / c.thickness;
        ft_sum[b] += (-c.force_on_grain).dot(&bins.axis.down) / c.thickness;
        if c.force_n > 0.0 {
            n[b] += 1;
        }
        if let Some(m) = c.mobilisation {
            m_n[b] += 1;
            m_sum[b] += m;
            if m >= COULOMB_LIMIT {
                m_lim[b] += 1;
            }
        }
    }
    Ok((0..k)
        .map(|b| {
            let (d0, d1) = bins.bounds(b);
            WallStressBin {
                depth_min: d0,
                depth_max: d1,
                length,
                normal_stress: -fn_sum[b] / length,
                shear_stress: ft_sum[b] / length,
                contacts: n[b],
                mean_mobilisation: (m_n[b] > 0).then(|| m_sum[b] / m_n[b] as f64),
                fraction_at_limit: (m_n[b] > 0).then(|| m_lim[b] as f64 / m_n[b] as f64),
            }
        })
        .collect())
}

/// The stress across one horizontal plane (method of planes).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlaneStress {
    /// Height of the plane (m).
    pub y: f64,
    /// Force per unit thickness that the material below exerts on the material above across
    /// the plane, `T` (N/m).
    pub force: Vector,
    /// Width of the sample used `W` (m).
    pub width: f64,
    /// `σ_yy = −T_y / W` (Pa, tension positive).
    pub sigma_yy: f64,
    /// `σ_xy = −T_x / W` (Pa).
    pub sigma_xy: f64,
}

/// Stress across the horizontal planes `y = levels[k]` by the method of planes (see the module
/// documentation). `width` is the sample width `W` (m); by default the periodic cell or the
/// grains' x extent. A branch crosses the plane when one end is at or below (`y ≤ y₀`) and the
/// other above (`y > y₀`): a plane at the surface of a bottom wall sees the wall's reaction.
pub fn plane_stress_profile(
    snapshot: &Snapshot,
    levels: &[f64],
    width: Option<f64>,
) -> Result<Vec<PlaneStress>> {
    check_snapshot(snapshot)?;
    let width = match width {
        Some(w) => positive("width", w)?,
        None => match snapshot.periodic_x {
            Some([a, b]) => b - a,
            None => grain_extent(snapshot)
                .map(|(a, b, _, _)| b - a)
                .ok_or_else(|| HomogeniseError::EmptyRegion("no grains: no width".into()))?,
        },
    };
    let is_grain = |i: u32| snapshot.bodies[i as usize].kind == BodyKind::Grain;
    // branch ends (y of a's end, y of b's end) and the force on b per unit thickness
    let branches: Vec<(f64, f64, Vector)> = snapshot
        .contacts
        .iter()
        .filter(|c| c.force_n != 0.0 || c.force_t != 0.0)
        .map(|c| {
            let ya = if is_grain(c.body_a) {
                c.point.y - c.lever_a.y
            } else {
                c.point.y
            };
            let yb = if is_grain(c.body_b) {
                c.point.y - c.lever_b.y
            } else {
                c.point.y
            };
            let t = if is_grain(c.body_b) {
                snapshot.bodies[c.body_b as usize].thickness
            } else {
                snapshot.bodies[c.body_a as usize].thickness
            };
            (ya, yb, c.force_on_b() / t)
        })
        .collect();
    levels
        .iter()
        .map(|&y0| {
            if !y0.is_finite() {
                return Err(HomogeniseError::InvalidParameter {
                    name: "levels",
                    reason: format!("non-finite level {y0}"),
                });
            }
            let mut t = Vector::zeros();
            for &(ya, yb, f) in &branches {
                if ya <= y0 && yb > y0 {
                    t += f; // b is above: force of the lower (a) on the upper (b)
                } else if yb <= y0 && ya > y0 {
                    t -= f;
                }
            }
            Ok(PlaneStress {
                y: y0,
                force: t,
                width,
                sigma_yy: -t.y / width,
                sigma_xy: -t.x / width,
            })
        })
        .collect()
}

/// What to measure near a wall of a sheared flow.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NearWallSpec {
    /// Name of the wall.
    pub wall: String,
    /// Direction of the flow along the wall (normalised, its normal part removed).
    pub flow_direction: Vector,
    /// Unit normal from the wall into the grains; by default that of a line wall, the segment's
    /// perpendicular on the grains' side, or for a clump the axis direction (±x or ±y) closest
    /// to the direction from the clump's centre to the grains' mean position.
    pub normal: Option<Vector>,
    /// Width of the distance bins (m).
    pub bin_width: f64,
    /// Number of distance bins.
    pub bins: usize,
    /// Grains whose centre is closer than this to the wall surface form the first layer (m);
    /// typically one mean grain diameter (plus the roughness for clumps).
    pub first_layer: f64,
}

/// Near-wall profiles of a sheared flow.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NearWallProfile {
    /// Unit normal into the grains used.
    pub normal: Vector,
    /// Unit flow direction used.
    pub flow_direction: Vector,
    /// Position of the wall surface along the normal `s_w` (m): the line itself, or the
    /// clump disks' outermost point `max_k (c_k · n + r_k)`.
    pub surface: f64,
    /// Centres of the distance bins (m), distance `c_p · n − s_w` of grain centres.
    pub distance: Vec<f64>,
    /// Mass-weighted mean velocity along the flow relative to the wall, per bin (m/s);
    /// `None` for an empty bin.
    pub velocity: Vec<Option<f64>>,
    /// Number of grain centres per bin.
    pub grains: Vec<usize>,
    /// Slip velocity: mass-weighted mean relative flow velocity of the first layer (m/s).
    pub slip_velocity: Option<f64>,
    /// Number of grains in the first layer.
    pub first_layer_grains: usize,
    /// Force of the grains on the wall along the normal, into the wall: `−F · n` (N).
    pub normal_force: f64,
    /// Force of the grains on the wall along the flow `F · e` (N).
    pub tangential_force: f64,
    /// Effective wall friction `τ_w / σ_w = |F · e| / (−F · n)`; `None` without normal force.
    pub effective_friction: Option<f64>,
}

/// Near-wall velocity profile, slip velocity of the first layer and effective friction of the
/// named wall (see [`NearWallSpec`], [`NearWallProfile`]). The wall's velocity at a point `x`
/// is `v_w + ω_w e_z × (x − c_w)` taken at the grain's projection on the wall.
pub fn near_wall_profile(snapshot: &Snapshot, spec: &NearWallSpec) -> Result<NearWallProfile> {
    check_snapshot(snapshot)?;
    positive("bin_width", spec.bin_width)?;
    positive("first_layer", spec.first_layer)?;
    if spec.bins == 0 {
        return Err(HomogeniseError::InvalidParameter {
            name: "bins",
            reason: "needs at least one bin".into(),
        });
    }
    let w = find_wall(snapshot, &spec.wall)?;
    let body = &snapshot.bodies[w.body as usize];
    let grains: Vec<_> = snapshot
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .collect();
    if grains.is_empty() {
        return Err(HomogeniseError::EmptyRegion(
            "no grains near the wall".into(),
        ));
    }
    let mean_grain = grains.iter().map(|b| b.position).sum::<Vector>() / grains.len() as f64;
    let toward = |base: Vector, n: Vector| {
        if (mean_grain - base).dot(&n) < 0.0 {
            -n
        } else {
            n
        }
    };
    let n = match (spec.normal, &w.geometry) {
        (Some(n), _) => n,
        (None, WallGeometry::Line { normal, .. }) => *normal,
        (None, WallGeometry::Segment { a, b }) => toward(*a, Vector::new(a.y - b.y, b.x - a.x)),
        (None, WallGeometry::Clump { .. }) => {
            let d = mean_grain - body.position;
            if d.x.abs() > d.y.abs() {
                Vector::new(d.x.signum(), 0.0)
            } else {
                Vector::new(0.0, d.y.signum())
            }
        }
    };
    let n = unit_normal(n)?;
    let f = spec.flow_direction - n * spec.flow_direction.dot(&n);
    let fnorm = f.norm();
    if !(fnorm.is_finite() && fnorm > 1e-6 * spec.flow_direction.norm()) {
        return Err(HomogeniseError::InvalidParameter {
            name: "flow_direction",
            reason: "must be finite and not along the wall normal".into(),
        });
    }
    let e = f / fnorm;
    let surface = match &w.geometry {
        WallGeometry::Line { point, .. } => point.dot(&n),
        WallGeometry::Segment { a, .. } => a.dot(&n),
        WallGeometry::Clump { centres, radii } => centres
            .iter()
            .zip(radii)
            .map(|(c, r)| c.dot(&n) + r)
            .fold(f64::NEG_INFINITY, f64::max),
    };
    if !surface.is_finite() {
        return Err(HomogeniseError::InvalidParameter {
            name: "wall",
            reason: format!("wall `{}` has no surface (empty clump)", spec.wall),
        });
    }
    let k = spec.bins;
    let (mut mv, mut m, mut count) = (vec![0.0; k], vec![0.0; k], vec![0usize; k]);
    let (mut slip_mv, mut slip_m, mut first) = (0.0, 0.0, 0usize);
    for g in &grains {
        let d = g.position.dot(&n) - surface;
        let proj = g.position - n * d;
        let r = proj - body.position;
        let vw = Twist::new(body.velocity, body.omega).velocity_at(&r);
        let u = (g.velocity - vw).dot(&e);
        if d >= 0.0 && d < spec.first_layer {
            slip_mv += g.mass * u;
            slip_m += g.mass;
            first += 1;
        }
        let b = d / spec.bin_width;
        if b >= 0.0 && b < k as f64 {
            let b = (b.floor() as usize).min(k - 1);
            mv[b] += g.mass * u;
            m[b] += g.mass;
            count[b] += 1;
        }
    }
    let normal_force = -w.force.dot(&n);
    let tangential_force = w.force.dot(&e);
    Ok(NearWallProfile {
        normal: n,
        flow_direction: e,
        surface,
        distance: (0..k).map(|b| (b as f64 + 0.5) * spec.bin_width).collect(),
        velocity: (0..k).map(|b| (m[b] > 0.0).then(|| mv[b] / m[b])).collect(),
        grains: count,
        slip_velocity: (slip_m > 0.0).then(|| slip_mv / slip_m),
        first_layer_grains: first,
        normal_force,
        tangential_force,
        effective_friction: (normal_force > 0.0).then(|| tangential_force.abs() / normal_force),
    })
}
