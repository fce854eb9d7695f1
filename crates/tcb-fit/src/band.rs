//! Least squares whose rows touch at most four consecutive unknowns: the
//! normal equations `AᵀA x = Aᵀy` are banded (half-bandwidth 3) and are
//! solved by a banded Cholesky factorization in O(n).
//!
//! A cubic Hermite segment depends on four consecutive unknowns whichever
//! way its tangents come: `p_k, g_k, p_{k+1}, g_{k+1}` with explicit
//! tangents, `P_{k-1} .. P_{k+2}` with tangents derived by a TCB rule.

/// One more than the half-bandwidth: the unknowns a row may touch.
pub(crate) const WIDTH: usize = 4;

/// One row of the design matrix: `coeffs[j]` multiplies unknown `start + j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Row {
    pub start: usize,
    pub coeffs: [f64; WIDTH],
}

impl Row {
    /// `Σ coeffs[j] x[start + j]`, for the unknowns that exist.
    #[inline]
    pub fn dot(&self, x: &[f64], stride: usize, col: usize) -> f64 {
        let mut s = 0.0;
        for (j, c) in self.coeffs.iter().enumerate() {
            if let Some(v) = x.get((self.start + j) * stride + col) {
                s += c * v;
            }
        }
        s
    }
}

/// The normal equations for `n` unknowns and `cols` right-hand sides.
pub(crate) struct Normal {
    n: usize,
    cols: usize,
    /// `lower[i][j] = N[i][i - j]`.
    lower: Vec<[f64; WIDTH]>,
    /// `rhs[i * cols + c]`.
    rhs: Vec<f64>,
}

impl Normal {
    pub fn new(n: usize, cols: usize) -> Self {
        Normal {
            n,
            cols,
            lower: vec![[0.0; WIDTH]; n],
            rhs: vec![0.0; n * cols],
        }
    }

    /// Add `row` with targets `y` (one per column), as `N += rᵀr`, `b += rᵀy`.
    pub fn add(&mut self, row: &Row, y: &[f64]) {
        for p in 0..WIDTH {
            let i = row.start + p;
            if i >= self.n || row.coeffs[p] == 0.0 {
                continue;
            }
            for q in 0..=p {
                self.lower[i][p - q] += row.coeffs[p] * row.coeffs[q];
            }
            let b = &mut self.rhs[i * self.cols..(i + 1) * self.cols];
            for (b, y) in b.iter_mut().zip(y) {
                *b += row.coeffs[p] * y;
            }
        }
    }

    /// Solve in place; the solution is `x[i * cols + c]`. A relative ridge
    /// `ridge * max diagonal` keeps unknowns no row constrains at zero
    /// instead of failing. `None` when the system is still not positive
    /// definite (non-finite data).
    pub fn solve(mut self, ridge: f64) -> Option<Vec<f64>> {
        let n = self.n;
        let max_diag = self.lower.iter().map(|r| r[0]).fold(0.0, f64::max);
        let eps = ridge * max_diag.max(f64::MIN_POSITIVE);
        for r in &mut self.lower {
            r[0] += eps;
        }
        // Cholesky: N = L Lᵀ, L stored in `lower` like N.
        for i in 0..n {
            for j in i.saturating_sub(WIDTH - 1)..=i {
                let mut sum = self.lower[i][i - j];
                for k in i.saturating_sub(WIDTH - 1)..j {
                    sum -= self.lower[i][i - k] * self.lower[j][j - k];
                }
                if i == j {
                    if !(sum > 0.0 && sum.is_finite()) {
                        return None;
                    }
                    self.lower[i][0] = sum.sqrt();
                } else {
                    self.lower[i][i - j] = sum / self.lower[j][0];
                }
            }
        }
        let c = self.cols;
        let x = &mut self.rhs;
        // L z = b
        for i in 0..n {
            for k in i.saturating_sub(WIDTH - 1)..i {
                let l = self.lower[i][i - k];
                for col in 0..c {
                    x[i * c + col] -= l * x[k * c + col];
                }
            }
            let d = self.lower[i][0];
            for col in 0..c {
                x[i * c + col] /= d;
            }
        }
        // Lᵀ x = z
        for i in (0..n).rev() {
            for k in i + 1..(i + WIDTH).min(n) {
                let l = self.lower[k][k - i];
                for col in 0..c {
                    x[i * c + col] -= l * x[k * c + col];
                }
            }
            let d = self.lower[i][0];
            for col in 0..c {
                x[i * c + col] /= d;
            }
        }
        x.iter().all(|v| v.is_finite()).then_some(self.rhs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_banded_solution_exactly() {
        // y_i = x_{i} + 2 x_{i+1} - x_{i+3} on consecutive windows, plus single rows.
        let truth: Vec<f64> = (0..9).map(|i| (i as f64 * 0.7).sin() + 1.0).collect();
        let mut rows = Vec::new();
        for start in 0..9 {
            rows.push(Row {
                start,
                coeffs: [1.0, 2.0, 0.0, -1.0],
            });
            rows.push(Row {
                start,
                coeffs: [0.5, 0.0, 0.0, 0.0],
            });
        }
        let mut normal = Normal::new(9, 2);
        for r in &rows {
            let y = r.dot(&truth, 1, 0);
            normal.add(r, &[y, 2.0 * y]);
        }
        let x = normal.solve(0.0).unwrap();
        for i in 0..9 {
            assert!((x[2 * i] - truth[i]).abs() < 1e-12, "{i}");
            assert!((x[2 * i + 1] - 2.0 * truth[i]).abs() < 1e-12, "{i}");
        }
    }

    #[test]
    fn unconstrained_unknowns_stay_zero_with_a_ridge() {
        let mut normal = Normal::new(3, 1);
        normal.add(
            &Row {
                start: 0,
                coeffs: [1.0, 0.0, 0.0, 0.0],
            },
            &[4.0],
        );
        assert!(Normal::new(3, 1).solve(0.0).is_none());
        let x = normal.solve(1e-12).unwrap();
        assert!((x[0] - 4.0).abs() < 1e-9 && x[1] == 0.0 && x[2] == 0.0);
    }
}
