//! Contact detection in O(N): a uniform cell grid over the disks (cell side ≥ the largest
//! diameter plus the detection gap, periodic along x when asked), each disk tested against the
//! disks of its 3×3 neighbourhood, and every line or segment tested against every disk.
//!
//! A contact is created for every pair whose gap is at most the detection gap `g_d`:
//! `g = |c_b − c_a| − R_a − R_b` for two disks, `g = (c − p)·n − R` for a line, and the distance
//! to the closest point minus `R` for a segment. Contacts come out sorted by the collider pair
//! key `(collider_a << 32) | collider_b` (a is the wall or the disk of lower index), so that the
//! next step can warm start by a linear merge.

use nalgebra::Vector2;

use crate::body::{Body, BodyKind};
use crate::cell::{Cell, Vect};
use crate::collider::{rotate, Collider, Shape};
use crate::contact::{ContactGeometry, ContactRow, ContactSet, CLOSED_GAP};
use crate::error::DemError;
use crate::local::ContactStatus;
use crate::material::ContactLaws;

/// Periodic cell along x, `[x_min, x_max)` (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Periodic {
    /// Lower bound (m).
    pub x_min: f64,
    /// Length L (m).
    pub length: f64,
}

impl Periodic {
    /// Wrap `x` into `[x_min, x_min + L)`.
    #[inline]
    pub fn wrap(&self, x: f64) -> f64 {
        let w = self.x_min + (x - self.x_min).rem_euclid(self.length);
        if w >= self.x_min + self.length {
            self.x_min
        } else {
            w
        }
    }

    /// Minimum-image difference along x.
    #[inline]
    pub fn min_image(&self, dx: f64) -> f64 {
        dx - self.length * (dx / self.length).round()
    }
}

/// Reusable detection buffers (kept between steps so that detection allocates nothing in the
/// steady state).
#[derive(Debug, Default, Clone)]
pub struct Detector {
    disk_collider: Vec<u32>,
    centre: Vec<[f64; 2]>,
    radius: Vec<f64>,
    margin: Vec<f64>,
    cell_of: Vec<u32>,
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
    neighbours: Vec<(u32, u32)>,
    fill: Vec<u32>,
    fast: Vec<u32>,
    reduced: Vec<[f64; 2]>,
    /// The change of a biperiodic cell's `L` within the step that the last detection's swept
    /// margins cover (1/s; [`Detector::detect_cell`]'s `rate_bound`, capped).
    image_rate: f64,
}

/// A line or segment in world coordinates.
enum WallShape {
    Line { p: Vector2<f64>, n: Vector2<f64> },
    Segment { a: Vector2<f64>, b: Vector2<f64> },
}

impl Detector {
    /// Detect all contacts that may close during a step of length `dt` and fill `out` (cleared
    /// first), with geometry, Delassus blocks and friction; impulses are zero.
    ///
    /// A pair becomes a contact when its gap is at most `detection_gap + m_a + m_b`, with the
    /// swept margin of a body `m = dt (|v| + dt |g| + |ω| ρ)` (ρ the distance of the shape from
    /// the body's centre): a grain moving several detection gaps per step is still caught before
    /// it overlaps. Pass `dt = 0` for a purely geometric test.
    #[allow(clippy::too_many_arguments)]
    pub fn detect(
        &mut self,
        bodies: &[Body],
        inv_mass: &[[f64; 3]],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        detection_gap: f64,
        dt: f64,
        gravity: f64,
        out: &mut ContactSet,
    ) -> Result<(), DemError> {
        out.clear();
        self.collect_disks(bodies, colliders, periodic, dt, gravity);
        let nd = self.centre.len();
        let mut max_d = 0.0f64;
        let mut max_m = 0.0f64;
        for (&r, &m) in self.radius.iter().zip(&self.margin) {
            max_d = max_d.max(2.0 * r);
            max_m = max_m.max(m);
        }
        // Cells are sized on geometry, the detection gap and a swept margin capped at one
        // diameter; the few disks moving farther than that in one step ("fast") are tested
        // against every disk, so one ejected grain does not coarsen the whole grid.
        let margin_cap = max_m.min(max_d);
        let mut cell = max_d + detection_gap.max(0.0) + 2.0 * margin_cap;
        if cell.is_nan() || cell <= 0.0 {
            cell = 1.0;
        }
        self.fast.clear();
        self.fast
            .extend((0..nd as u32).filter(|&d| self.margin[d as usize] > margin_cap));
        // Grid extent.
        let (mut xmin, mut xmax, mut ymin, mut ymax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for c in &self.centre {
            xmin = xmin.min(c[0]);
            xmax = xmax.max(c[0]);
            ymin = ymin.min(c[1]);
            ymax = ymax.max(c[1]);
        }
        if nd == 0 {
            (xmin, xmax, ymin, ymax) = (0.0, 1.0, 0.0, 1.0);
        }
        // Keep the number of cells O(N) even if one grain flies far away (counts computed in
        // f64 and capped before any integer conversion).
        let cap = 4 * nd + 64;
        let count = |extent: f64, size: f64, max: usize| -> usize {
            let n = (extent / size).floor() + 1.0;
            if n.is_finite() && n >= 1.0 {
                (n.min(max as f64)) as usize
            } else if n.is_finite() {
                1
            } else {
                max
            }
        };
        let (ncx, cx_size) = match periodic {
            Some(p) => {
                let n = (p.length / cell).floor();
                if n.is_nan() || n < 3.0 {
                    return Err(DemError::Parameter {
                        name: "periodic_x".into(),
                        reason: format!(
                            "the periodic length {} m must be at least 3 times the largest \
                             diameter plus the detection gap ({} m)",
                            p.length, cell
                        ),
                    });
                }
                let n = (n.min(cap as f64)) as usize;
                xmin = p.x_min;
                (n, p.length / n as f64)
            }
            None => {
                let n = count(xmax - xmin, cell, cap).max(1);
                (n, ((xmax - xmin) / n as f64).max(cell))
            }
        };
        let ncy = count(ymax - ymin, cell, (cap / ncx).max(1)).max(1);
        let cy_size = ((ymax - ymin) / ncy as f64).max(cell) * (1.0 + 1e-12);
        let ncells = ncx * ncy;
        // Counting sort of disks into cells.
        self.cell_of.clear();
        self.cell_start.clear();
        self.cell_start.resize(ncells + 1, 0);
        for c in &self.centre {
            let ix =
                (((c[0] - xmin) / cx_size).floor() as isize).clamp(0, ncx as isize - 1) as usize;
            let iy =
                (((c[1] - ymin) / cy_size).floor() as isize).clamp(0, ncy as isize - 1) as usize;
            let id = (iy * ncx + ix) as u32;
            self.cell_of.push(id);
            self.cell_start[id as usize + 1] += 1;
        }
        for i in 0..ncells {
            self.cell_start[i + 1] += self.cell_start[i];
        }
        self.cell_items.clear();
        self.cell_items.resize(nd, 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.cell_start[..ncells]);
        for (d, &cid) in self.cell_of.iter().enumerate() {
            self.cell_items[self.fill[cid as usize] as usize] = d as u32;
            self.fill[cid as usize] += 1;
        }

        // Ordered outer loop over colliders: disks find higher disks in the grid, walls find
        // every disk, so keys come out sorted.
        let mut disk_pos = 0usize;
        for (ci, col) in colliders.iter().enumerate() {
            match col.shape {
                Shape::Disk { .. } => {
                    let d = disk_pos;
                    disk_pos += 1;
                    let cid = self.cell_of[d] as usize;
                    let (ix, iy) = ((cid % ncx) as isize, (cid / ncx) as isize);
                    let mut around = [None; 9];
                    for (k, slot) in around.iter_mut().enumerate() {
                        let jy = iy + k as isize / 3 - 1;
                        let mut jx = ix + k as isize % 3 - 1;
                        if periodic.is_some() {
                            jx = jx.rem_euclid(ncx as isize);
                        }
                        if (0..ncy as isize).contains(&jy) && (0..ncx as isize).contains(&jx) {
                            *slot = Some(jy as usize * ncx + jx as usize);
                        }
                    }
                    self.gather_neighbours(d, nd, &around);
                    for k in 0..self.neighbours.len() {
                        let (cj, e) = self.neighbours[k];
                        self.disk_disk(
                            bodies,
                            inv_mass,
                            colliders,
                            laws,
                            periodic,
                            detection_gap,
                            ci as u32,
                            d,
                            cj,
                            e as usize,
                            out,
                        );
                    }
                }
                Shape::Line { .. } | Shape::Segment { .. } => {
                    let wb = &bodies[col.body as usize];
                    let extent = match &col.shape {
                        Shape::Segment { a, b } => a.norm().max(b.norm()),
                        Shape::Line { point, .. } => point.norm(),
                        Shape::Disk { .. } => 0.0,
                    };
                    // Swept margin of the wall, with its acceleration bound (gravity plus the
                    // applied force per unit mass) as for disks: a pressure-driven wall that
                    // starts at rest would otherwise miss the grains it reaches in the step.
                    let acc = if wb.mass > 0.0 && wb.mass.is_finite() {
                        wb.applied_force.norm() / wb.mass + if wb.gravity { gravity } else { 0.0 }
                    } else {
                        0.0
                    };
                    let wall_margin =
                        dt * (wb.velocity.norm() + dt * acc + wb.omega.abs() * extent);
                    let shape = match &col.shape {
                        Shape::Line { point, normal } => WallShape::Line {
                            p: wb.position + rotate(*point, wb.angle),
                            n: rotate(*normal, wb.angle).normalize(),
                        },
                        Shape::Segment { a, b } => WallShape::Segment {
                            a: wb.position + rotate(*a, wb.angle),
                            b: wb.position + rotate(*b, wb.angle),
                        },
                        Shape::Disk { .. } => unreachable!(),
                    };
                    for e in 0..nd {
                        self.wall_disk(
                            bodies,
                            inv_mass,
                            colliders,
                            laws,
                            periodic,
                            detection_gap + wall_margin + self.margin[e],
                            ci as u32,
                            &shape,
                            e,
                            out,
                        );
                    }
                }
            }
        }
        Ok(())
    }

    fn collect_disks(
        &mut self,
        bodies: &[Body],
        colliders: &[Collider],
        periodic: Option<Periodic>,
        dt: f64,
        gravity: f64,
    ) {
        self.disk_collider.clear();
        self.centre.clear();
        self.radius.clear();
        self.margin.clear();
        for (ci, col) in colliders.iter().enumerate() {
            if let Shape::Disk { radius, offset } = col.shape {
                let b = &bodies[col.body as usize];
                let mut c = b.position + rotate(offset, b.angle);
                if let Some(p) = periodic {
                    c.x = p.wrap(c.x);
                }
                self.disk_collider.push(ci as u32);
                self.centre.push([c.x, c.y]);
                self.radius.push(radius);
                // Acceleration bound: gravity plus the applied force per unit mass.
                let g = if b.gravity { gravity } else { 0.0 };
                let f = if b.mass > 0.0 && b.mass.is_finite() {
                    b.applied_force.norm() / b.mass
                } else {
                    0.0
                };
                self.margin
                    .push(dt * (b.velocity.norm() + dt * (g + f) + b.omega.abs() * offset.norm()));
            }
        }
    }

    /// The change of a biperiodic cell's velocity gradient within a step (1/s, sum of the
    /// magnitudes of its components, which bounds `|δ (h k)|/(|a₁| + |a₂|)` for `k ∈ {−1, 0, 1}²`)
    /// that the swept margins of the last [`Detector::detect_cell`] cover: an implicit cell that
    /// changed `L` by more may have moved an image into a disk no contact knew.
    pub fn image_rate(&self) -> f64 {
        self.image_rate
    }

    /// Whether some disk moved, over a step whose contacts the last [`Detector::detect`] found,
    /// farther than the swept margin that detection allowed it (`displacement` per body,
    /// `[Δx, Δy, Δθ]`): a disk kicked by a contact impulse can travel beyond the bound its
    /// velocity and loads gave at the start of the step, and then meet a disk no contact of the
    /// step knew about.
    pub fn outran(&self, colliders: &[Collider], displacement: &[[f64; 3]]) -> bool {
        self.disk_collider
            .iter()
            .zip(&self.margin)
            .any(|(&ci, &m)| {
                let col = &colliders[ci as usize];
                let d = displacement[col.body as usize];
                let arm = match col.shape {
                    Shape::Disk { offset, .. } => offset.norm(),
                    _ => 0.0,
                };
                d[0].hypot(d[1]) + d[2].abs() * arm > m
            })
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn disk_disk(
        &self,
        bodies: &[Body],
        inv_mass: &[[f64; 3]],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        gap_max: f64,
        ci: u32,
        di: usize,
        cj: u32,
        dj: usize,
        out: &mut ContactSet,
    ) {
        let (ca, cb) = (&colliders[ci as usize], &colliders[cj as usize]);
        if ca.body == cb.body {
            return;
        }
        let (ba, bb) = (ca.body as usize, cb.body as usize);
        if bodies[ba].is_kinematic() && bodies[bb].is_kinematic() {
            return;
        }
        let (pa, pb) = (self.centre[di], self.centre[dj]);
        let mut dx = pb[0] - pa[0];
        if let Some(p) = periodic {
            dx = p.min_image(dx);
        }
        let dy = pb[1] - pa[1];
        let (ra, rb) = (self.radius[di], self.radius[dj]);
        let reach = ra + rb + gap_max + self.margin[di] + self.margin[dj];
        let d2 = dx * dx + dy * dy;
        if d2 > reach * reach {
            return;
        }
        let dist = d2.sqrt();
        // Coincident centres: a full overlap with an arbitrary normal, so that validation
        // reports it and the solver keeps them from approaching further.
        let n = if dist > 0.0 {
            Vector2::new(dx / dist, dy / dist)
        } else {
            Vector2::new(0.0, 1.0)
        };
        let gap = dist - ra - rb;
        // Contact point on the surface of b; levers from the bodies' centres of mass.
        let off_a = disk_offset(&bodies[ba], ca);
        let off_b = disk_offset(&bodies[bb], cb);
        let lever_b = -n * rb + off_b;
        let lever_a = Vector2::new(dx, dy) - n * rb + off_a;
        let point = Vector2::new(pb[0], pb[1]) - n * rb;
        push_contact(
            out,
            inv_mass,
            laws,
            ca,
            cb,
            ci,
            cj,
            ba,
            bb,
            n,
            point,
            lever_a,
            lever_b,
            gap,
            CLOSED_GAP * ra.min(rb),
            Image::NONE,
        );
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn wall_disk(
        &self,
        bodies: &[Body],
        inv_mass: &[[f64; 3]],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        gap_max: f64,
        cw: u32,
        shape: &WallShape,
        e: usize,
        out: &mut ContactSet,
    ) {
        let cj = self.disk_collider[e];
        let (ca, cb) = (&colliders[cw as usize], &colliders[cj as usize]);
        let (ba, bb) = (ca.body as usize, cb.body as usize);
        if ba == bb || (bodies[ba].is_kinematic() && bodies[bb].is_kinematic()) {
            return;
        }
        let c = Vector2::new(self.centre[e][0], self.centre[e][1]);
        let r = self.radius[e];
        let (n, gap) = match *shape {
            WallShape::Line { p, n } => {
                let mut d = c - p;
                if let Some(per) = periodic {
                    d.x = per.min_image(d.x);
                }
                (n, d.dot(&n) - r)
            }
            WallShape::Segment { a, b } => {
                let ab = b - a;
                let l2 = ab.norm_squared();
                // With a periodic x, the nearest of the disk's images (a segment may be longer
                // than half the cell).
                let shifts: &[f64] = match periodic {
                    Some(per) => &[0.0, per.length, -per.length],
                    None => &[0.0],
                };
                let mut d = Vector2::new(f64::INFINITY, 0.0);
                for &sx in shifts {
                    let ac = c + Vector2::new(sx, 0.0) - a;
                    let s = if l2 > 0.0 {
                        (ac.dot(&ab) / l2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let di = ac - ab * s;
                    if di.norm_squared() < d.norm_squared() {
                        d = di;
                    }
                }
                let dist = d.norm();
                if dist - r > gap_max {
                    return;
                }
                let n = if dist > 0.0 {
                    d / dist
                } else {
                    Vector2::new(-ab.y, ab.x).normalize()
                };
                (n, dist - r)
            }
        };
        if gap > gap_max {
            return;
        }
        let point = c - n * r;
        let off_b = disk_offset(&bodies[bb], cb);
        let lever_b = -n * r + off_b;
        let mut lever_a = point - bodies[ba].position;
        if let Some(per) = periodic {
            lever_a.x = per.min_image(lever_a.x);
        }
        push_contact(
            out,
            inv_mass,
            laws,
            ca,
            cb,
            cw,
            cj,
            ba,
            bb,
            n,
            point,
            lever_a,
            lever_b,
            gap,
            CLOSED_GAP * r,
            Image::NONE,
        );
    }
}

#[inline]
fn disk_offset(b: &Body, c: &Collider) -> Vector2<f64> {
    match c.shape {
        Shape::Disk { offset, .. } => rotate(offset, b.angle),
        _ => Vector2::zeros(),
    }
}

/// The periodic image of `b` a contact sees: its shift vector `h k` (m) and the affine
/// velocity `L h k` (m/s) it moves with relative to `b` ([`crate::cell`]).
#[derive(Debug, Clone, Copy)]
struct Image {
    shift: Vector2<f64>,
    velocity: Vector2<f64>,
}

impl Image {
    const NONE: Image = Image {
        shift: Vector2::new(0.0, 0.0),
        velocity: Vector2::new(0.0, 0.0),
    };
}

#[allow(clippy::too_many_arguments)]
#[inline]
fn push_contact(
    out: &mut ContactSet,
    inv_mass: &[[f64; 3]],
    laws: &ContactLaws,
    ca: &Collider,
    cb: &Collider,
    ci: u32,
    cj: u32,
    ba: usize,
    bb: usize,
    n: Vector2<f64>,
    point: Vector2<f64>,
    lever_a: Vector2<f64>,
    lever_b: Vector2<f64>,
    gap: f64,
    closed_gap: f64,
    image: Image,
) {
    let t = Vector2::new(-n.y, n.x);
    let cross = |r: Vector2<f64>, v: Vector2<f64>| r.x * v.y - r.y * v.x;
    let k = [
        cross(lever_a, n),
        cross(lever_a, t),
        cross(lever_b, n),
        cross(lever_b, t),
    ];
    let nn = [n.x, n.y];
    let w = ContactRow::delassus(nn, k, &inv_mass[ba], &inv_mass[bb]);
    out.rows.push(ContactRow {
        a: ba as u32,
        b: bb as u32,
        n: nn,
        k,
        w,
        shift: 0.0,
        // −0.0 without an image: `x + (−0.0)` is `x` bit for bit (also for x = −0.0), so the
        // relative velocities of walls and the x-periodic cell are unchanged by the term.
        affine: if image.shift == Vector2::zeros() {
            [-0.0, -0.0]
        } else {
            [n.dot(&image.velocity), t.dot(&image.velocity)]
        },
        mu: laws.friction(ca.material, cb.material),
        r: [0.0, 0.0],
        basis: 0,
    });
    out.geometry.push(ContactGeometry {
        key: ((ci as u64) << 32) | cj as u64,
        point: [point.x, point.y],
        gap,
        lever_a: [lever_a.x, lever_a.y],
        lever_b: [lever_b.x, lever_b.y],
        restitution: laws.restitution(ca.material, cb.material),
        closed_gap,
        image: [image.shift.x, image.shift.y],
    });
    out.status.push(ContactStatus::Open);
}

impl Detector {
    /// Detection in a biperiodic deformable cell ([`crate::cell`]), in O(N): every disk is
    /// wrapped into the cell and binned on a grid of `n₁ × n₂` bins in reduced coordinates,
    /// `n_d = ⌊w_d / c⌋` with `w_d` the cell's width across faces ([`Cell::widths`]) and `c`
    /// the cut-off (largest diameter, detection gap and swept margins), so that two disks within
    /// `c` of each other (through any image) lie in neighbouring bins, the grid wrapping in both
    /// directions; each pair takes its shortest image ([`Cell::min_image`]). A contact with an
    /// image `x_b + h k` carries the image's shift vector `h k` and affine velocity `L h k`
    /// ([`crate::contact::ContactRow::affine`]).
    ///
    /// The swept margin of a disk is `m = dt (|v − L (x − c)| + dt |a| + |ω| ρ) + dt ‖L‖ r`
    /// with `r = R_max + g_d/2`: its velocity relative to the affine field, plus half the affine
    /// velocity difference across the largest pair, so that `m_a + m_b` bounds the pair's
    /// relative travel. Only disk grains are allowed (no walls in a periodic cell); the cell
    /// must be at least 3 cut-offs wide across both pairs of faces.
    #[allow(clippy::too_many_arguments)]
    pub fn detect_cell(
        &mut self,
        bodies: &[Body],
        inv_mass: &[[f64; 3]],
        colliders: &[Collider],
        laws: &ContactLaws,
        cell: &Cell,
        detection_gap: f64,
        dt: f64,
        rate_bound: f64,
        out: &mut ContactSet,
    ) -> Result<(), DemError> {
        out.clear();
        self.disk_collider.clear();
        self.centre.clear();
        self.radius.clear();
        self.margin.clear();
        self.reduced.clear();
        let inv = cell.inverse();
        let l_norm = cell.l.norm();
        let mut r_max = 0.0f64;
        for col in colliders {
            match col.shape {
                Shape::Disk { radius, .. } => r_max = r_max.max(radius),
                _ => {
                    return Err(DemError::Parameter {
                        name: "cell".into(),
                        reason: format!(
                            "a biperiodic cell holds disk grains only; body {} (`{}`) is a wall",
                            col.body, bodies[col.body as usize].name
                        ),
                    })
                }
            }
            if bodies[col.body as usize].kind != BodyKind::Grain {
                return Err(DemError::Parameter {
                    name: "cell".into(),
                    reason: format!(
                        "a biperiodic cell holds grains only; body {} (`{}`) is a wall",
                        col.body, bodies[col.body as usize].name
                    ),
                });
            }
        }
        // An implicit cell changes L by δ within the step while the grains keep their
        // velocities: an image (shift h k, k ∈ {−1, 0, 1}²) then moves by |δ h k| dt ≤
        // dt Σ|δ_ij| (|a₁| + |a₂|) relative to them; `rate_bound` bounds Σ|δ_ij|; half of it on
        // each disk's margin.
        // Capped at a quarter of the largest radius per disk (a small cell stays detectable);
        // a larger change is caught after the step ([`Detector::image_rate`]).
        let lattice = 0.5 * dt * (cell.h.column(0).norm() + cell.h.column(1).norm());
        let image_drift = (lattice * rate_bound).min(0.25 * r_max);
        self.image_rate = if lattice > 0.0 {
            image_drift / lattice
        } else {
            f64::INFINITY
        };
        let pair_affine = dt * l_norm * (r_max + 0.5 * detection_gap.max(0.0)) + image_drift;
        for (ci, col) in colliders.iter().enumerate() {
            if let Shape::Disk { radius, offset } = col.shape {
                let b = &bodies[col.body as usize];
                let c = b.position + rotate(offset, b.angle);
                let (c, _) = cell.wrap(&c);
                let mut sr = inv * c;
                for d in 0..2 {
                    if !(0.0..1.0).contains(&sr[d]) {
                        sr[d] = sr[d].rem_euclid(1.0);
                        if sr[d] >= 1.0 {
                            sr[d] = 0.0;
                        }
                    }
                }
                self.disk_collider.push(ci as u32);
                self.centre.push([c.x, c.y]);
                self.reduced.push([sr.x, sr.y]);
                self.radius.push(radius);
                let f = if b.mass > 0.0 && b.mass.is_finite() {
                    b.applied_force.norm() / b.mass
                } else {
                    0.0
                };
                let fluct = b.velocity - cell.affine_velocity(&c);
                self.margin.push(
                    dt * (fluct.norm() + dt * f + b.omega.abs() * offset.norm()) + pair_affine,
                );
            }
        }
        let nd = self.centre.len();
        let max_d = 2.0 * r_max;
        let max_m = self.margin.iter().cloned().fold(0.0f64, f64::max);
        let margin_cap = max_m.min(max_d);
        let cut = max_d + detection_gap.max(0.0) + 2.0 * margin_cap;
        self.fast.clear();
        self.fast
            .extend((0..nd as u32).filter(|&d| self.margin[d as usize] > margin_cap));
        let widths = cell.widths();
        let cap = (4 * nd + 64) as f64;
        let mut n = [0usize; 2];
        for d in 0..2 {
            let k = (widths[d] / cut).floor();
            if k.is_nan() || k < 3.0 {
                return Err(DemError::Parameter {
                    name: "cell".into(),
                    reason: format!(
                        "the cell is {:.4e} m wide across faces {}, less than 3 times the largest \
                         diameter plus the detection gap and swept margins ({:.4e} m)",
                        widths[d],
                        d + 1,
                        cut
                    ),
                });
            }
            n[d] = k.min(cap.sqrt().max(3.0)) as usize;
        }
        let (n1, n2) = (n[0], n[1]);
        let ncells = n1 * n2;
        self.cell_of.clear();
        self.cell_start.clear();
        self.cell_start.resize(ncells + 1, 0);
        for s in &self.reduced {
            let i1 = ((s[0] * n1 as f64) as usize).min(n1 - 1);
            let i2 = ((s[1] * n2 as f64) as usize).min(n2 - 1);
            let id = (i2 * n1 + i1) as u32;
            self.cell_of.push(id);
            self.cell_start[id as usize + 1] += 1;
        }
        for i in 0..ncells {
            self.cell_start[i + 1] += self.cell_start[i];
        }
        self.cell_items.clear();
        self.cell_items.resize(nd, 0);
        self.fill.clear();
        self.fill.extend_from_slice(&self.cell_start[..ncells]);
        for (d, &cid) in self.cell_of.iter().enumerate() {
            self.cell_items[self.fill[cid as usize] as usize] = d as u32;
            self.fill[cid as usize] += 1;
        }
        for d in 0..nd {
            let ci = self.disk_collider[d];
            let cid = self.cell_of[d] as usize;
            let (i1, i2) = ((cid % n1) as isize, (cid / n1) as isize);
            let mut around = [None; 9];
            for (k, slot) in around.iter_mut().enumerate() {
                let j2 = (i2 + k as isize / 3 - 1).rem_euclid(n2 as isize) as usize;
                let j1 = (i1 + k as isize % 3 - 1).rem_euclid(n1 as isize) as usize;
                *slot = Some(j2 * n1 + j1);
            }
            self.gather_neighbours(d, nd, &around);
            for k in 0..self.neighbours.len() {
                let (cj, e) = self.neighbours[k];
                self.disk_disk_cell(
                    bodies,
                    inv_mass,
                    colliders,
                    laws,
                    cell,
                    detection_gap,
                    ci,
                    d,
                    cj,
                    e as usize,
                    out,
                );
            }
        }
        Ok(())
    }

    /// The candidate partners of disk `d` (of `nd`) into `self.neighbours`, sorted and without
    /// repeats: the higher disks of the grid cells `around` (`None`: outside the grid) and the
    /// fast disks (a fast disk meets every disk; every disk meets the fast ones).
    fn gather_neighbours(&mut self, d: usize, nd: usize, around: &[Option<usize>; 9]) {
        self.neighbours.clear();
        if self.fast.binary_search(&(d as u32)).is_ok() {
            for e in d + 1..nd {
                self.neighbours.push((self.disk_collider[e], e as u32));
            }
        } else {
            for &e in &self.fast {
                if e as usize > d {
                    self.neighbours.push((self.disk_collider[e as usize], e));
                }
            }
        }
        for &c2 in around.iter().flatten() {
            for &e in
                &self.cell_items[self.cell_start[c2] as usize..self.cell_start[c2 + 1] as usize]
            {
                if (e as usize) > d {
                    self.neighbours.push((self.disk_collider[e as usize], e));
                }
            }
        }
        self.neighbours.sort_unstable();
        self.neighbours.dedup();
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn disk_disk_cell(
        &self,
        bodies: &[Body],
        inv_mass: &[[f64; 3]],
        colliders: &[Collider],
        laws: &ContactLaws,
        cell: &Cell,
        gap_max: f64,
        ci: u32,
        di: usize,
        cj: u32,
        dj: usize,
        out: &mut ContactSet,
    ) {
        let (ca, cb) = (&colliders[ci as usize], &colliders[cj as usize]);
        if ca.body == cb.body {
            return;
        }
        let (ba, bb) = (ca.body as usize, cb.body as usize);
        let (pa, pb) = (self.centre[di], self.centre[dj]);
        let raw = Vect::new(pb[0] - pa[0], pb[1] - pa[1]);
        let (branch, k) = cell.min_image(&raw);
        let (ra, rb) = (self.radius[di], self.radius[dj]);
        let reach = ra + rb + gap_max + self.margin[di] + self.margin[dj];
        let d2 = branch.norm_squared();
        if d2 > reach * reach {
            return;
        }
        let dist = d2.sqrt();
        let n = if dist > 0.0 {
            branch / dist
        } else {
            Vector2::new(0.0, 1.0)
        };
        let gap = dist - ra - rb;
        let off_a = disk_offset(&bodies[ba], ca);
        let off_b = disk_offset(&bodies[bb], cb);
        let lever_b = -n * rb + off_b;
        let lever_a = branch - n * rb + off_a;
        // The point is given near b (inside the cell); the image is that of b seen from a.
        let point = Vector2::new(pb[0], pb[1]) - n * rb;
        let image = if k == crate::cell::Shift::zeros() {
            Image::NONE
        } else {
            Image {
                shift: cell.shift_vector(&k),
                velocity: cell.image_velocity(&k),
            }
        };
        push_contact(
            out,
            inv_mass,
            laws,
            ca,
            cb,
            ci,
            cj,
            ba,
            bb,
            n,
            point,
            lever_a,
            lever_b,
            gap,
            CLOSED_GAP * ra.min(rb),
            image,
        );
    }
}
