//! The re-linearisation pass: the filter run again from its prior over all
//! stored observations, each linearised at the current estimate instead of
//! the estimate of its time, with the pixel noise set from the residuals.

use super::measure::{measure, select, symmetrize};
use super::{EkfCalibrator, N_INTRINSICS, N_POSE};
use crate::error::{Error, Result};
use crate::optim::dense;
use nalgebra::{DMatrix, DVector, Matrix2, Vector2};

/// Re-linearisation stop: relative change of the residual pixel sigma.
const RELINEARIZE_TOLERANCE: f64 = 1e-6;
/// Smallest pixel noise the pass assumes, px (exact data would otherwise
/// make the innovation covariance singular).
const MIN_PIXEL_SIGMA_PX: f64 = 1e-6;

impl EkfCalibrator {
    /// One re-linearisation pass (a smoother over the stored data): the
    /// state and covariance restart from the prior of every entry, then
    /// every point and quaternion-norm pseudo-measurement is processed one
    /// at a time as before, but with the measurement model linearised at
    /// the estimate `x*` before the pass (z ~ h(x*) + H (x - x*)). With one
    /// linearisation point the filter is linear, so the result is one
    /// Gauss-Newton step from `x*` with the prior as a regulariser and the
    /// covariance is (P0^-1 + H^T R^-1 H)^-1 at `x*`: the batch one. The
    /// pixel noise R is the residual variance at `x*` (sum of squares over
    /// 2 n_points - n_free), which is kept in the options. Returns that
    /// pixel sigma, px.
    pub fn relinearize(&mut self) -> Result<f64> {
        if self.views == 0 {
            return Err(Error::too_few("views in the filter", 1, 0));
        }
        let at = self.state.clone();
        // Linearise every observation once, and the residual variance.
        let mut linear = Vec::with_capacity(self.views);
        let (mut sum_sq, mut n_obs) = (0.0, 0usize);
        for (v, pairs) in self.observations.iter().enumerate() {
            let mut rows = Vec::with_capacity(pairs.len());
            for (object, pixel) in pairs {
                let (predicted, h) = measure(&at, v, object, self.size)?;
                let residual = pixel.coords - predicted;
                sum_sq += residual.norm_squared();
                n_obs += 2;
                rows.push((residual, h));
            }
            linear.push(rows);
        }
        let free_intrinsics = (0..N_INTRINSICS)
            .filter(|&i| self.prior_covariance[(i, i)] > 0.0)
            .count()
            - usize::from(self.calibration.fix_aspect_ratio);
        let n_free = free_intrinsics + 6 * self.views;
        if n_obs <= n_free {
            return Err(Error::too_few("pixel coordinates", n_free + 1, n_obs));
        }
        let sigma = (sum_sq / (n_obs - n_free) as f64)
            .sqrt()
            .max(MIN_PIXEL_SIGMA_PX);
        let r = Matrix2::identity() * sigma * sigma;
        self.state = self.prior_state.clone();
        self.covariance = self.prior_covariance.clone();
        for (v, rows) in linear.iter().enumerate() {
            let cols = self.columns(v);
            for (residual, h) in rows {
                let dx =
                    DVector::from_iterator(cols.len(), cols.iter().map(|&c| self.state[c] - at[c]));
                let innovation = residual - Vector2::from_iterator((h * dx).iter().copied());
                let pht = dense::columns_times_transpose(&self.covariance, &cols, h);
                let s = select(h, &pht, &cols) + r;
                let s_inv = s
                    .try_inverse()
                    .ok_or_else(|| Error::degenerate("EKF innovation covariance is singular"))?;
                let gain = &pht * DMatrix::from_iterator(2, 2, s_inv.iter().copied());
                self.state += &gain * DVector::from_column_slice(innovation.as_slice());
                dense::subtract_product_symmetric(&mut self.covariance, &gain, &pht);
            }
            self.update_quaternion_norm_at(v, &at);
        }
        self.options.pixel_sigma_px = sigma;
        Ok(sigma)
    }

    /// The pseudo-measurement |q|^2 = 1 of view `v`, linearised at `at`.
    fn update_quaternion_norm_at(&mut self, v: usize, at: &DVector<f64>) {
        let o = N_INTRINSICS + N_POSE * v;
        let q0 = at.rows(o, 4).into_owned();
        let h = q0.transpose() * 2.0;
        let dq = self.state.rows(o, 4) - &q0;
        let pht = self.covariance.columns(o, 4) * h.transpose();
        // One measurement of the view's norm per point, as in the filter.
        let n = self.observations[v].len().max(1) as f64;
        let s = (&h * pht.rows(o, 4))[(0, 0)] + self.options.quaternion_norm_sigma.powi(2) / n;
        let gain = &pht / s;
        let innovation = 1.0 - q0.norm_squared() - (&h * dq)[(0, 0)];
        self.state += &gain * innovation;
        self.covariance -= &gain * pht.transpose();
        symmetrize(&mut self.covariance);
    }

    /// [`EkfCalibrator::relinearize`] until the residual pixel sigma changes
    /// by less than 1e-6 of itself, at most `max_passes` times (at least
    /// once). Returns the last pixel sigma, px.
    pub fn relinearize_until_converged(&mut self, max_passes: usize) -> Result<f64> {
        let mut sigma = self.relinearize()?;
        for _ in 1..max_passes {
            let next = self.relinearize()?;
            let settled = (next - sigma).abs() <= RELINEARIZE_TOLERANCE * next;
            sigma = next;
            if settled {
                break;
            }
        }
        Ok(sigma)
    }
}
