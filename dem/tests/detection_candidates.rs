//! The candidate list kept between detections (a Verlet list with a skin,
//! [`dem::detection::Detector::detect`]) finds exactly the contacts of a full grid detection:
//! two copies of a shaken packing, one reusing its candidate pairs and one binning every
//! detection on the grid, step bit for bit alike (tolerance 0: every contact's key, geometry,
//! Delassus block and impulse, and every body's position and velocity, equal as bits).

mod common;
use common::{fingerprint, random_box};

use dem::World;
use nalgebra::Vector2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Steps `a` (candidate reuse) and `b` (full detection) side by side for `steps` steps, every
/// 25th step kicking every grain of both by the same random velocity (up to `kick` m/s), and
/// dropping one more grain into both halfway; asserts after every step that the contact sets
/// and the states are bit-identical. Returns the detections and candidate list builds of `a`
/// over the steps.
fn lockstep(
    mut a: World,
    mut b: World,
    steps: usize,
    kick: f64,
    seed: u64,
) -> dem::detection::CandidateCounts {
    let before = a.candidate_counts();
    b.set_full_detection(true);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut contacts = 0usize;
    for step in 0..steps {
        if step % 25 == 0 {
            let grains: Vec<usize> = (0..a.bodies.len())
                .filter(|&i| a.bodies[i].kind == dem::BodyKind::Grain)
                .collect();
            for i in grains {
                let v = Vector2::new(rng.random_range(-kick..kick), rng.random_range(0.0..kick));
                let w = rng.random_range(-50.0 * kick..50.0 * kick);
                for world in [&mut a, &mut b] {
                    world.bodies[i].velocity += v;
                    world.bodies[i].omega += w;
                }
            }
        }
        if step == steps / 2 {
            // A new disk: the list of the old ones no longer covers the pairs.
            for world in [&mut a, &mut b] {
                world.add_grain(Vector2::new(0.01, 0.08), 1.5e-3, 2500.0, 0);
            }
        }
        let (ra, rb) = (a.step().unwrap(), b.step().unwrap());
        assert_eq!(ra, rb, "step {step}: reports differ");
        let (ca, cb) = (a.contacts(), b.contacts());
        assert_eq!(ca.len(), cb.len(), "step {step}: contact counts differ");
        for (k, (ga, gb)) in ca.geometry.iter().zip(&cb.geometry).enumerate() {
            assert_eq!(ga.key, gb.key, "step {step}, contact {k}: pairs differ");
            assert_eq!(
                ga.gap.to_bits(),
                gb.gap.to_bits(),
                "step {step}, contact {k}"
            );
        }
        for (k, (x, y)) in ca.rows.iter().zip(&cb.rows).enumerate() {
            let bits = |r: &dem::contact::ContactRow| {
                [
                    r.n[0], r.n[1], r.k[0], r.k[1], r.k[2], r.k[3], r.w.nn, r.w.nt, r.w.tt,
                    r.shift, r.r[0], r.r[1],
                ]
                .map(f64::to_bits)
            };
            assert_eq!((x.a, x.b), (y.a, y.b), "step {step}, contact {k}");
            assert_eq!(bits(x), bits(y), "step {step}, contact {k}");
        }
        assert_eq!(
            fingerprint(&a),
            fingerprint(&b),
            "step {step}: states differ"
        );
        contacts += ca.len();
    }
    assert!(
        contacts > 100 * steps,
        "a dense packing: {contacts} contacts"
    );
    let after = a.candidate_counts();
    dem::detection::CandidateCounts {
        detections: after.detections - before.detections,
        builds: after.builds - before.builds,
        pairs: after.pairs,
    }
}

/// A box of 300 grains (radii 1–2 mm, μ = 0.5) settling under gravity, shaken every 25 steps
/// by kicks up to 0.3 m/s, 400 steps of 1 ms: the contacts with candidate reuse are those of
/// the full grid detection at every step. The kicks (up to 0.3 mm a step, more than half the
/// skin) and the settling keep the grains moving, so the list is rebuilt at about half of the
/// detections (the steps' and the few a position correction makes); the assertion is that it
/// is still reused by at least 45 % of them (measured: 216 of 455). Until the second
/// detection after a step was limited to disks that outran their margin by half the detection
/// gap, about 300 more detections per run (all reusing the list) were counted, and the
/// assertion was "fewer than half build it".
#[test]
fn candidate_reuse_finds_the_contacts_of_full_detection_in_a_shaken_box() {
    let mut w = random_box(300, 0.04, 1e-3, 2e-3, 0.5, 1.0, 7);
    w.params.solver.tolerance = 1e-4;
    w.params.solver.max_iterations = 300;
    let c = lockstep(w.clone(), w, 400, 0.3, 11);
    assert!(reused_often(&c), "{c:?}");
}

/// At least ten builds (the kicks are seen), and at least 45 % of the detections reuse the list.
fn reused_often(c: &dem::detection::CandidateCounts) -> bool {
    c.builds >= 10 && 20 * (c.detections - c.builds) >= 9 * c.detections
}

/// The same along a periodic x (no side walls; pairs across the boundary), with a rough floor
/// of glued disks (a clump: disk colliders on a wall body, never tested against each other).
#[test]
fn candidate_reuse_finds_the_contacts_of_full_detection_in_a_periodic_strip() {
    let width = 0.04;
    let mut w = random_box(250, width, 1e-3, 2e-3, 0.5, 1.0, 3);
    let mut p = World::new(w.params, w.laws.clone());
    p.params.periodic_x = Some([0.0, width]);
    p.params.solver.tolerance = 1e-4;
    p.params.solver.max_iterations = 300;
    p.add_line_wall("bottom", Vector2::new(0.0, 0.0), Vector2::new(0.0, 1.0), 0);
    let centres: Vec<Vector2<f64>> = (0..20)
        .map(|i| Vector2::new((i as f64 + 0.5) * width / 20.0, 0.0))
        .collect();
    p.add_clump("rough", &centres, &[1e-3; 20], 0);
    for b in w.bodies.drain(..) {
        if b.kind == dem::BodyKind::Grain {
            let i = p.add_grain(b.position + Vector2::new(0.0, 2e-3), b.radius, b.density, 0);
            p.bodies[i as usize].velocity = b.velocity;
            p.bodies[i as usize].omega = b.omega;
        }
    }
    let c = lockstep(p.clone(), p, 400, 0.3, 5);
    // Measured: 219 of 467 detections reuse the list (46.9 %).
    assert!(reused_often(&c), "{c:?}");
}
