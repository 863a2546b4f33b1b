//! Lower-triangle sparsity patterns of symmetric Newton matrices, in faer's compressed-sparse-column layout
//! (`docs/layout.md`, "Dependencies": faer's sparse Cholesky with a reused symbolic
//! analysis). The bottom layer shared by the micro solver's KKT system (`micro::linear`) and the cloth solver's
//! assembly (`shell::assemble`): both describe their matrix by the rows of each column, and this module turns
//! that into column pointers, sorted row indices and the value slot of every diagonal entry.

use faer::sparse::SymbolicSparseColMatRef;

/// The lower triangle of a symmetric n×n pattern in compressed sparse columns: the rows of column j are
/// `row_idx[col_ptr[j]..col_ptr[j + 1]]`, strictly increasing, all ≥ j, the diagonal entry always present. A
/// matrix with this pattern stores its values in the same order (one value slot per stored entry).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LowerPattern {
    /// Order of the matrix.
    pub n: usize,
    /// Column starts: column j's entries are at `col_ptr[j]..col_ptr[j + 1]` (n + 1 entries).
    pub col_ptr: Vec<usize>,
    /// Row index of each stored entry.
    pub row_idx: Vec<usize>,
    /// Value slot of each diagonal entry.
    pub diag: Vec<usize>,
}

impl LowerPattern {
    /// The pattern whose column j holds the rows `cols[j]` (any order, duplicates allowed, each row ≥ j) and the
    /// diagonal entry (j, j).
    pub fn from_columns(mut cols: Vec<Vec<usize>>) -> Self {
        let n = cols.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut diag = Vec::with_capacity(n);
        col_ptr.push(0);
        for (j, rows) in cols.iter_mut().enumerate() {
            rows.push(j);
            rows.sort_unstable();
            rows.dedup();
            diag.push(row_idx.len() + rows.binary_search(&j).expect("diagonal pushed"));
            row_idx.extend_from_slice(rows);
            col_ptr.push(row_idx.len());
        }
        LowerPattern {
            n,
            col_ptr,
            row_idx,
            diag,
        }
    }

    /// Number of stored (lower-triangle) entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// The rows of column `j`.
    pub fn rows(&self, j: usize) -> &[usize] {
        &self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]]
    }

    /// The value slot of entry (i, j) (i ≥ j), if the pattern has it.
    pub fn find(&self, i: usize, j: usize) -> Option<usize> {
        let start = self.col_ptr[j];
        self.rows(j).binary_search(&i).ok().map(|k| start + k)
    }

    /// The row lists of every column (the argument of [`from_columns`](Self::from_columns) that rebuilds this
    /// pattern).
    pub fn columns(&self) -> Vec<Vec<usize>> {
        (0..self.n).map(|j| self.rows(j).to_vec()).collect()
    }

    /// The pattern as faer's symbolic matrix (lower triangle of a symmetric matrix).
    pub fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }

    /// out += A x for the symmetric matrix A whose lower triangle has the values `values` (in slot order), column
    /// by column.
    pub fn add_symmetric_product(&self, values: &[f64], x: &[f64], out: &mut [f64]) {
        for j in 0..self.n {
            for s in self.col_ptr[j]..self.col_ptr[j + 1] {
                let (i, v) = (self.row_idx[s], values[s]);
                out[i] += v * x[j];
                if i != j {
                    out[j] += v * x[i];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unsorted, repeated rows give sorted unique columns with the diagonal added and its slot recorded; lookups
    /// find exactly the stored entries; the column lists rebuild the same pattern.
    #[test]
    fn columns_are_sorted_with_the_diagonal() {
        let p = LowerPattern::from_columns(vec![vec![3, 2, 3], vec![], vec![3, 2], vec![]]);
        assert_eq!(p.col_ptr, vec![0, 3, 4, 6, 7]);
        assert_eq!(p.row_idx, vec![0, 2, 3, 1, 2, 3, 3]);
        assert_eq!(p.diag, vec![0, 3, 4, 6]);
        assert_eq!(p.nnz(), 7);
        assert_eq!(p.find(3, 0), Some(2));
        assert_eq!(p.find(1, 0), None);
        assert_eq!(p.find(3, 2), Some(5));
        assert_eq!(LowerPattern::from_columns(p.columns()), p);
    }

    /// The symmetric product from the lower triangle equals the dense product.
    #[test]
    fn symmetric_product_matches_dense() {
        let p = LowerPattern::from_columns(vec![vec![1, 2], vec![2], vec![]]);
        // A = [[4, 1, 2], [1, 5, 3], [2, 3, 6]]
        let values = [4.0, 1.0, 2.0, 5.0, 3.0, 6.0];
        let x = [1.0, -2.0, 0.5];
        let mut out = [10.0, 0.0, 0.0];
        p.add_symmetric_product(&values, &x, &mut out);
        assert_eq!(
            out,
            [10.0 + 4.0 - 2.0 + 1.0, 1.0 - 10.0 + 1.5, 2.0 - 6.0 + 3.0]
        );
    }
}
