//! LAMMPS and LIGGGHTS text dumps, 2D (`docs/formats.md` § "LAMMPS and LIGGGHTS").
//!
//! - Per-atom `dump custom` files (`ITEM: ATOMS ...`): columns found by their header names, in
//!   any order: `id`, `x`, `y` (or `xu`, `yu`), `vx`, `vy`, `omegaz`, `radius`, `mass`;
//!   optional `fx`, `fy`, `tqz` (total force and torque: then `a = f/m`, `ω̇ = τ/I`);
//!   optional walls, one `fix wall/gran ... contacts` each, dumped as `f_ID[1]` … `f_ID[8]`
//!   (contact flag, force on the atom, the wall point nearest the atom, radius): the wall is
//!   named `ID`, a line through the mean wall point with the mean unit normal towards the grains.
//! - `dump local` files (`ITEM: ENTRIES ...`) of pair forces: the atoms' ids and the force on
//!   the first atom, normal part `fx fy` and tangential part `ftx fty` (LAMMPS `compute
//!   pair/local fx fy p1 p2` for the granular pair styles), optionally the contact point
//!   `cx cy`. LAMMPS names these columns after the computes (`c_pf[2]`): the defaults follow the
//!   commands of `docs/formats.md`, and [`ReadOptions::columns`] maps other names.
//!   Rows whose force is zero (neighbours not in contact) are left out.
//! - `dump local` files of wall contacts (LIGGGHTS `compute wall/gran/local pos id force`):
//!   the keys `wall.wall` (wall or mesh id), `wall.id` (particle), `wall.fx`, `wall.fy` (force on
//!   the particle), `wall.cx`, `wall.cy` (contact point), mapped with `--column wall.KEY=HEADER`;
//!   each wall id makes a wall `wallN`.
//!
//! The moment of inertia is `I = k m R²` with `k` = [`ReadOptions::inertia_factor`] (1/2 for
//! disks, `fix nve/sphere disc`). A dump file may hold several snapshots; per-atom and local
//! blocks are matched by their `TIMESTEP`.
//!
//! The cell is the box of the per-atom block's header, as LAMMPS writes it: orthogonal
//! (`ITEM: BOX BOUNDS pp ff pp`, lines `lo hi`) or triclinic (`ITEM: BOX BOUNDS xy xz yz pp pp
//! pp`, lines `lo_bound hi_bound tilt`, turned into the box's edges by the conversion of the
//! LAMMPS documentation, `parse_box`), periodic or not along x and y by its flags; every pair
//! takes the minimum image of that cell (`frame` module). Refused: a periodic cell tilted
//! beyond [`MAX_TILT_RATIO`], a 3D dump (z not periodic, z tilts, atoms off the plane z = 0),
//! and a series whose atom count or kind of box changes (`check_series`).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use dem::math::Vector;
use dem::snapshot::WallGeometry;

use super::frame::{ContactRecord, Frame, FrameCell, GrainRecord, Other, WallRecord};
use super::{build_snapshots, number, read_text, ExternalSnapshot, ReadError, ReadOptions};

/// Keys of the local (pair) columns and their default header names.
const LOCAL_KEYS: &[(&str, &[&str])] = &[
    ("id1", &["id1", "patom1", "c_ids[1]"]),
    ("id2", &["id2", "patom2", "c_ids[2]"]),
    ("fx", &["fx", "c_pf[2]"]),
    ("fy", &["fy", "c_pf[3]"]),
    ("ftx", &["ftx", "p1", "c_pf[4]"]),
    ("fty", &["fty", "p2", "c_pf[5]"]),
    ("cx", &["cx", "contactpoint_x"]),
    ("cy", &["cy", "contactpoint_y"]),
];

/// Keys of wall-contact local columns (LIGGGHTS `compute wall/gran/local`), given with
/// `--column wall.KEY=HEADER`; a local block with a `wall.wall` column is a wall block.
const WALL_KEYS: &[(&str, &[&str])] = &[
    ("wall.wall", &["wall_id", "mesh_id"]),
    ("wall.id", &["particle_id"]),
    ("wall.fx", &[]),
    ("wall.fy", &[]),
    ("wall.cx", &[]),
    ("wall.cy", &[]),
];

#[derive(Debug, PartialEq, Clone, Copy)]
enum Kind {
    Atoms,
    Entries,
}

/// Largest tilt of a periodic LAMMPS cell over its x length, `|xy| / l_x` (LAMMPS refuses a
/// box beyond one half, "Triclinic box skew is too large"); the 10⁻³ above it allows the step
/// at which `fix deform` has passed the half and flips the cell at the next one.
pub const MAX_TILT_RATIO: f64 = 0.5 + 1e-3;

/// The box of a dump block (`ITEM: BOX BOUNDS`), converted to a [`FrameCell`].
#[derive(Debug, Clone, Copy)]
struct DumpBox {
    cell: FrameCell,
    /// `ITEM: BOX BOUNDS xy xz yz ...` (a triclinic box).
    triclinic: bool,
    /// Line of the `ITEM: BOX BOUNDS` header (1-based).
    line: usize,
}

impl DumpBox {
    /// How the box reads in a message: `orthogonal pp ff` or `triclinic pp pp`.
    fn describe(&self) -> String {
        let f = |p: bool| if p { "periodic" } else { "not periodic" };
        format!(
            "{} box, x {}, y {}",
            if self.triclinic {
                "triclinic"
            } else {
                "orthogonal"
            },
            f(self.cell.periodic[0]),
            f(self.cell.periodic[1])
        )
    }
}

/// One block of a dump file.
#[derive(Debug)]
struct Block {
    kind: Kind,
    step: u64,
    time: Option<f64>,
    /// The box, when the block has one.
    cell: Option<DumpBox>,
    header: Vec<String>,
    /// Line number of the first row.
    first_line: usize,
    /// Line of the count (`ITEM: NUMBER OF ...` value), 1-based.
    count_line: usize,
    cols: usize,
    values: Vec<f64>,
}

/// Reads the three lines of `ITEM: BOX BOUNDS [xy xz yz] FLAGS` (the header at 0-based line
/// `ln`, `rest` what follows `BOX BOUNDS`): bounds `lo hi` per axis, with the tilt factors as
/// third numbers when the box is triclinic. The triclinic bounds are those of the box's
/// bounding box, turned into its edges as the LAMMPS documentation ("Triclinic (non-orthogonal)
/// simulation boxes") gives: `x_lo = x_lo,bound − min(0, xy, xz, xy + xz)`,
/// `x_hi = x_hi,bound − max(0, xy, xz, xy + xz)`, `y_lo = y_lo,bound − min(0, yz)`,
/// `y_hi = y_hi,bound − max(0, yz)`. A 2D run's box is periodic in z without z tilts: anything
/// else is a 3D dump, refused.
fn parse_box<'a>(
    path: &Path,
    ln: usize,
    rest: &str,
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
) -> Result<DumpBox, ReadError> {
    let tokens: Vec<&str> = rest.split_whitespace().collect();
    let triclinic = tokens.contains(&"xy");
    let flags: Vec<&str> = tokens
        .iter()
        .copied()
        .filter(|f| f.len() == 2 && f.chars().all(|c| "pfsm".contains(c)))
        .collect();
    let header_line = ln + 1;
    if flags.len() == 3 && flags[2] != "pp" {
        return Err(ReadError::parse(
            path,
            header_line,
            format!(
                "a 3D dump (the z boundary is `{}`; LAMMPS' 2D runs are periodic in z): 3D is not supported yet, grainlaw reads 2D dumps",
                flags[2]
            ),
        ));
    }
    let mut axes = [[0.0; 3]; 3];
    for (a, name) in ["x", "y", "z"].iter().enumerate() {
        let (l, t) = lines.next().ok_or_else(|| {
            ReadError::parse(path, header_line, "the file ends within the box bounds")
        })?;
        let xs: Vec<&str> = t.split_whitespace().collect();
        let need = if triclinic { 3 } else { 2 };
        if xs.len() < need {
            return Err(ReadError::parse(
                path,
                l + 1,
                format!(
                    "the {name} bounds of a {} box need {need} numbers, got {}",
                    if triclinic { "triclinic" } else { "orthogonal" },
                    xs.len()
                ),
            ));
        }
        for k in 0..need {
            axes[a][k] = number(path, l + 1, &format!("{name} bound"), xs[k])?;
        }
    }
    let [[xlb, xhb, xy], [ylb, yhb, xz], [_, _, yz]] = axes;
    if xz != 0.0 || yz != 0.0 {
        return Err(ReadError::parse(
            path,
            header_line,
            format!("a 3D dump (tilt factors xz = {xz}, yz = {yz}; a 2D box has none): 3D is not supported yet, grainlaw reads 2D dumps"),
        ));
    }
    let (xlo, xhi) = (
        xlb - 0f64.min(xy).min(xz).min(xy + xz),
        xhb - 0f64.max(xy).max(xz).max(xy + xz),
    );
    let (ylo, yhi) = (ylb - 0f64.min(yz), yhb - 0f64.max(yz));
    let (lx, ly) = (xhi - xlo, yhi - ylo);
    if !(lx > 0.0 && ly > 0.0) {
        return Err(ReadError::parse(
            path,
            header_line,
            format!("the box has no area: x from {xlo} to {xhi}, y from {ylo} to {yhi}"),
        ));
    }
    let periodic = [flags.first() == Some(&"pp"), flags.get(1) == Some(&"pp")];
    if periodic[0] && xy.abs() > MAX_TILT_RATIO * lx {
        return Err(ReadError::parse(
            path,
            header_line,
            format!(
                "the cell's tilt xy = {xy:e} m is {:.3} of its x length {lx:e} m: beyond LAMMPS' own limit of one half (a box read wrong, or a run with `box tilt large`, which grainlaw does not read)",
                xy.abs() / lx
            ),
        ));
    }
    Ok(DumpBox {
        cell: FrameCell {
            origin: Vector::new(xlo, ylo),
            lx,
            ly,
            xy,
            periodic,
        },
        triclinic,
        line: header_line,
    })
}

impl Block {
    fn rows(&self) -> usize {
        self.values.len().checked_div(self.cols).unwrap_or(0)
    }
    fn col(&self, names: &[&str]) -> Option<usize> {
        names
            .iter()
            .find_map(|n| self.header.iter().position(|h| h.eq_ignore_ascii_case(n)))
    }
}

fn parse_blocks(path: &Path, text: &str) -> Result<Vec<Block>, ReadError> {
    let mut blocks = Vec::new();
    let mut lines = text.lines().enumerate().peekable();
    let mut time = None;
    let mut step: Option<u64> = None;
    let mut count: Option<(usize, usize)> = None;
    let mut cell = None;
    let err = |l: usize, r: String| ReadError::parse(path, l + 1, r);
    while let Some((ln, line)) = lines.next() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let Some(item) = line.strip_prefix("ITEM:") else {
            return Err(err(
                ln,
                format!("expected an `ITEM:` line, got `{}`", short(line)),
            ));
        };
        let item = item.trim();
        let mut next_line = |what: &str| {
            lines
                .next()
                .ok_or_else(|| err(ln, format!("the file ends before the {what}")))
        };
        if item == "TIMESTEP" {
            let (l, t) = next_line("time step")?;
            step = Some(
                t.trim()
                    .parse()
                    .map_err(|_| err(l, format!("time step `{}` is not an integer", short(t))))?,
            );
        } else if item == "TIME" {
            let (l, t) = next_line("time")?;
            time = Some(number(path, l + 1, "time", t)?);
        } else if item.starts_with("NUMBER OF") {
            let (l, t) = next_line("count")?;
            count = Some((
                t.trim()
                    .parse()
                    .map_err(|_| err(l, format!("count `{}` is not an integer", short(t))))?,
                l + 1,
            ));
        } else if let Some(rest) = item.strip_prefix("BOX BOUNDS") {
            cell = Some(parse_box(path, ln, rest, &mut lines)?);
        } else if let Some(cols) = item
            .strip_prefix("ATOMS")
            .or_else(|| item.strip_prefix("ENTRIES"))
        {
            let kind = if item.starts_with("ATOMS") {
                Kind::Atoms
            } else {
                Kind::Entries
            };
            let header: Vec<String> = cols.split_whitespace().map(String::from).collect();
            let s = step.ok_or_else(|| err(ln, "no `ITEM: TIMESTEP` before the data".into()))?;
            let (n, count_line) =
                count.ok_or_else(|| err(ln, "no `ITEM: NUMBER OF ...` before the data".into()))?;
            let ncols = header.len();
            let mut values = Vec::with_capacity(n * ncols);
            for r in 0..n {
                let (l, row) = lines.next().ok_or_else(|| {
                    err(
                        ln,
                        format!("the block announces {n} rows, the file ends after {r}"),
                    )
                })?;
                let before = values.len();
                for tok in row.split_ascii_whitespace() {
                    values.push(
                        fast_number(tok)
                            .ok_or_else(|| err(l, format!("`{}` is not a number", short(tok))))?,
                    );
                }
                if values.len() - before != ncols {
                    return Err(err(
                        l,
                        format!("{} values for {ncols} columns", values.len() - before),
                    ));
                }
            }
            blocks.push(Block {
                kind,
                step: s,
                time: time.take(),
                cell: cell.take(),
                header,
                first_line: ln + 2,
                count_line,
                cols: ncols,
                values,
            });
            step = None;
            count = None;
        } else {
            // other items (UNITS, ...): their value line is skipped
            next_line("value")?;
        }
    }
    Ok(blocks)
}

fn fast_number(tok: &str) -> Option<f64> {
    tok.parse::<f64>().ok().filter(|v| v.is_finite())
}

fn short(s: &str) -> String {
    let s = s.trim();
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

fn require(path: &Path, b: &Block, names: &[&str]) -> Result<usize, ReadError> {
    b.col(names).ok_or_else(|| {
        ReadError::parse(
            path,
            b.first_line - 1,
            format!(
                "no column `{}` in the header ({})",
                names[0],
                b.header.join(" ")
            ),
        )
    })
}

/// Wall groups `f_ID[k]`: name → column of k (1..=8).
fn wall_columns(b: &Block) -> Vec<(String, [Option<usize>; 8])> {
    let mut groups: BTreeMap<String, [Option<usize>; 8]> = BTreeMap::new();
    for (i, h) in b.header.iter().enumerate() {
        let Some(rest) = h.strip_prefix("f_") else {
            continue;
        };
        let Some((name, k)) = rest.strip_suffix(']').and_then(|r| r.split_once('[')) else {
            continue;
        };
        if let Ok(k) = k.parse::<usize>() {
            if (1..=8).contains(&k) {
                groups.entry(name.to_string()).or_default()[k - 1] = Some(i);
            }
        }
    }
    groups
        .into_iter()
        .filter(|(_, c)| [0, 1, 2, 4, 5].iter().all(|&k| c[k].is_some()))
        .collect()
}

fn atoms_frame(path: &Path, b: &Block, opts: &ReadOptions) -> Result<Frame, ReadError> {
    let id = require(path, b, &["id"])?;
    let x = require(path, b, &["x", "xu"])?;
    let y = require(path, b, &["y", "yu"])?;
    let vx = require(path, b, &["vx"])?;
    let vy = require(path, b, &["vy"])?;
    let om = require(path, b, &["omegaz"])?;
    let r = require(path, b, &["radius"])?;
    let m = require(path, b, &["mass"])?;
    let forces = match (b.col(&["fx"]), b.col(&["fy"]), b.col(&["tqz"])) {
        (Some(a), Some(c), Some(d)) => Some((a, c, d)),
        _ => None,
    };
    let walls = wall_columns(b);
    // a 2D run keeps every atom in the plane z = 0 (`fix enforce2d`): z that differ are 3D
    if let Some(z) = b.col(&["z", "zu", "zs"]) {
        let z0 = b.values.get(z).copied().unwrap_or(0.0);
        if let Some(row) = (0..b.rows()).find(|&r| b.values[r * b.cols + z] != z0) {
            return Err(ReadError::parse(
                path,
                b.first_line + row,
                format!(
                    "a 3D dump (atom z = {} where the first atom's is {z0}): 3D is not supported yet, grainlaw reads 2D dumps",
                    b.values[row * b.cols + z]
                ),
            ));
        }
    }
    let k = opts.inertia_factor;
    let mut frame = Frame {
        step: b.step,
        time: b.time,
        cell: b.cell.map(|c| c.cell),
        source: path.display().to_string(),
        ..Default::default()
    };
    let mut wall_acc: Vec<(Vector, Vector, usize)> =
        vec![(Vector::zeros(), Vector::zeros(), 0); walls.len()];
    let mut wall_contacts: Vec<(usize, u64, Vector, Vector)> = Vec::new();
    for row in 0..b.rows() {
        let v = &b.values[row * b.cols..(row + 1) * b.cols];
        let line = b.first_line + row;
        let gid = v[id];
        if gid < 0.0 || gid.fract() != 0.0 {
            return Err(ReadError::parse(
                path,
                line,
                format!("atom id {gid} is not a non-negative integer"),
            ));
        }
        let (mass, radius) = (v[m], v[r]);
        if !(mass > 0.0 && radius > 0.0) {
            return Err(ReadError::parse(
                path,
                line,
                format!("atom {gid}: mass {mass} and radius {radius} must be > 0"),
            ));
        }
        let inertia = k * mass * radius * radius;
        let pos = Vector::new(v[x], v[y]);
        frame.grains.push(GrainRecord {
            id: gid as u64,
            position: pos,
            angle: 0.0,
            velocity: Vector::new(v[vx], v[vy]),
            omega: v[om],
            radius,
            mass,
            inertia,
            acceleration: forces
                .map(|(fx, fy, tq)| (Vector::new(v[fx], v[fy]) / mass, v[tq] / inertia)),
        });
        for (w, (_, c)) in walls.iter().enumerate() {
            let col = |k: usize| c[k].map_or(0.0, |i| v[i]);
            if col(0) == 0.0 {
                continue;
            }
            let p = Vector::new(col(4), col(5));
            let d = pos - p;
            if d.norm() == 0.0 {
                return Err(ReadError::parse(
                    path,
                    line,
                    format!("atom {gid}: its centre is on wall `{}`", walls[w].0),
                ));
            }
            let f = Vector::new(col(1), col(2));
            wall_acc[w].0 += p;
            wall_acc[w].1 += d / d.norm();
            wall_acc[w].2 += 1;
            wall_contacts.push((w, gid as u64, f, d / d.norm()));
        }
    }
    // walls with contacts in this snapshot
    let mut wall_index = vec![None; walls.len()];
    for (w, (name, _)) in walls.iter().enumerate() {
        let (ps, ns, count) = wall_acc[w];
        if count == 0 {
            continue;
        }
        let point = ps / count as f64;
        let normal = ns.try_normalize(0.0).unwrap_or(Vector::new(0.0, 1.0));
        wall_index[w] = Some(frame.walls.len());
        frame.walls.push(WallRecord {
            name: name.clone(),
            geometry: WallGeometry::Line { point, normal },
            position: point,
            velocity: Vector::zeros(),
        });
    }
    for (w, gid, f, n) in wall_contacts {
        if let Some(k) = wall_index[w] {
            frame.contacts.push(ContactRecord {
                a: Other::Wall(k),
                b: gid,
                force: f,
                point: None,
                normal: Some(n),
            });
        }
    }
    Ok(frame)
}

/// Resolves the local column keys against a block's header.
fn local_columns(
    path: &Path,
    b: &Block,
    opts: &ReadOptions,
    keys: &[(&'static str, &[&str])],
    required: &[&str],
) -> Result<HashMap<&'static str, usize>, ReadError> {
    let mut map = HashMap::new();
    for (key, _) in &opts.columns {
        if !LOCAL_KEYS.iter().chain(WALL_KEYS).any(|(k, _)| k == key) {
            return Err(ReadError::content(
                path,
                format!(
                    "unknown column key `{key}`: expected one of {}",
                    LOCAL_KEYS
                        .iter()
                        .chain(WALL_KEYS)
                        .map(|k| k.0)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    }
    for (key, defaults) in keys {
        let given = opts.columns.iter().rev().find(|(k, _)| k == key);
        let col = match given {
            Some((_, h)) => Some(b.col(&[h.as_str()]).ok_or_else(|| {
                ReadError::parse(
                    path,
                    b.first_line - 1,
                    format!(
                        "no column `{h}` (given for `{key}`) in the header ({})",
                        b.header.join(" ")
                    ),
                )
            })?),
            None => b.col(defaults),
        };
        if let Some(c) = col {
            map.insert(*key, c);
        }
    }
    for key in required {
        if !map.contains_key(key) {
            return Err(ReadError::parse(
                path,
                b.first_line - 1,
                format!(
                    "no column for `{key}` in the header ({}): name it with --column {key}=HEADER",
                    b.header.join(" ")
                ),
            ));
        }
    }
    if map.contains_key("cx") != map.contains_key("cy") {
        return Err(ReadError::content(
            path,
            "the contact point needs both `cx` and `cy`",
        ));
    }
    Ok(map)
}

fn add_pairs(
    path: &Path,
    b: &Block,
    frame: &mut Frame,
    opts: &ReadOptions,
) -> Result<(), ReadError> {
    let c = local_columns(path, b, opts, LOCAL_KEYS, &["id1", "id2", "fx", "fy"])?;
    let get = |v: &[f64], k: &str| c.get(k).map_or(0.0, |&i| v[i]);
    for row in 0..b.rows() {
        let v = &b.values[row * b.cols..(row + 1) * b.cols];
        let f = Vector::new(get(v, "fx") + get(v, "ftx"), get(v, "fy") + get(v, "fty"));
        if f.x == 0.0 && f.y == 0.0 {
            continue;
        }
        let (i1, i2) = (get(v, "id1"), get(v, "id2"));
        if i1 < 0.0 || i2 < 0.0 || i1.fract() != 0.0 || i2.fract() != 0.0 {
            return Err(ReadError::parse(
                path,
                b.first_line + row,
                "atom ids must be non-negative integers",
            ));
        }
        frame.contacts.push(ContactRecord {
            a: Other::Grain(i2 as u64),
            b: i1 as u64,
            force: f,
            point: c
                .contains_key("cx")
                .then(|| Vector::new(get(v, "cx"), get(v, "cy"))),
            normal: None,
        });
    }
    Ok(())
}

/// Per wall id: the sums of the contact points and of the unit normals, and the contacts
/// (particle id, force on it, contact point, unit normal).
type WallSums = (Vector, Vector, Vec<(u64, Vector, Vector, Vector)>);

/// Whether a local block holds wall contacts (a `wall.wall` column by name or by mapping).
fn is_wall_block(b: &Block, opts: &ReadOptions) -> bool {
    match opts.columns.iter().rev().find(|(k, _)| k == "wall.wall") {
        Some((_, h)) => b.col(&[h.as_str()]).is_some(),
        None => b.col(WALL_KEYS[0].1).is_some(),
    }
}

/// Wall contacts of a local block (LIGGGHTS `compute wall/gran/local pos id force`): per row
/// the wall (mesh) id, the particle id, the force on the particle and the contact point. Each
/// wall id becomes a wall `wallN`: the line through the mean contact point with the mean unit
/// normal from the contact points to the particles' centres.
fn add_walls(
    path: &Path,
    b: &Block,
    frame: &mut Frame,
    opts: &ReadOptions,
) -> Result<(), ReadError> {
    let c = local_columns(
        path,
        b,
        opts,
        WALL_KEYS,
        &[
            "wall.wall",
            "wall.id",
            "wall.fx",
            "wall.fy",
            "wall.cx",
            "wall.cy",
        ],
    )?;
    let centre: HashMap<u64, Vector> = frame.grains.iter().map(|g| (g.id, g.position)).collect();
    let mut walls: BTreeMap<i64, WallSums> = BTreeMap::new();
    for row in 0..b.rows() {
        let v = &b.values[row * b.cols..(row + 1) * b.cols];
        let line = b.first_line + row;
        let (w, id) = (v[c["wall.wall"]], v[c["wall.id"]]);
        if w.fract() != 0.0 || id < 0.0 || id.fract() != 0.0 {
            return Err(ReadError::parse(
                path,
                line,
                "wall and particle ids must be integers",
            ));
        }
        let x = Vector::new(v[c["wall.cx"]], v[c["wall.cy"]]);
        let cp = *centre.get(&(id as u64)).ok_or_else(|| {
            ReadError::parse(
                path,
                line,
                format!(
                    "particle {id} is not in the per-atom dump of step {}",
                    b.step
                ),
            )
        })?;
        let d = cp - x;
        if d.norm() == 0.0 {
            return Err(ReadError::parse(
                path,
                line,
                format!("particle {id}: contact point at its centre"),
            ));
        }
        let n = d / d.norm();
        let e = walls
            .entry(w as i64)
            .or_insert((Vector::zeros(), Vector::zeros(), Vec::new()));
        e.0 += x;
        e.1 += n;
        e.2.push((
            id as u64,
            Vector::new(v[c["wall.fx"]], v[c["wall.fy"]]),
            x,
            n,
        ));
    }
    for (w, (ps, ns, contacts)) in walls {
        let k = frame.walls.len();
        let point = ps / contacts.len() as f64;
        frame.walls.push(WallRecord {
            name: format!("wall{w}"),
            geometry: WallGeometry::Line {
                point,
                normal: ns.try_normalize(0.0).unwrap_or(Vector::new(0.0, 1.0)),
            },
            position: point,
            velocity: Vector::zeros(),
        });
        for (id, f, x, n) in contacts {
            frame.contacts.push(ContactRecord {
                a: Other::Wall(k),
                b: id,
                force: f,
                point: Some(x),
                normal: Some(n),
            });
        }
    }
    Ok(())
}

/// One series is one sample: every per-atom snapshot has as many atoms as the first, and a box
/// of the same kind (orthogonal or triclinic, the same periodic axes; its size and tilt may
/// change). The first snapshot that differs is named by its file and line.
fn check_series(
    series: &BTreeMap<u64, (PathBuf, Option<DumpBox>, usize, usize)>,
) -> Result<(), ReadError> {
    let mut it = series.iter();
    let Some((s0, (p0, b0, _, n0))) = it.next() else {
        return Ok(());
    };
    for (s, (p, b, count_line, n)) in it {
        if n != n0 {
            return Err(ReadError::parse(
                p,
                *count_line,
                format!(
                    "step {s} has {n} atoms where step {s0} ({}) has {n0}: a series must keep its grains (homogenise snapshots of another sample separately)",
                    p0.display()
                ),
            ));
        }
        let kind = |b: &Option<DumpBox>| b.map(|b| (b.triclinic, b.cell.periodic));
        if kind(b) != kind(b0) {
            let describe = |b: &Option<DumpBox>| b.map_or("no box".to_string(), |b| b.describe());
            return Err(ReadError::parse(
                p,
                b.map_or(*count_line, |b| b.line),
                format!(
                    "the cell changes within the series: step {s} has a {} where step {s0} ({}) has a {}",
                    describe(b),
                    p0.display(),
                    describe(b0)
                ),
            ));
        }
    }
    Ok(())
}

/// Reads LAMMPS/LIGGGHTS dumps: per-atom files and pair-force local files in any order (the
/// kind of each block is told by its `ITEM: ATOMS` or `ITEM: ENTRIES` line), gzip or plain.
/// One snapshot per per-atom block, with the local block of the same time step.
pub fn read_lammps(
    files: &[PathBuf],
    opts: &ReadOptions,
) -> Result<Vec<ExternalSnapshot>, ReadError> {
    let mut frames: BTreeMap<u64, Frame> = BTreeMap::new();
    // per step: the file, its box and the line of its atom count (the series checks)
    let mut series: BTreeMap<u64, (PathBuf, Option<DumpBox>, usize, usize)> = BTreeMap::new();
    let mut locals: Vec<(PathBuf, Block)> = Vec::new();
    for path in files {
        let text = read_text(path)?;
        let blocks = parse_blocks(path, &text)?;
        if blocks.is_empty() {
            return Err(ReadError::content(
                path,
                "no dump block (`ITEM: TIMESTEP` … `ITEM: ATOMS`/`ENTRIES`)",
            ));
        }
        for b in blocks {
            match b.kind {
                Kind::Atoms => {
                    let f = atoms_frame(path, &b, opts)?;
                    series.insert(b.step, (path.clone(), b.cell, b.count_line, b.rows()));
                    if frames.insert(b.step, f).is_some() {
                        return Err(ReadError::content(
                            path,
                            format!("a second per-atom snapshot of step {}", b.step),
                        ));
                    }
                }
                Kind::Entries => locals.push((path.clone(), b)),
            }
        }
    }
    if frames.is_empty() {
        return Err(ReadError::Content {
            file: files
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
            reason: "no per-atom dump (`ITEM: ATOMS`): the grains are needed".into(),
        });
    }
    check_series(&series)?;
    let mut seen = std::collections::HashSet::new();
    for (path, b) in &locals {
        let f = frames.get_mut(&b.step).ok_or_else(|| {
            ReadError::content(
                path,
                format!(
                    "local dump of step {} has no per-atom dump of the same step",
                    b.step
                ),
            )
        })?;
        if is_wall_block(b, opts) {
            add_walls(path, b, f, opts)?;
            f.source = format!("{} + {}", f.source, path.display());
            continue;
        }
        if !seen.insert(b.step) {
            return Err(ReadError::content(
                path,
                format!("a second local dump of step {}", b.step),
            ));
        }
        add_pairs(path, b, f, opts)?;
        f.source = format!("{} + {}", f.source, path.display());
    }
    if locals.iter().any(|(_, b)| !is_wall_block(b, opts)) {
        if let Some(step) = frames.keys().find(|s| !seen.contains(s)) {
            return Err(ReadError::Content {
                file: frames[step].source.clone(),
                reason: format!("no local (pair force) dump of step {step}"),
            });
        }
    }
    build_snapshots(frames.into_values().collect(), opts)
}
