//! Contact detection in O(N): a uniform cell grid over the disks (cell side ≥ the largest
//! diameter plus the detection gap, periodic along x when asked), each disk tested against the
//! disks of its 3×3 neighbourhood, and every line or segment tested against every disk.
//!
//! A contact is created for every pair whose gap is at most the detection gap `g_d`:
//! `g = |c_b − c_a| − R_a − R_b` for two disks, `g = (c − p)·n − R` for a line, and the distance
//! to the closest point minus `R` for a segment. Contacts come out sorted by the collider pair
//! key `(collider_a << 32) | collider_b` (a is the wall or the disk of lower index), so that the
//! next step can warm start by a linear merge.
//!
//! The disk pairs to test are kept between detections in a candidate list (a Verlet neighbour
//! list with a skin: L. Verlet, Phys. Rev. 159 (1967) 98; Allen & Tildesley, *Computer
//! Simulation of Liquids*, §5.3): built from the grid for reaches widened by the skin
//! ([`CANDIDATE_SKIN`] of the smallest radius) and twice each disk's swept margin, it is
//! reused while no disk has moved far enough, with its margin, to bring a pair that it left
//! out within reach ([`Detector::detect`]); the sub-steps of a subdivided step and the
//! detection after a step whose disks outran their margins reuse it too. Every pair it gives is
//! tested exactly as the grid's, in the same order, so the contacts are the same bit for bit.

use crate::math::{Spatial, Vector};

use crate::body::{Body, BodyKind};
use crate::cell::Cell;
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
    /// Per disk of the last [`Detector::collect_disks`]: its body, whether that body is
    /// kinematic, and its offset from the body's centre in the world frame, so that the pair
    /// tests read dense arrays rather than the bodies.
    disk_body: Vec<u32>,
    disk_kinematic: Vec<bool>,
    disk_offset: Vec<Vector>,
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
    /// The drift of an image over the step that the last [`Detector::detect_cell`] allowed
    /// for, per disk of a pair through the cell's boundary (m): half the reach such a pair
    /// gains (`image_rate` times the half-lattice `dt (|a₁| + |a₂|)/2`).
    image_drift: f64,
    /// Detection gap `g_d ≥ 0` of the last detection that set the swept margins (m): with
    /// them, it bounds how far a disk may travel before [`Detector::outran`] holds (0 after a
    /// biperiodic cell's detection, whose margins include the cell's own deformation).
    swept_gap: f64,
    /// Per line or segment at the last [`Detector::detect`]: its collider, swept margin (m)
    /// and the farthest distance of its shape's reference points from the body's centre (m),
    /// for [`Detector::outran`] (an imposed motion may start within the step).
    walls: Vec<(u32, f64, f64)>,
    /// Disk pairs kept between detections ([`Detector::detect`]).
    candidates: Candidates,
    /// Bin every detection on the grid instead of reusing the candidate list.
    full_detection: bool,
}

/// Skin of the candidate list as a fraction of the smallest radius: the list holds the pairs
/// up to this much farther apart than a detection needs, so it stays valid while the disks
/// move by up to half of it between its builds (plus what their swept margins leave over).
pub const CANDIDATE_SKIN: f64 = 0.25;

/// The candidate pairs of disks kept between detections (a Verlet neighbour list with a skin:
/// L. Verlet, Phys. Rev. 159 (1967) 98; Allen & Tildesley, *Computer Simulation of Liquids*,
/// §5.3), with what was true when it was built: a detection takes its pairs from the list as
/// long as [`Detector::candidates_cover`] holds, and tests each exactly as the grid's pairs.
#[derive(Debug, Default, Clone)]
struct Candidates {
    /// Whether a list was built (and not given up).
    built: bool,
    /// Gap `g₀` the list was built for (m).
    gap: f64,
    /// Length scale of the rounding allowance (m): the largest diameter plus `g₀` and the skin.
    scale: f64,
    /// Periodic cell at the build.
    periodic: Option<Periodic>,
    /// Per disk at the build: its collider, radius, wrapped centre and reach `ρ` (m).
    collider: Vec<u32>,
    radius: Vec<f64>,
    centre: Vec<[f64; 2]>,
    reach: Vec<f64>,
    /// Partners `(collider, disk)` of disk `d`: `partners[start[d]..start[d + 1]]`, higher
    /// disks only, in increasing order.
    start: Vec<u32>,
    partners: Vec<(u32, u32)>,
    /// Builds since the detector was made.
    builds: u64,
    /// Detections since the detector was made.
    detections: u64,
}

/// How often a detector reused its candidate list ([`Detector::candidate_counts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CandidateCounts {
    /// Calls of [`Detector::detect`] (a biperiodic cell's detection keeps no list).
    pub detections: u64,
    /// Of those, the ones that built the candidate list anew from the cell grid (the others
    /// reused it; all of them with full detection, which builds one for no reuse).
    pub builds: u64,
    /// Disk pairs in the list now.
    pub pairs: usize,
}

/// The cell grid of one detection ([`Detector::bin`]).
#[derive(Debug, Clone, Copy)]
struct Grid {
    ncx: usize,
    ncy: usize,
}

impl Grid {
    /// The 3×3 cells around cell `cid` (`None` outside the grid; wrapped along x when
    /// periodic).
    fn around(&self, cid: usize, periodic: bool) -> [Option<usize>; 9] {
        let (ncx, ncy) = (self.ncx, self.ncy);
        let (ix, iy) = ((cid % ncx) as isize, (cid / ncx) as isize);
        let mut around = [None; 9];
        for (k, slot) in around.iter_mut().enumerate() {
            let jy = iy + k as isize / 3 - 1;
            let mut jx = ix + k as isize % 3 - 1;
            if periodic {
                jx = jx.rem_euclid(ncx as isize);
            }
            if (0..ncy as isize).contains(&jy) && (0..ncx as isize).contains(&jx) {
                *slot = Some(jy as usize * ncx + jx as usize);
            }
        }
        around
    }
}

/// A line or segment in world coordinates.
enum WallShape {
    Line { p: Vector, n: Vector },
    Segment { a: Vector, b: Vector },
}

impl Detector {
    /// Detect all contacts that may close during a step of length `dt` and fill `out` (cleared
    /// first), with geometry, Delassus blocks and friction; impulses are zero.
    ///
    /// A pair becomes a contact when its gap is at most `detection_gap + m_a + m_b`, with the
    /// swept margin of a body `m = dt (|v| + dt |g| + |ω| ρ)` (ρ the distance of the shape from
    /// the body's centre): a grain moving several detection gaps per step is still caught before
    /// it overlaps. Pass `dt = 0` for a purely geometric test.
    ///
    /// The disk pairs to test come from the candidate list of an earlier call while it still
    /// covers every pair that can pass the test (a Verlet list, module documentation), else
    /// from the cell grid, which then builds a new list; the contacts found are the same either
    /// way, in the same order.
    #[allow(clippy::too_many_arguments)]
    pub fn detect(
        &mut self,
        bodies: &[Body],
        inv_mass: &[Spatial],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        detection_gap: f64,
        dt: f64,
        gravity: f64,
        out: &mut ContactSet,
    ) -> Result<(), DemError> {
        out.clear();
        self.detect_to(
            bodies,
            inv_mass,
            colliders,
            laws,
            periodic,
            detection_gap,
            dt,
            gravity,
            out,
        )
    }

    /// Whether [`Detector::detect`] with these arguments would find a contact that the
    /// position correction counts as violated at the positions as they are
    /// ([`crate::stabilise::Projection::project`] with no displacement: its gap below
    /// `−(1 + TOLERANCE)` times its closed gap, with `W_nn > 0`), without making the contacts:
    /// the same pairs, gaps and blocks, but only those deep enough are assembled. `Err` as
    /// [`Detector::detect`].
    #[allow(clippy::too_many_arguments)]
    pub fn finds_deep_overlap(
        &mut self,
        bodies: &[Body],
        inv_mass: &[Spatial],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        detection_gap: f64,
        dt: f64,
        gravity: f64,
    ) -> Result<bool, DemError> {
        let mut probe = DeepOverlapProbe { found: false };
        self.detect_to(
            bodies,
            inv_mass,
            colliders,
            laws,
            periodic,
            detection_gap,
            dt,
            gravity,
            &mut probe,
        )?;
        Ok(probe.found)
    }

    /// [`Detector::detect`] into any sink.
    #[allow(clippy::too_many_arguments)]
    fn detect_to<S: ContactSink>(
        &mut self,
        bodies: &[Body],
        inv_mass: &[Spatial],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        detection_gap: f64,
        dt: f64,
        gravity: f64,
        out: &mut S,
    ) -> Result<(), DemError> {
        self.candidates.detections += 1;
        self.collect_disks(bodies, colliders, periodic, dt, gravity);
        self.swept_gap = detection_gap.max(0.0);
        self.walls.clear();
        let nd = self.centre.len();
        let listed = !self.full_detection
            && (self.candidates_cover(periodic, detection_gap)
                || self.build_candidates(periodic, detection_gap));
        let grid = if listed {
            None
        } else {
            Some(self.bin(periodic, detection_gap)?)
        };

        // Ordered outer loop over colliders: disks find higher disks (in the grid or the
        // candidate list), walls find every disk, so keys come out sorted.
        let mut disk_pos = 0usize;
        for (ci, col) in colliders.iter().enumerate() {
            match col.shape {
                Shape::Disk { .. } => {
                    let d = disk_pos;
                    disk_pos += 1;
                    if let Some(grid) = grid {
                        let around = grid.around(self.cell_of[d] as usize, periodic.is_some());
                        self.gather_neighbours(d, nd, &around);
                        for k in 0..self.neighbours.len() {
                            let (cj, e) = self.neighbours[k];
                            self.disk_disk(
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
                    } else {
                        let list = &self.candidates;
                        for k in list.start[d] as usize..list.start[d + 1] as usize {
                            let (cj, e) = self.candidates.partners[k];
                            self.disk_disk(
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
                    self.walls.push((ci as u32, wall_margin, extent));
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

    /// Bins the disks collected by [`Detector::collect_disks`] on a cell grid fit for pairs
    /// within `detection_gap` plus their margins (`self.margin`): cells of side at least the
    /// largest diameter, the gap and twice the swept margin (capped at one diameter; the disks
    /// moving farther, "fast", are listed to be tested against every disk).
    fn bin(&mut self, periodic: Option<Periodic>, detection_gap: f64) -> Result<Grid, DemError> {
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
        Ok(Grid { ncx, ncy })
    }

    /// Whether the candidate list still holds every disk pair that a detection with gap `gap`
    /// and the margins just collected can find: for a pair left out of the list, built at gap
    /// `g₀` with per-disk reaches `ρ` (swept margin then plus half the skin), the centres were
    /// farther apart than `R_a + R_b + g₀ + ρ_a + ρ_b`; each centre has since moved by `|Δ|`
    /// and now sweeps `m`, so the pair is still out of reach when the slacks
    /// `s = ρ − |Δ| − m` of its two disks add up to at least `gap − g₀`. The two smallest
    /// slacks over all disks are checked (the Verlet list's displacement criterion: Verlet
    /// 1967; Allen & Tildesley, *Computer Simulation of Liquids*, §5.3). Also false when the
    /// disks changed (added, removed, resized) or the periodic cell did.
    fn candidates_cover(&self, periodic: Option<Periodic>, gap: f64) -> bool {
        let c = &self.candidates;
        if !c.built
            || c.periodic != periodic
            || c.collider != self.disk_collider
            || c.radius != self.radius
        {
            return false;
        }
        let (mut s1, mut s2) = (f64::INFINITY, f64::INFINITY);
        for d in 0..self.centre.len() {
            let (now, then) = (self.centre[d], c.centre[d]);
            let mut dx = now[0] - then[0];
            if let Some(p) = periodic {
                dx = p.min_image(dx);
            }
            let dy = now[1] - then[1];
            let slack = c.reach[d] - (dx * dx + dy * dy).sqrt() - self.margin[d];
            if slack.is_nan() {
                return false;
            }
            if slack < s1 {
                s2 = s1;
                s1 = slack;
            } else if slack < s2 {
                s2 = slack;
            }
        }
        // Rounding of the distances, far below any slack that matters.
        let rounding = 1e-9 * (c.scale + gap.abs());
        s1 + s2 >= gap - c.gap + rounding
    }

    /// Builds the candidate list from the cell grid: every pair of disks closer than
    /// `R_a + R_b + g₀ + ρ_a + ρ_b`, with `g₀` the largest of `gap` and the gaps asked before,
    /// and reaches `ρ = 2 m + skin / 2` ([`CANDIDATE_SKIN`] of the smallest radius): a disk
    /// that sweeps far in one step is listed with the partners of the next step too. Returns
    /// false (no list) when the grid cannot be built for those reaches (a periodic length too
    /// short for them), and the caller bins for the exact reaches instead.
    fn build_candidates(&mut self, periodic: Option<Periodic>, gap: f64) -> bool {
        let nd = self.centre.len();
        let r_min = self.radius.iter().copied().fold(f64::INFINITY, f64::min);
        let r_max = self.radius.iter().copied().fold(0.0f64, f64::max);
        let half_skin = 0.5 * CANDIDATE_SKIN * if nd > 0 { r_min } else { 0.0 };
        let gap0 = if self.candidates.built {
            gap.max(self.candidates.gap)
        } else {
            gap
        };
        let mut reach = std::mem::take(&mut self.candidates.reach);
        reach.clear();
        reach.extend(self.margin.iter().map(|&m| 2.0 * m + half_skin));
        if !(half_skin.is_finite() && gap0.is_finite() && reach.iter().all(|r| r.is_finite())) {
            self.candidates.reach = reach;
            self.candidates.built = false;
            return false;
        }
        // The grid for the widened reaches: `self.margin` holds them while it is built.
        std::mem::swap(&mut self.margin, &mut reach);
        let grid = self.bin(periodic, gap0);
        let Ok(grid) = grid else {
            std::mem::swap(&mut self.margin, &mut reach);
            self.candidates.reach = reach;
            self.candidates.built = false;
            return false;
        };
        let mut list = std::mem::take(&mut self.candidates);
        list.start.clear();
        list.partners.clear();
        list.start.push(0);
        for d in 0..nd {
            let around = grid.around(self.cell_of[d] as usize, periodic.is_some());
            self.gather_neighbours(d, nd, &around);
            let (pa, ra, ma) = (self.centre[d], self.radius[d], self.margin[d]);
            for &(cj, e) in &self.neighbours {
                let eu = e as usize;
                let pb = self.centre[eu];
                let mut dx = pb[0] - pa[0];
                if let Some(p) = periodic {
                    dx = p.min_image(dx);
                }
                let dy = pb[1] - pa[1];
                let r = ra + self.radius[eu] + gap0 + ma + self.margin[eu];
                if dx * dx + dy * dy <= r * r {
                    list.partners.push((cj, e));
                }
            }
            list.start.push(list.partners.len() as u32);
        }
        std::mem::swap(&mut self.margin, &mut reach);
        list.reach = reach;
        list.built = true;
        list.gap = gap0;
        list.periodic = periodic;
        list.scale = 2.0 * r_max + gap0.abs() + half_skin;
        list.collider.clone_from(&self.disk_collider);
        list.radius.clone_from(&self.radius);
        list.centre.clone_from(&self.centre);
        list.builds += 1;
        self.candidates = list;
        true
    }

    /// Lists the disk pairs to test from the candidate list of earlier detections while it
    /// covers them all (the default), or from the cell grid at every call (`true`). The
    /// contacts found are the same either way; the full grid is the reference the list is
    /// tested against.
    pub fn set_full_detection(&mut self, full: bool) {
        self.full_detection = full;
    }

    /// Detections ([`Detector::detect`]) and builds of their candidate list since this
    /// detector was made.
    pub fn candidate_counts(&self) -> CandidateCounts {
        CandidateCounts {
            detections: self.candidates.detections,
            builds: self.candidates.builds,
            pairs: self.candidates.partners.len(),
        }
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
        self.disk_body.clear();
        self.disk_kinematic.clear();
        self.disk_offset.clear();
        self.centre.clear();
        self.radius.clear();
        self.margin.clear();
        for (ci, col) in colliders.iter().enumerate() {
            if let Shape::Disk { radius, offset } = col.shape {
                let b = &bodies[col.body as usize];
                let arm = rotate(offset, b.angle);
                let mut c = b.position + arm;
                if let Some(p) = periodic {
                    c.x = p.wrap(c.x);
                }
                self.disk_collider.push(ci as u32);
                self.disk_body.push(col.body);
                self.disk_kinematic.push(b.is_kinematic());
                self.disk_offset.push(arm);
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

    /// Whether some disk may have met, over a step whose contacts the last [`Detector::detect`]
    /// (or [`Detector::detect_cell`]) found, a disk or wall that no contact of the step knew
    /// about: a disk kicked by a contact impulse can travel beyond the bound its velocity and
    /// loads gave at the start of the step. `displacement` is each body's travel over the step
    /// (`[Δx, Δy, Δθ]`) and `correction` the position correction applied after it (same layout,
    /// empty for none).
    ///
    /// A pair that the detection left out had a gap `g > g_d + m_a + m_b` (`g_d` the detection
    /// gap, `m` the swept margins), so it can only close if the two travels `δ_a + δ_b` exceed
    /// `g_d + m_a + m_b`. The test is therefore `δ > m + g_d/2` for some disk, line or segment,
    /// with `δ = |Δx + Δx_corr| + |Δθ + Δθ_corr| ρ`
    /// (ρ the shape's distance from its body's centre, as in its swept margin): when nothing
    /// outran, no pair unknown to the step can overlap. In a biperiodic cell the margins
    /// include the cell's deformation, which the travels given (relative to the affine field)
    /// do not, so there the test is `δ > m`.
    pub fn outran(
        &self,
        colliders: &[Collider],
        displacement: &[Spatial],
        correction: &[Spatial],
    ) -> bool {
        let slack = 0.5 * self.swept_gap;
        let travel = |body: usize, arm: f64| {
            let mut d = displacement[body];
            if let Some(c) = correction.get(body) {
                d = [d[0] + c[0], d[1] + c[1], d[2] + c[2]];
            }
            (d[0] * d[0] + d[1] * d[1]).sqrt() + d[2].abs() * arm
        };
        let disks = self
            .disk_collider
            .iter()
            .zip(&self.margin)
            .any(|(&ci, &m)| {
                let col = &colliders[ci as usize];
                let arm = match col.shape {
                    Shape::Disk { offset, .. } => offset.norm(),
                    _ => 0.0,
                };
                travel(col.body as usize, arm) > m + slack
            });
        disks
            || self.walls.iter().any(|&(ci, m, extent)| {
                travel(colliders[ci as usize].body as usize, extent) > m + slack
            })
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn disk_disk<S: ContactSink>(
        &self,
        inv_mass: &[Spatial],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        gap_max: f64,
        ci: u32,
        di: usize,
        cj: u32,
        dj: usize,
        out: &mut S,
    ) {
        let (ba, bb) = (self.disk_body[di] as usize, self.disk_body[dj] as usize);
        if ba == bb || (self.disk_kinematic[di] && self.disk_kinematic[dj]) {
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
            Vector::new(dx / dist, dy / dist)
        } else {
            Vector::new(0.0, 1.0)
        };
        let gap = dist - ra - rb;
        // Contact point on the surface of b; levers from the bodies' centres of mass.
        let lever_b = -n * rb + self.disk_offset[dj];
        let lever_a = Vector::new(dx, dy) - n * rb + self.disk_offset[di];
        let point = Vector::new(pb[0], pb[1]) - n * rb;
        let (ca, cb) = (&colliders[ci as usize], &colliders[cj as usize]);
        out.contact(
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
    fn wall_disk<S: ContactSink>(
        &self,
        bodies: &[Body],
        inv_mass: &[Spatial],
        colliders: &[Collider],
        laws: &ContactLaws,
        periodic: Option<Periodic>,
        gap_max: f64,
        cw: u32,
        shape: &WallShape,
        e: usize,
        out: &mut S,
    ) {
        let cj = self.disk_collider[e];
        let (ca, cb) = (&colliders[cw as usize], &colliders[cj as usize]);
        let (ba, bb) = (ca.body as usize, cb.body as usize);
        if ba == bb || (bodies[ba].is_kinematic() && bodies[bb].is_kinematic()) {
            return;
        }
        let c = Vector::new(self.centre[e][0], self.centre[e][1]);
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
                let mut d = Vector::new(f64::INFINITY, 0.0);
                for &sx in shifts {
                    let ac = c + Vector::new(sx, 0.0) - a;
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
                    Vector::new(-ab.y, ab.x).normalize()
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
        out.contact(
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
fn disk_offset(b: &Body, c: &Collider) -> Vector {
    match c.shape {
        Shape::Disk { offset, .. } => rotate(offset, b.angle),
        _ => Vector::zeros(),
    }
}

/// The periodic image of `b` a contact sees: its shift vector `h k` (m) and the affine
/// velocity `L h k` (m/s) it moves with relative to `b` ([`crate::cell`]).
#[derive(Debug, Clone, Copy)]
struct Image {
    shift: Vector,
    velocity: Vector,
}

impl Image {
    const NONE: Image = Image {
        shift: Vector::new(0.0, 0.0),
        velocity: Vector::new(0.0, 0.0),
    };
}

/// Where a detection puts the contacts it finds: a [`ContactSet`] keeps them
/// ([`push_contact`]); a [`DeepOverlapProbe`] only notes whether one is deep.
trait ContactSink {
    /// One contact of the detection, as [`push_contact`] takes it.
    #[allow(clippy::too_many_arguments)]
    fn contact(
        &mut self,
        inv_mass: &[Spatial],
        laws: &ContactLaws,
        ca: &Collider,
        cb: &Collider,
        ci: u32,
        cj: u32,
        ba: usize,
        bb: usize,
        n: Vector,
        point: Vector,
        lever_a: Vector,
        lever_b: Vector,
        gap: f64,
        closed_gap: f64,
        image: Image,
    );
}

impl ContactSink for ContactSet {
    #[inline]
    fn contact(
        &mut self,
        inv_mass: &[Spatial],
        laws: &ContactLaws,
        ca: &Collider,
        cb: &Collider,
        ci: u32,
        cj: u32,
        ba: usize,
        bb: usize,
        n: Vector,
        point: Vector,
        lever_a: Vector,
        lever_b: Vector,
        gap: f64,
        closed_gap: f64,
        image: Image,
    ) {
        push_contact(
            self, inv_mass, laws, ca, cb, ci, cj, ba, bb, n, point, lever_a, lever_b, gap,
            closed_gap, image,
        );
    }
}

/// Notes whether a detection finds a contact that the position correction would count as
/// violated with no displacement ([`crate::stabilise::Projection::project`]: gap below
/// `−(1 + TOLERANCE)` times the closed gap and `W_nn > 0`); only such a contact's block is
/// computed, as [`push_contact`] does.
struct DeepOverlapProbe {
    found: bool,
}

impl ContactSink for DeepOverlapProbe {
    #[inline]
    fn contact(
        &mut self,
        inv_mass: &[Spatial],
        _laws: &ContactLaws,
        _ca: &Collider,
        _cb: &Collider,
        _ci: u32,
        _cj: u32,
        ba: usize,
        bb: usize,
        n: Vector,
        _point: Vector,
        lever_a: Vector,
        lever_b: Vector,
        gap: f64,
        closed_gap: f64,
        _image: Image,
    ) {
        if gap < -(1.0 + crate::stabilise::TOLERANCE) * closed_gap {
            let (_, w) = contact_block(inv_mass, ba, bb, n, lever_a, lever_b);
            if w.nn > 0.0 {
                self.found = true;
            }
        }
    }
}

/// The lever cross products `[ρ_a×n, ρ_a×t, ρ_b×n, ρ_b×t]` and the local Delassus block of a
/// contact of normal `n` between bodies `ba` and `bb`.
#[inline(always)]
fn contact_block(
    inv_mass: &[Spatial],
    ba: usize,
    bb: usize,
    n: Vector,
    lever_a: Vector,
    lever_b: Vector,
) -> ([f64; 4], crate::local::Delassus2) {
    let t = Vector::new(-n.y, n.x);
    let cross = |r: Vector, v: Vector| r.x * v.y - r.y * v.x;
    let k = [
        cross(lever_a, n),
        cross(lever_a, t),
        cross(lever_b, n),
        cross(lever_b, t),
    ];
    let w = ContactRow::delassus([n.x, n.y], k, &inv_mass[ba], &inv_mass[bb]);
    (k, w)
}

#[allow(clippy::too_many_arguments)]
#[inline]
fn push_contact(
    out: &mut ContactSet,
    inv_mass: &[Spatial],
    laws: &ContactLaws,
    ca: &Collider,
    cb: &Collider,
    ci: u32,
    cj: u32,
    ba: usize,
    bb: usize,
    n: Vector,
    point: Vector,
    lever_a: Vector,
    lever_b: Vector,
    gap: f64,
    closed_gap: f64,
    image: Image,
) {
    let t = Vector::new(-n.y, n.x);
    let (k, w) = contact_block(inv_mass, ba, bb, n, lever_a, lever_b);
    let nn = [n.x, n.y];
    out.rows.push(ContactRow {
        a: ba as u32,
        b: bb as u32,
        n: nn,
        k,
        w,
        shift: 0.0,
        // −0.0 without an image: `x + (−0.0)` is `x` bit for bit (also for x = −0.0), so the
        // relative velocities of walls and the x-periodic cell are unchanged by the term.
        affine: if image.shift == Vector::zeros() {
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
    /// relative travel. A pair through the boundary (`k ≠ 0`) reaches `2 e` farther, `e =
    /// min(dt (|a₁| + |a₂|) ρ̇ / 2, R_max / 4)` (`ρ̇ = rate_bound`): its image drifts by
    /// `|δ h k| dt ≤ 2 e` under a change `δ` of `L` within the step with `Σ|δ_ij| ≤ ρ̇`, the
    /// grains keeping their velocities; a pair inside the cell does not drift so and gains
    /// nothing. Only disk grains are allowed (no walls in a periodic cell); the cell
    /// must be at least 3 cut-offs wide across both pairs of faces.
    #[allow(clippy::too_many_arguments)]
    pub fn detect_cell(
        &mut self,
        bodies: &[Body],
        inv_mass: &[Spatial],
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
        // Not used by the cell's pair test (`disk_disk_cell` reads the bodies): emptied so that
        // nothing reads them stale.
        self.disk_body.clear();
        self.disk_kinematic.clear();
        self.disk_offset.clear();
        self.centre.clear();
        self.radius.clear();
        self.margin.clear();
        self.reduced.clear();
        // The margins below include the cell's deformation over the step, which the travels
        // `outran` is given (relative to the affine field) do not: no slack is added to them.
        self.swept_gap = 0.0;
        self.walls.clear();
        let inv = cell.inverse();
        let l_norm = cell.l.norm();
        let r_max = cell_disks_only(bodies, colliders)?;
        // An implicit cell changes L by δ within the step while the grains keep their
        // velocities: an image (shift h k, k ∈ {−1, 0, 1}²) then moves by |δ h k| dt ≤
        // dt Σ|δ_ij| (|a₁| + |a₂|) relative to them; `rate_bound` bounds Σ|δ_ij|. Only the
        // pairs through the boundary (k ≠ 0) drift so: their reach gains that drift (half of
        // it per disk, `image_drift`), the disks' own margins do not (a pair inside the cell
        // moves with the grains' velocities whatever δ: with the drift on every margin, a
        // shear step of 10⁴ grains had 1.6 times the rows).
        // Capped at a quarter of the largest radius per disk (a small cell stays detectable);
        // a larger change is caught after the step ([`Detector::image_rate`]).
        let lattice = 0.5 * dt * (cell.h.column(0).norm() + cell.h.column(1).norm());
        let image_drift = (lattice * rate_bound).min(0.25 * r_max);
        self.image_drift = image_drift;
        self.image_rate = if lattice > 0.0 {
            image_drift / lattice
        } else {
            f64::INFINITY
        };
        let pair_affine = dt * l_norm * (r_max + 0.5 * detection_gap.max(0.0));
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
        let cut = max_d + detection_gap.max(0.0) + 2.0 * (margin_cap + image_drift);
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
        self.bin_cell_disks(n1, n2);
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

    /// Bins the disks of [`Detector::detect_cell`] into its `n1 × n2` grid of the reduced
    /// coordinates (`cell_of`, `cell_start`, `cell_items`).
    fn bin_cell_disks(&mut self, n1: usize, n2: usize) {
        let ncells = n1 * n2;
        let nd = self.centre.len();
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
        inv_mass: &[Spatial],
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
        let raw = Vector::new(pb[0] - pa[0], pb[1] - pa[1]);
        let (branch, k) = cell.min_image(&raw);
        let (ra, rb) = (self.radius[di], self.radius[dj]);
        let drift = if k == crate::cell::Shift::zeros() {
            0.0
        } else {
            2.0 * self.image_drift
        };
        let reach = ra + rb + gap_max + self.margin[di] + self.margin[dj] + drift;
        let d2 = branch.norm_squared();
        if d2 > reach * reach {
            return;
        }
        let dist = d2.sqrt();
        let n = if dist > 0.0 {
            branch / dist
        } else {
            Vector::new(0.0, 1.0)
        };
        let gap = dist - ra - rb;
        let off_a = disk_offset(&bodies[ba], ca);
        let off_b = disk_offset(&bodies[bb], cb);
        let lever_b = -n * rb + off_b;
        let lever_a = branch - n * rb + off_a;
        // The point is given near b (inside the cell); the image is that of b seen from a.
        let point = Vector::new(pb[0], pb[1]) - n * rb;
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

/// The largest disk radius of a biperiodic cell's colliders (m), after checking that they are
/// all disks of grains ([`Detector::detect_cell`]).
fn cell_disks_only(bodies: &[Body], colliders: &[Collider]) -> Result<f64, DemError> {
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
    Ok(r_max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The contact keys of every pair within reach, by testing all pairs: disks within
    /// `R_a + R_b + gap + m_a + m_b` (`m = dt |v|`, no gravity) and disks within `gap + m`
    /// of the floor `y = 0` (collider 0).
    fn brute_force(bodies: &[Body], gap: f64, dt: f64, periodic: Option<Periodic>) -> Vec<u64> {
        let mut keys = vec![];
        for (i, a) in bodies.iter().enumerate().skip(1) {
            let ma = dt * a.velocity.norm();
            if a.position.y - a.radius <= gap + ma {
                keys.push(i as u64);
            }
            for (j, b) in bodies.iter().enumerate().skip(i + 1) {
                let mut dx = b.position.x - a.position.x;
                if let Some(p) = periodic {
                    dx = p.min_image(dx);
                }
                let d = dx.hypot(b.position.y - a.position.y);
                if d <= a.radius + b.radius + gap + ma + dt * b.velocity.norm() {
                    keys.push(((i as u64) << 32) | j as u64);
                }
            }
        }
        keys.sort_unstable();
        keys
    }

    /// 150 disks (radii 1–2 mm) on a floor, in a box or along a periodic x, each moving at a
    /// velocity that takes random kicks (up to 0.02 m/s a component, damped by 0.9: speeds up
    /// to about 0.2 m/s), 0.5 ms between detections, detected 600 times: the contacts are those
    /// of the all-pairs test at every detection (the same keys, tolerance 0), with candidate
    /// reuse and with full detection alike, and the list is built at fewer than a fifth of
    /// the detections.
    #[test]
    fn reused_candidates_find_every_pair_within_reach_during_random_walks() {
        for periodic in [
            None,
            Some(Periodic {
                x_min: 0.0,
                length: 0.05,
            }),
        ] {
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let mut bodies = vec![Body::wall("floor", Vector::zeros(), Vector::zeros())];
            let mut colliders = vec![Collider {
                body: 0,
                shape: Shape::Line {
                    point: Vector::zeros(),
                    normal: Vector::new(0.0, 1.0),
                },
                material: 0,
            }];
            while bodies.len() < 151 {
                let r = rng.random_range(1e-3..2e-3);
                let c = Vector::new(rng.random_range(0.0..0.05), rng.random_range(r..0.03));
                let free = bodies.iter().skip(1).all(|b| {
                    let mut dx = b.position.x - c.x;
                    if let Some(p) = periodic {
                        dx = p.min_image(dx);
                    }
                    dx.hypot(b.position.y - c.y) > b.radius + r
                });
                if free {
                    colliders.push(Collider {
                        body: bodies.len() as u32,
                        shape: Shape::Disk {
                            radius: r,
                            offset: Vector::zeros(),
                        },
                        material: 0,
                    });
                    bodies.push(Body::disk(c, r, 2500.0, 1.0));
                }
            }
            let inv: Vec<Spatial> = bodies.iter().map(Body::inverse_mass).collect();
            let laws = ContactLaws::new(&["m"], 0.5);
            let (gap, dt) = (1e-4, 5e-4);
            let mut full = Detector::default();
            full.set_full_detection(true);
            let mut reuse = Detector::default();
            let (mut a, mut b) = (ContactSet::default(), ContactSet::default());
            let mut found = 0;
            for call in 0..600 {
                for body in bodies.iter_mut().skip(1) {
                    let kick =
                        Vector::new(rng.random_range(-0.02..0.02), rng.random_range(-0.02..0.02));
                    body.velocity = body.velocity * 0.9 + kick;
                    let v = body.velocity;
                    body.position += v * dt;
                    if let Some(p) = periodic {
                        body.position.x = p.wrap(body.position.x);
                    }
                }
                // every third call a static test at a wider gap, as after a step (`dt = 0`)
                let (g, h) = if call % 3 == 2 {
                    (2.5e-4, 0.0)
                } else {
                    (gap, dt)
                };
                for (det, out) in [(&mut full, &mut a), (&mut reuse, &mut b)] {
                    det.detect(&bodies, &inv, &colliders, &laws, periodic, g, h, 0.0, out)
                        .unwrap();
                }
                let keys = |s: &ContactSet| s.geometry.iter().map(|g| g.key).collect::<Vec<_>>();
                let expected = brute_force(&bodies, g, h, periodic);
                assert_eq!(keys(&a), expected, "call {call}: full detection");
                assert_eq!(keys(&b), expected, "call {call}: reused candidates");
                assert_eq!(a.rows, b.rows, "call {call}");
                found += expected.len();
            }
            assert!(found > 600 * 50, "{found} contacts in 600 detections");
            let c = reuse.candidate_counts();
            assert_eq!(c.detections, 600);
            assert!(c.builds >= 5 && 5 * c.builds < c.detections, "{c:?}");
        }
    }

    /// 20 pairs of disks (radii 1.5 mm), far apart, approaching head-on at 0.01 m/s each from
    /// gaps (k + 1)·0.5 µm beyond the reach of the first candidate list, detected 100 times
    /// every 0.5 ms (each gap closes by 10 µm, a tenth of the
    /// detection gap, between detections; swept margins 5 µm): the contacts with candidate
    /// reuse are those of the all-pairs test at every detection (the same keys, tolerance 0),
    /// although some pair comes within reach at nearly every detection that is the last
    /// before a rebuild.
    #[test]
    fn reused_candidates_find_pairs_approaching_head_on() {
        let (r, v, dt, gap) = (1.5e-3, 0.01, 5e-4, 1e-4);
        let mut bodies = vec![Body::wall("floor", Vector::zeros(), Vector::zeros())];
        let mut colliders = vec![Collider {
            body: 0,
            shape: Shape::Line {
                point: Vector::zeros(),
                normal: Vector::new(0.0, 1.0),
            },
            material: 0,
        }];
        // Just beyond the first list's reach, gap + 2 (2 m + skin/2) with m = dt v: the pairs
        // enter the detection's reach about when the list must be rebuilt.
        let listed = gap + 2.0 * (2.0 * dt * v + 0.5 * CANDIDATE_SKIN * r);
        for k in 0..20 {
            let y = 0.01 + 0.01 * k as f64;
            let g0 = listed + 5e-7 * (k + 1) as f64;
            for (x, vx) in [(0.01, v), (0.01 + 2.0 * r + g0, -v)] {
                colliders.push(Collider {
                    body: bodies.len() as u32,
                    shape: Shape::Disk {
                        radius: r,
                        offset: Vector::zeros(),
                    },
                    material: 0,
                });
                let mut b = Body::disk(Vector::new(x, y), r, 2500.0, 1.0);
                b.velocity = Vector::new(vx, 0.0);
                bodies.push(b);
            }
        }
        let inv: Vec<Spatial> = bodies.iter().map(Body::inverse_mass).collect();
        let laws = ContactLaws::new(&["m"], 0.5);
        let mut det = Detector::default();
        let mut out = ContactSet::default();
        let mut found = 0;
        for call in 0..100 {
            det.detect(
                &bodies, &inv, &colliders, &laws, None, gap, dt, 0.0, &mut out,
            )
            .unwrap();
            let keys: Vec<u64> = out.geometry.iter().map(|g| g.key).collect();
            assert_eq!(keys, brute_force(&bodies, gap, dt, None), "call {call}");
            found += keys.len();
            for b in bodies.iter_mut().skip(1) {
                let v = b.velocity;
                b.position += v * dt;
            }
        }
        assert!(found > 1000, "{found}");
        let c = det.candidate_counts();
        assert!(c.builds >= 3 && 3 * c.builds < c.detections, "{c:?}");
    }

    /// Pairs of disks (radii 1–2 mm) overlapping by random depths around the correction's
    /// threshold `(1 + TOLERANCE) · 10⁻⁴ R_min` (0.3 to 1.1 times it), in 400 random draws of
    /// 8 pairs, one pair of them a fixed clump (glued disks of one body, never a contact) and
    /// one disk of some pairs on the floor: [`Detector::finds_deep_overlap`] says true exactly
    /// when the contacts of [`Detector::detect`] make the projection with no displacement find
    /// a violated contact.
    #[test]
    fn the_deep_overlap_probe_agrees_with_the_projection() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let laws = ContactLaws::new(&["m"], 0.5);
        let mut projection = crate::stabilise::Projection::default();
        let (mut deep, mut shallow) = (0, 0);
        let mut det = Detector::default();
        for draw in 0..400 {
            let mut bodies = vec![Body::wall("floor", Vector::zeros(), Vector::zeros())];
            let mut colliders = vec![Collider {
                body: 0,
                shape: Shape::Line {
                    point: Vector::zeros(),
                    normal: Vector::new(0.0, 1.0),
                },
                material: 0,
            }];
            let threshold = (1.0 + crate::stabilise::TOLERANCE) * crate::contact::CLOSED_GAP;
            for k in 0..8 {
                let (ra, rb): (f64, f64) =
                    (rng.random_range(1e-3..2e-3), rng.random_range(1e-3..2e-3));
                let depth = rng.random_range(0.3..1.1) * threshold * ra.min(rb);
                let (x, y) = (0.01 * k as f64, 0.005);
                let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                let dir = Vector::new(angle.cos(), angle.sin());
                let a = Vector::new(x, if rng.random_bool(0.2) { ra } else { y });
                let b = a + dir * (ra + rb - depth);
                if k == 0 {
                    // A clump of the two disks, fixed: no contact between them.
                    bodies.push(Body::wall("clump", (a + b) * 0.5, Vector::zeros()));
                    for (c, r) in [(a, ra), (b, rb)] {
                        colliders.push(Collider {
                            body: 1,
                            shape: Shape::Disk {
                                radius: r,
                                offset: c - (a + b) * 0.5,
                            },
                            material: 0,
                        });
                    }
                    continue;
                }
                for (c, r) in [(a, ra), (b, rb)] {
                    colliders.push(Collider {
                        body: bodies.len() as u32,
                        shape: Shape::Disk {
                            radius: r,
                            offset: Vector::zeros(),
                        },
                        material: 0,
                    });
                    bodies.push(Body::disk(c, r, 2500.0, 1.0));
                }
            }
            let inv: Vec<Spatial> = bodies.iter().map(Body::inverse_mass).collect();
            let reach = 2.5e-4;
            let probe = det
                .finds_deep_overlap(&bodies, &inv, &colliders, &laws, None, reach, 0.0, 0.0)
                .unwrap();
            let mut set = ContactSet::default();
            det.detect(
                &bodies, &inv, &colliders, &laws, None, reach, 0.0, 0.0, &mut set,
            )
            .unwrap();
            let still = vec![[0.0; 3]; bodies.len()];
            let report = projection.project(&set.rows, &set.geometry, &still, &inv);
            assert_eq!(
                probe,
                report.violated_contacts > 0,
                "draw {draw}: {report:?}"
            );
            if probe {
                deep += 1;
            } else {
                shallow += 1;
            }
        }
        // Both outcomes are drawn.
        assert!(deep > 50 && shallow > 50, "{deep} deep, {shallow} shallow");
    }
}
