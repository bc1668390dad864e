//! VTK files for ParaView: XML PolyData (`.vtp`) per frame, binary (base64 of zlib-compressed
//! blocks), and `.pvd` collections that make them a time series.
//!
//! Every file is a `VTKFile` of version 1.0 with `byte_order="LittleEndian"`,
//! `header_type="UInt64"` and `compressor="vtkZLibDataCompressor"`; every `DataArray` is
//! `format="binary"`: the little-endian values are cut into blocks of 32 768 bytes, each block
//! compressed with zlib (RFC 1950), and the array's text is the base64 (RFC 4648) of the header
//! `[number of blocks, block size, size of the last block if partial (else 0), compressed size of
//! each block]` (UInt64 words) followed by the base64 of the compressed blocks put end to end —
//! the layout of VTK's `vtkXMLWriter` (VTK User's Guide, "VTK File Formats", XML binary data).
//! Doubles are written as they are (Float64), so a reader gets the bits of the simulation.
//!
//! Identifiers: a grain's `id` is the index of its body in the world (walls are bodies too, so
//! the first grain is not always 0); a wall's is `−1 − k`, `k` its index among the world's
//! walls. Both appear as `id_a`, `id_b` on the contacts.
//!
//! Per frame, in `vtk/`:
//! - `grains_NNNN.vtp`: one vertex per grain at its centre; point data `id`, `radius` (m),
//!   `mass` (kg per metre of thickness), `velocity` (m/s), `omega` (angular velocity, rad/s),
//!   `angle` (rad), `stress` (the grain's mean stress with inertia Σ_p, Pa, tension positive,
//!   3×3 with zero z row and column) and `inertia_ratio` (‖Σ_i‖/‖Σ_c‖); show them with the
//!   "Point Gaussian" representation scaled by `radius`;
//! - `contacts_NNNN.vtp`: one line per contact of the step (open ones included), from body a's
//!   centre (a wall's contact point) to body b's centre; cell data `id_a`, `id_b`, `status`
//!   (0 open, 1 stick, 2 slide), `contact_point` (m), `normal` (unit, from a to b), `gap` (m),
//!   `normal_force`, `tangential_force` (N), `force` (vector on b, N), `mobilisation`
//!   |f_t|/(μ f_n);
//! - `walls_NNNN.vtp`: line and segment walls as lines, rough-wall disks as vertices; point
//!   data `id` and `radius`.
//!
//! `grains.pvd`, `contacts.pvd`, `walls.pvd` list the frames with their times (s).

use std::fmt::Write as _;
use std::io::Write as _;

use base64::engine::general_purpose::STANDARD as BASE64;
use base64::Engine as _;
use dem::local::ContactStatus;
use dem::math::Vector;
use dem::snapshot::{BodyKind, Snapshot, WallGeometry};
use flate2::write::ZlibEncoder;
use flate2::Compression;
use homogenise::tensor::frobenius;
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::output::OutputDir;

/// Frames written so far, to be listed in the `.pvd` collections (serialisable, for run
/// checkpoints).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct VtkSeries {
    frames: Vec<(f64, usize)>,
    prefix: String,
}

/// Uncompressed size of one compressed block (bytes), VTK's default.
pub const BLOCK_SIZE: usize = 1 << 15;

/// The text of a `format="binary"` DataArray holding `raw` (little-endian values): base64 of the
/// UInt64 compression header, then base64 of the zlib blocks (module documentation). zlib at
/// its fast level (1): on the float arrays of a frame, level 6 made the files about 10 % smaller
/// but took most of `grainlaw homogenise`'s time on 10⁵ grains.
pub fn encode_binary(raw: &[u8]) -> String {
    let blocks = raw.len().div_ceil(BLOCK_SIZE);
    let mut header: Vec<u64> = Vec::with_capacity(3 + blocks);
    header.extend([
        blocks as u64,
        BLOCK_SIZE as u64,
        (raw.len() % BLOCK_SIZE) as u64,
    ]);
    let mut data = Vec::new();
    for chunk in raw.chunks(BLOCK_SIZE) {
        let before = data.len();
        let mut z = ZlibEncoder::new(&mut data, Compression::fast());
        // Writing into a Vec cannot fail.
        let _ = z.write_all(chunk);
        let _ = z.finish();
        header.push((data.len() - before) as u64);
    }
    let head: Vec<u8> = header.iter().flat_map(|w| w.to_le_bytes()).collect();
    let mut s = BASE64.encode(head);
    s.push_str(&BASE64.encode(data));
    s
}

/// One `DataArray` element of VTK type `ty` (`Float64`, `Int64`, `UInt8`) holding `raw`.
fn array_xml(s: &mut String, name: &str, ty: &str, comps: usize, raw: &[u8]) {
    let _ = writeln!(
        s,
        "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"binary\">\n          {}\n        </DataArray>",
        encode_binary(raw)
    );
}

/// A Float64 array; values that are not finite are written as 0.
fn data_array(s: &mut String, name: &str, comps: usize, values: impl Iterator<Item = f64>) {
    let raw: Vec<u8> = values
        .flat_map(|v| (if v.is_finite() { v } else { 0.0 }).to_le_bytes())
        .collect();
    array_xml(s, name, "Float64", comps, &raw);
}

/// An Int64 array of one component.
fn int_array(s: &mut String, name: &str, values: impl Iterator<Item = i64>) {
    let raw: Vec<u8> = values.flat_map(i64::to_le_bytes).collect();
    array_xml(s, name, "Int64", 1, &raw);
}

/// Connectivity and offsets of `cells` cells of `per` consecutive points each, from point 0.
fn cells(s: &mut String, tag: &str, first: &[usize], per: usize) {
    let _ = writeln!(s, "      <{tag}>");
    int_array(
        s,
        "connectivity",
        first.iter().flat_map(|&k| (k..k + per).map(|p| p as i64)),
    );
    int_array(s, "offsets", (1..=first.len()).map(|k| (per * k) as i64));
    let _ = writeln!(s, "      </{tag}>");
}

fn header(nverts: usize, nlines: usize, npoints: usize) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n  <PolyData>\n    <Piece NumberOfPoints=\"{npoints}\" NumberOfVerts=\"{nverts}\" NumberOfLines=\"{nlines}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
    )
}

const FOOTER: &str = "    </Piece>\n  </PolyData>\n</VTKFile>\n";

fn points(s: &mut String, p: &[Vector]) {
    s.push_str("      <Points>\n");
    data_array(s, "Points", 3, p.iter().flat_map(|p| [p.x, p.y, 0.0]));
    s.push_str("      </Points>\n");
}

/// The id of body `body` in the VTK files: its index for a grain, `−1 − k` for the `k`-th wall
/// of the snapshot (module documentation).
pub fn body_id(snap: &Snapshot, body: u32) -> i64 {
    match snap.bodies.get(body as usize).map(|b| b.kind) {
        Some(BodyKind::Grain) | None => i64::from(body),
        Some(BodyKind::Wall) => snap
            .walls
            .iter()
            .position(|w| w.body == body)
            .map_or(i64::from(body), |k| -1 - k as i64),
    }
}

/// Code of a contact status in the `status` array: 0 open, 1 stick, 2 slide.
pub fn status_code(s: ContactStatus) -> u8 {
    match s {
        ContactStatus::Open => 0,
        ContactStatus::Stick => 1,
        ContactStatus::Slide => 2,
    }
}

/// The grains of a snapshot as `.vtp` text.
pub fn grains_vtp(snap: &Snapshot) -> Result<String> {
    let stresses = homogenise::grain_stresses(snap)?;
    let grains: Vec<(usize, _)> = snap
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.kind == BodyKind::Grain)
        .collect();
    let n = grains.len();
    let mut s = header(n, 0, n);
    s.push_str("      <PointData Scalars=\"radius\" Vectors=\"velocity\" Tensors=\"stress\">\n");
    int_array(&mut s, "id", grains.iter().map(|(i, _)| *i as i64));
    data_array(&mut s, "radius", 1, grains.iter().map(|(_, b)| b.radius));
    data_array(&mut s, "mass", 1, grains.iter().map(|(_, b)| b.mass));
    data_array(
        &mut s,
        "velocity",
        3,
        grains
            .iter()
            .flat_map(|(_, b)| [b.velocity.x, b.velocity.y, 0.0]),
    );
    data_array(&mut s, "omega", 1, grains.iter().map(|(_, b)| b.omega));
    data_array(&mut s, "angle", 1, grains.iter().map(|(_, b)| b.angle));
    data_array(
        &mut s,
        "stress",
        9,
        stresses.iter().flat_map(|g| {
            let t = g.total;
            [
                t[(0, 0)],
                t[(0, 1)],
                0.0,
                t[(1, 0)],
                t[(1, 1)],
                0.0,
                0.0,
                0.0,
                0.0,
            ]
        }),
    );
    data_array(
        &mut s,
        "inertia_ratio",
        1,
        stresses.iter().map(|g| {
            let c = frobenius(&g.contact);
            if c > 0.0 {
                frobenius(&g.inertia) / c
            } else {
                f64::NAN
            }
        }),
    );
    s.push_str("      </PointData>\n");
    points(
        &mut s,
        &grains.iter().map(|(_, b)| b.position).collect::<Vec<_>>(),
    );
    cells(&mut s, "Verts", &(0..n).collect::<Vec<_>>(), 1);
    s.push_str(FOOTER);
    Ok(s)
}

/// Ends of the branch of a contact: body a's end (its centre, or the contact point for a
/// wall) and body b's centre, both as seen from b (periodic images handled by the levers).
pub fn branch(snap: &Snapshot, c: &dem::snapshot::ContactState) -> (Vector, Vector) {
    let a = &snap.bodies[c.body_a as usize];
    let pa = if a.kind == BodyKind::Grain {
        c.point - c.lever_a
    } else {
        c.point
    };
    let b = &snap.bodies[c.body_b as usize];
    let pb = if b.kind == BodyKind::Grain {
        c.point - c.lever_b
    } else {
        c.point
    };
    (pa, pb)
}

/// The contacts of a snapshot (every contact of the step, open ones included) as `.vtp` text.
pub fn contacts_vtp(snap: &Snapshot) -> String {
    let cs = &snap.contacts;
    let n = cs.len();
    let mut s = header(0, n, 2 * n);
    s.push_str("      <CellData Scalars=\"normal_force\" Vectors=\"force\">\n");
    int_array(&mut s, "id_a", cs.iter().map(|c| body_id(snap, c.body_a)));
    int_array(&mut s, "id_b", cs.iter().map(|c| body_id(snap, c.body_b)));
    let status: Vec<u8> = cs.iter().map(|c| status_code(c.status)).collect();
    array_xml(&mut s, "status", "UInt8", 1, &status);
    data_array(
        &mut s,
        "contact_point",
        3,
        cs.iter().flat_map(|c| [c.point.x, c.point.y, 0.0]),
    );
    data_array(
        &mut s,
        "normal",
        3,
        cs.iter().flat_map(|c| [c.normal.x, c.normal.y, 0.0]),
    );
    data_array(&mut s, "gap", 1, cs.iter().map(|c| c.gap));
    data_array(&mut s, "normal_force", 1, cs.iter().map(|c| c.force_n));
    data_array(&mut s, "tangential_force", 1, cs.iter().map(|c| c.force_t));
    data_array(
        &mut s,
        "force",
        3,
        cs.iter().flat_map(|c| {
            let f = c.force_on_b();
            [f.x, f.y, 0.0]
        }),
    );
    data_array(
        &mut s,
        "mobilisation",
        1,
        cs.iter().map(|c| c.mobilisation().unwrap_or(0.0)),
    );
    s.push_str("      </CellData>\n");
    let pts: Vec<Vector> = cs
        .iter()
        .flat_map(|c| {
            let (a, b) = branch(snap, c);
            [a, b]
        })
        .collect();
    points(&mut s, &pts);
    cells(
        &mut s,
        "Lines",
        &(0..n).map(|k| 2 * k).collect::<Vec<_>>(),
        2,
    );
    s.push_str(FOOTER);
    s
}

/// Extent of the grains `(x_min, x_max, y_min, y_max)` (m), with a margin of 2 largest radii.
pub fn grain_extent(snap: &Snapshot) -> (f64, f64, f64, f64) {
    let mut e = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    let mut rmax: f64 = 0.0;
    for b in snap.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
        e.0 = e.0.min(b.position.x - b.radius);
        e.1 = e.1.max(b.position.x + b.radius);
        e.2 = e.2.min(b.position.y - b.radius);
        e.3 = e.3.max(b.position.y + b.radius);
        rmax = rmax.max(b.radius);
    }
    if e.0 > e.1 {
        return (0.0, 1.0, 0.0, 1.0);
    }
    (
        e.0 - 2.0 * rmax,
        e.1 + 2.0 * rmax,
        e.2 - 2.0 * rmax,
        e.3 + 2.0 * rmax,
    )
}

/// Clips the infinite line through `p` with normal `n` to the box `(x0, x1, y0, y1)`.
pub fn clip_line(p: Vector, n: Vector, e: (f64, f64, f64, f64)) -> Option<(Vector, Vector)> {
    let d = Vector::new(-n.y, n.x);
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for (pc, dc, lo, hi) in [(p.x, d.x, e.0, e.1), (p.y, d.y, e.2, e.3)] {
        if dc.abs() < 1e-14 {
            if pc < lo || pc > hi {
                return None;
            }
        } else {
            let (a, b) = ((lo - pc) / dc, (hi - pc) / dc);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then(|| (p + d * t0, p + d * t1))
}

/// The walls of a snapshot as `.vtp` text (lines clipped to the grains' extent).
pub fn walls_vtp(snap: &Snapshot) -> String {
    let ext = grain_extent(snap);
    let mut pts = Vec::new();
    let mut radius = Vec::new();
    let mut ids = Vec::new();
    let mut lines = Vec::new();
    let mut verts = Vec::new();
    for (k, w) in snap.walls.iter().enumerate() {
        let id = -1 - k as i64;
        match &w.geometry {
            WallGeometry::Line { point, normal } => {
                if let Some((a, b)) = clip_line(*point, *normal, ext) {
                    lines.push(pts.len());
                    pts.extend([a, b]);
                    radius.extend([0.0, 0.0]);
                    ids.extend([id, id]);
                }
            }
            WallGeometry::Segment { a, b } => {
                lines.push(pts.len());
                pts.extend([*a, *b]);
                radius.extend([0.0, 0.0]);
                ids.extend([id, id]);
            }
            WallGeometry::Clump { centres, radii } => {
                for (c, r) in centres.iter().zip(radii) {
                    verts.push(pts.len());
                    pts.push(*c);
                    radius.push(*r);
                    ids.push(id);
                }
            }
        }
    }
    if let Some(cell) = &snap.cell {
        // The biperiodic cell's four edges.
        let (a1, a2) = (cell.h.column(0).into_owned(), cell.h.column(1).into_owned());
        let corners = [Vector::zeros(), a1, a1 + a2, a2];
        for k in 0..4 {
            lines.push(pts.len());
            pts.push(corners[k]);
            pts.push(corners[(k + 1) % 4]);
            radius.extend([0.0, 0.0]);
        }
    }
    let mut s = header(verts.len(), lines.len(), pts.len());
    s.push_str("      <PointData Scalars=\"radius\">\n");
    int_array(&mut s, "id", ids.into_iter());
    data_array(&mut s, "radius", 1, radius.into_iter());
    s.push_str("      </PointData>\n");
    points(&mut s, &pts);
    cells(&mut s, "Verts", &verts, 1);
    cells(&mut s, "Lines", &lines, 2);
    s.push_str(FOOTER);
    s
}

impl VtkSeries {
    /// An empty series.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty series whose files are named `PREFIXgrains_NNNN.vtp`, `PREFIXgrains.pvd`, ...
    pub fn with_prefix(prefix: &str) -> Self {
        Self {
            frames: Vec::new(),
            prefix: prefix.to_string(),
        }
    }

    /// Writes the three files of one frame under `vtk/` (`PREFIXgrains_NNNN.vtp`, ...).
    pub fn add_frame(&mut self, out: &mut OutputDir, snap: &Snapshot) -> Result<()> {
        let k = self.frames.len();
        let p = &self.prefix;
        out.write(
            &format!("vtk/{p}grains_{k:04}.vtp"),
            grains_vtp(snap)?.as_bytes(),
        )?;
        out.write(
            &format!("vtk/{p}contacts_{k:04}.vtp"),
            contacts_vtp(snap).as_bytes(),
        )?;
        out.write(
            &format!("vtk/{p}walls_{k:04}.vtp"),
            walls_vtp(snap).as_bytes(),
        )?;
        self.frames.push((snap.time, k));
        Ok(())
    }

    /// Number of frames written.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True when no frame was written.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Writes `grains.pvd`, `contacts.pvd` and `walls.pvd`.
    pub fn finish(&self, out: &mut OutputDir) -> Result<()> {
        for kind in ["grains", "contacts", "walls"] {
            let mut s = String::from(
                "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
            );
            for (t, k) in &self.frames {
                let _ = writeln!(
                    s,
                    "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"vtk/{}{kind}_{k:04}.vtp\"/>",
                    self.prefix
                );
            }
            s.push_str("  </Collection>\n</VTKFile>\n");
            out.write(&format!("{}{kind}.pvd", self.prefix), s.as_bytes())?;
        }
        Ok(())
    }
}
