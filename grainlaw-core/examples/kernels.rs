//! Exploration: time of the parallel kernels on 1 and 2 threads.
use dem::colouring::ContactColouring;
use dem::math::Twist;
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(10000);
    let w = grainlaw_core::benchmarks::scaling_deposit(n, 30, true, 1).unwrap();
    let rows0 = w.contacts().rows.clone();
    let inv: Vec<[f64; 3]> = w.bodies.iter().map(dem::Body::inverse_mass).collect();
    let mobile: Vec<bool> = inv.iter().map(|i| i.iter().any(|&x| x != 0.0)).collect();
    let pos: Vec<[f64; 2]> = w
        .bodies
        .iter()
        .map(|b| [b.position.x, b.position.y])
        .collect();
    // The engine's packed twists (v_x, v_y, ω), the layout of its kernels.
    let vfree: Vec<[f64; 3]> = w
        .bodies
        .iter()
        .map(|b| Twist::new(b.velocity, b.omega).to_array())
        .collect();
    let blocks: usize = std::env::var("BLOCKS").map_or(16, |v| v.parse().unwrap());
    let mut l = dem::blocked::BlockLayout::default();
    let (rows0, inv, mobile, pos, vfree) = if std::env::var("LAYOUT").is_ok() {
        l.gather(&rows0, &vfree, &vfree, &inv, &mobile, &pos, blocks);
        (
            l.rows.clone(),
            l.inv.clone(),
            l.mobile.clone(),
            l.pos.clone(),
            l.v_free.clone(),
        )
    } else {
        (rows0, inv, mobile, pos, vfree)
    };
    let mut col = ContactColouring::default();
    let t = Instant::now();
    col.build_blocked(&rows0, &mobile, &pos, blocks);
    println!(
        "contacts {} build {:.2} ms, separator {} in {} classes",
        rows0.len(),
        t.elapsed().as_secs_f64() * 1e3,
        col.order.len(),
        col.colours()
    );
    for threads in [1, 2] {
        use rayon::prelude::*;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let t = Instant::now();
        let s: f64 = pool.install(|| {
            (0..40_000_000u64)
                .into_par_iter()
                .map(|i| ((i as f64) * 1.0001).sqrt().sin())
                .sum()
        });
        println!(
            "raw compute {threads} threads: {:.3} s ({s:.1})",
            t.elapsed().as_secs_f64()
        );
    }
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut rows = rows0.clone();
            let mut vel = vfree.clone();
            let k = 100;
            let t = Instant::now();
            for _ in 0..k {
                dem::parallel::coloured_sweep(&mut rows, &col, &mut vel, &inv, &mobile, 1.0);
            }
            let sweep = t.elapsed().as_secs_f64() / k as f64;
            let mut vs = vel.clone();
            let t = Instant::now();
            for _ in 0..k {
                dem::parallel::scatter_velocities(&rows, &col, &mut vs, &vfree, &inv, &mobile);
            }
            let rebuild = t.elapsed().as_secs_f64() / k as f64;
            let t = Instant::now();
            let mut e = 0.0;
            for _ in 0..k {
                e += dem::solver::error_measure(&rows, &vel, 1.0);
            }
            let err = t.elapsed().as_secs_f64() / k as f64;
            let mut aa = dem::anderson::Anderson::new(4, 2 * rows.len());
            let x: Vec<f64> = rows.iter().flat_map(|c| c.r).collect();
            let mut g = x.clone();
            let t = Instant::now();
            for i in 0..k {
                g.iter_mut().for_each(|v| *v *= 1.0 + 1e-9 * i as f64);
                aa.step(&x, &mut g);
            }
            let anderson = t.elapsed().as_secs_f64() / k as f64;
            println!("{threads} threads: sweep {:.3} ms, rebuild {:.3} ms, error {:.3} ms, anderson {:.3} ms ({e:.1e})", sweep * 1e3, rebuild * 1e3, err * 1e3, anderson * 1e3);
        });
    }
}

#[allow(dead_code)]
fn raw() {}
