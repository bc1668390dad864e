//! The plain grainlaw snapshot format `grainlaw-snapshot-v1`: one JSON object per snapshot
//! (plain or gzip), that any code's output can be converted to in a few lines. Schema in
//! `docs/formats.md` § "Plain snapshots". Unknown keys are refused (a misspelt key is not
//! silently dropped).

use std::path::PathBuf;

use dem::math::{Spatial, Vector};
use dem::snapshot::WallGeometry;
use serde::{Deserialize, Serialize};

use super::frame::{ContactRecord, Frame, GrainRecord, Other, WallRecord};
use super::{build_snapshots, read_text, ExternalSnapshot, ReadError, ReadOptions};

/// The value of the `format` key.
pub const PLAIN_FORMAT: &str = "grainlaw-snapshot-v1";

/// One snapshot in the plain format.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlainSnapshot {
    /// Always `grainlaw-snapshot-v1`.
    pub format: String,
    /// Step index.
    pub step: u64,
    /// Time (s).
    pub time: f64,
    /// Periodic cell along x `[x_min, x_max)` (m), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic_x: Option<[f64; 2]>,
    /// The grains (disks).
    pub grains: Vec<PlainGrain>,
    /// The walls.
    #[serde(default)]
    pub walls: Vec<PlainWall>,
    /// The contacts.
    #[serde(default)]
    pub contacts: Vec<PlainContact>,
}

/// A grain: a rigid disk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlainGrain {
    /// Id, unique in the snapshot and the same across snapshots.
    pub id: u64,
    /// Centre (m).
    pub x: f64,
    /// Centre (m).
    pub y: f64,
    /// Velocity (m/s).
    pub vx: f64,
    /// Velocity (m/s).
    pub vy: f64,
    /// Angular velocity (rad/s, counter-clockwise).
    pub omega: f64,
    /// Radius (m).
    pub radius: f64,
    /// Mass (kg per metre of thickness).
    pub mass: f64,
    /// Moment of inertia (kg·m² per metre); default `m R²/2`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<f64>,
    /// Acceleration `[a_x, a_y, ω̇]` (m/s², rad/s²); when absent in any grain, finite
    /// differences of the velocities are used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceleration: Option<Spatial>,
}

/// A wall: a line (`point`, `normal` towards the grains) or a segment (`a`, `b`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlainWall {
    /// Name (used in outputs: `wall_profile_NAME.csv`).
    pub name: String,
    /// Line: a point (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 2]>,
    /// Line: unit normal towards the grains.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 2]>,
    /// Segment: first end (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a: Option<[f64; 2]>,
    /// Segment: second end (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b: Option<[f64; 2]>,
}

/// A contact: the force `[fx, fy]` (N) on grain `b` from grain `a` or from wall `wall`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlainContact {
    /// Id of the other grain (or use `wall`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a: Option<u64>,
    /// Name of the wall (or use `a`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall: Option<String>,
    /// Id of the grain that receives `force`.
    pub b: u64,
    /// Force on `b` (N).
    pub force: [f64; 2],
    /// Contact point (m); default from the geometry (`docs/formats.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 2]>,
}

fn v2(a: [f64; 2]) -> Vector {
    Vector::new(a[0], a[1])
}

/// Reads plain snapshots, one JSON file each (plain or `.gz`).
pub fn read_plain(
    files: &[PathBuf],
    opts: &ReadOptions,
) -> Result<Vec<ExternalSnapshot>, ReadError> {
    let mut frames = Vec::with_capacity(files.len());
    for path in files {
        let text = read_text(path)?;
        let p: PlainSnapshot = serde_json::from_str(&text).map_err(|e| {
            ReadError::parse(
                path,
                e.line(),
                format!("{e}")
                    .split(" at line")
                    .next()
                    .unwrap_or("")
                    .to_string(),
            )
        })?;
        if p.format != PLAIN_FORMAT {
            return Err(ReadError::content(
                path,
                format!("format is `{}`, expected `{PLAIN_FORMAT}`", p.format),
            ));
        }
        let mut frame = Frame {
            step: p.step,
            time: Some(p.time),
            periodic_x: p.periodic_x,
            source: path.display().to_string(),
            ..Default::default()
        };
        for g in &p.grains {
            frame.grains.push(GrainRecord {
                id: g.id,
                position: Vector::new(g.x, g.y),
                angle: 0.0,
                velocity: Vector::new(g.vx, g.vy),
                omega: g.omega,
                radius: g.radius,
                mass: g.mass,
                inertia: g.inertia.unwrap_or(0.5 * g.mass * g.radius * g.radius),
                acceleration: g.acceleration.map(|a| (Vector::new(a[0], a[1]), a[2])),
            });
        }
        for w in &p.walls {
            let geometry = match (w.point, w.normal, w.a, w.b) {
                (Some(p), Some(n), None, None) => {
                    let n = v2(n);
                    if (n.norm() - 1.0).abs() > 1e-9 {
                        return Err(ReadError::content(
                            path,
                            format!("wall `{}`: normal is not a unit vector", w.name),
                        ));
                    }
                    WallGeometry::Line {
                        point: v2(p),
                        normal: n,
                    }
                }
                (None, None, Some(a), Some(b)) => WallGeometry::Segment { a: v2(a), b: v2(b) },
                _ => {
                    return Err(ReadError::content(
                        path,
                        format!(
                        "wall `{}`: give `point` and `normal` (a line) or `a` and `b` (a segment)",
                        w.name
                    ),
                    ))
                }
            };
            let position = match &geometry {
                WallGeometry::Line { point, .. } => *point,
                WallGeometry::Segment { a, b } => (a + b) * 0.5,
                WallGeometry::Clump { .. } => Vector::zeros(),
            };
            frame.walls.push(WallRecord {
                name: w.name.clone(),
                geometry,
                position,
                velocity: Vector::zeros(),
            });
        }
        for (k, c) in p.contacts.iter().enumerate() {
            let a = match (&c.a, &c.wall) {
                (Some(id), None) => Other::Grain(*id),
                (None, Some(name)) => Other::Wall(
                    p.walls
                        .iter()
                        .position(|w| &w.name == name)
                        .ok_or_else(|| {
                            ReadError::content(path, format!("contact {k}: no wall named `{name}`"))
                        })?,
                ),
                _ => {
                    return Err(ReadError::content(
                        path,
                        format!("contact {k}: give either `a` (a grain id) or `wall`"),
                    ))
                }
            };
            frame.contacts.push(ContactRecord {
                a,
                b: c.b,
                force: v2(c.force),
                point: c.point.map(v2),
                normal: None,
            });
        }
        frames.push(frame);
    }
    build_snapshots(frames, opts)
}
