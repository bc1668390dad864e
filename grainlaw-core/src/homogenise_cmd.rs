//! `grainlaw homogenise --from FORMAT FILES...`: snapshots of another DEM code
//! ([`crate::readers`]) homogenised as a scenario's are (`docs/cli.md`, outputs in
//! `docs/outputs.md` § "homogenise"): per-grain and whole-sample mean stress with its contact
//! (Love–Weber) and inertia parts (`docs/physics.md` §2.1–2.2), solid fraction, coordination,
//! fabric, wall loads and wall stress profiles, the vertical stress by slices, force
//! polarisation (friction mobilisation), Gaussian coarse-grained fields, figures, VTK; for a
//! column between two vertical walls the table `grainlaw fit janssen` reads (`janssen.csv`),
//! and for a series of a sheared biperiodic cell the point of μ(I), φ(I) (`rheology.csv`,
//! [`crate::rve`]).

use std::path::PathBuf;

use dem::snapshot::{Snapshot, WallGeometry};
use homogenise::coarse::{coarse_grain, Grid};
use homogenise::depth::{DepthAxis, DepthBins};
use homogenise::invariants::stress_invariants;
use homogenise::mobilisation::{contact_mobilisations, mobilisation_stats, ContactClass};
use homogenise::state::{coordination, fabric, solid_fraction, ContactCounting};
use homogenise::stress::{grain_stresses, mean_stress, slice_stress_profile};
use homogenise::walls::wall_stress_profile;
use homogenise::{Region, Tensor2};

use crate::error::{CliError, Result};
use crate::output::vtk::VtkSeries;
use crate::output::{CsvTable, OutputDir, Summary};
use crate::plot::colormap::Scale;
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_xy, Axis, Series, Style, XyPlot};
use crate::readers::{self, ExternalSnapshot, Format, ReadOptions};

/// What `grainlaw homogenise` was asked.
#[derive(Debug, Clone)]
pub struct HomogenisePlan {
    /// Input format.
    pub format: Format,
    /// Input files.
    pub files: Vec<PathBuf>,
    /// Output directory.
    pub out: PathBuf,
    /// Reader options.
    pub options: ReadOptions,
    /// No report on stdout.
    pub quiet: bool,
}

/// The stress columns of the whole-sample and per-grain tables (Pa, tension positive): the
/// total mean stress, its contact (Love–Weber) part and its inertia part.
const STRESS_COLUMNS: [&str; 12] = [
    "sigma_xx_Pa",
    "sigma_xy_Pa",
    "sigma_yx_Pa",
    "sigma_yy_Pa",
    "contact_sigma_xx_Pa",
    "contact_sigma_xy_Pa",
    "contact_sigma_yx_Pa",
    "contact_sigma_yy_Pa",
    "inertia_sigma_xx_Pa",
    "inertia_sigma_xy_Pa",
    "inertia_sigma_yx_Pa",
    "inertia_sigma_yy_Pa",
];

/// Parses `KEY=HEADER` column overrides.
pub fn parse_columns(items: &[String]) -> Result<Vec<(String, String)>> {
    items
        .iter()
        .map(|s| {
            s.split_once('=')
                .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                .filter(|(k, v)| !k.is_empty() && !v.is_empty())
                .ok_or_else(|| CliError::Usage(format!("--column `{s}`: expected KEY=HEADER")))
        })
        .collect()
}

fn t4(t: &Tensor2) -> [f64; 4] {
    [t[(0, 0)], t[(0, 1)], t[(1, 0)], t[(1, 1)]]
}

fn mean_diameter(s: &Snapshot) -> f64 {
    let (sum, n) = s
        .bodies
        .iter()
        .filter(|b| b.kind == dem::snapshot::BodyKind::Grain)
        .fold((0.0, 0usize), |(a, n), b| (a + 2.0 * b.radius, n + 1));
    if n > 0 {
        sum / n as f64
    } else {
        0.0
    }
}

/// What [`homogenise()`] did: the report lines and the files it wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct HomogeniseOutcome {
    /// The report printed by the command line (last snapshot's state, wall forces).
    pub lines: Vec<String>,
    /// The files written, relative to the output directory, in the order written
    /// (`summary.json` last).
    pub files: Vec<String>,
}

/// Reads the files, homogenises every snapshot, writes the outputs (CSV tables, figures, VTK
/// series, `summary.json`; `docs/outputs.md` § "homogenise"); returns the report and the files.
/// The one implementation behind `grainlaw homogenise` and the Python `grainlaw.homogenise`.
///
/// Stages: options checked → the files read → per-snapshot tables (`SeriesTables`) → the
/// last snapshot's outputs (`last_outputs`), Janssen table, cell and simple-shear point →
/// summary and report.
pub fn homogenise(plan: &HomogenisePlan) -> Result<HomogeniseOutcome> {
    check_options(plan)?;
    let snaps = readers::read(plan.format, &plan.files, &plan.options)
        .map_err(|e| CliError::Usage(e.to_string()))?;
    if plan.out.exists() && !plan.out.is_dir() {
        return Err(CliError::Usage(format!(
            "--out {}: is a file, not a directory",
            plan.out.display()
        )));
    }
    let mut out = OutputDir::create(&plan.out)?;
    let started = std::time::Instant::now();
    let mut series = SeriesTables::new();
    let mut summary = summary_header(plan, &snaps);
    for ext in &snaps {
        series.add(&mut out, ext)?;
    }
    let (wall_names, last_lines) = series.finish(&mut out)?;
    let last = snaps
        .last()
        .ok_or_else(|| CliError::Usage("homogenise: no snapshot read".into()))?;
    last_outputs(&mut out, last, &mut summary)?;
    janssen_table(&mut out, &snaps, &plan.options, &mut summary)?;
    summary.set("walls", wall_names.into());
    if let Some(c) = last.snapshot.cell {
        summary
            .set(
                "cell_matrix_m",
                vec![c.h[(0, 0)], c.h[(0, 1)], c.h[(1, 0)], c.h[(1, 1)]].into(),
            )
            .num("cell_area_m2", c.volume());
    }
    let rve = crate::rve::rve_point(&snaps)?;
    if let Some(p) = &rve {
        p.write(&mut out)?;
        p.keys(&mut summary);
    }
    let s = &last.snapshot;
    for w in &s.walls {
        summary
            .num(&format!("wall_{}_force_x_N", w.name), w.force.x)
            .num(&format!("wall_{}_force_y_N", w.name), w.force.y);
    }
    summary.num("wall_seconds", started.elapsed().as_secs_f64());
    out.write("summary.json", summary.to_json().as_bytes())?;
    let mut lines = vec![format!("report: {}/", plan.out.display())];
    lines.extend(last_lines);
    for w in &s.walls {
        lines.push(format!(
            "wall {}: force ({:.6e}, {:.6e}) N",
            w.name, w.force.x, w.force.y
        ));
    }
    if let Some(p) = &rve {
        lines.extend(p.lines());
        refuse_rve(plan, p)?;
    }
    Ok(HomogeniseOutcome {
        lines,
        files: out.written().to_vec(),
    })
}

/// Checks the plan's files and friction and inertia settings. Errors: [`CliError::Usage`].
fn check_options(plan: &HomogenisePlan) -> Result<()> {
    if plan.files.is_empty() {
        return Err(CliError::Usage("homogenise: no input file".into()));
    }
    if let Some(mu) = plan.options.mu {
        if !(mu.is_finite() && mu > 0.0) {
            return Err(CliError::Usage(format!(
                "--mu must be finite and > 0, got {mu}"
            )));
        }
    }
    if let Some(mu) = plan.options.wall_mu {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(CliError::Usage(format!(
                "--wall-mu must be finite and ≥ 0, got {mu}"
            )));
        }
    }
    if !(plan.options.inertia_factor.is_finite() && plan.options.inertia_factor > 0.0) {
        return Err(CliError::Usage(
            "--inertia-factor must be finite and > 0".into(),
        ));
    }
    Ok(())
}

/// A refused simple-shear point is an error ([`CliError::Verdict`]).
fn refuse_rve(plan: &HomogenisePlan, p: &crate::rve::RvePoint) -> Result<()> {
    if p.verdict == crate::verdict::Verdict::Refused {
        return Err(CliError::Verdict {
            dir: plan.out.display().to_string(),
            reason: format!(
                "the simple-shear point is refused (rheology.csv, point_verdict 2): {}",
                p.checks
                    .reasons
                    .iter()
                    .map(|r| r.message.as_str())
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        });
    }
    Ok(())
}

/// The summary's keys that describe the input: command, format, files, snapshots, the
/// sources of the accelerations and of the velocity gradients.
fn summary_header(plan: &HomogenisePlan, snaps: &[ExternalSnapshot]) -> Summary {
    let mut summary = Summary::new();
    summary
        .text("command", "homogenise")
        .text(
            "format",
            match plan.format {
                Format::Lammps => "lammps",
                Format::Lmgc90 => "lmgc90",
                Format::Plain => "plain",
            },
        )
        .set(
            "files",
            plan.files
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .into(),
        )
        .int("snapshots", snaps.len() as u64)
        .set(
            "accelerations",
            snaps
                .iter()
                .map(|s| s.accelerations.name())
                .collect::<Vec<_>>()
                .into(),
        );
    if snaps.iter().any(|s| s.velocity_gradient.is_some()) {
        summary.set(
            "velocity_gradients",
            snaps
                .iter()
                .map(|s| s.velocity_gradient.map_or("none", |g| g.name()))
                .collect::<Vec<_>>()
                .into(),
        );
    }
    summary
}

/// The tables of the series of snapshots: `snapshots.csv`, `walls.csv`, the VTK series, and
/// the report lines of the last snapshot.
struct SeriesTables {
    /// `snapshots.csv`.
    table: CsvTable,
    /// `walls.csv`.
    walls: CsvTable,
    /// The VTK series.
    vtk: VtkSeries,
    /// The walls' names, in the order of their first appearance.
    wall_names: Vec<String>,
    /// The report lines of the last snapshot added.
    last_lines: Vec<String>,
}

impl SeriesTables {
    /// Empty tables with their columns and comments.
    fn new() -> Self {
        let mut table = CsvTable::new(
            &[
                &[
                    "step",
                    "time_s",
                    "grains",
                    "contacts",
                    "solid_fraction",
                    "z",
                    "z_without_rattlers",
                    "rattler_fraction",
                    "fabric_anisotropy",
                    "fabric_major_angle_rad",
                ][..],
                &STRESS_COLUMNS,
                &[
                    "pressure_Pa",
                    "shear_stress_Pa",
                    "stress_ratio",
                    "mean_mobilisation",
                    "fraction_at_limit",
                ],
            ]
            .concat(),
        );
        table
            .comments
            .push("whole-sample means per snapshot (grainlaw homogenise)".into());
        let mut walls = CsvTable::new(&[
            "step",
            "wall",
            "force_x_N",
            "force_y_N",
            "torque_Nm",
            "contacts",
        ]);
        walls
            .comments
            .push("wall index: the order of `walls` in summary.json".into());
        SeriesTables {
            table,
            walls,
            vtk: VtkSeries::new(),
            wall_names: Vec::new(),
            last_lines: Vec::new(),
        }
    }

    /// Adds one snapshot: its row, its `grains_STEP.csv`, its walls' rows, its VTK frame.
    fn add(&mut self, out: &mut OutputDir, ext: &ExternalSnapshot) -> Result<()> {
        let s = &ext.snapshot;
        let (row, grains) = snapshot_row(ext)?;
        let (phi, z, whole_total) = (row.phi, row.z, row.whole_total);
        let inv = stress_invariants(&whole_total);
        self.table.push(row.values);
        let mut g =
            CsvTable::new(&[&["id", "x_m", "y_m", "radius_m"][..], &STRESS_COLUMNS].concat());
        g.comments.push(format!(
            "per-grain mean stress at step {} (t = {} s), accelerations: {}",
            s.step,
            s.time,
            ext.accelerations.name()
        ));
        for (id, gs) in ext.grain_ids.iter().zip(&grains) {
            let mut r = vec![*id as f64, gs.position.x, gs.position.y, gs.radius];
            r.extend(t4(&gs.total));
            r.extend(t4(&gs.contact));
            r.extend(t4(&gs.inertia));
            g.push(r);
        }
        g.write(out, &format!("grains_{}.csv", s.step))?;
        for w in &s.walls {
            let k = match self.wall_names.iter().position(|n| n == &w.name) {
                Some(k) => k,
                None => {
                    self.wall_names.push(w.name.clone());
                    self.wall_names.len() - 1
                }
            };
            let nc = s
                .contacts
                .iter()
                .filter(|c| c.body_a == w.body || c.body_b == w.body)
                .count();
            self.walls.push(vec![
                s.step as f64,
                k as f64,
                w.force.x,
                w.force.y,
                w.torque,
                nc as f64,
            ]);
        }
        self.vtk.add_frame(out, s)?;
        self.last_lines = vec![
            format!(
                "step {} (t = {:.6} s): {} grains, {} contacts, φ = {:.4}, Z = {:.3}, accelerations: {}",
                s.step, s.time, grains.len(), s.contacts.len(), phi, z, ext.accelerations.name()
            ),
            format!(
                "mean stress (Pa, tension > 0): σxx = {:.4e}, σyy = {:.4e}, σxy = {:.4e}; p = {:.4e}, q/p = {}",
                whole_total[(0, 0)], whole_total[(1, 1)], 0.5 * (whole_total[(0, 1)] + whole_total[(1, 0)]),
                inv.pressure, inv.friction.map_or("-".into(), |f| format!("{f:.4}"))
            ),
        ];
        Ok(())
    }

    /// Writes `snapshots.csv`, `walls.csv` (when there are walls) and the VTK series; returns
    /// the walls' names and the last snapshot's report lines.
    fn finish(self, out: &mut OutputDir) -> Result<(Vec<String>, Vec<String>)> {
        self.table.write(out, "snapshots.csv")?;
        if !self.wall_names.is_empty() {
            self.walls.write(out, "walls.csv")?;
        }
        self.vtk.finish(out)?;
        Ok((self.wall_names, self.last_lines))
    }
}

/// The row of `snapshots.csv` of one snapshot (whole-sample means: solid fraction,
/// coordination, fabric, mean stress and its parts, invariants, mobilisation) and the per-grain
/// stresses.
/// One snapshot's row of the series table ([`snapshot_row`]): its values in the table's column
/// order, with the ones the report reads kept by name.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesRow {
    /// The row's values, in the series table's column order.
    pub values: Vec<f64>,
    /// Solid fraction of the whole sample (1).
    pub phi: f64,
    /// Coordination number `Z` (contacts per grain, rattlers included).
    pub z: f64,
    /// Whole-sample mean stress, total (Pa, tension positive).
    pub whole_total: Tensor2,
}

/// The series row of one snapshot ([`SeriesRow`]) and its grains' mean stresses.
pub fn snapshot_row(ext: &ExternalSnapshot) -> Result<(SeriesRow, Vec<homogenise::GrainStress>)> {
    let s = &ext.snapshot;
    let counting = ContactCounting::default();
    let grains = grain_stresses(s)?;
    let whole = mean_stress(s, &grains, &Region::Whole)?;
    let phi = solid_fraction(s, &Region::Whole)?;
    let z = coordination(s, &Region::Whole, &counting)?;
    let fab = fabric(s, &Region::Whole, &counting)?;
    let inv = stress_invariants(&whole.total);
    let mob: Vec<f64> = contact_mobilisations(s, &ContactClass::All)?
        .into_iter()
        .map(|(_, m)| m)
        .collect();
    let ms = mobilisation_stats(&mob, 20, homogenise::mobilisation::COULOMB_LIMIT)?;
    let mut row = vec![
        s.step as f64,
        s.time,
        grains.len() as f64,
        s.contacts.len() as f64,
        phi,
        z.z,
        z.z_without_rattlers,
        z.rattler_fraction,
        fab.anisotropy,
        fab.major_angle,
    ];
    row.extend(t4(&whole.total));
    row.extend(t4(&whole.contact));
    row.extend(t4(&whole.inertia));
    row.extend([
        inv.pressure,
        inv.shear_stress,
        inv.friction.unwrap_or(f64::NAN),
        ms.mean.unwrap_or(f64::NAN),
        ms.fraction_at_limit.unwrap_or(f64::NAN),
    ]);
    Ok((
        SeriesRow {
            values: row,
            phi,
            z: z.z,
            whole_total: whole.total,
        },
        grains,
    ))
}

/// A synthetic LAMMPS snapshot for the benchmark: `n` disks of radius 0.5 mm on a square
/// lattice of spacing 0.999 mm (side `⌈√n⌉`), each in contact with its right and upper
/// neighbours (about `2n` contacts), pseudo-random velocities and forces: the per-atom dump
/// (with `fx fy tqz`) and the local dump, in the column names of `docs/formats.md` §7.1.
pub fn synthetic_lammps_dump(n: usize) -> (String, String) {
    use std::fmt::Write as _;
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    let (r, a) = (5e-4, 9.99e-4);
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mass = 2500.0 * std::f64::consts::PI * r * r;
    let mut atoms = format!(
        "ITEM: TIMESTEP\n1000\nITEM: NUMBER OF ATOMS\n{n}\nITEM: BOX BOUNDS ff ff pp\n0 {l}\n0 {l}\n-0.0005 0.0005\nITEM: ATOMS id x y vx vy omegaz radius mass fx fy tqz\n",
        l = side as f64 * a
    );
    for i in 0..n {
        let (cx, cy) = ((i % side) as f64 * a + r, (i / side) as f64 * a + r);
        let _ = writeln!(
            atoms,
            "{} {cx:.17e} {cy:.17e} {:.17e} {:.17e} {:.17e} {r:.17e} {mass:.17e} {:.17e} {:.17e} {:.17e}",
            i + 1, 1e-3 * rnd(), 1e-3 * rnd(), 1e-1 * rnd(), 1e-2 * rnd(), 1e-2 * rnd(), 1e-6 * rnd()
        );
    }
    let mut rows = String::new();
    let mut count = 0usize;
    for i in 0..n {
        for j in [i + 1, i + side] {
            if j >= n || (j == i + 1 && (i + 1) % side == 0) {
                continue;
            }
            let (nx, ny) = if j == i + 1 { (-1.0, 0.0) } else { (0.0, -1.0) };
            let fn_ = 1.0 + rnd().abs();
            let ft = 0.3 * fn_ * rnd();
            let _ = writeln!(
                rows,
                "{} {} {a:.17e} {:.17e} {:.17e} {:.17e} {:.17e} 0",
                i + 1,
                j + 1,
                fn_ * nx,
                fn_ * ny,
                -ft * ny,
                ft * nx
            );
            count += 1;
        }
    }
    let pairs = format!(
        "ITEM: TIMESTEP\n1000\nITEM: NUMBER OF ENTRIES\n{count}\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n-0.0005 0.0005\nITEM: ENTRIES c_ids[1] c_ids[2] c_pf[1] c_pf[2] c_pf[3] c_pf[4] c_pf[5] c_pf[6]\n{rows}"
    );
    (atoms, pairs)
}

/// Benchmark row: writes a synthetic dump of `n` grains (and about `2n` contacts) into `dir`,
/// then times reading it ([`crate::readers::read_lammps`]) and homogenising it
/// ([`snapshot_row`]: per-grain stresses, whole-sample means, fabric, coordination,
/// mobilisation). Returns `(contacts, read seconds, homogenise seconds)`.
pub fn bench_homogenise(n: usize, dir: &std::path::Path) -> Result<(usize, f64, f64)> {
    let (atoms, pairs) = synthetic_lammps_dump(n);
    let a = dir.join(format!("bench_atoms_{n}.dump"));
    let p = dir.join(format!("bench_pairs_{n}.dump"));
    std::fs::write(&a, atoms).map_err(|e| CliError::io(&a, e))?;
    std::fs::write(&p, pairs).map_err(|e| CliError::io(&p, e))?;
    let t0 = std::time::Instant::now();
    let snaps = readers::read_lammps(
        &[a.clone(), p.clone()],
        &ReadOptions {
            mu: Some(0.5),
            ..Default::default()
        },
    )
    .map_err(|e| CliError::Usage(e.to_string()))?;
    let t1 = std::time::Instant::now();
    let mut contacts = 0;
    for ext in &snaps {
        snapshot_row(ext)?;
        contacts += ext.snapshot.contacts.len();
    }
    let t2 = std::time::Instant::now();
    let _ = std::fs::remove_file(&a);
    let _ = std::fs::remove_file(&p);
    Ok((contacts, (t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64()))
}

/// The outputs of the last snapshot: summary keys ([`last_summary_keys`]), the stress by
/// slice, the walls' stress profiles, the mobilisation, the coarse-grained fields and the
/// picture of the grains.
fn last_outputs(out: &mut OutputDir, ext: &ExternalSnapshot, summary: &mut Summary) -> Result<()> {
    let s = &ext.snapshot;
    let grains = grain_stresses(s)?;
    last_summary_keys(ext, &grains, summary)?;
    let d = mean_diameter(s);
    slice_profile(out, s, &grains, d)?;
    wall_profiles(out, s, d)?;
    mobilisation_outputs(out, s, summary)?;
    if d > 0.0 {
        coarse_fields(out, s, &grains, d)?;
    }
    grains_figure(out, s, &grains)
}

/// The summary's whole-sample keys of the last snapshot: counts, solid fraction,
/// coordination, fabric, mean stress and its parts, invariants.
fn last_summary_keys(
    ext: &ExternalSnapshot,
    grains: &[homogenise::GrainStress],
    summary: &mut Summary,
) -> Result<()> {
    let s = &ext.snapshot;
    let whole = mean_stress(s, grains, &Region::Whole)?;
    let counting = ContactCounting::default();
    let inv = stress_invariants(&whole.total);
    let z = coordination(s, &Region::Whole, &counting)?;
    let fab = fabric(s, &Region::Whole, &counting)?;
    summary
        .int("step", s.step)
        .num("time_s", s.time)
        .int("grains", grains.len() as u64)
        .int("contacts", s.contacts.len() as u64)
        .text("acceleration_source", ext.accelerations.name())
        .num("solid_fraction", solid_fraction(s, &Region::Whole)?)
        .num("coordination", z.z)
        .num("coordination_without_rattlers", z.z_without_rattlers)
        .num("rattler_fraction", z.rattler_fraction)
        .num("fabric_anisotropy", fab.anisotropy)
        .num("fabric_major_angle_rad", fab.major_angle);
    for (name, t) in [
        ("sigma", whole.total),
        ("contact_sigma", whole.contact),
        ("inertia_sigma", whole.inertia),
    ] {
        let [xx, xy, yx, yy] = t4(&t);
        summary
            .num(&format!("{name}_xx_Pa"), xx)
            .num(&format!("{name}_xy_Pa"), xy)
            .num(&format!("{name}_yx_Pa"), yx)
            .num(&format!("{name}_yy_Pa"), yy);
    }
    summary
        .num("pressure_Pa", inv.pressure)
        .num("shear_stress_Pa", inv.shear_stress)
        .num("stress_ratio", inv.friction.unwrap_or(f64::NAN));
    Ok(())
}

/// `stress_profile.csv` and `.png`: the mean stress in horizontal slices of two mean
/// diameters `d` (nothing without grains).
fn slice_profile(
    out: &mut OutputDir,
    s: &Snapshot,
    grains: &[homogenise::GrainStress],
    d: f64,
) -> Result<()> {
    let Some((_, _, y0, y1)) = grain_extent(s) else {
        return Ok(());
    };
    let h = 2.0 * d;
    let k = ((y1 - y0) / h).ceil().max(1.0) as usize;
    let edges: Vec<f64> = (0..=k).map(|i| y0 + i as f64 * h).collect();
    let prof = slice_stress_profile(s, grains, &edges)?;
    let mut t = CsvTable::new(&[
        "y_m",
        "sigma_xx_Pa",
        "sigma_xy_Pa",
        "sigma_yx_Pa",
        "sigma_yy_Pa",
        "solid_area_fraction",
    ]);
    t.comments.push(format!(
        "mean stress in horizontal slices of {h:e} m, step {}",
        s.step
    ));
    let mut pts = Vec::new();
    for (w, r) in edges.windows(2).zip(&prof) {
        let y = 0.5 * (w[0] + w[1]);
        let mut row = vec![y];
        row.extend(t4(&r.total));
        row.push(r.grain_area / r.area);
        t.push(row);
        pts.push((-r.total[(1, 1)], y));
    }
    t.write(out, "stress_profile.csv")?;
    let mut plot = XyPlot::new(
        "vertical stress by slice",
        Axis::new("−σyy (Pa)"),
        Axis::new("y (m)"),
    );
    plot.series.push(Series::new(
        "−σyy",
        Style::LinePoints,
        crate::plot::colormap::viridis(0.2),
        pts,
    ));
    draw_xy(out, "stress_profile.png", &plot)
}

/// `wall_profile_NAME.csv`: the stress profile along each wall (clumps left out) in depth
/// bins of two mean diameters `d` along gravity (nothing without gravity).
fn wall_profiles(out: &mut OutputDir, s: &Snapshot, d: f64) -> Result<()> {
    let Ok(axis) = DepthAxis::from_gravity(s) else {
        return Ok(());
    };
    let top = grain_extent(s).map(|e| e.3 - e.2).unwrap_or(0.0);
    let width = 2.0 * d;
    let count = ((top / width).ceil() as usize).max(1);
    let Ok(bins) = DepthBins::new(axis, width, count) else {
        return Ok(());
    };
    for w in &s.walls {
        if matches!(w.geometry, WallGeometry::Clump { .. }) {
            continue;
        }
        let Ok(p) = wall_stress_profile(s, &w.name, &bins) else {
            continue;
        };
        let mut t = CsvTable::new(&[
            "depth_m",
            "normal_stress_Pa",
            "shear_stress_Pa",
            "contacts",
            "mean_mobilisation",
        ]);
        t.comments.push(format!(
            "wall `{}`, step {}, bins of {width:e} m along gravity; one wall's stresses, tension positive: the table a Janssen fit reads is janssen.csv (grainlaw fit janssen janssen.csv)",
            w.name, s.step
        ));
        for b in &p {
            t.push(vec![
                b.depth(),
                b.normal_stress,
                b.shear_stress,
                b.contacts as f64,
                b.mean_mobilisation.unwrap_or(f64::NAN),
            ]);
        }
        t.write(out, &format!("wall_profile_{}.csv", sanitize(&w.name)))?;
    }
    Ok(())
}

/// Force polarisation: the mobilisation of friction (it needs a friction coefficient), its
/// summary keys and `mobilisation.csv` (its histogram).
fn mobilisation_outputs(out: &mut OutputDir, s: &Snapshot, summary: &mut Summary) -> Result<()> {
    let mob: Vec<f64> = contact_mobilisations(s, &ContactClass::All)?
        .into_iter()
        .map(|(_, m)| m)
        .collect();
    let ms = mobilisation_stats(&mob, 20, homogenise::mobilisation::COULOMB_LIMIT)?;
    summary
        .int("mobilisation_contacts", ms.contacts as u64)
        .num("mean_mobilisation", ms.mean.unwrap_or(f64::NAN))
        .num(
            "fraction_at_coulomb_limit",
            ms.fraction_at_limit.unwrap_or(f64::NAN),
        );
    if ms.contacts > 0 {
        let mut t = CsvTable::new(&["mobilisation_low", "mobilisation_high", "fraction"]);
        for (e, f) in ms.histogram.edges.windows(2).zip(ms.histogram.fractions()) {
            t.push(vec![e[0], e[1], f]);
        }
        t.write(out, "mobilisation.csv")?;
    }
    Ok(())
}

/// `coarse.csv`: Gaussian coarse-grained fields of width one mean diameter `d`, nodes every
/// half diameter (left out above 4 million nodes).
fn coarse_fields(
    out: &mut OutputDir,
    s: &Snapshot,
    grains: &[homogenise::GrainStress],
    d: f64,
) -> Result<()> {
    let grid = Grid::covering(s, 0.5 * d, 5.0 * d)?;
    if grid.nx * grid.ny > 4_000_000 {
        return Ok(());
    }
    let f = coarse_grain(s, grains, &grid, d, 5.0)?;
    let mut t = CsvTable::new(&[
        "x_m",
        "y_m",
        "density_kg_m3",
        "velocity_x_m_s",
        "velocity_y_m_s",
        "sigma_xx_Pa",
        "sigma_xy_Pa",
        "sigma_yx_Pa",
        "sigma_yy_Pa",
    ]);
    t.comments.push(format!(
        "Gaussian coarse graining, width {d:e} m, cutoff 5 widths, step {}",
        s.step
    ));
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let x = grid.node(i, j);
            let st = f.stress.at(i, j);
            t.push(vec![
                x.x,
                x.y,
                f.density[[j, i]],
                f.velocity_x[[j, i]],
                f.velocity_y[[j, i]],
                st[(0, 0)],
                st[(0, 1)],
                st[(1, 0)],
                st[(1, 1)],
            ]);
        }
    }
    t.write(out, "coarse.csv")
}

/// `grains.png`: the grains coloured by their pressure, and the force chains.
fn grains_figure(
    out: &mut OutputDir,
    s: &Snapshot,
    grains: &[homogenise::GrainStress],
) -> Result<()> {
    let p: Vec<f64> = grains.iter().map(|g| -g.total.trace() / 2.0).collect();
    let hi = p.iter().cloned().fold(0.0f64, f64::max);
    draw_particles(
        out,
        "grains.png",
        &ParticleView {
            snap: s,
            title: format!("step {}: grain pressure and contact forces", s.step),
            fill: GrainFill::Values {
                values: p,
                scale: Scale {
                    min: 0.0,
                    max: if hi > 0.0 { hi } else { 1.0 },
                    log: false,
                },
                label: "grain pressure −tr Σp/2 (Pa)".into(),
            },
            forces: true,
            axis_labels: ("x (m)".into(), "y (m)".into()),
            width_px: 900,
            overlays: Vec::new(),
        },
    )
}

/// The two side walls of a column: the vertical line walls whose normals point to +x (left)
/// and to −x (right), when there is exactly one of each.
fn side_walls(s: &Snapshot) -> Option<(String, String)> {
    let side = |sign: f64| -> Vec<&str> {
        s.walls
            .iter()
            .filter(|w| {
                matches!(w.geometry, WallGeometry::Line { normal, .. }
                    if sign * normal.x > 1.0 - 1e-6)
            })
            .map(|w| w.name.as_str())
            .collect()
    };
    match (side(1.0).as_slice(), side(-1.0).as_slice()) {
        ([l], [r]) => Some((l.to_string(), r.to_string())),
        _ => None,
    }
}

/// `janssen.csv`, the table `grainlaw fit janssen` reads (`identify::user_fit`), of a column
/// between two vertical walls under gravity along −y ([`side_walls`]): per depth bin of two
/// mean diameters below the free surface, `z_m`, `sigma_v_Pa` (across horizontal planes),
/// `sigma_h_Pa` and `tau_w_Pa` (the two walls' mean), compressive positive
/// ([`homogenise::column::column_profile`]), averaged over the snapshots (the series is the
/// measurement window, as the `janssen` scenario averages its last steps); metadata `width_m`
/// (between the walls), `bulk_density_kg_m3` (φ ρ of the column), `gravity_m_s2`, the fitted
/// depths (one mean diameter below the surface to one above the lowest grain) and
/// `wall_friction` (`--wall-mu`, else `--mu`; without either the table fits `janssen-kmu`).
/// As in the `janssen` scenario, τ_w is named `tau_w_Pa` (a datum of the fit) only when it is
/// nowhere negative in the fitted depths, `tau_w_measured_Pa` otherwise. Nothing is written
/// for a sample that is not such a column.
fn janssen_table(
    out: &mut OutputDir,
    snaps: &[ExternalSnapshot],
    opts: &ReadOptions,
    summary: &mut Summary,
) -> Result<()> {
    let Some(last) = snaps.last().map(|e| &e.snapshot) else {
        return Ok(());
    };
    let g = last.gravity;
    let d = mean_diameter(last);
    let Some((left, right)) = side_walls(last) else {
        return Ok(());
    };
    if !(g.y < 0.0 && g.x.abs() <= 1e-12 * g.y.abs() && d > 0.0) {
        return Ok(());
    }
    let spec = homogenise::column::ColumnSpec {
        left,
        right,
        bin_width: 2.0 * d,
    };
    let mut profiles = Vec::with_capacity(snaps.len());
    for e in snaps {
        if side_walls(&e.snapshot).as_ref() != Some(&(spec.left.clone(), spec.right.clone())) {
            continue;
        }
        match homogenise::column::column_profile(&e.snapshot, &spec) {
            Ok(p) => profiles.push(p),
            Err(err) => {
                summary.text(
                    "janssen_table",
                    &format!("not written: step {}: {err}", e.snapshot.step),
                );
                return Ok(());
            }
        }
    }
    // the depths common to every snapshot's profile
    let bins = profiles.iter().map(|p| p.depth.len()).min().unwrap_or(0);
    if bins == 0 {
        return Ok(());
    }
    let m = profiles.len() as f64;
    let mean = |f: &dyn Fn(&homogenise::column::ColumnProfile) -> f64| {
        profiles.iter().map(f).sum::<f64>() / m
    };
    let at = |f: fn(&homogenise::column::ColumnProfile) -> &Vec<f64>| -> Vec<f64> {
        (0..bins)
            .map(|k| profiles.iter().map(|p| f(p)[k]).sum::<f64>() / m)
            .collect()
    };
    let z = profiles[profiles.len() - 1].depth[..bins].to_vec();
    let (sv, sh, tw, svm, phi) = (
        at(|p| &p.sigma_v),
        at(|p| &p.sigma_h),
        at(|p| &p.tau_w),
        at(|p| &p.sigma_v_mean),
        at(|p| &p.solid_fraction),
    );
    let height = grain_extent(last).map_or(0.0, |e| e.3 - e.2);
    let window = (d, (height - d).max(d));
    let uses_tau = z
        .iter()
        .zip(&tw)
        .all(|(z, t)| *z < window.0 || *z > window.1 || *t >= 0.0);
    let mut t = CsvTable::new(&[
        "z_m",
        "sigma_v_Pa",
        "sigma_h_Pa",
        if uses_tau {
            "tau_w_Pa"
        } else {
            "tau_w_measured_Pa"
        },
        "sigma_v_mean_Pa",
        "solid_fraction",
    ]);
    t.comments.push(format!(
        "Janssen column between the walls `{}` and `{}`, mean of {} snapshots: depth below the free surface, vertical stress across planes, wall normal and shear stress (mean of both walls; shear positive when the grains drag the walls down), compressive positive; sigma_v_mean_Pa is -sigma_yy of the bin's mean stress. Fit with: grainlaw fit janssen janssen.csv",
        spec.left,
        spec.right,
        profiles.len()
    ));
    if !uses_tau {
        t.comments.push("the wall shear stress is negative at some fitted depth: named tau_w_measured_Pa, it is not a datum of the fit".into());
    }
    let width = mean(&|p| p.width);
    let bulk = mean(&|p| p.bulk_density);
    t.metadata = vec![
        ("width_m".into(), width),
        ("bulk_density_kg_m3".into(), bulk),
        ("gravity_m_s2".into(), g.norm()),
        ("depth_min_m".into(), window.0),
        ("depth_max_m".into(), window.1),
    ];
    match opts.wall_mu.or(opts.mu) {
        Some(mu) => t.metadata.push(("wall_friction".into(), mu)),
        None => t.comments.push(
            "no wall friction given (--wall-mu or --mu): fit janssen-kmu, or add `# wall_friction = MU`"
                .into(),
        ),
    }
    for k in 0..bins {
        t.push(vec![z[k], sv[k], sh[k], tw[k], svm[k], phi[k]]);
    }
    t.write(out, "janssen.csv")?;
    summary
        .num("janssen_width_m", width)
        .num("janssen_bulk_density_kg_m3", bulk);
    Ok(())
}

fn grain_extent(s: &Snapshot) -> Option<(f64, f64, f64, f64)> {
    let mut e: Option<(f64, f64, f64, f64)> = None;
    for b in s
        .bodies
        .iter()
        .filter(|b| b.kind == dem::snapshot::BodyKind::Grain)
    {
        let (x0, x1, y0, y1) = (
            b.position.x - b.radius,
            b.position.x + b.radius,
            b.position.y - b.radius,
            b.position.y + b.radius,
        );
        e = Some(match e {
            None => (x0, x1, y0, y1),
            Some(a) => (a.0.min(x0), a.1.max(x1), a.2.min(y0), a.3.max(y1)),
        });
    }
    e
}

fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
