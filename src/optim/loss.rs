//! Robust losses applied to the squared norm of each residual block.

use serde::{Deserialize, Serialize};

/// How a residual block's squared norm `s` enters the cost `0.5 * rho(s)`.
/// The scale is in residual units (pixels for reprojection errors): blocks
/// with norm below it count as in plain least squares.
///
/// In JSON `{"kind": "huber", "scale": 1.0}`, tagged by `kind` (serde's
/// derive).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Loss {
    /// Plain least squares: `rho(s) = s`.
    Squared,
    /// Huber: `s` for `s <= c^2`, `2 c sqrt(s) - c^2` beyond.
    Huber {
        /// The threshold c, in residual units.
        scale: f64,
    },
    /// Cauchy: `c^2 ln(1 + s / c^2)`.
    Cauchy {
        /// The scale c, in residual units.
        scale: f64,
    },
}

impl Loss {
    /// `rho(s)` and `rho'(s)` for a squared norm `s`.
    pub fn evaluate(&self, s: f64) -> (f64, f64) {
        match *self {
            Loss::Squared => (s, 1.0),
            Loss::Huber { scale } => {
                let c2 = scale * scale;
                if s <= c2 {
                    (s, 1.0)
                } else {
                    let r = s.sqrt();
                    (2.0 * scale * r - c2, scale / r)
                }
            }
            Loss::Cauchy { scale } => {
                let c2 = scale * scale;
                (c2 * (s / c2).ln_1p(), 1.0 / (1.0 + s / c2))
            }
        }
    }
}
