use dem::fc::*;
fn cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(0)
}
fn main() {
    let files: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let omega: f64 = std::env::var("FC_OMEGA")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let ordering = match std::env::var("FC_ORDER").as_deref() {
        Ok("natural") => ContactOrdering::Natural,
        Ok("reverse") => ContactOrdering::ReverseLoadFront,
        _ => ContactOrdering::LoadFront,
    };
    let acceleration = match std::env::var("FC_AA")
        .ok()
        .and_then(|s| s.parse::<usize>().ok())
    {
        Some(0) => Acceleration::None,
        Some(m) => Acceleration::Anderson { memory: m },
        None => Acceleration::default(),
    };
    for f in files {
        let p = read_problem(&f).unwrap();
        let opts = FcOptions {
            omega,
            ordering,
            acceleration,
            ..Default::default()
        };
        let mut best = f64::MAX;
        let mut sol = None;
        let mut bestcpu = f64::MAX;
        for _ in 0..std::env::var("FC_REP")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(5)
        {
            let c0 = cpu_ns();
            let s = solve(&p, &opts).unwrap();
            bestcpu = bestcpu.min((cpu_ns() - c0) as f64 * 1e-9);
            best = best.min(s.seconds);
            sol = Some(s);
        }
        let s = sol.unwrap();
        let e2 = fc_error(&p, &s.r);
        println!(
            "{:<45} nc={:>6} its={:>6} err={:.3e} (recomputed {:.3e}) conv={} s={:.4} cpu={:.4} Mupd/s(cpu)={:.1}",
            f.rsplit('/').next().unwrap(), p.contacts(), s.iterations, s.error, e2, s.converged, best, bestcpu,
            (s.iterations * p.contacts()) as f64 / bestcpu / 1e6
        );
    }
}
