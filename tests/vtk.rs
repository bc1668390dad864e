//! The VTK files, read back by an independent reader: the XML parsed with `roxmltree`, each
//! binary `DataArray` decoded from base64 and inflated block by block with `flate2` as VTK's
//! `vtkXMLDataParser` does (UInt64 header `[blocks, block size, last partial size, compressed
//! sizes…]`, then the zlib blocks), and the arrays compared with the snapshot they were written
//! from, and with the CSV of a scenario run.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;
use std::process::Command;

use base64::engine::general_purpose::STANDARD as BASE64;
use base64::Engine as _;
use dem::snapshot::{BodyKind, Snapshot};
use flate2::read::ZlibDecoder;
use grainlaw::output::vtk::{contacts_vtp, grains_vtp, walls_vtp, BLOCK_SIZE};

/// A decoded array: its VTK type, components and values (integers as f64 are exact below 2⁵³).
#[derive(Debug)]
struct Array {
    ty: String,
    comps: usize,
    values: Vec<f64>,
}

/// A decoded PolyData piece: its counts and every array by name (`Points`, point, cell and
/// topology arrays, the latter as `Verts/offsets`, `Lines/connectivity`, ...).
#[derive(Debug)]
struct Piece {
    points: usize,
    verts: usize,
    lines: usize,
    arrays: BTreeMap<String, Array>,
}

/// Decodes one binary compressed DataArray text.
fn decode(text: &str, ty: &str) -> Vec<f64> {
    let text: String = text.split_whitespace().collect();
    let b64_len = |bytes: usize| bytes.div_ceil(3) * 4;
    let first = BASE64.decode(&text[..b64_len(24)]).unwrap();
    let word = |b: &[u8], k: usize| u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().unwrap());
    let blocks = word(&first, 0) as usize;
    let head_len = b64_len(8 * (3 + blocks));
    let head = BASE64.decode(&text[..head_len]).unwrap();
    let block_size = word(&head, 1) as usize;
    let last = word(&head, 2) as usize;
    assert_eq!(block_size, BLOCK_SIZE);
    let data = BASE64.decode(&text[head_len..]).unwrap();
    let mut raw = Vec::new();
    let mut at = 0;
    for k in 0..blocks {
        let c = word(&head, 3 + k) as usize;
        let mut out = Vec::new();
        ZlibDecoder::new(&data[at..at + c])
            .read_to_end(&mut out)
            .unwrap();
        let expected = if k + 1 == blocks && last != 0 {
            last
        } else {
            block_size
        };
        assert_eq!(out.len(), expected, "block {k} of {blocks}");
        raw.extend(out);
        at += c;
    }
    assert_eq!(at, data.len(), "compressed sizes add up to the data");
    match ty {
        "Float64" => raw
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
        "Int64" => raw
            .chunks(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()) as f64)
            .collect(),
        "UInt8" => raw.iter().map(|&b| f64::from(b)).collect(),
        other => panic!("unexpected type {other}"),
    }
}

fn parse(xml: &str) -> Piece {
    let doc = roxmltree::Document::parse(xml).unwrap();
    let root = doc.root_element();
    assert_eq!(root.attribute("type"), Some("PolyData"));
    assert_eq!(root.attribute("byte_order"), Some("LittleEndian"));
    assert_eq!(root.attribute("header_type"), Some("UInt64"));
    assert_eq!(root.attribute("compressor"), Some("vtkZLibDataCompressor"));
    let piece = root
        .descendants()
        .find(|n| n.has_tag_name("Piece"))
        .unwrap();
    let count = |k: &str| piece.attribute(k).unwrap().parse::<usize>().unwrap();
    let mut arrays = BTreeMap::new();
    for da in piece.descendants().filter(|n| n.has_tag_name("DataArray")) {
        assert_eq!(da.attribute("format"), Some("binary"));
        let parent = da.parent_element().unwrap().tag_name().name();
        let name = da.attribute("Name").unwrap();
        let key = if matches!(parent, "Verts" | "Lines") {
            format!("{parent}/{name}")
        } else {
            name.to_string()
        };
        let ty = da.attribute("type").unwrap().to_string();
        let comps = da
            .attribute("NumberOfComponents")
            .map_or(1, |c| c.parse().unwrap());
        let values = decode(da.text().unwrap_or(""), &ty);
        assert!(arrays
            .insert(key.clone(), Array { ty, comps, values })
            .is_none());
    }
    let p = Piece {
        points: count("NumberOfPoints"),
        verts: count("NumberOfVerts"),
        lines: count("NumberOfLines"),
        arrays,
    };
    // Every array has one tuple per point or cell it belongs to.
    for (name, a) in &p.arrays {
        assert_eq!(a.values.len() % a.comps, 0, "{name}");
    }
    p
}

impl Piece {
    fn get(&self, name: &str) -> &[f64] {
        &self
            .arrays
            .get(name)
            .unwrap_or_else(|| panic!("no array {name}"))
            .values
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()) || a == b
}

fn assert_close(name: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{name}: length");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(close(*g, *w), "{name}[{k}]: {g} vs {w}");
    }
}

/// The id of a body in the files: its index for a grain, `−1 − k` for the `k`-th wall.
fn id_of(s: &Snapshot, body: u32) -> f64 {
    match s.bodies[body as usize].kind {
        BodyKind::Grain => f64::from(body),
        BodyKind::Wall => -1.0 - s.walls.iter().position(|w| w.body == body).unwrap() as f64,
    }
}

/// 600 grains dropped on a floor between two walls for 300 steps: the three files of the
/// snapshot decode to its values (positions, ids, radii, masses, velocities, stresses; every
/// contact with its pair, point, normal, forces and status), with arrays long enough to span
/// several compressed blocks.
#[test]
fn frames_decode_to_the_snapshot() {
    let mut w = grainlaw::benchmarks::grid_world(600, 0.08, 0.3, 3);
    for _ in 0..300 {
        w.step().unwrap();
    }
    let s = w.snapshot();
    let grains: Vec<(usize, &dem::snapshot::BodyState)> = s
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.kind == BodyKind::Grain)
        .collect();
    let n = grains.len();
    assert_eq!(n, 600);

    let g = parse(&grains_vtp(&s).unwrap());
    assert_eq!((g.points, g.verts, g.lines), (n, n, 0));
    assert_eq!(g.arrays["id"].ty, "Int64");
    assert_close(
        "id",
        g.get("id"),
        &grains.iter().map(|(i, _)| *i as f64).collect::<Vec<_>>(),
    );
    let flat = |f: &dyn Fn(&dem::snapshot::BodyState) -> Vec<f64>| -> Vec<f64> {
        grains.iter().flat_map(|(_, b)| f(b)).collect()
    };
    assert_close(
        "Points",
        g.get("Points"),
        &flat(&|b| vec![b.position.x, b.position.y, 0.0]),
    );
    assert_close("radius", g.get("radius"), &flat(&|b| vec![b.radius]));
    assert_close("mass", g.get("mass"), &flat(&|b| vec![b.mass]));
    assert_close(
        "velocity",
        g.get("velocity"),
        &flat(&|b| vec![b.velocity.x, b.velocity.y, 0.0]),
    );
    assert_close("omega", g.get("omega"), &flat(&|b| vec![b.omega]));
    assert_close("angle", g.get("angle"), &flat(&|b| vec![b.angle]));
    let stresses = homogenise::grain_stresses(&s).unwrap();
    let want: Vec<f64> = stresses
        .iter()
        .flat_map(|t| {
            let t = t.total;
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
        })
        .collect();
    assert!(
        want.len() * 8 > BLOCK_SIZE && !(want.len() * 8).is_multiple_of(BLOCK_SIZE),
        "stress spans two blocks, the last one partial"
    );
    assert_close("stress", g.get("stress"), &want);
    assert_close(
        "Verts/connectivity",
        g.get("Verts/connectivity"),
        &(0..n).map(|k| k as f64).collect::<Vec<_>>(),
    );
    assert_close(
        "Verts/offsets",
        g.get("Verts/offsets"),
        &(1..=n).map(|k| k as f64).collect::<Vec<_>>(),
    );

    let c = parse(&contacts_vtp(&s));
    let m = s.contacts.len();
    assert!(m > 100, "the falling grains touch ({m} contacts)");
    assert_eq!((c.points, c.verts, c.lines), (2 * m, 0, m));
    let cs = &s.contacts;
    let ids_a: Vec<f64> = cs.iter().map(|k| id_of(&s, k.body_a)).collect();
    assert!(ids_a.iter().any(|&i| i < 0.0), "wall contacts present");
    assert_close("id_a", c.get("id_a"), &ids_a);
    assert_close(
        "id_b",
        c.get("id_b"),
        &cs.iter().map(|k| id_of(&s, k.body_b)).collect::<Vec<_>>(),
    );
    assert_close(
        "status",
        c.get("status"),
        &cs.iter()
            .map(|k| match k.status {
                dem::ContactStatus::Open => 0.0,
                dem::ContactStatus::Stick => 1.0,
                dem::ContactStatus::Slide => 2.0,
            })
            .collect::<Vec<_>>(),
    );
    assert_close(
        "contact_point",
        c.get("contact_point"),
        &cs.iter()
            .flat_map(|k| [k.point.x, k.point.y, 0.0])
            .collect::<Vec<_>>(),
    );
    assert_close(
        "normal",
        c.get("normal"),
        &cs.iter()
            .flat_map(|k| [k.normal.x, k.normal.y, 0.0])
            .collect::<Vec<_>>(),
    );
    assert_close(
        "normal_force",
        c.get("normal_force"),
        &cs.iter().map(|k| k.force_n).collect::<Vec<_>>(),
    );
    assert_close(
        "tangential_force",
        c.get("tangential_force"),
        &cs.iter().map(|k| k.force_t).collect::<Vec<_>>(),
    );
    assert_close(
        "gap",
        c.get("gap"),
        &cs.iter().map(|k| k.gap).collect::<Vec<_>>(),
    );
    // One line of two points per contact.
    assert_eq!(c.get("Points").len(), 6 * m);
    assert_close(
        "Lines/offsets",
        c.get("Lines/offsets"),
        &(1..=m).map(|k| 2.0 * k as f64).collect::<Vec<_>>(),
    );

    let wl = parse(&walls_vtp(&s));
    assert_eq!((wl.points, wl.lines), (6, 3));
    assert_close(
        "walls id",
        wl.get("id"),
        &[-1.0, -1.0, -2.0, -2.0, -3.0, -3.0],
    );
}

/// An empty frame (no contact) is a valid file with empty arrays (no block).
#[test]
fn an_empty_contact_frame_decodes() {
    let w = grainlaw::benchmarks::grid_world(10, 0.05, 0.3, 1);
    let s = w.snapshot();
    assert!(s.contacts.is_empty());
    let c = parse(&contacts_vtp(&s));
    assert_eq!((c.points, c.lines), (0, 0));
    assert!(c.get("normal_force").is_empty());
}

/// A `rolling` run: every frame listed in each `.pvd` exists and decodes; the last frame is
/// the state of the last row of `history.csv` (same time; speed, spin and the invariants of
/// the mean stress with inertia to 1e-12 relative).
#[test]
fn a_run_writes_series_that_agree_with_its_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let o = Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .args(["run", "rolling", "-q", "--out"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut last_grains = None;
    for kind in ["grains", "contacts", "walls"] {
        let pvd = std::fs::read_to_string(dir.join(format!("{kind}.pvd"))).unwrap();
        let doc = roxmltree::Document::parse(&pvd).unwrap();
        let sets: Vec<_> = doc
            .descendants()
            .filter(|n| n.has_tag_name("DataSet"))
            .map(|n| {
                (
                    n.attribute("timestep").unwrap().parse::<f64>().unwrap(),
                    n.attribute("file").unwrap().to_string(),
                )
            })
            .collect();
        assert_eq!(sets.len(), 21, "{kind}");
        for (t, f) in &sets {
            let p = parse(&std::fs::read_to_string(dir.join(Path::new(f))).unwrap());
            if kind == "grains" {
                assert_eq!(p.points, 1);
                last_grains = Some((*t, p));
            }
        }
    }
    let (t, g) = last_grains.unwrap();
    let csv = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = csv.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let row: Vec<f64> = lines
        .next_back()
        .unwrap()
        .split(',')
        .map(|c| c.parse().unwrap())
        .collect();
    let col = |name: &str| row[header.iter().position(|h| *h == name).unwrap()];
    assert!(close(t, col("time_s")), "{t} vs {}", col("time_s"));
    let v = g.get("velocity");
    assert!(close(v[0].hypot(v[1]), col("velocity_m_s").abs()));
    assert!(close(g.get("omega")[0], col("omega_rad_s")));
    let st = g.get("stress");
    let (trace, det) = (st[0] + st[4], st[0] * st[4] - st[1] * st[3]);
    let trace_csv = col("stress_xx_Pa") + col("stress_yy_Pa");
    let det_csv =
        col("stress_xx_Pa") * col("stress_yy_Pa") - col("stress_xy_Pa") * col("stress_yx_Pa");
    assert!((trace - trace_csv).abs() <= 1e-12 * st[0].abs().max(st[4].abs()) * 4.0);
    assert!((det - det_csv).abs() <= 1e-12 * det.abs().max(det_csv.abs()) * 4.0 + 1e-9);
}
