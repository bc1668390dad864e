//! Reading Gerris' text snapshots (`OutputSimulation { format = text }`) and the granular
//! interface in them (`docs/continuum.md` §4).
//!
//! A snapshot is one line per leaf cell, `x y z` then the variables asked for, after a header
//! `# 1:x 2:y 3:z 4:T 5:U ... TIME`; columns are found by their names in the header.
//!
//! **Height profile.** The cases refine every cell holding grains (`T > 0`) and its neighbours
//! to the finest level, so those cells have the side `Δ = L/2^level` and centres
//! `((i + ½)Δ, (j + ½)Δ)`; the height of the granular layer in column `i` is the volume of
//! grains above that strip of floor, `h_i = Σ_j T_ij Δ` (exact for a layer without overhang,
//! and the mass-conserving measure in any case). A cell with grains off that grid is an error:
//! the profile would be wrong.
//!
//! **Front.** `x_f` is the largest `x` where `h` exceeds a threshold `h_f` (the DEM contract's
//! one grain diameter, or the cell when it is larger: a layer thinner than one cell is not
//! resolved and moves with the light phase's viscosity): the right face of the last column
//! above it, as the DEM takes the edge of its last bin above one diameter, advanced into the
//! next column in proportion to its height (so that `x_f(t)` moves continuously).

use std::path::Path;

use crate::error::{CliError, Result};

/// One leaf cell of a snapshot; variables the snapshot lacks are NaN.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Centre `x`.
    pub x: f64,
    /// Centre `y`.
    pub y: f64,
    /// Volume fraction of grains `T` (VOF tracer).
    pub fraction: f64,
    /// Velocity `U`.
    pub u: f64,
    /// Velocity `V`.
    pub v: f64,
    /// Pressure `P`.
    pub p: f64,
    /// The law's inertial number (`Inertial`, 0 outside the grains).
    pub inertial: f64,
    /// `x` of the interface Gerris reconstructs in the cell (`X` of `VariablePosition X T x`),
    /// NaN where there is none (Gerris writes `G_MAXDOUBLE`) or the snapshot lacks it.
    pub interface_x: f64,
    /// `y` of the reconstructed interface (`Y`), likewise.
    pub interface_y: f64,
}

/// A text snapshot.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Gerris time of the snapshot (from its header).
    pub time: f64,
    /// The variables in the file (header names after `x y z`).
    pub variables: Vec<String>,
    /// The leaf cells.
    pub cells: Vec<Cell>,
}

impl Snapshot {
    /// Parses the text of a snapshot; `name` is used in errors. Errors: [`CliError::Input`]
    /// naming the file and line (no header, a header without the time or `x`, `y`, a row with
    /// another count of fields, a field that is not a number).
    pub fn parse(text: &str, name: &str) -> Result<Snapshot> {
        let bad = |line: usize, reason: String| CliError::Input {
            path: name.to_string(),
            reason: format!("line {line}: {reason}"),
        };
        let mut lines = text.lines().enumerate();
        let (_, header) = lines
            .by_ref()
            .find(|(_, l)| !l.trim().is_empty())
            .ok_or_else(|| bad(1, "empty file (no Gerris text header)".into()))?;
        let header = header
            .trim()
            .strip_prefix('#')
            .ok_or_else(|| bad(1, "no Gerris text header `# 1:x 2:y 3:z ... TIME`".into()))?;
        let mut names = Vec::new();
        let mut time = None;
        for (k, tok) in header.split_whitespace().enumerate() {
            match tok.split_once(':') {
                Some((idx, n)) if idx.parse::<usize>() == Ok(k + 1) => names.push(n.to_string()),
                _ => {
                    time = Some(tok.parse::<f64>().map_err(|_| {
                        bad(
                            1,
                            format!("header field `{tok}` is neither `N:name` nor the time"),
                        )
                    })?)
                }
            }
        }
        let time = time.ok_or_else(|| bad(1, "the header carries no time".into()))?;
        let col = |n: &str| names.iter().position(|c| c == n);
        let (ix, iy) = match (col("x"), col("y")) {
            (Some(x), Some(y)) => (x, y),
            _ => {
                return Err(bad(
                    1,
                    format!("the header lacks x or y ({})", names.join(" ")),
                ))
            }
        };
        let [it, iu, iv, ip, ii, ix2, iy2] = ["T", "U", "V", "P", "Inertial", "X", "Y"].map(col);
        let mut cells = Vec::new();
        for (k, line) in lines {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let f: Vec<f64> = line
                .split_whitespace()
                .map(|t| t.parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| bad(k + 1, format!("a field is not a number: `{line}`")))?;
            if f.len() != names.len() {
                return Err(bad(
                    k + 1,
                    format!("{} fields, the header names {}", f.len(), names.len()),
                ));
            }
            let get = |i: Option<usize>| i.map_or(f64::NAN, |i| f[i]);
            // Gerris marks "no interface here" with G_MAXDOUBLE
            let position =
                |i: Option<usize>| Some(get(i)).filter(|v| v.abs() < 1e300).unwrap_or(f64::NAN);
            cells.push(Cell {
                x: f[ix],
                y: f[iy],
                fraction: get(it),
                u: get(iu),
                v: get(iv),
                p: get(ip),
                inertial: get(ii),
                interface_x: position(ix2),
                interface_y: position(iy2),
            });
        }
        Ok(Snapshot {
            time,
            variables: names.into_iter().skip(3).collect(),
            cells,
        })
    }

    /// Reads a snapshot file ([`Snapshot::parse`]). Errors: [`CliError::Io`] when unreadable.
    pub fn read(path: &Path) -> Result<Snapshot> {
        let text = std::fs::read_to_string(path).map_err(|e| CliError::io(path, e))?;
        Snapshot::parse(&text, &path.display().to_string())
    }

    /// The height profile `h_i = Σ_j T_ij Δ` on columns of side `cell` (module documentation):
    /// `(x_i, h_i)` at the column centres from `x = Δ/2` to the last column holding grains.
    /// Errors: [`CliError::Input`] for a cell with grains whose centre is not on the grid of
    /// side `cell` (the case did not refine it to the finest level), or a snapshot without `T`.
    pub fn height_profile(&self, cell: f64, name: &str) -> Result<Vec<(f64, f64)>> {
        if !self.variables.iter().any(|v| v == "T") {
            return Err(CliError::Input {
                path: name.into(),
                reason: "the snapshot has no volume fraction T".into(),
            });
        }
        let mut h: Vec<f64> = Vec::new();
        for c in self.cells.iter().filter(|c| c.fraction > 0.0) {
            let (i, j) = (c.x / cell - 0.5, c.y / cell - 0.5);
            if (i - i.round()).abs() > 1e-3 || (j - j.round()).abs() > 1e-3 || i < -1e-3 {
                return Err(CliError::Input {
                    path: name.into(),
                    reason: format!(
                        "the cell at ({}, {}) holds grains (T = {}) but is not a finest cell of side {cell}: the profile needs every such cell at the finest level",
                        c.x, c.y, c.fraction
                    ),
                });
            }
            let i = i.round() as usize;
            if h.len() <= i {
                h.resize(i + 1, 0.0);
            }
            h[i] += c.fraction.min(1.0) * cell;
        }
        Ok(h.into_iter()
            .enumerate()
            .map(|(i, h)| ((i as f64 + 0.5) * cell, h))
            .collect())
    }

    /// Area of grains `Σ T Δ²` over the cells with grains (each of side `cell`).
    pub fn grain_area(&self, cell: f64) -> f64 {
        self.cells
            .iter()
            .filter(|c| c.fraction > 0.0)
            .map(|c| c.fraction.min(1.0) * cell * cell)
            .sum()
    }

    /// The law's inertial number in the cells full of grains (`T > 0.999`, where `Inertial` is
    /// computed): the largest with its cell, and the area fraction of the grains above
    /// `limit`. `None` when the snapshot has no `Inertial` or no full cell.
    pub fn inertial_statistics(&self, cell: f64, limit: f64) -> Option<InertialStatistics> {
        let full: Vec<&Cell> = self
            .cells
            .iter()
            .filter(|c| c.fraction > 0.999 && c.inertial.is_finite())
            .collect();
        let top = full
            .iter()
            .max_by(|a, b| a.inertial.total_cmp(&b.inertial))?;
        let area = self.grain_area(cell);
        let above = full.iter().filter(|c| c.inertial > limit).count() as f64 * cell * cell;
        Some(InertialStatistics {
            time: self.time,
            max: top.inertial,
            at: (top.x, top.y),
            fraction_above: if area > 0.0 { above / area } else { 0.0 },
        })
    }
}

/// The law's inertial number over one snapshot ([`Snapshot::inertial_statistics`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertialStatistics {
    /// Gerris time.
    pub time: f64,
    /// Largest `I` in a cell full of grains.
    pub max: f64,
    /// That cell's centre (Gerris units).
    pub at: (f64, f64),
    /// Area fraction of the grains whose `I` exceeds the limit.
    pub fraction_above: f64,
}

/// The front of a height profile `(x_i, h_i)` on columns of side `cell` (module
/// documentation): the right face `x_i + cell/2` of the last column whose height exceeds
/// `threshold` (the DEM contract's rule, on bins of one cell), advanced into the next column by
/// `cell · h_{i+1}/threshold` (that column's height is below the threshold, so the advance is
/// less than a cell): a front that fills the next column continuously reaches its face when
/// that column's height reaches the threshold, so `x_f(t)` has no steps of one cell, and a
/// vertical edge (`h_{i+1} = 0`) is its face. `None` when no column exceeds the threshold.
pub fn front(profile: &[(f64, f64)], threshold: f64, cell: f64) -> Option<f64> {
    let last = profile.iter().rposition(|p| p.1 > threshold)?;
    let next = profile.get(last + 1).map_or(0.0, |p| p.1.max(0.0));
    Some(profile[last].0 + 0.5 * cell + cell * (next / threshold).min(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hand-made snapshot: a 2 × 3 block of full cells of side 0.5 with a half-full cell on
    /// top of the first column and a quarter-full one at the foot of the third.
    fn block() -> Snapshot {
        let text = "# 1:x 2:y 3:z 4:T 5:Inertial 2.5\n\
                    0.25 0.25 0 1 0.1\n0.25 0.75 0 1 0.3\n0.25 1.25 0 0.5 0\n\
                    0.75 0.25 0 1 0.2\n0.75 0.75 0 1 0.05\n\
                    1.25 0.25 0 0.25 0\n3 3 0 0 0\n";
        Snapshot::parse(text, "block.txt").unwrap()
    }

    #[test]
    fn profile_area_front_and_inertial_number_by_hand() {
        let s = block();
        assert_eq!(s.time, 2.5);
        assert_eq!(s.variables, ["T", "Inertial"]);
        let p = s.height_profile(0.5, "block.txt").unwrap();
        assert_eq!(p, vec![(0.25, 1.25), (0.75, 1.0), (1.25, 0.125)]);
        assert!((s.grain_area(0.5) - (4.0 + 0.5 + 0.25) * 0.25).abs() < 1e-15);
        // threshold 0.5: the last column above it is x = 0.75 (h 1), its right face 1.0,
        // advanced by 0.5 · 0.125/0.5 into the next column
        assert_eq!(front(&p, 0.5, 0.5), Some(1.0 + 0.125));
        // the last column itself above the threshold: its face, nothing beyond
        assert_eq!(front(&p, 0.1, 0.5), Some(1.5));
        assert_eq!(front(&p, 2.0, 0.5), None);
        // a vertical edge: the face exactly
        assert_eq!(front(&[(0.25, 3.0), (0.75, 0.0)], 0.1, 0.5), Some(0.5));
        let st = s.inertial_statistics(0.5, 0.15).unwrap();
        assert_eq!((st.max, st.at), (0.3, (0.25, 0.75)));
        // two of the four full cells above 0.15: 2·0.25 over the area 1.1875
        assert!((st.fraction_above - 0.5 / 1.1875).abs() < 1e-15);
    }

    #[test]
    fn bad_snapshots_name_the_line() {
        let e = Snapshot::parse("0.25 0.25 0 1\n", "a.txt")
            .unwrap_err()
            .to_string();
        assert!(e.contains("a.txt") && e.contains("line 1"), "{e}");
        let e = Snapshot::parse("# 1:x 2:y 3:z 4:T 1\n0.25 0.25 0\n", "b.txt")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("3 fields"), "{e}");
        let e = Snapshot::parse("# 1:x 2:y 3:z 4:T 1\n0.3 0.25 0 1\n", "c.txt")
            .unwrap()
            .height_profile(0.5, "c.txt")
            .unwrap_err()
            .to_string();
        assert!(e.contains("finest"), "{e}");
        let e = Snapshot::parse("# 1:x 2:y 3:z 4:T\n", "d.txt")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no time"), "{e}");
    }
}
