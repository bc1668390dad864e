//! Hand-built snapshots for the tests, until the engine produces them: one rolling disk from
//! the analytic solution, columns and stacks at rest, random dynamic states whose accelerations
//! are consistent with their forces (`m a = m g + Σ f`, `I ω̇ = Σ l × f`, as the engine's).
#![allow(dead_code)]

use dem::local::ContactStatus;
use dem::math::{cross, Tensor, Vector};
use dem::snapshot::{BodyKind, BodyState, ContactState, Snapshot, WallGeometry, WallState};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub fn v(x: f64, y: f64) -> Vector {
    Vector::new(x, y)
}

/// Builds a snapshot body by body and contact by contact; `finish` sets the grains'
/// accelerations from the forces and the walls' total forces.
pub struct Builder {
    pub snap: Snapshot,
}

impl Builder {
    pub fn new(gravity: Vector) -> Self {
        Self {
            snap: Snapshot {
                step: 1,
                time: 1e-3,
                dt: 1e-3,
                gravity,
                periodic_x: None,
                cell: None,
                bodies: Vec::new(),
                contacts: Vec::new(),
                walls: Vec::new(),
            },
        }
    }

    pub fn grain(&mut self, position: Vector, radius: f64, density: f64, thickness: f64) -> u32 {
        self.snap
            .bodies
            .push(BodyState::disk(position, radius, density, thickness));
        (self.snap.bodies.len() - 1) as u32
    }

    pub fn motion(&mut self, id: u32, velocity: Vector, omega: f64) {
        let b = &mut self.snap.bodies[id as usize];
        b.velocity = velocity;
        b.omega = omega;
    }

    fn wall_body(&mut self, name: &str, position: Vector, geometry: WallGeometry) -> u32 {
        self.snap
            .bodies
            .push(BodyState::wall(name, position, Vector::zeros()));
        let id = (self.snap.bodies.len() - 1) as u32;
        self.snap.walls.push(WallState {
            body: id,
            name: name.to_string(),
            geometry,
            force: Vector::zeros(),
            torque: 0.0,
        });
        id
    }

    /// A line wall through `point` with unit `normal` into the grains.
    pub fn line_wall(&mut self, name: &str, point: Vector, normal: Vector) -> u32 {
        self.wall_body(name, point, WallGeometry::Line { point, normal })
    }

    /// A rough wall: a clump of disks, body centre at the disks' mean.
    pub fn clump_wall(&mut self, name: &str, centres: Vec<Vector>, radii: Vec<f64>) -> u32 {
        let c = centres.iter().sum::<Vector>() / centres.len() as f64;
        self.wall_body(name, c, WallGeometry::Clump { centres, radii })
    }

    /// A contact between `a` and `b` at `point` with normal `n` (from a to b) and forces on b
    /// `f_n n + f_t t`; levers from the bodies' positions. (Mirrors `ContactState`'s fields.)
    #[allow(clippy::too_many_arguments)]
    pub fn contact(
        &mut self,
        a: u32,
        b: u32,
        point: Vector,
        normal: Vector,
        f_n: f64,
        f_t: f64,
        mu: f64,
    ) {
        let status = if f_n <= 0.0 {
            ContactStatus::Open
        } else if f_t.abs() >= mu * f_n * (1.0 - 1e-12) {
            ContactStatus::Slide
        } else {
            ContactStatus::Stick
        };
        let pa = self.snap.bodies[a as usize].position;
        let pb = self.snap.bodies[b as usize].position;
        self.snap.contacts.push(ContactState {
            body_a: a,
            body_b: b,
            point,
            normal,
            force_n: f_n,
            force_t: f_t,
            gap: 0.0,
            mu,
            status,
            lever_a: point - pa,
            lever_b: point - pb,
        });
    }

    /// Net contact force and torque on every body.
    pub fn net(&self) -> Vec<(Vector, f64)> {
        let mut net = vec![(Vector::zeros(), 0.0); self.snap.bodies.len()];
        for c in &self.snap.contacts {
            let f = c.force_on_b();
            net[c.body_b as usize].0 += f;
            net[c.body_b as usize].1 += cross(&c.lever_b, &f);
            net[c.body_a as usize].0 -= f;
            net[c.body_a as usize].1 -= cross(&c.lever_a, &f);
        }
        net
    }

    /// Grain accelerations from the forces (`a = g + Σf/m`, `ω̇ = Σ l×f / I`), wall totals.
    pub fn finish(mut self) -> Snapshot {
        let net = self.net();
        let g = self.snap.gravity;
        for (b, (f, t)) in self.snap.bodies.iter_mut().zip(&net) {
            if b.kind == BodyKind::Grain {
                b.acceleration = g + f / b.mass;
                b.angular_acceleration = t / b.inertia;
            }
        }
        for w in &mut self.snap.walls {
            w.force = net[w.body as usize].0;
            w.torque = net[w.body as usize].1;
        }
        self.snap
    }
}

/// The analytic rolling disk of `docs/physics.md` §2.3 at time `t`.
pub struct Rolling {
    pub snap: Snapshot,
    /// Down the slope.
    pub e1: Vector,
    /// Outward normal of the slope.
    pub e2: Vector,
    pub travelled: f64,
    /// Expected Σ_p in the slope frame.
    pub sigma: Tensor,
    /// Expected contact part in the slope frame.
    pub contact: Tensor,
    pub omega: f64,
    pub omega_dot: f64,
}

/// A disk of radius `a`, density `rho`, released at rest at t = 0 on a slope `phi` going down
/// to the right (or to the left when `mirrored`), rolling without slipping, at time `t`.
/// The slope passes through `origin`; gravity g = 9.81.
pub fn rolling_disk(phi: f64, a: f64, rho: f64, t: f64, mirrored: bool, origin: Vector) -> Rolling {
    let g = 9.81;
    let (e1, e2) = if mirrored {
        (v(-phi.cos(), -phi.sin()), v(-phi.sin(), phi.cos()))
    } else {
        (v(phi.cos(), -phi.sin()), v(phi.sin(), phi.cos()))
    };
    let hand = cross(&e1, &e2); // +1 right-handed slope frame, −1 mirrored
    let acc = 2.0 / 3.0 * g * phi.sin();
    let travelled = 0.5 * acc * t * t;
    let speed = acc * t;
    // rolling without slipping: v e1 + ω e_z × (−a e2) = 0 ⇒ ω = −hand · v / a
    let omega = -hand * speed / a;
    let omega_dot = -hand * acc / a;
    let mut b = Builder::new(v(0.0, -g));
    b.snap.time = t;
    let wall = b.line_wall("slope", origin, e2);
    let centre = origin + e2 * a + e1 * travelled;
    let disk = b.grain(centre, a, rho, 1.0);
    b.motion(disk, e1 * speed, omega);
    let m = b.snap.bodies[disk as usize].mass;
    // reaction (eq. 13): r = m g (−sinφ/3 e1 + cosφ e2)
    let r = (e1 * (-phi.sin() / 3.0) + e2 * phi.cos()) * (m * g);
    let tangent = v(-e2.y, e2.x);
    b.contact(
        wall,
        disk,
        centre - e2 * a,
        e2,
        r.dot(&e2),
        r.dot(&tangent),
        1.0,
    );
    let snap = b.finish();
    let (s, c) = (phi.sin(), phi.cos());
    Rolling {
        snap,
        e1,
        e2,
        travelled,
        sigma: Tensor::new(0.0, s / 6.0, s / 6.0, -c) * (rho * g * a)
            + Tensor::identity() * (rho * g * travelled * s / 3.0),
        contact: Tensor::new(0.0, s / 3.0, 0.0, -c) * (rho * g * a),
        omega,
        omega_dot,
    }
}

/// A single-file column of `layers` disks of radius `r` between two frictional vertical walls
/// `left` (x = 0) and `right` (x = 2r) on a `bottom` wall (y = 0), at rest. Each disk is
/// pressed by both side walls with `h` (N) and held up by wall friction `t_k` (N) per side
/// (`t_k` of layer k from the bottom); disk-disk and bottom contacts carry the load above.
pub fn column(
    layers: usize,
    r: f64,
    rho: f64,
    thickness: f64,
    mu: f64,
    h: f64,
    t: &[f64],
) -> Snapshot {
    assert_eq!(t.len(), layers);
    let g = 9.81;
    let mut b = Builder::new(v(0.0, -g));
    let left = b.line_wall("left", v(0.0, 0.0), v(1.0, 0.0));
    let right = b.line_wall("right", v(2.0 * r, 0.0), v(-1.0, 0.0));
    let bottom = b.line_wall("bottom", v(0.0, 0.0), v(0.0, 1.0));
    let ids: Vec<u32> = (0..layers)
        .map(|k| b.grain(v(r, r + 2.0 * r * k as f64), r, rho, thickness))
        .collect();
    let w = b.snap.bodies[ids[0] as usize].mass * g;
    // load under layer k: P_k = Σ_{j ≥ k} (w − 2 t_j)
    let mut p = vec![0.0; layers + 1];
    for k in (0..layers).rev() {
        p[k] = p[k + 1] + w - 2.0 * t[k];
        assert!(p[k] >= 0.0, "the walls would hold layer {k} up by tension");
    }
    b.contact(bottom, ids[0], v(r, 0.0), v(0.0, 1.0), p[0], 0.0, mu);
    for k in 0..layers {
        let y = r + 2.0 * r * k as f64;
        if k + 1 < layers {
            b.contact(
                ids[k],
                ids[k + 1],
                v(r, y + r),
                v(0.0, 1.0),
                p[k + 1],
                0.0,
                mu,
            );
        }
        // left wall: n = +x, t = (0, 1): upward friction is f_t = +t_k
        b.contact(left, ids[k], v(0.0, y), v(1.0, 0.0), h, t[k], mu);
        // right wall: n = −x, t = (0, −1): upward friction is f_t = −t_k
        b.contact(right, ids[k], v(2.0 * r, y), v(-1.0, 0.0), h, -t[k], mu);
    }
    b.finish()
}

/// Three frictionless disks in a box of width 4r: two on the bottom, one in their groove.
pub fn cannonball(r: f64, rho: f64) -> Snapshot {
    let g = 9.81;
    let mut b = Builder::new(v(0.0, -g));
    let left = b.line_wall("left", v(0.0, 0.0), v(1.0, 0.0));
    let right = b.line_wall("right", v(4.0 * r, 0.0), v(-1.0, 0.0));
    let bottom = b.line_wall("bottom", v(0.0, 0.0), v(0.0, 1.0));
    let p1 = b.grain(v(r, r), r, rho, 1.0);
    let p2 = b.grain(v(3.0 * r, r), r, rho, 1.0);
    let p3 = b.grain(v(2.0 * r, r + 3f64.sqrt() * r), r, rho, 1.0);
    let w = b.snap.bodies[p1 as usize].mass * g;
    let f = w / 3f64.sqrt();
    b.contact(bottom, p1, v(r, 0.0), v(0.0, 1.0), 1.5 * w, 0.0, 0.0);
    b.contact(bottom, p2, v(3.0 * r, 0.0), v(0.0, 1.0), 1.5 * w, 0.0, 0.0);
    b.contact(left, p1, v(0.0, r), v(1.0, 0.0), 0.5 * f, 0.0, 0.0);
    b.contact(right, p2, v(4.0 * r, r), v(-1.0, 0.0), 0.5 * f, 0.0, 0.0);
    b.contact(p1, p2, v(2.0 * r, r), v(1.0, 0.0), 0.0, 0.0, 0.0);
    for (pb, s) in [(p1, 1.0), (p2, -1.0)] {
        let n = v(s * 0.5, 3f64.sqrt() / 2.0); // from the bottom disk to the top one
        let c = b.snap.bodies[pb as usize].position;
        b.contact(pb, p3, c + n * r, n, f, 0.0, 0.0);
    }
    b.finish()
}

/// A random dynamic state: `nx × ny` polydisperse grains on a jittered lattice in a box with a
/// bottom and two side walls (everything shifted by `offset`), contacts between lattice
/// neighbours and with the walls, random forces inside the Coulomb cone, random velocities;
/// accelerations consistent with the forces. Same seed, same state (up to the offset).
pub fn random_dynamic(seed: u64, nx: usize, ny: usize, offset: Vector) -> Snapshot {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let r0 = 1.5e-3;
    let cell = 2.0 * r0;
    let mut b = Builder::new(v(0.0, -9.81));
    let left = b.line_wall("left", offset, v(1.0, 0.0));
    let right = b.line_wall("right", offset + v(nx as f64 * cell, 0.0), v(-1.0, 0.0));
    let bottom = b.line_wall("bottom", offset, v(0.0, 1.0));
    let mut ids = vec![vec![0u32; nx]; ny];
    for (j, row) in ids.iter_mut().enumerate() {
        for (i, id) in row.iter_mut().enumerate() {
            let r = r0 * rng.random_range(0.7..0.95);
            let jitter = v(rng.random_range(-0.04..0.04), rng.random_range(-0.04..0.04)) * r0;
            let c = offset + v((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell) + jitter;
            *id = b.grain(c, r, 2500.0, 1.0);
            let vel = v(rng.random_range(-0.3..0.3), rng.random_range(-0.3..0.3));
            b.motion(*id, vel, rng.random_range(-50.0..50.0));
        }
    }
    let mu = 0.4;
    let force = |rng: &mut ChaCha8Rng| {
        let f_n: f64 = rng.random_range(0.0..0.05);
        (f_n, mu * f_n * rng.random_range(-1.0..1.0))
    };
    for j in 0..ny {
        for i in 0..nx {
            let a = ids[j][i];
            for (di, dj) in [(1usize, 0usize), (0, 1), (1, 1)] {
                let (i2, j2) = (i + di, j + dj);
                if i2 >= nx || j2 >= ny {
                    continue;
                }
                let bb = ids[j2][i2];
                let (ca, cb) = (
                    b.snap.bodies[a as usize].position,
                    b.snap.bodies[bb as usize].position,
                );
                let n = (cb - ca).normalize();
                let rb = b.snap.bodies[bb as usize].radius;
                let (f_n, f_t) = force(&mut rng);
                b.contact(a, bb, cb - n * rb, n, f_n, f_t, mu);
            }
        }
    }
    for row in &ids {
        for (i, wall, n) in [(0usize, left, v(1.0, 0.0)), (nx - 1, right, v(-1.0, 0.0))] {
            let id = row[i];
            let (c, r) = (
                b.snap.bodies[id as usize].position,
                b.snap.bodies[id as usize].radius,
            );
            let (f_n, f_t) = force(&mut rng);
            b.contact(wall, id, c - n * r, n, f_n, f_t, mu);
        }
    }
    for &id in &ids[0] {
        let (c, r) = (
            b.snap.bodies[id as usize].position,
            b.snap.bodies[id as usize].radius,
        );
        let (f_n, f_t) = force(&mut rng);
        b.contact(bottom, id, c - v(0.0, r), v(0.0, 1.0), f_n, f_t, mu);
    }
    b.finish()
}

/// Largest relative difference `‖a − b‖_F / max(‖b‖_F, tiny)`.
pub fn rel(a: &Tensor, b: &Tensor) -> f64 {
    (a - b).norm() / b.norm().max(1e-300)
}
