//! The code-neutral content of one snapshot, and how it becomes a [`Snapshot`].
//!
//! Contact geometry, for a contact whose force on grain `b` is `F` (N):
//! - grain–grain (`a`, `b` grains, centres `c_a`, `c_b`, radii `R_a`, `R_b`): normal
//!   `n = (c_b − c_a)/|c_b − c_a|` (nearest periodic image), gap `g = |c_b − c_a| − R_a − R_b`;
//!   contact point the one the file gives, else the middle of the overlap on the line of centres,
//!   `x = c_b − (R_b + g/2) n`, so that the levers satisfy `(x − c_a) − (x − c_b) = c_b − c_a`
//!   and the Love–Weber sum `Σ_p Σ_α r_α ⊗ (x_α − c_p)` over the two grains is
//!   `−F ⊗ (c_b − c_a)`, the pair virial of the other code, whatever the point;
//! - wall–grain (a line wall through `p` with unit normal `n` pointing to the grain): gap
//!   `g = (c_b − p)·n − R_b`, contact point the file's, else `x = c_b − R_b n` (the point
//!   where codes such as LAMMPS apply the torque).
//!
//! `f_n = F·n`, `f_t = F·t` with `t = (−n_y, n_x)` ([`dem::snapshot::ContactState`]).
//!
//! **Periodic cells** ([`FrameCell`], a LAMMPS box): "nearest periodic image" is the minimum
//! image of the cell's lattice. A cell periodic along both edges (biperiodic, possibly tilted)
//! becomes the snapshot's [`dem::cell::Cell`] (`h = [a₁ a₂]`, corner at the origin: positions
//! are taken relative to the file's corner and wrapped into the cell), its images those of
//! [`dem::cell::Cell::min_image`]; its velocity gradient `L` is the cell's own rate of
//! deformation `L = ḣ h⁻¹` between consecutive snapshots (`h` of the later one and the earlier
//! one with its tilt unwrapped by whole periods, `ḣ = Δh/Δt`, `h` at the middle: exact for a
//! tilt growing linearly, `L_xy = Δxy/(l_y Δt)`), the first snapshot taking the interval with
//! the second; for a single snapshot, or snapshots without times, the mass-weighted affine fit
//! of the grain velocities over the cell ([`homogenise::kinematics::velocity_gradient`]), or
//! zero when the grains are too few or aligned for that fit. [`GradientSource`] says which. A cell periodic along one edge only gives the images along
//! that edge (`x ± l_x`; `x ± a₂`).

use std::collections::HashMap;

use dem::cell::Cell;
use dem::local::ContactStatus;
use dem::math::{Tensor as Mat, Vector};
use dem::snapshot::{BodyKind, BodyState, ContactState, Snapshot, WallGeometry, WallState};
use homogenise::kinematics::{velocity_gradient, VelocityWeight};
use homogenise::Region;

use super::{AccelerationSource, ExternalSnapshot, GradientSource, ReadError, ReadOptions};

/// One grain as a file describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct GrainRecord {
    /// The code's id.
    pub id: u64,
    /// Centre (m).
    pub position: Vector,
    /// Rotation angle (rad), 0 when the file has none.
    pub angle: f64,
    /// Velocity (m/s).
    pub velocity: Vector,
    /// Angular velocity (rad/s).
    pub omega: f64,
    /// Radius (m).
    pub radius: f64,
    /// Mass (kg, per the thickness).
    pub mass: f64,
    /// Moment of inertia (kg·m²).
    pub inertia: f64,
    /// Acceleration and angular acceleration when the file gives them (or forces and torques
    /// that give them).
    pub acceleration: Option<(Vector, f64)>,
}

/// A wall: a line through `point` with unit `normal` pointing to the grains, or a segment.
#[derive(Debug, Clone, PartialEq)]
pub struct WallRecord {
    /// Name (the LAMMPS fix id, the LMGC90 body number, the plain file's name).
    pub name: String,
    /// Geometry.
    pub geometry: WallGeometry,
    /// Reference point (m): the body's centre, where its lever arms start.
    pub position: Vector,
    /// Velocity (m/s).
    pub velocity: Vector,
}

/// The other body of a contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Other {
    /// A grain, by the code's id.
    Grain(u64),
    /// A wall, by its index in [`Frame::walls`].
    Wall(usize),
}

/// A contact: the force `force` (N) that body `a` exerts on grain `b`.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRecord {
    /// Body `a`.
    pub a: Other,
    /// Grain `b`, by id.
    pub b: u64,
    /// Force on `b` (N); `a` receives the opposite.
    pub force: Vector,
    /// Contact point (m) when the file gives it.
    pub point: Option<Vector>,
    /// Unit normal from `a` to `b` when the file gives it (else from the geometry).
    pub normal: Option<Vector>,
}

/// The periodic cell of a frame, as LAMMPS describes its box: the parallelogram with corner
/// `origin` and edges `a₁ = (l_x, 0)`, `a₂ = (xy, l_y)` (m), periodic along `a₁` when
/// `periodic[0]` and along `a₂` when `periodic[1]` (a non-periodic edge only bounds the box).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameCell {
    /// Corner `(x_lo, y_lo)` (m).
    pub origin: Vector,
    /// Length along x `l_x = x_hi − x_lo` (m).
    pub lx: f64,
    /// Height `l_y = y_hi − y_lo` (m).
    pub ly: f64,
    /// Tilt `xy` (m): the x offset of the top edge from the bottom one.
    pub xy: f64,
    /// Periodic along `a₁` (x) and along `a₂`.
    pub periodic: [bool; 2],
}

impl FrameCell {
    /// The cell matrix `h = [a₁ a₂] = [[l_x, xy], [0, l_y]]` (m).
    pub fn matrix(&self) -> Mat {
        Mat::new(self.lx, self.xy, 0.0, self.ly)
    }

    /// Whether the cell is periodic along both edges.
    pub fn biperiodic(&self) -> bool {
        self.periodic == [true, true]
    }
}

/// One snapshot as a reader found it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Frame {
    /// Step index.
    pub step: u64,
    /// Time (s) when known.
    pub time: Option<f64>,
    /// Periodic cell along x, if any (when [`Frame::cell`] is `None`).
    pub periodic_x: Option<[f64; 2]>,
    /// The periodic cell (LAMMPS' box), if the file describes one; it overrides `periodic_x`.
    pub cell: Option<FrameCell>,
    /// The grains.
    pub grains: Vec<GrainRecord>,
    /// The walls.
    pub walls: Vec<WallRecord>,
    /// The contacts.
    pub contacts: Vec<ContactRecord>,
    /// The file(s) read, for messages.
    pub source: String,
}

fn content(source: &str, reason: String) -> ReadError {
    ReadError::Content {
        file: source.to_string(),
        reason,
    }
}

/// The periodic images of a frame.
enum Images {
    None,
    /// Along x with this period (m).
    X(f64),
    /// Along the edge `a₂` (m) alone.
    Edge(Vector),
    /// Biperiodic cell.
    Cell(Cell),
}

impl Images {
    fn of(f: &Frame) -> Result<Self, ReadError> {
        Ok(match (f.cell, f.periodic_x) {
            (Some(c), _) if c.biperiodic() => Images::Cell(cell_of(f, &c, Mat::zeros())?),
            (Some(c), _) if c.periodic[0] => Images::X(c.lx),
            (Some(c), _) if c.periodic[1] => Images::Edge(Vector::new(c.xy, c.ly)),
            (Some(_), _) => Images::None,
            (None, Some([a, b])) => Images::X(b - a),
            (None, None) => Images::None,
        })
    }

    /// `d` mapped to its shortest periodic image.
    fn min(&self, mut d: Vector) -> Vector {
        match self {
            Images::None => d,
            Images::X(l) => {
                d.x -= l * (d.x / l).round();
                d
            }
            Images::Edge(a2) => d - a2 * (d.y / a2.y).round(),
            Images::Cell(c) => c.min_image(&d).0,
        }
    }
}

/// The [`Cell`] of a frame's biperiodic cell with the velocity gradient `l` (1/s).
fn cell_of(f: &Frame, c: &FrameCell, l: Mat) -> Result<Cell, ReadError> {
    Cell::new(c.matrix(), l).map_err(|e| content(&f.source, format!("the periodic cell: {e}")))
}

/// Per grain, the acceleration (m/s²) and angular acceleration (rad/s²).
type Accelerations = Vec<(Vector, f64)>;

/// The time of each frame: the file's, else `step · dt`.
fn times(frames: &[Frame], opts: &ReadOptions) -> Result<Vec<Option<f64>>, ReadError> {
    Ok(frames
        .iter()
        .map(|f| f.time.or_else(|| opts.dt.map(|dt| f.step as f64 * dt)))
        .collect())
}

/// Makes the snapshots of `frames` (sorted by step): bodies (grains in the frame's order,
/// then walls), contacts with their normal, tangential and normal force parts and levers,
/// accelerations from the file or by finite differences (see the module documentation of
/// [`crate::readers`]).
pub fn build_snapshots(
    mut frames: Vec<Frame>,
    opts: &ReadOptions,
) -> Result<Vec<ExternalSnapshot>, ReadError> {
    frames.sort_by_key(|f| f.step);
    let times = times(&frames, opts)?;
    let n = frames.len();
    // Accelerations: file, else finite differences by id, else zero.
    let mut acc: Vec<(Accelerations, AccelerationSource)> = Vec::with_capacity(n);
    for k in 0..n {
        let f = &frames[k];
        if f.grains.iter().all(|g| g.acceleration.is_some()) && !f.grains.is_empty() {
            acc.push((
                f.grains
                    .iter()
                    .map(|g| g.acceleration.unwrap_or_default())
                    .collect(),
                AccelerationSource::File,
            ));
            continue;
        }
        if n < 2 {
            acc.push((
                vec![(Vector::zeros(), 0.0); f.grains.len()],
                AccelerationSource::Zero,
            ));
            continue;
        }
        let (j0, j1, src) = if k > 0 {
            (k - 1, k, AccelerationSource::BackwardDifference)
        } else {
            (0, 1, AccelerationSource::ForwardDifference)
        };
        let (t0, t1) = match (times[j0], times[j1]) {
            (Some(a), Some(b)) => (a, b),
            _ => {
                return Err(content(
                    &f.source,
                    "accelerations by finite difference need the snapshots' times: the file has none (LAMMPS: `dump_modify ID time yes`), give --dt".into(),
                ))
            }
        };
        let h = t1 - t0;
        if h.is_nan() || h <= 0.0 {
            return Err(content(
                &f.source,
                format!(
                    "snapshots at steps {} and {} have the same time: no finite difference",
                    frames[j0].step, frames[j1].step
                ),
            ));
        }
        let before: HashMap<u64, &GrainRecord> =
            frames[j0].grains.iter().map(|g| (g.id, g)).collect();
        let mut a = Vec::with_capacity(f.grains.len());
        for g in &frames[j1].grains {
            let p = before.get(&g.id).ok_or_else(|| {
                content(
                    &frames[j1].source,
                    format!(
                        "grain {} is not in the snapshot of step {}: no finite difference",
                        g.id, frames[j0].step
                    ),
                )
            })?;
            a.push(((g.velocity - p.velocity) / h, (g.omega - p.omega) / h));
        }
        if k == 0 {
            // forward difference: a of frame 1 computed above, keyed by frame 1's order
            let by_id: HashMap<u64, (Vector, f64)> = frames[1]
                .grains
                .iter()
                .zip(&a)
                .map(|(g, v)| (g.id, *v))
                .collect();
            a = f
                .grains
                .iter()
                .map(|g| by_id.get(&g.id).copied().unwrap_or_default())
                .collect();
        }
        acc.push((a, src));
    }
    let dt_all = opts.dt.or_else(|| {
        // the time step from consecutive snapshots' times and steps
        (n >= 2)
            .then(|| match (times[0], times[1]) {
                (Some(a), Some(b)) if frames[1].step > frames[0].step => {
                    Some((b - a) / (frames[1].step - frames[0].step) as f64)
                }
                _ => None,
            })
            .flatten()
    });
    let gradients = cell_gradients(&frames, &times);
    frames
        .into_iter()
        .zip(acc)
        .zip(times)
        .zip(gradients)
        .map(|(((f, (acc, src)), time), gradient)| {
            let extras = FrameExtras {
                acc,
                src,
                time,
                dt: dt_all,
                gradient,
            };
            build_one(f, extras, opts)
        })
        .collect()
}

/// The velocity gradient `L = ḣ h⁻¹` (1/s) of each frame's biperiodic cell from the cell's
/// deformation between consecutive frames (module documentation): the interval ending at the
/// frame, the first frame taking the one after it; `None` for a frame without a biperiodic
/// cell, and for every frame when there is a single frame or a time is unknown (the velocity
/// profile then gives `L`, [`build_one`]).
fn cell_gradients(frames: &[Frame], times: &[Option<f64>]) -> Vec<Option<Mat>> {
    let n = frames.len();
    let cells: Vec<Option<FrameCell>> = frames
        .iter()
        .map(|f| f.cell.filter(FrameCell::biperiodic))
        .collect();
    if n < 2 || times.iter().any(Option::is_none) {
        return vec![None; n];
    }
    let rate = |j0: usize, j1: usize| -> Option<Mat> {
        let (c0, c1) = (cells[j0]?, cells[j1]?);
        let (t0, t1) = (times[j0]?, times[j1]?);
        let dt = t1 - t0;
        if !(dt > 0.0 && dt.is_finite()) {
            return None;
        }
        // a flip of the tilt between the two (LAMMPS' `fix deform ... flip yes`) moves a₂ by a
        // whole a₁: undone on the earlier cell
        let mut h0 = c0.matrix();
        let h1 = c1.matrix();
        let m = ((h1[(0, 1)] - h0[(0, 1)]) / c0.lx).round();
        h0[(0, 1)] += m * c0.lx;
        let mid = (h0 + h1) * 0.5;
        let inv = mid.try_inverse()?;
        let l = (h1 - h0) / dt * inv;
        l.iter().all(|v| v.is_finite()).then_some(l)
    };
    (0..n)
        .map(|k| {
            cells[k]?;
            if k == 0 {
                rate(0, 1)
            } else {
                rate(k - 1, k)
            }
        })
        .collect()
}

/// Moves a frame with a biperiodic cell to the cell's frame: every position relative to the
/// cell's corner, grain centres wrapped into the cell (their velocities unchanged: LAMMPS'
/// `remap v` velocities are those of the wrapped atom).
fn to_cell_frame(f: &mut Frame, c: &FrameCell) -> Result<(), ReadError> {
    let cell = cell_of(f, c, Mat::zeros())?;
    let o = c.origin;
    for g in &mut f.grains {
        g.position = cell.wrap(&(g.position - o)).0;
    }
    for w in &mut f.walls {
        w.position -= o;
        match &mut w.geometry {
            WallGeometry::Line { point, .. } => *point -= o,
            WallGeometry::Segment { a, b } => {
                *a -= o;
                *b -= o;
            }
            WallGeometry::Clump { centres, .. } => centres.iter_mut().for_each(|p| *p -= o),
        }
    }
    for ct in &mut f.contacts {
        if let Some(p) = &mut ct.point {
            *p -= o;
        }
    }
    Ok(())
}

/// What [`build_one`] adds to a frame: its accelerations, their source, its time, the time
/// step and the velocity gradient of its cell.
struct FrameExtras {
    /// `(a, α)` per grain, in the frame's order.
    acc: Vec<(Vector, f64)>,
    /// Where the accelerations come from.
    src: AccelerationSource,
    /// The frame's time (s), when known.
    time: Option<f64>,
    /// The time step (s), when known.
    dt: Option<f64>,
    /// The velocity gradient from the cell's deformation, when known.
    gradient: Option<Mat>,
}

/// The bodies of a frame: grains first, then walls.
struct FrameBodies {
    /// Body index of each grain id.
    index: HashMap<u64, u32>,
    /// The bodies.
    bodies: Vec<BodyState>,
    /// Index of the first wall in `bodies`.
    first_wall: usize,
}

/// The force and torque `(F, T)` the contacts exert on a wall.
type WallLoad = (Vector, f64);

/// Where a contact acts, from the record or the geometry.
struct ContactGeometry {
    /// Body `a`'s index.
    ia: u32,
    /// Unit normal from `a` to `b`.
    normal: Vector,
    /// Gap (m), `NaN` when the record gives the normal of a wall contact.
    gap: f64,
    /// Contact point (m).
    point: Vector,
}

/// Builds the snapshot of frame `f`: the frame moved to its cell's frame (biperiodic cell) →
/// the bodies → the contacts and the walls' forces → the snapshot with its cell and velocity
/// gradient (from the cell's deformation, else fitted to the grains' velocities).
fn build_one(
    mut f: Frame,
    extras: FrameExtras,
    opts: &ReadOptions,
) -> Result<ExternalSnapshot, ReadError> {
    let biperiodic = f.cell.filter(FrameCell::biperiodic);
    if let Some(c) = &biperiodic {
        to_cell_frame(&mut f, c)?;
    }
    let images = Images::of(&f)?;
    let fb = frame_bodies(&f, &extras.acc)?;
    let (contacts, wall_force) = frame_contacts(&f, &fb, &images, opts)?;
    let walls = f
        .walls
        .iter()
        .enumerate()
        .map(|(k, w)| WallState {
            body: (fb.first_wall + k) as u32,
            name: w.name.clone(),
            geometry: w.geometry.clone(),
            force: wall_force[k].0,
            torque: wall_force[k].1,
        })
        .collect();
    let grain_ids = f.grains.iter().map(|g| g.id).collect();
    let periodic_x = match f.cell {
        Some(c) if c.periodic == [true, false] => Some([c.origin.x, c.origin.x + c.lx]),
        Some(_) => None,
        None => f.periodic_x,
    };
    let cell = match &biperiodic {
        Some(c) => Some(cell_of(&f, c, extras.gradient.unwrap_or_else(Mat::zeros))?),
        None => None,
    };
    let mut snapshot = Snapshot {
        step: f.step,
        time: extras.time.unwrap_or(f.step as f64),
        dt: extras
            .dt
            .filter(|d| *d > 0.0 && d.is_finite())
            .unwrap_or(1.0),
        gravity: Vector::new(opts.gravity[0], opts.gravity[1]),
        periodic_x,
        cell,
        bodies: fb.bodies,
        contacts,
        walls,
    };
    let velocity_gradient = match (&biperiodic, extras.gradient) {
        (None, _) => None,
        (Some(_), Some(_)) => Some(GradientSource::CellDeformation),
        (Some(c), None) => Some(fit_cell_gradient(&f, c, &mut snapshot)?),
    };
    Ok(ExternalSnapshot {
        snapshot,
        grain_ids,
        accelerations: extras.src,
        velocity_gradient,
        source: f.source,
    })
}

/// Sets the cell's velocity gradient of `snapshot` to the mass-weighted affine fit of the
/// grain velocities over the cell, when the grains determine it (else leaves it zero).
fn fit_cell_gradient(
    f: &Frame,
    c: &FrameCell,
    snapshot: &mut Snapshot,
) -> Result<GradientSource, ReadError> {
    Ok(
        match velocity_gradient(snapshot, &Region::Whole, VelocityWeight::Mass) {
            Ok(fit) => {
                snapshot.cell = Some(cell_of(f, c, fit.gradient)?);
                GradientSource::VelocityProfile
            }
            Err(_) => GradientSource::Zero,
        },
    )
}

/// The bodies of `f`: its grains (with accelerations `acc`; ids unique, radius, mass and
/// inertia positive), then its walls (fixed: infinite mass).
fn frame_bodies(f: &Frame, acc: &[(Vector, f64)]) -> Result<FrameBodies, ReadError> {
    let mut index: HashMap<u64, u32> = HashMap::with_capacity(f.grains.len());
    let mut bodies = Vec::with_capacity(f.grains.len() + f.walls.len());
    for (g, (a, w)) in f.grains.iter().zip(acc) {
        if index.insert(g.id, bodies.len() as u32).is_some() {
            return Err(content(
                &f.source,
                format!("grain id {} appears twice", g.id),
            ));
        }
        for (what, v) in [
            ("radius", g.radius),
            ("mass", g.mass),
            ("inertia", g.inertia),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(content(
                    &f.source,
                    format!("grain {}: {what} must be > 0, got {v}", g.id),
                ));
            }
        }
        let thickness = 1.0;
        bodies.push(BodyState {
            kind: BodyKind::Grain,
            name: String::new(),
            position: g.position,
            angle: g.angle,
            velocity: g.velocity,
            omega: g.omega,
            acceleration: *a,
            angular_acceleration: *w,
            mass: g.mass,
            inertia: g.inertia,
            radius: g.radius,
            density: g.mass / (std::f64::consts::PI * g.radius * g.radius * thickness),
            thickness,
        });
    }
    let first_wall = bodies.len();
    for w in &f.walls {
        bodies.push(BodyState::wall(&w.name, w.position, w.velocity));
    }
    Ok(FrameBodies {
        index,
        bodies,
        first_wall,
    })
}

/// The contacts of `f` (force split into normal and tangential parts, status from the
/// friction coefficient of `opts`) and the force and torque `(F, T)` the contacts exert on
/// each wall.
fn frame_contacts(
    f: &Frame,
    fb: &FrameBodies,
    images: &Images,
    opts: &ReadOptions,
) -> Result<(Vec<ContactState>, Vec<WallLoad>), ReadError> {
    let grain_mu = opts.mu.unwrap_or(0.0);
    let wall_mu = opts.wall_mu.or(opts.mu).unwrap_or(0.0);
    let mut contacts = Vec::with_capacity(f.contacts.len());
    let mut wall_force = vec![(Vector::zeros(), 0.0); f.walls.len()];
    for c in &f.contacts {
        let ib = *fb.index.get(&c.b).ok_or_else(|| {
            content(
                &f.source,
                format!(
                    "a contact names grain {}, which is not in the snapshot",
                    c.b
                ),
            )
        })?;
        let ContactGeometry {
            ia,
            normal,
            gap,
            point,
        } = match c.a {
            Other::Grain(id) => grain_contact_geometry(f, c, id, ib, fb, images)?,
            Other::Wall(k) => wall_contact_geometry(f, c, k, ib, fb)?,
        };
        if (normal.norm() - 1.0).abs() > 1e-6 {
            return Err(content(
                &f.source,
                format!("contact on grain {}: the normal is not a unit vector", c.b),
            ));
        }
        let t = Vector::new(-normal.y, normal.x);
        let (fn_, ft) = (c.force.dot(&normal), c.force.dot(&t));
        let ca = fb.bodies[ia as usize].position;
        let cb = fb.bodies[ib as usize].position;
        let lever_a = images.min(point - ca);
        let lever_b = images.min(point - cb);
        let mu = match c.a {
            Other::Grain(_) => grain_mu,
            Other::Wall(_) => wall_mu,
        };
        let status = if fn_ == 0.0 && ft == 0.0 {
            ContactStatus::Open
        } else if mu > 0.0 && ft.abs() >= 0.999 * mu * fn_ {
            ContactStatus::Slide
        } else {
            ContactStatus::Stick
        };
        if let Other::Wall(k) = c.a {
            wall_force[k].0 -= c.force;
            wall_force[k].1 -= lever_a.x * c.force.y - lever_a.y * c.force.x;
        }
        contacts.push(ContactState {
            body_a: ia,
            body_b: ib,
            point,
            normal,
            force_n: fn_,
            force_t: ft,
            gap: if gap.is_finite() { gap } else { 0.0 },
            mu,
            status,
            lever_a,
            lever_b,
        });
    }
    Ok((contacts, wall_force))
}

/// The geometry of contact `c` between grain `id` and grain `c.b` (body `ib`): the normal
/// from the record or the nearest image of the centres, the gap, the point (the record's, or
/// mid-gap on the line of centres).
fn grain_contact_geometry(
    f: &Frame,
    c: &ContactRecord,
    id: u64,
    ib: u32,
    fb: &FrameBodies,
    images: &Images,
) -> Result<ContactGeometry, ReadError> {
    let gb = &fb.bodies[ib as usize];
    let (cb, rb) = (gb.position, gb.radius);
    let ia = *fb.index.get(&id).ok_or_else(|| {
        content(
            &f.source,
            format!("a contact names grain {id}, which is not in the snapshot"),
        )
    })?;
    if ia == ib {
        return Err(content(
            &f.source,
            format!("grain {id} in contact with itself"),
        ));
    }
    let ga = &fb.bodies[ia as usize];
    let d = images.min(cb - ga.position);
    let dist = d.norm();
    let normal = match c.normal {
        Some(n) => n,
        None if dist > 0.0 => d / dist,
        None => {
            return Err(content(
                &f.source,
                format!("grains {id} and {} have the same centre: no normal", c.b),
            ))
        }
    };
    let gap = dist - ga.radius - rb;
    let point = c.point.unwrap_or(cb - normal * (rb + 0.5 * gap));
    Ok(ContactGeometry {
        ia,
        normal,
        gap,
        point,
    })
}

/// The geometry of contact `c` between wall `k` and grain `c.b` (body `ib`): the normal from
/// the record (gap unknown) or the wall's line or segment, the point (the record's, or on the
/// grain's surface).
fn wall_contact_geometry(
    f: &Frame,
    c: &ContactRecord,
    k: usize,
    ib: u32,
    fb: &FrameBodies,
) -> Result<ContactGeometry, ReadError> {
    let gb = &fb.bodies[ib as usize];
    let (cb, rb) = (gb.position, gb.radius);
    let w = f.walls.get(k).ok_or_else(|| {
        content(
            &f.source,
            format!("a contact names wall {k}, which does not exist"),
        )
    })?;
    let (normal, gap) = match (&w.geometry, c.normal) {
        (_, Some(n)) => (n, f64::NAN),
        (WallGeometry::Line { point, normal }, None) => {
            let s = (cb - point).dot(normal);
            (normal * s.signum(), s.abs() - rb)
        }
        (WallGeometry::Segment { a, b }, None) => {
            let e = b - a;
            let t = ((cb - a).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
            let d = cb - (a + e * t);
            let dist = d.norm();
            if dist == 0.0 {
                return Err(content(
                    &f.source,
                    format!("grain {} centred on wall `{}`", c.b, w.name),
                ));
            }
            (d / dist, dist - rb)
        }
        (WallGeometry::Clump { .. }, None) => {
            return Err(content(
                &f.source,
                "clump walls need the contact normal".into(),
            ))
        }
    };
    Ok(ContactGeometry {
        ia: (fb.first_wall + k) as u32,
        normal,
        gap,
        point: c.point.unwrap_or(cb - normal * rb),
    })
}
