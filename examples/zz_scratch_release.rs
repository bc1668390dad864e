use datasets::config::common::{FrictionSpec, GrainSpec};
use dem::local::natural_map_residual;
use nalgebra::Vector2;
fn main() {
    let g = GrainSpec {
        density: 2500.0,
        radius_mean: 1.5e-3,
        radius_spread: 1e-3,
    };
    let f = FrictionSpec {
        grain_grain: 0.25,
        grain_wall: 0.25,
    };
    let width = datasets::build::column_width(&g, 350, 4.0);
    let mut col = datasets::build::column(&g, 350, width, &f, 1, 2.5e-4).unwrap();
    let bottom = col.bottom;
    let w = &mut col.world;
    w.params.solver.tolerance = 1e-4;
    w.params.solver.max_iterations = 1000;
    for _ in 0..716 {
        w.step().unwrap();
    }
    w.params.dt = 1e-3;
    w.bodies[bottom].velocity = Vector2::new(0.0, -1e-3);
    for s in 0..40 {
        let r = w.step().unwrap();
        if s % 10 == 0 {
            println!(
                "release step {s}: its {} err {:.2e}",
                r.solver.iterations, r.solver.error
            );
        }
    }
    let before = w.clone();
    for (m, mi) in [(4usize, 1000usize), (4, 10000), (0, 10000)] {
        let mut c = before.clone();
        c.params.solver.anderson_memory = m;
        c.params.solver.max_iterations = mi;
        c.params.solver.tolerance = 1e-8;
        let r = c.step().unwrap();
        println!(
            "m {m} its {}: err {:.3e}",
            r.solver.iterations, r.solver.error
        );
        if mi == 10000 && m == 4 {
            let vel: Vec<[f64; 3]> = c
                .bodies
                .iter()
                .map(|b| [b.velocity.x, b.velocity.y, b.omega])
                .collect();
            let cs = c.contacts();
            let mut v: Vec<(f64, usize)> = cs
                .rows
                .iter()
                .enumerate()
                .map(|(i, k)| {
                    let u = k.velocity(&vel[k.a as usize], &vel[k.b as usize]);
                    let e = natural_map_residual(k.r, u, k.mu);
                    ((e[0] * e[0] + e[1] * e[1]).sqrt(), i)
                })
                .collect();
            v.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
            for &(e, i) in v.iter().take(8) {
                let k = &cs.rows[i];
                let u = k.velocity(&vel[k.a as usize], &vel[k.b as usize]);
                println!("   c{i} {}-{} res {e:.2e} r [{:.3e},{:.3e}] u [{:.3e},{:.3e}] gap {:.2e} shift {:.2e} st {:?}", k.a, k.b, k.r[0], k.r[1], u[0], u[1], cs.geometry[i].gap, k.shift, cs.status[i]);
            }
        }
    }
}
