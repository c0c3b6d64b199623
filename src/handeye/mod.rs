//! Hand-eye calibration: where the camera sits on the robot (eye-in-hand,
//! `gripper_from_camera`) or in the robot's world (eye-to-hand,
//! `base_from_camera`), plus the pose of the calibration target.
//!
//! # The equations, with `a_from_b` names
//!
//! Every view `i` gives the robot's `base_from_gripper[i]` and the camera's
//! `camera_from_target[i]`. Both setups reduce to one chain
//! `robot[i] * x * camera[i] = y` ([`Chain`]):
//!
//! | setup        | `robot[i]`             | `x`                   | `y` (constant)        |
//! |--------------|------------------------|-----------------------|-----------------------|
//! | eye-in-hand  | `base_from_gripper[i]` | `gripper_from_camera` | `base_from_target`    |
//! | eye-to-hand  | `gripper_from_base[i]` | `base_from_camera`    | `gripper_from_target` |
//!
//! (eye-to-hand: `base_from_camera * camera_from_target[i] =
//! base_from_gripper[i] * gripper_from_target`, left-multiplied by
//! `gripper_from_base[i]`.)
//!
//! **AX = XB** (seed 004): for two views `i`, `j`, eliminating `y` gives
//! `A * X = X * B` with `A = robot[j]^-1 * robot[i]` (for eye-in-hand
//! `gripper_j_from_gripper_i`), `B = camera[j] * camera[i]^-1`
//! (`camera_j_from_camera_i`) and `X = x`. Motions are built from all pairs
//! `i < j` (default) or consecutive views ([`MotionPairs`]); pairs whose robot
//! or camera rotation is below [`MIN_MOTION_ROTATION_DEG`] are discarded with
//! a note, because their rotation axis is noise.
//!
//! **AX = ZB** (robot-world-hand-eye, Shah and Li): per view
//! `robot[i] * X = Z * camera[i]^-1` with `Z = y`, solved for both at once
//! without forming motions.
//!
//! # Layout, by stage
//!
//! [`solve`] is the orchestrator: it runs [`quality::checks`] on the input,
//! the [`closed_form`] solvers, picks the primary solution, then the
//! refinements of [`refine`] (over the poses by default, over the pixels of
//! the image path), and it alone writes the [`HandEyeResult`]: the refiners
//! return what they found. What a calibration takes is [`input`], what it
//! produces [`result`]: the stages read them without importing the
//! orchestrator (no import cycle among the files, checked by
//! src/architecture_tests.rs). [`quality`] measures the result (closure
//! residuals, repeatability, whether the reported uncertainty can be
//! trusted) and catches input mistakes; [`report`] is the JSON report.
//! [`rig`] solves a whole camera rig's transform (`gripper_from_rig`,
//! `base_from_rig`) from every camera's views together. The camera pose of
//! one view from its points (PnP) is [`crate::calib::pnp`]. [`plan`] plans
//! the robot poses of a calibration and predicts the error they reach.

pub mod closed_form;
pub mod input;
pub mod math;
pub mod plan;
pub mod quality;
pub mod refine;
pub mod report;
pub mod result;
pub mod rig;
pub mod solve;

/// Most robot/camera pose pairs one hand-eye calibration takes. Motions are
/// formed between every two poses and each leave-one-out run re-measures the
/// residuals of every view, so time and memory grow with the square of the
/// count (docs/bounds.md, BENCHMARKS.md "Hand-eye speed"). Real data sets
/// have 10 to a few hundred poses.
pub const MAX_POSES: usize = 1000;

/// Fewest pose pairs hand-eye calibration accepts (the gross-error check
/// of [`quality::gross`] needs one more).
pub const MIN_POSES: usize = 3;

#[cfg(test)]
mod solver_tests;

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

pub use closed_form::motion::{Motion, MotionPairs};
pub use input::{HandEyeInput, HandEyeOptions};
pub use result::{HandEyeResult, MethodResult};
pub use solve::calibrate;

pub use crate::geometry::Pose;

/// Motion pairs whose robot or camera rotation is below this angle (degrees)
/// are discarded: their rotation axis is dominated by noise.
pub const MIN_MOTION_ROTATION_DEG: f64 = 2.0;

/// Where the camera is mounted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Setup {
    /// Camera on the gripper: solves `gripper_from_camera` and `base_from_target`.
    #[serde(rename = "eye-in-hand")]
    EyeInHand,
    /// Camera fixed in the robot's world: solves `base_from_camera` and
    /// `gripper_from_target`.
    #[serde(rename = "eye-to-hand")]
    EyeToHand,
}

impl Setup {
    /// `eye-in-hand` or `eye-to-hand`.
    pub fn name(self) -> &'static str {
        match self {
            Setup::EyeInHand => "eye-in-hand",
            Setup::EyeToHand => "eye-to-hand",
        }
    }

    /// JSON key of the solved camera transform.
    pub fn camera_key(self) -> &'static str {
        match self {
            Setup::EyeInHand => "gripper_from_camera",
            Setup::EyeToHand => "base_from_camera",
        }
    }

    /// JSON key of the solved target transform.
    pub fn target_key(self) -> &'static str {
        match self {
            Setup::EyeInHand => "base_from_target",
            Setup::EyeToHand => "gripper_from_target",
        }
    }
}

impl std::str::FromStr for Setup {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().replace('_', "-").as_str() {
            "eye-in-hand" => Ok(Setup::EyeInHand),
            "eye-to-hand" => Ok(Setup::EyeToHand),
            _ => Err(Error::invalid(
                "setup",
                format!("unknown setup '{s}' (valid: eye-in-hand, eye-to-hand)"),
            )),
        }
    }
}

/// The closed-form hand-eye solvers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HandEyeMethod {
    /// Tsai and Lenz 1989: modified Rodrigues vectors, then translation.
    TsaiLenz,
    /// Park and Martin 1994: rotation logarithms aligned by SVD.
    ParkMartin,
    /// Horaud and Dornaika 1995: quaternion eigenvector.
    Horaud,
    /// Andreff et al. 2001: linear Kronecker-product formulation.
    Andreff,
    /// Daniilidis 1999: dual quaternions via SVD.
    Daniilidis,
    /// Chou and Kamel 1991: quaternion rotation-axis equations via SVD.
    ChouKamel,
    /// Shah 2013: AX = ZB by Kronecker product.
    Shah,
    /// Li, Wang and Wu 2010: AX = ZB, simultaneous linear solution.
    Li,
}

impl HandEyeMethod {
    /// Every method, in report order.
    pub const ALL: [HandEyeMethod; 8] = [
        HandEyeMethod::TsaiLenz,
        HandEyeMethod::ParkMartin,
        HandEyeMethod::Horaud,
        HandEyeMethod::Andreff,
        HandEyeMethod::Daniilidis,
        HandEyeMethod::ChouKamel,
        HandEyeMethod::Shah,
        HandEyeMethod::Li,
    ];

    /// The kebab-case name used in JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            HandEyeMethod::TsaiLenz => "tsai-lenz",
            HandEyeMethod::ParkMartin => "park-martin",
            HandEyeMethod::Horaud => "horaud",
            HandEyeMethod::Andreff => "andreff",
            HandEyeMethod::Daniilidis => "daniilidis",
            HandEyeMethod::ChouKamel => "chou-kamel",
            HandEyeMethod::Shah => "shah",
            HandEyeMethod::Li => "li",
        }
    }

    /// Whether the method solves AX = ZB (both transforms at once).
    pub fn is_axzb(self) -> bool {
        match self {
            HandEyeMethod::Shah | HandEyeMethod::Li => true,
            HandEyeMethod::TsaiLenz
            | HandEyeMethod::ParkMartin
            | HandEyeMethod::Horaud
            | HandEyeMethod::Andreff
            | HandEyeMethod::Daniilidis
            | HandEyeMethod::ChouKamel => false,
        }
    }
}

impl std::str::FromStr for HandEyeMethod {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let wanted = s.to_ascii_lowercase().replace(['_', ' '], "-");
        HandEyeMethod::ALL
            .into_iter()
            .find(|m| m.name() == wanted)
            .ok_or_else(|| {
                let names: Vec<&str> = HandEyeMethod::ALL.iter().map(|m| m.name()).collect();
                Error::invalid(
                    "method",
                    format!("unknown method '{s}' (valid: {})", names.join(", ")),
                )
            })
    }
}

/// The setup-independent chain `robot[i] * x * camera[i] = y` (see the
/// module docs for what each factor is in each setup).
#[derive(Debug, Clone)]
pub struct Chain {
    /// `base_from_gripper[i]` (eye-in-hand) or `gripper_from_base[i]` (eye-to-hand).
    pub robot: Vec<Pose>,
    /// `camera_from_target[i]`.
    pub camera: Vec<Pose>,
}

impl Chain {
    /// Build the chain; the two lists must pair up one to one.
    pub fn new(
        setup: Setup,
        base_from_gripper: &[Pose],
        camera_from_target: &[Pose],
    ) -> Result<Chain> {
        if base_from_gripper.len() != camera_from_target.len() {
            return Err(Error::invalid(
                "poses",
                format!(
                    "{} robot poses but {} camera poses: they must pair up one to one",
                    base_from_gripper.len(),
                    camera_from_target.len()
                ),
            ));
        }
        if base_from_gripper.len() > MAX_POSES {
            let n = base_from_gripper.len();
            return Err(Error::invalid(
                "poses",
                format!(
                    "{n} poses: at most {MAX_POSES} are supported (the solvers and the \
                     repeatability check use every pair of poses, which grows with the \
                     square); keep a subset spread over the workspace, e.g. every {} pose",
                    crate::error::ordinal(n.div_ceil(MAX_POSES))
                ),
            ));
        }
        let robot = match setup {
            Setup::EyeInHand => base_from_gripper.to_vec(),
            Setup::EyeToHand => base_from_gripper.iter().map(|p| p.inverse()).collect(),
        };
        Ok(Chain {
            robot,
            camera: camera_from_target.to_vec(),
        })
    }

    /// Number of views.
    pub fn len(&self) -> usize {
        self.robot.len()
    }

    /// Whether there is no view.
    pub fn is_empty(&self) -> bool {
        self.robot.is_empty()
    }

    /// The chain restricted to the views `indices` (repeats allowed).
    pub fn subset(&self, indices: &[usize]) -> Chain {
        Chain {
            robot: indices.iter().map(|&i| self.robot[i]).collect(),
            camera: indices.iter().map(|&i| self.camera[i]).collect(),
        }
    }

    /// `robot[i] * x * camera[i]`: the target pose implied by view `i`.
    pub fn implied_target(&self, i: usize, x: &Pose) -> Pose {
        self.robot[i] * x * self.camera[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn method_names_round_trip_and_unknown_lists_valid_names() {
        for m in HandEyeMethod::ALL {
            assert_eq!(m.name().parse::<HandEyeMethod>().unwrap(), m);
        }
        assert_eq!(
            "Tsai_Lenz".parse::<HandEyeMethod>().unwrap(),
            HandEyeMethod::TsaiLenz
        );
        assert_eq!(
            "tsai".parse::<HandEyeMethod>().unwrap_err().to_string(),
            "method: unknown method 'tsai' (valid: tsai-lenz, park-martin, horaud, \
             andreff, daniilidis, chou-kamel, shah, li)"
        );
        assert_eq!(
            "eye-on-hand".parse::<Setup>().unwrap_err().to_string(),
            "setup: unknown setup 'eye-on-hand' (valid: eye-in-hand, eye-to-hand)"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn more_poses_than_the_cap_are_refused_with_a_subset_to_keep() {
        let poses = vec![Pose::identity(); 100_000];
        let err = Chain::new(Setup::EyeInHand, &poses, &poses).unwrap_err();
        assert_eq!(
            err.to_string(),
            "poses: 100000 poses: at most 1000 are supported (the solvers and the repeatability \
             check use every pair of poses, which grows with the square); keep a subset spread \
             over the workspace, e.g. every 100th pose"
        );
        assert!(Chain::new(Setup::EyeInHand, &poses[..MAX_POSES], &poses[..MAX_POSES]).is_ok());
    }
}
