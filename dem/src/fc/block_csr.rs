//! Square block-sparse matrix of 2×2 blocks in compressed-row storage (block CSR): the Delassus
//! matrix `W` of a 2D frictional-contact problem, one block row and one block column per contact.

use super::error::FcError;

/// One 2×2 block, row-major: `[a, b, c, d]` is `[[a, b], [c, d]]` (`a = W_nn`, `b = W_nt`,
/// `c = W_tn`, `d = W_tt` for the local frame, normal first).
pub type Block2 = [f64; 4];

/// Square matrix of `n × n` blocks of size 2×2 in block CSR storage.
///
/// Block row `i` holds the blocks `val[k]` in columns `col[k]` for `k ∈ row_ptr[i]..row_ptr[i+1]`,
/// columns strictly increasing within a row. Blocks absent from the pattern are zero.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BlockCsr2 {
    n: usize,
    row_ptr: Vec<usize>,
    col: Vec<u32>,
    val: Vec<Block2>,
}

impl BlockCsr2 {
    /// Builds the matrix of scalar size `2n × 2n` from COO triplets `(row[k], col[k], val[k])`
    /// (scalar indices); duplicate entries are summed, as in the usual COO convention.
    ///
    /// The three slices must have equal lengths and the indices must be `< 2n` (checked, errors
    /// name `W.row` / `W.col` / `W.val`).
    pub fn from_triplets(
        n: usize,
        row: &[usize],
        col: &[usize],
        val: &[f64],
    ) -> Result<Self, FcError> {
        if n > (u32::MAX as usize) / 2 {
            return Err(FcError::InvalidValue {
                key: "nc".into(),
                reason: format!("{n} contacts is more than this solver's index type holds"),
            });
        }
        if col.len() != row.len() {
            return Err(FcError::SizeMismatch {
                key: "W.col".into(),
                expected: row.len(),
                found: col.len(),
            });
        }
        if val.len() != row.len() {
            return Err(FcError::SizeMismatch {
                key: "W.val".into(),
                expected: row.len(),
                found: val.len(),
            });
        }
        let size = 2 * n;
        for (key, idx) in [("W.row", row), ("W.col", col)] {
            if let Some((entry, &index)) = idx.iter().enumerate().find(|(_, &i)| i >= size) {
                return Err(FcError::IndexOutOfRange {
                    key: key.into(),
                    entry,
                    index,
                    size,
                });
            }
        }
        for (k, v) in val.iter().enumerate() {
            if !v.is_finite() {
                return Err(FcError::NonFinite {
                    key: format!("W.val[{k}]"),
                });
            }
        }
        // Bucket the triplets by block row (counting sort), then sort each row by block column.
        let mut count = vec![0usize; n + 1];
        for &i in row {
            count[i / 2 + 1] += 1;
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let mut next = count.clone();
        let mut order = vec![0usize; row.len()];
        for (k, &i) in row.iter().enumerate() {
            let b = i / 2;
            order[next[b]] = k;
            next[b] += 1;
        }
        let mut row_ptr = Vec::with_capacity(n + 1);
        let mut bcol: Vec<u32> = Vec::new();
        let mut bval: Vec<Block2> = Vec::new();
        row_ptr.push(0);
        for b in 0..n {
            let slot = &mut order[count[b]..count[b + 1]];
            slot.sort_unstable_by_key(|&k| col[k] / 2);
            for &k in slot.iter() {
                let bj = (col[k] / 2) as u32;
                let local = 2 * (row[k] % 2) + col[k] % 2;
                if bcol.len() == row_ptr[b] || *bcol.last().unwrap_or(&u32::MAX) != bj {
                    bcol.push(bj);
                    bval.push([0.0; 4]);
                }
                if let Some(last) = bval.last_mut() {
                    last[local] += val[k];
                }
            }
            row_ptr.push(bcol.len());
        }
        Ok(Self {
            n,
            row_ptr,
            col: bcol,
            val: bval,
        })
    }

    /// Builds the matrix from dense rows (`rows.len() = 2n`, each of length `2n`); exact zeros
    /// blocks are dropped from the pattern.
    pub fn from_dense(rows: &[Vec<f64>]) -> Result<Self, FcError> {
        let size = rows.len();
        if let Some((i, r)) = rows.iter().enumerate().find(|(_, r)| r.len() != size) {
            return Err(FcError::NotSquare {
                key: format!("W.data[{i}]"),
                rows: size,
                cols: r.len(),
            });
        }
        if !size.is_multiple_of(2) {
            return Err(FcError::InvalidValue {
                key: "W.data".into(),
                reason: format!("size {size} is odd, a 2D problem has 2 rows per contact"),
            });
        }
        let (mut ri, mut ci, mut v) = (Vec::new(), Vec::new(), Vec::new());
        for (i, r) in rows.iter().enumerate() {
            for (j, &x) in r.iter().enumerate() {
                if !x.is_finite() {
                    return Err(FcError::NonFinite {
                        key: format!("W.data[{i}][{j}]"),
                    });
                }
                if x != 0.0 {
                    ri.push(i);
                    ci.push(j);
                    v.push(x);
                }
            }
        }
        Self::from_triplets(size / 2, &ri, &ci, &v)
    }

    /// Number of block rows (= contacts).
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of stored blocks.
    pub fn nnz_blocks(&self) -> usize {
        self.col.len()
    }

    /// Block-row pointers (length `n + 1`).
    pub fn row_ptr(&self) -> &[usize] {
        &self.row_ptr
    }

    /// Block-column index of every stored block.
    pub fn col(&self) -> &[u32] {
        &self.col
    }

    /// Stored blocks, row-major 2×2.
    pub fn val(&self) -> &[Block2] {
        &self.val
    }

    /// The stored blocks of block row `i` as `(column, block)` pairs.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (usize, &Block2)> + '_ {
        let s = self.row_ptr[i];
        let e = self.row_ptr[i + 1];
        self.col[s..e]
            .iter()
            .map(|&c| c as usize)
            .zip(self.val[s..e].iter())
    }

    /// Diagonal block `W_ii` (zero if absent from the pattern).
    pub fn diagonal(&self, i: usize) -> Block2 {
        self.row(i)
            .find(|(j, _)| *j == i)
            .map(|(_, b)| *b)
            .unwrap_or([0.0; 4])
    }

    /// `y = W x + y0` for vectors of length `2n` (interleaved `(n, t)` per contact).
    ///
    /// # Panics
    /// If `x`, `y0` or `y` is shorter than `2n` (programming error, not user input).
    pub fn mul_add(&self, x: &[f64], y0: &[f64], y: &mut [f64]) {
        for i in 0..self.n {
            let (mut a0, mut a1) = (y0[2 * i], y0[2 * i + 1]);
            for (j, b) in self.row(i) {
                let (x0, x1) = (x[2 * j], x[2 * j + 1]);
                a0 += b[0] * x0 + b[1] * x1;
                a1 += b[2] * x0 + b[3] * x1;
            }
            y[2 * i] = a0;
            y[2 * i + 1] = a1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triplets_sum_duplicates_and_match_dense_product() {
        // 3 contacts, scalar size 6; an entry given twice is summed.
        let row = [0, 1, 0, 5, 4, 2, 3, 0];
        let col = [0, 1, 5, 0, 4, 2, 3, 0];
        let val = [1.0, 2.0, 0.5, 0.5, 3.0, 4.0, 5.0, 1.5];
        let w = BlockCsr2::from_triplets(3, &row, &col, &val).unwrap();
        let mut dense = [[0.0f64; 6]; 6];
        for k in 0..row.len() {
            dense[row[k]][col[k]] += val[k];
        }
        assert_eq!(w.diagonal(0), [2.5, 0.0, 0.0, 2.0]);
        let x = [1.0, -2.0, 0.25, 3.0, -1.0, 0.5];
        let y0 = [0.1; 6];
        let mut y = [0.0; 6];
        w.mul_add(&x, &y0, &mut y);
        for i in 0..6 {
            let expect: f64 = 0.1 + (0..6).map(|j| dense[i][j] * x[j]).sum::<f64>();
            assert!(
                (y[i] - expect).abs() <= 1e-15,
                "row {i}: {} vs {expect}",
                y[i]
            );
        }
    }

    #[test]
    fn bad_triplets_are_rejected_with_the_key() {
        let e = BlockCsr2::from_triplets(1, &[0, 2], &[0, 0], &[1.0, 1.0]).unwrap_err();
        assert!(
            matches!(e, FcError::IndexOutOfRange { ref key, entry: 1, index: 2, size: 2 } if key == "W.row")
        );
        let e = BlockCsr2::from_triplets(1, &[0], &[0, 1], &[1.0]).unwrap_err();
        assert!(matches!(e, FcError::SizeMismatch { ref key, .. } if key == "W.col"));
        let e = BlockCsr2::from_triplets(1, &[0], &[0], &[f64::NAN]).unwrap_err();
        assert!(matches!(e, FcError::NonFinite { ref key } if key == "W.val[0]"));
    }
}
