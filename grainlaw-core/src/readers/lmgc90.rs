//! LMGC90 2D output files (`docs/formats.md` § "LMGC90"): `BODIES.DAT` (rigid bodies `RBDY2`
//! with their reference coordinates, `PLAIN` bulk element `avrd`/`gyrd`, and one contactor:
//! `DISKx` of radius `byrd` for a grain, `JONCx` of half-axes `ax1`, `ax2` for a wall),
//! `DOF.OUT` (per body `X(1..3)`, the displacement from the reference coordinates and the
//! rotation, and `V(1..3)`), and `Vloc_Rloc.OUT` (per contact `DKDKx` or `DKJCx`: candidate
//! and antagonist bodies, `rlt/H`, `rln/H` (N), the unit normal `n` from the antagonist to the
//! candidate, and the contact point `coo1`, `coo2`).
//!
//! LMGC90's tangent is `t = (n_y, −n_x)` and the reaction on the candidate `rln n + rlt t`; with
//! the antagonist as body `a` and the candidate as body `b` the force on `b` is that vector.
//! Masses are `m = ρ π avrd²` (per metre of thickness, `ρ` = [`ReadOptions::density`], the
//! `Umas` of `BULK_BEHAV.DAT`) and `I = m gyrd²`, as LMGC90 computes them. Several `DOF.OUT`
//! / `Vloc_Rloc.OUT` files (`DOF.OUT.1`, ...) are matched by their `$steps` number.
//!
//! The layout follows LMGC90's writers (`write_out_dof`, `write_bodies`,
//! `write_out_Vloc_Rloc` of the `RBDY2`, `DKDKx` and `DKJCx` modules). The tests read a sample
//! written by hand in that layout and the files of a real LMGC90 run
//! (`datasets/external/lmgc90/real`), checked against LMGC90's own positions and reactions.
//!
//! The contact point is the one LMGC90 writes, that of its detection configuration (the
//! θ-scheme's mid-step positions), while `DOF.OUT` holds the end-of-step centres: on grains
//! still moving the levers `x − c` then differ from LMGC90's own (`∓R n`) by the motion over
//! half a step; on a settled sample they agree (the test's moments to 1e-6).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use dem::math::{Spatial, Vector};
use dem::snapshot::WallGeometry;

use super::frame::{ContactRecord, Frame, GrainRecord, Other, WallRecord};
use super::{build_snapshots, number, read_text, ExternalSnapshot, ReadError, ReadOptions};

/// The value following `label` on `line` (`label` may end in `=` or hold spaces: `ax1 =`).
fn labeled<'a>(line: &'a str, label: &str) -> Option<&'a str> {
    let at = line.find(label)? + label.len();
    line[at..].split_whitespace().next()
}

fn labeled_number(path: &Path, ln: usize, line: &str, label: &str) -> Result<f64, ReadError> {
    let v = labeled(line, label)
        .ok_or_else(|| ReadError::parse(path, ln, format!("no `{}` on the line", label.trim())))?;
    number(path, ln, label.trim_end_matches(['=', ' ']), v)
}

/// Half-axis `k` of a `JONCx`: `axeK=` as LMGC90's pre-processor (pylmgc90.pre) writes
/// `DATBOX/BODIES.DAT`, `axK =` as LMGC90's own writer writes `OUTBOX/BODIES.OUT`.
fn jonc_axis(path: &Path, ln: usize, line: &str, k: u8) -> Result<f64, ReadError> {
    let pre = format!("axe{k}=");
    if labeled(line, &pre).is_some() {
        labeled_number(path, ln, line, &pre)
    } else {
        labeled_number(path, ln, line, &format!("ax{k} ="))
    }
}

#[derive(Debug, Clone)]
enum Tactor {
    Disk {
        radius: f64,
    },
    /// A rounded rectangle of half-length `ax1` (its half-thickness `ax2` is checked, unused).
    Jonc {
        ax1: f64,
    },
}

#[derive(Debug, Clone)]
struct Body {
    cooref: [f64; 3],
    avrd: f64,
    gyrd: f64,
    tactor: Option<Tactor>,
}

fn parse_bodies(path: &Path, text: &str) -> Result<BTreeMap<u64, Body>, ReadError> {
    let mut bodies = BTreeMap::new();
    let mut current: Option<(u64, Body)> = None;
    let mut section = "";
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i];
        let ln = i + 1;
        let t = line.trim();
        i += 1;
        if t.starts_with('!') || t.is_empty() {
            continue;
        }
        if t.starts_with('$') {
            section = match t {
                "$bdyty" => {
                    let next = lines.get(i).copied().unwrap_or("");
                    let toks: Vec<&str> = next.split_whitespace().collect();
                    if toks.len() < 2 || toks[0] != "RBDY2" {
                        return Err(ReadError::parse(path, ln + 1, format!("expected ` RBDY2  number`, got `{}` (only 2D rigid bodies are read)", next.trim())));
                    }
                    let id = toks[1].parse::<u64>().map_err(|_| {
                        ReadError::parse(path, ln + 1, "body number is not an integer")
                    })?;
                    current = Some((
                        id,
                        Body {
                            cooref: [0.0; 3],
                            avrd: 0.0,
                            gyrd: 0.0,
                            tactor: None,
                        },
                    ));
                    i += 1;
                    "bdyty"
                }
                "$blmty" => "blmty",
                "$nodty" => "nodty",
                "$tacty" => "tacty",
                "$$$$$$" => {
                    if let Some((id, b)) = current.take() {
                        bodies.insert(id, b);
                    }
                    ""
                }
                _ => "",
            };
            continue;
        }
        let Some((id, body)) = current.as_mut() else {
            continue;
        };
        match section {
            "blmty" if t.starts_with("PLAIN") => {
                body.avrd = labeled_number(path, ln, line, "avrd=")?;
                body.gyrd = labeled_number(path, ln, line, "gyrd=")?;
            }
            "nodty" => {
                body.cooref = [
                    labeled_number(path, ln, line, "coo1=")?,
                    labeled_number(path, ln, line, "coo2=")?,
                    labeled_number(path, ln, line, "coo3=").unwrap_or(0.0),
                ];
            }
            "tacty" => {
                let kind = t.split_whitespace().next().unwrap_or("");
                let tactor = match kind {
                    "DISKx" => Tactor::Disk { radius: labeled_number(path, ln, line, "byrd=")? },
                    "JONCx" => {
                        jonc_axis(path, ln, line, 2)?;
                        Tactor::Jonc { ax1: jonc_axis(path, ln, line, 1)? }
                    }
                    other => {
                        return Err(ReadError::parse(path, ln, format!("body {id}: contactor `{other}` is not read (DISKx grains and JONCx walls only)")))
                    }
                };
                if body.tactor.is_some() {
                    return Err(ReadError::parse(
                        path,
                        ln,
                        format!("body {id}: more than one contactor (clusters are not read)"),
                    ));
                }
                body.tactor = Some(tactor);
            }
            _ => {}
        }
    }
    if bodies.is_empty() {
        return Err(ReadError::content(path, "no `$bdyty` block"));
    }
    Ok(bodies)
}

/// `$steps N  time= T` headers: (step, time).
fn steps_header(path: &Path, ln: usize, line: &str) -> Result<(u64, f64), ReadError> {
    let toks: Vec<&str> = line.split_whitespace().collect();
    let step = toks
        .get(1)
        .and_then(|s| s.parse::<u64>().ok())
        .ok_or_else(|| ReadError::parse(path, ln, "`$steps` without a step number"))?;
    Ok((step, labeled_number(path, ln, line, "time=")?))
}

/// A body's degrees of freedom in a DOF file: its displacement `(x, y, θ)` and velocity
/// `(v_x, v_y, ω)`, packed per body (`dem::math::Spatial`).
type Dof = HashMap<u64, (Spatial, Spatial)>;

fn parse_dof(path: &Path, text: &str) -> Result<Vec<(u64, f64, Dof)>, ReadError> {
    let mut out: Vec<(u64, f64, Dof)> = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim();
        let ln = i + 1;
        i += 1;
        if t.starts_with("$steps") {
            let (s, time) = steps_header(path, ln, t)?;
            out.push((s, time, HashMap::new()));
        } else if t == "$bdyty" {
            let Some(cur) = out.last_mut() else {
                return Err(ReadError::parse(
                    path,
                    ln,
                    "`$bdyty` before any `$steps` header",
                ));
            };
            let head = lines.get(i).copied().unwrap_or("");
            let id = head
                .split_whitespace()
                .nth(1)
                .and_then(|s| s.parse::<u64>().ok())
                .ok_or_else(|| ReadError::parse(path, ln + 1, "expected ` RBDY2  number`"))?;
            // $nodty, X line, V line
            let xl = lines.get(i + 2).copied().unwrap_or("");
            let vl = lines.get(i + 3).copied().unwrap_or("");
            let x = [
                labeled_number(path, ln + 3, xl, "X(1)=")?,
                labeled_number(path, ln + 3, xl, "X(2)=")?,
                labeled_number(path, ln + 3, xl, "X(3)=")?,
            ];
            let v = [
                labeled_number(path, ln + 4, vl, "V(1)=")?,
                labeled_number(path, ln + 4, vl, "V(2)=")?,
                labeled_number(path, ln + 4, vl, "V(3)=")?,
            ];
            cur.2.insert(id, (x, v));
            i += 4;
        }
    }
    if out.is_empty() {
        return Err(ReadError::content(path, "no `$steps` header"));
    }
    Ok(out)
}

#[derive(Debug, Clone)]
struct LmgcContact {
    candidate: u64,
    antagonist: u64,
    antagonist_is_wall: bool,
    rt: f64,
    rn: f64,
    n: Vector,
    point: Vector,
}

fn parse_vloc(path: &Path, text: &str) -> Result<Vec<(u64, Vec<LmgcContact>)>, ReadError> {
    let mut out: Vec<(u64, Vec<LmgcContact>)> = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim();
        let ln = i + 1;
        i += 1;
        if t.starts_with("$steps") {
            out.push((steps_header(path, ln, t)?.0, Vec::new()));
        } else if let Some(rest) = t.strip_prefix("$icdan") {
            let kind = rest.split_whitespace().next().unwrap_or("");
            if kind != "DKDKx" && kind != "DKJCx" {
                return Err(ReadError::parse(
                    path,
                    ln,
                    format!("contact type `{kind}` is not read (DKDKx and DKJCx only)"),
                ));
            }
            if out.is_empty() {
                out.push((0, Vec::new()));
            }
            // header line, values line, then labelled lines up to a blank line
            let vals: Vec<&str> = lines
                .get(i + 1)
                .copied()
                .unwrap_or("")
                .split_whitespace()
                .collect();
            if vals.len() < 9 {
                return Err(ReadError::parse(
                    path,
                    ln + 2,
                    "expected `cdbdy numbr cdtac numbr behav anbdy numbr antac numbr ...`",
                ));
            }
            let int = |s: &str, what: &str| {
                s.parse::<u64>().map_err(|_| {
                    ReadError::parse(path, ln + 2, format!("{what} `{s}` is not an integer"))
                })
            };
            let candidate = int(vals[1], "candidate body")?;
            let antagonist = int(vals[6], "antagonist body")?;
            let mut block = String::new();
            let mut j = i + 2;
            while j < lines.len()
                && !lines[j].trim().is_empty()
                && !lines[j].trim().starts_with('$')
            {
                block.push_str(lines[j]);
                block.push(' ');
                j += 1;
            }
            let get = |labels: &[&str]| -> Result<f64, ReadError> {
                for l in labels {
                    if labeled(&block, l).is_some() {
                        return labeled_number(path, ln, &block, l);
                    }
                }
                Err(ReadError::parse(
                    path,
                    ln,
                    format!("contact without `{}`", labels[0]),
                ))
            };
            let contact = LmgcContact {
                candidate,
                antagonist,
                antagonist_is_wall: kind == "DKJCx",
                rt: get(&["rlt/H", "rlt  "])?,
                rn: get(&["rln/H", "rln  "])?,
                n: Vector::new(get(&["n(1)="])?, get(&["n(2)="])?),
                point: Vector::new(get(&["coo1="])?, get(&["coo2="])?),
            };
            if let Some(o) = out.last_mut() {
                o.1.push(contact);
            }
            i = j;
        }
    }
    Ok(out)
}

/// Reads LMGC90 2D files: one `BODIES.DAT`, one or more `DOF.OUT` and (optionally) the
/// `Vloc_Rloc.OUT` of the same steps; the kind of each file is told by its name (`BODIES`,
/// `DOF`, `Vloc_Rloc`), gzip or plain. Needs [`ReadOptions::density`].
pub fn read_lmgc90(
    files: &[PathBuf],
    opts: &ReadOptions,
) -> Result<Vec<ExternalSnapshot>, ReadError> {
    let all = files
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let content = |reason: String| ReadError::Content {
        file: all.clone(),
        reason,
    };
    let density = opts.density.filter(|d| d.is_finite() && *d > 0.0).ok_or_else(|| {
        content("LMGC90 files do not hold the grains' density: give --density RHO (kg/m³, the Umas of BULK_BEHAV.DAT)".into())
    })?;
    let mut bodies = None;
    let mut dofs: Vec<(PathBuf, u64, f64, Dof)> = Vec::new();
    let mut vlocs: HashMap<u64, (PathBuf, Vec<LmgcContact>)> = HashMap::new();
    for path in files {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_uppercase())
            .unwrap_or_default();
        let text = read_text(path)?;
        if name.contains("BODIES") {
            if bodies.is_some() {
                return Err(ReadError::content(path, "a second BODIES file"));
            }
            bodies = Some((path.clone(), parse_bodies(path, &text)?));
        } else if name.contains("DOF") {
            for (s, t, d) in parse_dof(path, &text)? {
                dofs.push((path.clone(), s, t, d));
            }
        } else if name.contains("VLOC_RLOC") {
            for (s, c) in parse_vloc(path, &text)? {
                vlocs.insert(s, (path.clone(), c));
            }
        } else {
            return Err(ReadError::content(
                path,
                "not an LMGC90 file this reader knows (BODIES.DAT, DOF.OUT, Vloc_Rloc.OUT)",
            ));
        }
    }
    let (bpath, bodies) = bodies.ok_or_else(|| content("no BODIES.DAT among the files".into()))?;
    if dofs.is_empty() {
        return Err(content("no DOF.OUT among the files".into()));
    }
    let mut frames = Vec::new();
    for (dpath, step, time, dof) in dofs {
        let mut frame = Frame {
            step,
            time: Some(time),
            source: format!("{} + {}", bpath.display(), dpath.display()),
            ..Default::default()
        };
        let mut wall_of: HashMap<u64, usize> = HashMap::new();
        for (id, b) in &bodies {
            let (x, v) = dof.get(id).copied().unwrap_or(([0.0; 3], [0.0; 3]));
            let c = Vector::new(b.cooref[0] + x[0], b.cooref[1] + x[1]);
            match b.tactor {
                Some(Tactor::Disk { radius }) => {
                    let mass = density * std::f64::consts::PI * b.avrd * b.avrd;
                    frame.grains.push(GrainRecord {
                        id: *id,
                        position: c,
                        angle: x[2],
                        velocity: Vector::new(v[0], v[1]),
                        omega: v[2],
                        radius,
                        mass,
                        inertia: mass * b.gyrd * b.gyrd,
                        acceleration: None,
                    });
                }
                Some(Tactor::Jonc { ax1 }) => {
                    let e = Vector::new(x[2].cos(), x[2].sin());
                    wall_of.insert(*id, frame.walls.len());
                    frame.walls.push(WallRecord {
                        name: format!("body{id}"),
                        geometry: WallGeometry::Segment {
                            a: c - e * ax1,
                            b: c + e * ax1,
                        },
                        position: c,
                        velocity: Vector::new(v[0], v[1]),
                    });
                }
                None => {
                    return Err(ReadError::content(
                        &bpath,
                        format!("body {id} has no contactor"),
                    ));
                }
            }
        }
        if let Some((vpath, contacts)) = vlocs.get(&step) {
            frame.source = format!("{} + {}", frame.source, vpath.display());
            for c in contacts {
                let a = if c.antagonist_is_wall {
                    Other::Wall(*wall_of.get(&c.antagonist).ok_or_else(|| {
                        ReadError::content(
                            vpath,
                            format!(
                                "DKJCx contact with body {}, which is not a JONCx wall",
                                c.antagonist
                            ),
                        )
                    })?)
                } else {
                    Other::Grain(c.antagonist)
                };
                let t = Vector::new(c.n.y, -c.n.x);
                frame.contacts.push(ContactRecord {
                    a,
                    b: c.candidate,
                    force: c.n * c.rn + t * c.rt,
                    point: Some(c.point),
                    normal: Some(c.n),
                });
            }
        } else if !vlocs.is_empty() {
            return Err(ReadError::content(
                &dpath,
                format!("no Vloc_Rloc file of step {step}"),
            ));
        }
        frames.push(frame);
    }
    build_snapshots(frames, opts)
}
