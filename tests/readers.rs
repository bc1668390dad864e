//! Readers of other codes' snapshots (`grainlaw::readers`) and `grainlaw homogenise`:
//! LAMMPS dumps of a real 2D run (`datasets/external/lammps`, made with the LAMMPS of Debian
//! 12, see its README) checked against LAMMPS' own stress and wall forces; LMGC90 files written
//! by hand in LMGC90's layout (`datasets/external/lmgc90`); the plain format against analytic
//! answers; errors naming file and line.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use dem::snapshot::BodyKind;
use grainlaw::readers::{self, AccelerationSource, Format, ReadOptions};
use homogenise::grain_stresses;
use homogenise::tensor::Tensor2;
use nalgebra::Vector2;

fn data(dir: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("datasets/external")
        .join(dir)
}

fn lammps_files() -> Vec<PathBuf> {
    let d = data("lammps");
    [400000, 400001, 400002]
        .iter()
        .flat_map(|s| {
            [
                d.join(format!("atoms.{s}.dump.gz")),
                d.join(format!("pairs.{s}.dump.gz")),
            ]
        })
        .collect()
}

/// LAMMPS' thermo lines: step → values (c_wall[1..6], c_spair[1..3] at the end).
fn thermo() -> Vec<(u64, Vec<f64>)> {
    let text = std::fs::read_to_string(data("lammps").join("thermo.txt")).unwrap();
    text.lines()
        .filter_map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            let step = t.first()?.parse::<u64>().ok()?;
            Some((
                step,
                t.iter()
                    .skip(4)
                    .map(|v| v.parse::<f64>().unwrap())
                    .collect(),
            ))
        })
        .collect()
}

/// `Σ_p V_p Σ_c,p` over the grains, counting grain–grain contacts only (N·m).
fn pair_moment(s: &dem::Snapshot) -> Tensor2 {
    let mut pairs = s.clone();
    pairs.contacts.retain(|c| {
        s.bodies[c.body_a as usize].kind == BodyKind::Grain
            && s.bodies[c.body_b as usize].kind == BodyKind::Grain
    });
    grain_stresses(&pairs)
        .unwrap()
        .iter()
        .fold(Tensor2::zeros(), |m, g| m + g.contact * g.volume)
}

#[test]
fn lammps_contact_stress_equals_lammps_pair_virial() {
    let snaps = readers::read_lammps(&lammps_files(), &ReadOptions::default()).unwrap();
    assert_eq!(snaps.len(), 3);
    let th = thermo();
    for ext in &snaps {
        let s = &ext.snapshot;
        assert_eq!(
            s.bodies
                .iter()
                .filter(|b| b.kind == BodyKind::Grain)
                .count(),
            152
        );
        // LAMMPS' stress/atom is −(virial) per atom, `−½ Σ_j (x_i − x_j) ⊗ F_ij` in N·m for
        // 2D SI units: tension positive like grainlaw, first index the branch: its xy is
        // grainlaw's yx (grainlaw's first index is the force).
        let m = pair_moment(s);
        let l =
            common::lammps_stress_sum(&data("lammps").join(format!("atoms.{}.dump.gz", s.step)));
        let ours = [m[(0, 0)], m[(1, 1)], m[(1, 0)]];
        let scale = l.iter().map(|v| v * v).sum::<f64>().sqrt();
        let worst = (0..3).map(|k| (ours[k] - l[k]).abs()).fold(0.0, f64::max) / scale;
        eprintln!("step {}: Σ V_p Σ_c = {ours:?} N·m, LAMMPS Σ S_i = {l:?}, relative difference {worst:.1e}", s.step);
        for k in 0..3 {
            assert!(
                (ours[k] - l[k]).abs() <= 1e-9 * scale,
                "step {} component {k}: grainlaw {} LAMMPS {}",
                s.step,
                ours[k],
                l[k]
            );
        }
        // the same against the reduce of the thermo output
        let t = &th.iter().find(|(st, _)| *st == s.step).unwrap().1;
        for k in 0..3 {
            assert!((ours[k] - t[6 + k]).abs() <= 1e-9 * scale, "thermo {k}");
        }
        // compression: the pair stress moment is negative on the diagonal
        assert!(m[(0, 0)] < 0.0 && m[(1, 1)] < 0.0);
    }
}

#[test]
fn lammps_wall_loads_equal_lammps_wall_forces() {
    let snaps = readers::read_lammps(&lammps_files(), &ReadOptions::default()).unwrap();
    let th = thermo();
    for ext in &snaps {
        let s = &ext.snapshot;
        let t = &th.iter().find(|(st, _)| *st == s.step).unwrap().1;
        for (k, name) in ["left", "right", "bottom"].iter().enumerate() {
            let w = s.walls.iter().find(|w| &w.name == name).unwrap();
            // LAMMPS reports the force of the wall on the atoms; the wall receives the opposite
            let lammps = Vector2::new(-t[2 * k], -t[2 * k + 1]);
            let err = (w.force - lammps).norm();
            assert!(
                err <= 1e-12 * lammps.norm().max(1.0),
                "{name}: {} vs {}",
                w.force,
                lammps
            );
        }
        // the walls carry the weight of 152 disks (75.249 N) to within the slight residual
        // acceleration of the settling column (kinetic energy 6e-8 J)
        let weight: f64 = s
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .map(|b| b.mass * 9.81)
            .sum();
        let carried: f64 = s.walls.iter().map(|w| -w.force.y).sum();
        assert!(
            (carried - weight).abs() < 0.02 * weight,
            "{carried} vs {weight}"
        );
    }
}

#[test]
fn lammps_forces_give_accelerations_and_symmetric_stress() {
    let snaps = readers::read_lammps(&lammps_files(), &ReadOptions::default()).unwrap();
    for ext in &snaps {
        assert_eq!(ext.accelerations, AccelerationSource::File);
        // ω̇ = τ/I from the dump's torque: the inertia term cancels the skew part of the contact
        // term up to the lever difference of LAMMPS (torque at R) and the mid-overlap contact
        // point (R − δ/2), δ/R ~ 1e-4 here.
        for g in grain_stresses(&ext.snapshot).unwrap() {
            let skew = 0.5 * (g.total[(0, 1)] - g.total[(1, 0)]).abs();
            let norm = g.contact.norm();
            if norm > 0.0 {
                assert!(
                    skew <= 1e-3 * norm,
                    "grain {}: skew {skew} of {norm}",
                    g.body
                );
            }
        }
    }
    // The finite difference of the dumped velocities over one step (h = 2e-6 s) agrees with
    // the dumped f/m up to the change of f over the step (velocity Verlet averages it).
    let s1 = &snaps[1].snapshot;
    let s0 = &snaps[0].snapshot;
    let h = s1.time - s0.time;
    assert!((h - 2e-6).abs() < 1e-15);
    let mut worst: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for (b1, b0) in s1
        .bodies
        .iter()
        .zip(&s0.bodies)
        .filter(|(b, _)| b.kind == BodyKind::Grain)
    {
        let fd = (b1.velocity - b0.velocity) / h;
        worst = worst.max((fd - b1.acceleration).norm());
        scale = scale.max(b1.acceleration.norm());
    }
    assert!(
        worst < 0.05 * scale,
        "finite difference {worst} vs f/m scale {scale}"
    );
}

/// The two steps of the LMGC90 run in `d` (bodies file `bodies`, `DOF.OUT.1`–`2`,
/// `Vloc_Rloc.OUT.1`–`2`), read with grain density `density` (kg/m³) and friction `mu`.
fn lmgc90_pair(d: &Path, bodies: &str, density: f64, mu: f64) -> Vec<readers::ExternalSnapshot> {
    let files: Vec<PathBuf> = [
        bodies,
        "DOF.OUT.1",
        "DOF.OUT.2",
        "Vloc_Rloc.OUT.1",
        "Vloc_Rloc.OUT.2",
    ]
    .iter()
    .map(|f| d.join(f))
    .collect();
    let opts = ReadOptions {
        density: Some(density),
        mu: Some(mu),
        ..Default::default()
    };
    readers::read_lmgc90(&files, &opts).unwrap()
}

#[test]
fn lmgc90_hand_written_sample() {
    let snaps = lmgc90_pair(&data("lmgc90"), "BODIES.DAT", 1000.0, 0.5);
    assert_eq!(snaps.len(), 2);
    assert_eq!(
        snaps[0].accelerations,
        AccelerationSource::ForwardDifference
    );
    assert_eq!(
        snaps[1].accelerations,
        AccelerationSource::BackwardDifference
    );
    let s = &snaps[1].snapshot;
    let (r, v) = (0.1, std::f64::consts::PI * 0.01);
    let g = grain_stresses(s).unwrap();
    // upper disk (body 2): 300 N up at its bottom (lever −R ŷ): σ_yy = −300 R / V
    assert!((g[1].contact[(1, 1)] + 300.0 * r / v).abs() < 1e-9 * 300.0 * r / v);
    // lower disk (body 1): 300 N down at its top, 600 N up at its bottom, and the wall's
    // tangential 30 N along LMGC90's t = (n_y, −n_x) = +x̂ at lever −R ŷ: σ_xy = −30 R / V
    assert!((g[0].contact[(1, 1)] + 900.0 * r / v).abs() < 1e-9 * 900.0 * r / v);
    assert!((g[0].contact[(0, 1)] + 30.0 * r / v).abs() < 1e-9 * 30.0 * r / v);
    assert!(g[0].contact[(1, 0)].abs() < 1e-9);
    // finite difference: ω of body 1 goes 0 → 0.5 rad/s in 1 ms: ω̇ = 500 rad/s²; the inertia
    // term's xy is (I/(2V)) ω̇ with I = m gyrd², m = ρ π avrd²
    let m = 1000.0 * v;
    let i = m * 0.07071068f64.powi(2);
    assert!((s.bodies[0].angular_acceleration - 500.0).abs() < 1e-9);
    let expect = i / (2.0 * v) * 500.0;
    assert!((g[0].inertia[(0, 1)] - expect).abs() < 1e-9 * expect);
    assert!((s.bodies[1].acceleration.y + 1.0).abs() < 1e-9);
    // the floor (JONCx body 3) receives (−30, −600) N
    let w = &s.walls[0];
    assert_eq!(w.name, "body3");
    assert!((w.force - Vector2::new(-30.0, -600.0)).norm() < 1e-9);
    // mobilisation of the wall contact: 30 / (0.5 · 600) = 0.1
    let wc = s.contacts.iter().find(|c| c.body_a == w.body).unwrap();
    assert!((wc.mobilisation().unwrap() - 0.1).abs() < 1e-12);
}

/// `lmgc90_reference_K.csv` of the real LMGC90 run: per LMGC90 body number, LMGC90's own
/// `Coor_` (x, y, θ) and `Reac_` (force x, y and moment of its contacts), full precision.
fn lmgc90_reference(k: usize) -> BTreeMap<u64, [f64; 6]> {
    let text =
        std::fs::read_to_string(data("lmgc90/real").join(format!("lmgc90_reference_{k}.csv")))
            .unwrap();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("body"))
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            let mut row = [0.0; 6];
            for (r, x) in row.iter_mut().zip(&v[1..]) {
                *r = x.parse().unwrap();
            }
            (v[0].parse().unwrap(), row)
        })
        .collect()
}

#[test]
fn lmgc90_real_run_matches_lmgc90_positions_and_reactions() {
    // 36 disks settled for 400 steps of 1 ms in a box of three JONCx walls by LMGC90 itself
    // (datasets/external/lmgc90/real, its README): the files LMGC90 wrote, read by grainlaw,
    // against what LMGC90's solver held at the same steps. LMGC90 prints its files with 7
    // significant digits (D/E formats), hence the tolerances of a few 1e-7, relative.
    let d = data("lmgc90/real");
    for bodies in ["BODIES.DAT", "BODIES.OUT"] {
        // the pre-processor's BODIES.DAT (`axe1=`) and LMGC90's own BODIES.OUT (`ax1 =`)
        let snaps = lmgc90_pair(&d, bodies, 2500.0, 0.3);
        assert_eq!(snaps.len(), 2);
        for (k, ext) in snaps.iter().enumerate() {
            let s = &ext.snapshot;
            assert_eq!(s.step, 200 * (k as u64 + 1));
            let reference = lmgc90_reference(k + 1);
            // LMGC90 body number of every snapshot body: grains by `grain_ids`, walls by name
            let mut id = vec![0u64; s.bodies.len()];
            let grains: Vec<usize> = (0..s.bodies.len())
                .filter(|&b| s.bodies[b].kind == BodyKind::Grain)
                .collect();
            assert_eq!(grains.len(), 36);
            for (&b, &g) in grains.iter().zip(&ext.grain_ids) {
                id[b] = g;
            }
            assert_eq!(s.walls.len(), 3);
            for w in &s.walls {
                id[w.body as usize] = w.name.trim_start_matches("body").parse().unwrap();
            }
            // the resultant force and moment of each body's contacts, assembled by grainlaw
            let mut force = vec![Vector2::zeros(); s.bodies.len()];
            let mut moment = vec![0.0; s.bodies.len()];
            let cross = |l: Vector2<f64>, f: Vector2<f64>| l.x * f.y - l.y * f.x;
            let (mut dkdk, mut dkjc) = (0, 0);
            for c in &s.contacts {
                let f = c.force_on_b();
                force[c.body_b as usize] += f;
                moment[c.body_b as usize] += cross(c.lever_b, f);
                force[c.body_a as usize] -= f;
                moment[c.body_a as usize] -= cross(c.lever_a, f);
                if s.bodies[c.body_a as usize].kind == BodyKind::Grain {
                    dkdk += 1;
                } else {
                    dkjc += 1;
                }
            }
            assert!(dkdk > 40 && dkjc > 8, "{dkdk} DKDKx, {dkjc} DKJCx");
            let scale = reference
                .values()
                .map(|r| r[3].hypot(r[4]))
                .fold(0.0, f64::max);
            for (b, body) in s.bodies.iter().enumerate() {
                let r = reference[&id[b]];
                // positions: the BODIES reference coordinates plus DOF.OUT's displacement
                assert!(
                    (body.position - Vector2::new(r[0], r[1])).norm() < 2e-8,
                    "body {}: {} vs {r:?}",
                    id[b],
                    body.position
                );
                // the contact reactions: LMGC90's `Reac_` summed by LMGC90 over the same
                // contacts, against grainlaw's sum of Vloc_Rloc.OUT's rln/H n + rlt/H t
                let err = (force[b] - Vector2::new(r[3], r[4])).norm();
                assert!(
                    err < 1e-6 * scale,
                    "body {}: {} vs ({}, {}), scale {scale}",
                    id[b],
                    force[b],
                    r[3],
                    r[4]
                );
                // moments about the centre (levers of 5 mm: force × 1e-2 m), on the settled snapshot:
                // at step 200 some grains still move, and the contact points LMGC90 writes
                // (its mid-step detection configuration) are off the end-of-step centres of
                // DOF.OUT by their motion over half a step (1.7 % of the moment of body 30)
                if k == 1 {
                    assert!(
                        (moment[b] - r[5]).abs() < 1e-6 * scale * 1e-2,
                        "body {}: moment {} vs {}",
                        id[b],
                        moment[b],
                        r[5]
                    );
                }
            }
            for w in &s.walls {
                let r = reference[&id[w.body as usize]];
                assert!(
                    (w.force - Vector2::new(r[3], r[4])).norm() < 1e-6 * scale,
                    "{}",
                    w.name
                );
            }
            if k == 1 {
                // settled at step 400: every grain's contacts carry its weight m g with m = ρ π R²
                // (grainlaw's masses, LMGC90's reactions), and the walls carry the whole weight
                let mut weight = 0.0;
                for &b in &grains {
                    let m = s.bodies[b].mass;
                    assert!(
                        (m - 2500.0 * std::f64::consts::PI * s.bodies[b].radius.powi(2)).abs()
                            < 1e-12 * m
                    );
                    let r = reference[&id[b]];
                    assert!(
                        (r[4] - m * 9.81).abs() < 1e-5 * m * 9.81,
                        "body {}: {} vs m g = {}",
                        id[b],
                        r[4],
                        m * 9.81
                    );
                    weight += m * 9.81;
                }
                let carried: f64 = s.walls.iter().map(|w| -w.force.y).sum();
                assert!(
                    (carried - weight).abs() < 1e-5 * weight,
                    "{carried} vs {weight}"
                );
            }
        }
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn plain_disk_on_a_floor_and_finite_differences() {
    let dir = tempfile::tempdir().unwrap();
    // a disk of radius R, mass m at rest on the floor y = 0: the floor pushes m g up at the
    // disk's bottom. σ_yy = −m g R / (π R²), the floor receives −m g ŷ.
    let (r, m, g) = (0.01, 0.2, 9.81);
    let snap = |step: u64, t: f64, vy: f64| {
        format!(
            r#"{{"format": "grainlaw-snapshot-v1", "step": {step}, "time": {t},
  "grains": [{{"id": 7, "x": 0.5, "y": {r}, "vx": 0, "vy": {vy}, "omega": 0, "radius": {r}, "mass": {m}}}],
  "walls": [{{"name": "floor", "point": [0, 0], "normal": [0, 1]}}],
  "contacts": [{{"wall": "floor", "b": 7, "force": [0, {f}]}}]}}"#,
            f = m * g
        )
    };
    let a = write(dir.path(), "s0.json", &snap(0, 0.0, 0.0));
    let b = write(dir.path(), "s1.json", &snap(10, 0.01, -0.002));
    let snaps = readers::read_plain(&[a.clone(), b], &ReadOptions::default()).unwrap();
    let s = &snaps[1].snapshot;
    let gs = grain_stresses(s).unwrap();
    let expect = -m * g * r / (std::f64::consts::PI * r * r);
    assert!((gs[0].contact[(1, 1)] - expect).abs() < 1e-12 * expect.abs());
    assert!((s.walls[0].force - Vector2::new(0.0, -m * g)).norm() < 1e-12);
    // a = Δv/Δt = −0.2 m/s², backward for the second, forward for the first
    assert_eq!(
        snaps[1].accelerations,
        AccelerationSource::BackwardDifference
    );
    assert!((s.bodies[0].acceleration.y + 0.2).abs() < 1e-12);
    assert!((snaps[0].snapshot.bodies[0].acceleration.y + 0.2).abs() < 1e-12);
    // a single snapshot without accelerations: zero, and said so
    let one = readers::read_plain(&[a], &ReadOptions::default()).unwrap();
    assert_eq!(one[0].accelerations, AccelerationSource::Zero);
}

#[test]
fn errors_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "bad.dump",
        "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n-0.5 0.5\nITEM: ATOMS id x y vx vy omegaz radius mass\n1 0.5 0.5 0 0 0 0.1 1\n2 0.5 0.x 0 0 0 0.1 1\n",
    );
    let e = readers::read_lammps(std::slice::from_ref(&p), &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.dump:11:") && e.contains("0.x"), "{e}");
    let q = write(
        dir.path(),
        "nomass.dump",
        "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n-0.5 0.5\nITEM: ATOMS id x y vx vy omegaz radius\n1 0.5 0.5 0 0 0 0.1\n",
    );
    let e = readers::read_lammps(&[q], &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("nomass.dump:9:") && e.contains("`mass`"), "{e}");
    // the command line: one line, exit code 2
    let code = grainlaw::cli::main_with_args([
        "grainlaw",
        "homogenise",
        "--from",
        "lammps",
        p.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert_eq!("lmgc90".parse::<Format>().unwrap(), Format::Lmgc90);
    assert!("vasp".parse::<Format>().is_err());
}

#[test]
fn homogenise_command_writes_the_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut args: Vec<String> = std::iter::once(&"grainlaw")
        .chain(common::HOMOGENISE_LAMMPS)
        .map(|s| s.to_string())
        .collect();
    args.push(out.display().to_string());
    args.extend(lammps_files().iter().map(|p| p.display().to_string()));
    assert_eq!(grainlaw::cli::main_with_args(args), 0);
    for f in [
        "summary.json",
        "snapshots.csv",
        "walls.csv",
        "grains_400002.csv",
        "stress_profile.csv",
        "coarse.csv",
        "mobilisation.csv",
        "grains.png",
        "grains.pvd",
        "wall_profile_left.csv",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["snapshots"], 3);
    assert_eq!(s["acceleration_source"], "file");
    // the bottom wall carries most of the weight (75.25 N)
    let fy = s["wall_bottom_force_y_N"].as_f64().unwrap();
    assert!(fy < -70.0 && fy > -80.0, "{fy}");
    // settled packing: solid fraction of a 2D disk packing
    let phi = s["solid_fraction"].as_f64().unwrap();
    assert!(phi > 0.75 && phi < 0.91, "{phi}");
}

#[test]
fn homogenise_lists_csv_figures_and_vtk_of_every_snapshot() {
    // the library call behind the command line and Python's `grainlaw.homogenise`: the three
    // snapshots of the LAMMPS run give one per-grain table and one VTK frame (grains, contacts,
    // walls) each, the figures are PNG, every file written is listed once, summary.json last
    let dir = tempfile::tempdir().unwrap();
    let plan = grainlaw::homogenise_cmd::HomogenisePlan {
        format: Format::Lammps,
        files: lammps_files(),
        out: dir.path().join("out"),
        options: ReadOptions {
            mu: Some(0.5),
            ..Default::default()
        },
        quiet: true,
    };
    let o = grainlaw::homogenise_cmd::homogenise(&plan).unwrap();
    assert_eq!(o.files.last().map(String::as_str), Some("summary.json"));
    let mut unique = o.files.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), o.files.len(), "{:?}", o.files);
    for f in &o.files {
        let len = std::fs::metadata(plan.out.join(f)).unwrap().len();
        assert!(len > 0, "{f} empty");
    }
    let count = |pre: &str, ext: &str| {
        o.files
            .iter()
            .filter(|f| f.starts_with(pre) && f.ends_with(ext))
            .count()
    };
    assert_eq!(count("grains_", ".csv"), 3);
    for kind in ["grains", "contacts", "walls"] {
        assert_eq!(count(&format!("vtk/{kind}_"), ".vtp"), 3, "{kind}");
        let pvd = std::fs::read_to_string(plan.out.join(format!("{kind}.pvd"))).unwrap();
        assert_eq!(pvd.matches("<DataSet ").count(), 3, "{kind}.pvd");
    }
    for png in ["grains.png", "stress_profile.png"] {
        let bytes = std::fs::read(plan.out.join(png)).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{png}");
    }
    // the grains VTK frame holds every grain of its snapshot (the run has 152 disks)
    let vtp = std::fs::read_to_string(plan.out.join("vtk/grains_0002.vtp")).unwrap();
    assert!(vtp.contains("NumberOfPoints=\"152\""), "{}", &vtp[..300]);
    assert_eq!(o.lines[0], format!("report: {}/", plan.out.display()));
}

#[test]
fn synthetic_benchmark_dump_reads_back() {
    // the generator of `grainlaw bench --homogenise-grains`: a 20 × 20 square lattice has
    // 2 · 20 · 19 = 760 neighbour contacts, and a lattice of spacing 0.999 d a solid fraction
    // of π/4 / 0.999² inside its cells
    let dir = tempfile::tempdir().unwrap();
    let (c, read_s, hom_s) = grainlaw::homogenise_cmd::bench_homogenise(400, dir.path()).unwrap();
    assert_eq!(c, 760);
    assert!(read_s >= 0.0 && hom_s >= 0.0);
    let (atoms, pairs) = grainlaw::homogenise_cmd::synthetic_lammps_dump(400);
    let a = write(dir.path(), "a.dump", &atoms);
    let p = write(dir.path(), "p.dump", &pairs);
    let s = &readers::read_lammps(&[a, p], &ReadOptions::default()).unwrap()[0].snapshot;
    let phi = homogenise::state::solid_fraction(s, &homogenise::Region::Whole).unwrap();
    // the whole-sample box is the grains' extent, 19 spacings plus one diameter wide and high (in d)
    let w = 19.0 * 0.999 + 1.0;
    let expect = 400.0 * std::f64::consts::PI * 0.25 / (w * w);
    assert!((phi - expect).abs() < 1e-9, "{phi} vs {expect}");
}

#[test]
fn liggghts_wall_contacts_from_wall_gran_local() {
    // LIGGGHTS `compute wgl all wall/gran/local pos id force` dumped as c_wgl[1..12]:
    // contact point (3), particle centre (3), mesh id, triangle id, particle id, force (3).
    // Two disks of radius 0.01 m pressed 0.1 mm into the floor y = 0.
    let dir = tempfile::tempdir().unwrap();
    let atoms = write(
        dir.path(),
        "atoms.dump",
        "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n-0.5 0.5\nITEM: ATOMS id x y vx vy omegaz radius mass\n1 0.1 0.0099 0 0 0 0.01 0.5\n2 0.3 0.0099 0 0 0 0.01 0.5\n",
    );
    let walls = write(
        dir.path(),
        "walls.dump",
        "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ENTRIES\n2\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n-0.5 0.5\nITEM: ENTRIES c_wgl[1] c_wgl[2] c_wgl[3] c_wgl[4] c_wgl[5] c_wgl[6] c_wgl[7] c_wgl[8] c_wgl[9] c_wgl[10] c_wgl[11] c_wgl[12]\n0.1 0 0 0.1 0.0099 0 4 17 1 0.2 5.0 0\n0.3 0 0 0.3 0.0099 0 4 18 2 -0.1 3.0 0\n",
    );
    let columns = [
        ("wall.wall", 7),
        ("wall.id", 9),
        ("wall.fx", 10),
        ("wall.fy", 11),
        ("wall.cx", 1),
        ("wall.cy", 2),
    ]
    .iter()
    .map(|(k, c)| (k.to_string(), format!("c_wgl[{c}]")))
    .collect();
    let opts = ReadOptions {
        columns,
        dt: Some(1e-5),
        ..Default::default()
    };
    let s = &readers::read_lammps(&[atoms, walls], &opts).unwrap()[0].snapshot;
    assert_eq!(s.walls.len(), 1);
    let w = &s.walls[0];
    assert_eq!(w.name, "wall4");
    // the wall receives minus the forces on the particles
    assert!((w.force - Vector2::new(-0.1, -8.0)).norm() < 1e-12);
    // grain 1: 5 N up and 0.2 N along x at the contact point 9.9 mm below its centre
    let g = grain_stresses(s).unwrap();
    let v = std::f64::consts::PI * 1e-4;
    assert!((g[0].contact[(1, 1)] + 5.0 * 0.0099 / v).abs() < 1e-9);
    assert!((g[0].contact[(0, 1)] + 0.2 * 0.0099 / v).abs() < 1e-9);
    // the wall is the line y = 0 with its normal up
    match &w.geometry {
        dem::snapshot::WallGeometry::Line { point, normal } => {
            assert!(point.y.abs() < 1e-15 && (normal - Vector2::new(0.0, 1.0)).norm() < 1e-12);
        }
        other => panic!("{other:?}"),
    }
}

/// Runs the grainlaw executable: (exit code, stdout, stderr).
fn grainlaw_exe(args: &[&str]) -> (Option<i32>, String, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).to_string(),
        String::from_utf8_lossy(&o.stderr).to_string(),
    )
}

#[test]
fn walls_take_their_own_friction() {
    // the example's walls are at 0.3, its grains at 0.5 (in.settle2d)
    let opts = ReadOptions {
        mu: Some(0.5),
        wall_mu: Some(0.3),
        ..Default::default()
    };
    let snaps = readers::read_lammps(&lammps_files(), &opts).unwrap();
    let s = &snaps[2].snapshot;
    let (mut walls, mut pairs) = (0, 0);
    for c in &s.contacts {
        let wall = s.bodies[c.body_a as usize].kind == BodyKind::Wall;
        assert_eq!(c.mu, if wall { 0.3 } else { 0.5 });
        if wall {
            walls += 1;
        } else {
            pairs += 1;
        }
    }
    assert!(
        walls > 10 && pairs > 100,
        "{walls} wall, {pairs} pair contacts"
    );
    // without --wall-mu the walls take --mu
    let one = readers::read_lammps(
        &lammps_files(),
        &ReadOptions {
            mu: Some(0.5),
            ..Default::default()
        },
    )
    .unwrap();
    assert!(one[2].snapshot.contacts.iter().all(|c| c.mu == 0.5));
}

#[test]
fn dumps_of_a_column_to_a_janssen_law_in_two_commands() {
    // datasets/external/lammps/column: 228 disks between walls 30 mm apart, the floor sinking
    // (its README). `homogenise` writes janssen.csv in the form `fit janssen` reads; the
    // released column's wall friction is mobilised, and the law comes out.
    let d = data("lammps/column");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("h");
    let (code, stdout, stderr) = grainlaw_exe(&[
        "homogenise",
        "--from",
        "lammps",
        "--mu",
        "0.5",
        "--wall-mu",
        "0.3",
        "--out",
        out.to_str().unwrap(),
        d.join("atoms.450000.dump.gz").to_str().unwrap(),
        d.join("pairs.450000.dump.gz").to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    // the report names the stress ratio it prints: q/p, the invariants' ratio
    assert!(
        stdout.contains("q/p = ") && !stdout.contains("τ/P"),
        "{stdout}"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let ratio = s["stress_ratio"].as_f64().unwrap();
    let q_over_p = s["shear_stress_Pa"].as_f64().unwrap() / s["pressure_Pa"].as_f64().unwrap();
    assert!((ratio - q_over_p).abs() < 1e-12);
    assert!(stdout.contains(&format!("q/p = {ratio:.4}")), "{stdout}");
    let table = out.join("janssen.csv");
    let text = std::fs::read_to_string(&table).unwrap();
    for key in [
        "width_m = 3",
        "wall_friction = 3e-1",
        "bulk_density_kg_m3 = ",
    ] {
        assert!(text.contains(key), "{key}: {text}");
    }
    let law = dir.path().join("janssen_law.json");
    let (code, stdout, stderr) = grainlaw_exe(&[
        "fit",
        "janssen",
        table.to_str().unwrap(),
        "--out",
        law.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&law).unwrap()).unwrap();
    let param = |n: &str| {
        json["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == n)
            .unwrap()["value"]
            .as_f64()
            .unwrap()
    };
    // a Janssen column: K of order 1, the wall friction mobilised below its 0.3
    let (k, mu_w) = (param("K"), param("mu_w"));
    assert!(
        k > 0.3 && k < 3.0 && mu_w > 0.0 && mu_w < 0.3,
        "K = {k}, mu_w = {mu_w}"
    );
    // the per-wall profiles say which table a fit reads
    let w = std::fs::read_to_string(out.join("wall_profile_left.csv")).unwrap();
    assert!(w.contains("grainlaw fit janssen janssen.csv"));
}
