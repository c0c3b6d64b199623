//! The dense covariance updates of a Kalman filter (the EKF calibration),
//! as plain functions on `DMatrix<f64>`: here, and not as nalgebra
//! expressions at the call site, so that the wasm build compiles them with
//! this crate's speed settings (nalgebra's generic operators are compiled in
//! the crate that calls them).

use nalgebra::{DMatrix, DMatrixView, Dyn};

/// `m^T` as a view of `m`'s own storage (row and column strides swapped):
/// no copy. Private: nalgebra 0.34's small-matrix product path (any
/// dimension of 5 or less) walks a strided *left* operand's columns past
/// their end, so the view is only handed out by the two products below,
/// which keep it where that cannot happen.
fn transposed(m: &DMatrix<f64>) -> DMatrixView<'_, f64, Dyn, Dyn> {
    DMatrixView::from_slice_with_strides(m.as_slice(), m.ncols(), m.nrows(), m.nrows(), 1)
}

/// nalgebra's bound: a product with every dimension above it goes to
/// matrixmultiply (which takes any strides), below it column by column.
const SMALL_DIM: usize = 5;

/// `out += alpha a b^T` without copying `b^T`. The view is the right operand,
/// read element by element on either of nalgebra's paths, and
/// matrixmultiply packs either layout into the same panels: the same
/// numbers added in the same order as `out.gemm(alpha, a, &b.transpose(),
/// 1.0)`, bit for bit.
pub fn add_times_transpose(out: &mut DMatrix<f64>, alpha: f64, a: &DMatrix<f64>, b: &DMatrix<f64>) {
    out.gemm(alpha, a, &transposed(b), 1.0);
}

/// `a * b^T` without copying `b^T` (as [`add_times_transpose`]).
pub fn times_transpose(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    a * transposed(b)
}

/// `a^T * b`, bit for bit `a.transpose() * b`: without the copy of `a^T`
/// when the product goes to matrixmultiply (every dimension above
/// [`SMALL_DIM`]), with it otherwise (the case where a strided left
/// operand is not safe, see [`transposed`]).
pub fn transpose_times(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    if a.nrows() > SMALL_DIM && a.ncols() > SMALL_DIM && b.ncols() > SMALL_DIM {
        transposed(a) * b
    } else {
        a.transpose() * b
    }
}

/// `p[:, cols] * h^T` for an `m x cols.len()` matrix `h`: the gain
/// numerator `P H^T` when `H` is zero outside the columns `cols`.
pub fn columns_times_transpose(p: &DMatrix<f64>, cols: &[usize], h: &DMatrix<f64>) -> DMatrix<f64> {
    assert_eq!(
        h.ncols(),
        cols.len(),
        "h has one column per selected column of p"
    );
    let (n, m) = (p.nrows(), h.nrows());
    // Column-major storage: column c of p is p[c * n..(c + 1) * n].
    let ps = p.as_slice();
    let mut out = vec![0.0; n * m];
    for (r, column) in out.chunks_exact_mut(n.max(1)).enumerate().take(m) {
        for (k, &c) in cols.iter().enumerate() {
            let w = h[(r, k)];
            if w == 0.0 {
                continue;
            }
            for (o, &v) in column.iter_mut().zip(&ps[c * n..(c + 1) * n]) {
                *o += v * w;
            }
        }
    }
    DMatrix::from_vec(n, m, out)
}

/// `p <- sym(p - a b^T)` for `n x k` matrices `a`, `b`, where
/// `sym(x) = (x + x^T) / 2`: the covariance update `P - K (P H^T)^T`, kept
/// exactly symmetric.
pub fn subtract_product_symmetric(p: &mut DMatrix<f64>, a: &DMatrix<f64>, b: &DMatrix<f64>) {
    let n = p.nrows();
    assert!(
        p.ncols() == n && a.nrows() == n && b.nrows() == n && a.ncols() == b.ncols(),
        "p is n x n, a and b are n x k"
    );
    if n == 0 {
        return;
    }
    let (a, b) = (a.as_slice(), b.as_slice());
    let ps = p.as_mut_slice();
    for k in 0..b.len() / n {
        let ak = &a[k * n..(k + 1) * n];
        for (j, pj) in ps.chunks_exact_mut(n).enumerate() {
            let w = b[k * n + j];
            if w == 0.0 {
                continue;
            }
            for (o, &v) in pj.iter_mut().zip(ak) {
                *o -= v * w;
            }
        }
    }
    symmetrize(p);
}

/// `p <- (p + p^T) / 2` in place.
pub fn symmetrize(p: &mut DMatrix<f64>) {
    let n = p.nrows();
    if p.ncols() != n {
        return;
    }
    let ps = p.as_mut_slice();
    for j in 0..n {
        for i in 0..j {
            let m = (ps[j * n + i] + ps[i * n + j]) * 0.5;
            ps[j * n + i] = m;
            ps[i * n + j] = m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    fn matrix(r: usize, c: usize, seed: f64) -> DMatrix<f64> {
        DMatrix::from_fn(r, c, |i, j| ((i * 7 + j * 3) as f64 * seed).sin())
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn same_as_the_nalgebra_expressions() {
        let p0 = {
            let m = matrix(9, 9, 0.37);
            &m * m.transpose()
        };
        let cols = [0, 2, 3, 8];
        let mut h = matrix(2, 4, 1.3);
        h[(1, 2)] = 0.0;
        let pht = columns_times_transpose(&p0, &cols, &h);
        let want = p0.select_columns(&cols) * h.transpose();
        assert!((&pht - &want).amax() < 1e-12, "{pht} vs {want}");

        let gain = matrix(9, 2, 0.71);
        let mut p = p0.clone();
        subtract_product_symmetric(&mut p, &gain, &pht);
        let raw = &p0 - &gain * pht.transpose();
        let want = (&raw + raw.transpose()) * 0.5;
        assert!((&p - &want).amax() < 1e-12);
        assert_eq!(p, p.transpose(), "exactly symmetric");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn products_with_a_transposed_view_equal_the_copied_transpose_bit_for_bit() {
        // Shapes on both of nalgebra's paths: every dimension above 5
        // (matrixmultiply) and some at or below it (column by column),
        // including a single column and an empty block.
        let shapes = [
            (9, 176, 6),
            (6, 176, 6),
            (3, 40, 2),
            (12, 5, 9),
            (7, 30, 1),
            (4, 0, 3),
        ];
        for (m, k, n) in shapes {
            let a = matrix(m, k, 0.37);
            let b = matrix(n, k, 0.91);
            let mut out = matrix(m, n, 0.13);
            let mut reference = out.clone();
            reference.gemm(-1.0, &a, &b.transpose(), 1.0);
            add_times_transpose(&mut out, -1.0, &a, &b);
            assert_eq!(out, reference, "a b^T added, {m} x {k} x {n}");
            assert_eq!(
                times_transpose(&a, &b),
                &a * b.transpose(),
                "a b^T, {m} x {k} x {n}"
            );
            let c = matrix(k, n, 0.53);
            let d = matrix(k, m, 0.29);
            assert_eq!(
                transpose_times(&d, &c),
                d.transpose() * &c,
                "d^T c, {k} x {m} x {n}"
            );
        }
    }
}
