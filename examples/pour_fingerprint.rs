//! Settles the poured benchmark column of `grainlaw bench --pour` alone (no LAMMPS peer) and
//! prints its report with a fingerprint of the final state: a 64-bit FNV-1a hash of the bits
//! of every body's position, angle, velocity and spin and of every contact's key and impulse.
//! Two builds that print the same fingerprint settled the column bit for bit the same way.
//!
//! Also printed: the subdivision's counts (kept sub-steps, undone attempts, discarded sweeps)
//! and the detection's (detections, builds of the candidate list). `FULL_DETECTION=1` takes
//! every detection's pairs from the cell grid (the same fingerprint, slower); `POUR_HIST=1`
//! prints how many kept sub-steps took 0, 1, … 100 sweeps; `POUR_TRACE=1` writes one line a
//! step on stderr: step, kept sub-steps, sweeps, KE/PE after it, seconds since the start.
//!
//! With a step count, the run stops after that many steps whether settled or not: the time to
//! settle follows a chaotic trajectory (391 to 874 steps over seeds 1–6), so two builds whose
//! numbers differ compare best on the cost of the same stretch of simulated time.
//!
//! `cargo run --release --example pour_fingerprint -- [grains (2000)] [seed (1)] [steps]`
use grainlaw::benchmarks::{janssen_column, ColumnRun, Preparation};
use std::time::Instant;

fn fnv(h: &mut u64, x: u64) {
    for b in x.to_le_bytes() {
        *h ^= u64::from(b);
        *h = h.wrapping_mul(0x100_0000_01b3);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args.first().and_then(|s| s.parse().ok()).unwrap_or(2000);
    let seed: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let max_steps: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(u64::MAX);
    let run = ColumnRun::for_column(Preparation::Pour, n);
    let mut w = janssen_column(n, Preparation::Pour, &run, seed).unwrap();
    if std::env::var_os("FULL_DETECTION").is_some() {
        w.set_full_detection(true);
    }
    assert!(
        run.step_control().is_none(),
        "the pour runs at a fixed step"
    );
    // `dem::settle::settle` without step control, step by step, with the subdivision's counts.
    let t0 = Instant::now();
    let mut sub = dem::step_control::Subdivision::default();
    let (mut steps, mut simulated, mut ratio) = (0u64, 0.0f64, dem::settle::energy_ratio(&w));
    let mut hist = [0usize; 101];
    let trace = std::env::var_os("POUR_TRACE").is_some();
    let (mut sweeps, mut discarded, mut capped, mut substeps, mut retries) = (0, 0, 0, 0, 0);
    while simulated < run.max_time - 0.5 * w.params.dt && steps < max_steps {
        let h = w.params.dt;
        let s = dem::step_control::step_subdivided(&mut w, &mut sub).unwrap();
        steps += 1;
        simulated += h;
        sweeps += s.report.solver.iterations;
        discarded += s.discarded_sweeps;
        capped += usize::from(!s.report.solver.converged);
        substeps += s.substeps.len();
        retries += s.retries;
        if std::env::var_os("POUR_HIST").is_some() {
            for sub in &s.substeps {
                hist[sub.report.solver.iterations.min(100)] += 1;
            }
        }
        ratio = dem::settle::energy_ratio(&w);
        if trace {
            eprintln!(
                "{steps} {} {} {ratio:.3e} {:.3}",
                s.substeps.len(),
                s.report.solver.iterations,
                t0.elapsed().as_secs_f64()
            );
        }
        if ratio < 1e-8 && s.report.solver.converged {
            break;
        }
    }
    let secs = t0.elapsed().as_secs_f64();
    if std::env::var_os("POUR_HIST").is_some() {
        println!("sweeps per kept sub-step: {hist:?}");
    }
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for x in w.state_bits() {
        fnv(&mut h, x);
    }
    let c = w.contacts();
    let overlap = c.geometry.iter().map(|g| -g.gap).fold(0.0, f64::max);
    println!(
        "{n} grains: {steps} steps, {:.1} sweeps/step, {capped} capped, KE/PE {ratio:.3e}, \
         overlap/r_min {:.5}, {} contacts, {secs:.2} s",
        sweeps as f64 / steps.max(1) as f64,
        overlap / 1e-3,
        c.len()
    );
    println!(
        "kept sub-steps {substeps}, undone attempts {retries}, sweeps {sweeps} of which \
         {discarded} discarded"
    );
    let counts = w.candidate_counts();
    println!(
        "detections {}, candidate list builds {}, candidate pairs now {}",
        counts.detections, counts.builds, counts.pairs
    );
    println!("fingerprint {h:016x}");
}
