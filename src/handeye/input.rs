//! What a hand-eye calibration takes: the paired poses ([`HandEyeInput`])
//! and the tunables ([`HandEyeOptions`]). Read by the checks, the solvers
//! and the refiners; it names nothing above the closed forms.

use crate::error::Result;
use crate::handeye::{Chain, HandEyeMethod, MotionPairs, Pose, Setup};

/// Default number of bootstrap resamples.
pub const DEFAULT_BOOTSTRAP_SAMPLES: usize = 100;

/// What to solve: the setup and the paired poses (metres).
#[derive(Debug, Clone)]
pub struct HandEyeInput {
    /// Camera on the gripper or fixed in the world.
    pub setup: Setup,
    /// Robot poses, one per view.
    pub base_from_gripper: Vec<Pose>,
    /// Target poses seen by the camera, one per view, paired with the robot poses.
    pub camera_from_target: Vec<Pose>,
}

impl HandEyeInput {
    /// The setup-independent chain of these poses ([`Chain::new`]: the two
    /// lists must pair up one to one, at most [`crate::handeye::MAX_POSES`]).
    pub fn chain(&self) -> Result<Chain> {
        Chain::new(
            self.setup,
            &self.base_from_gripper,
            &self.camera_from_target,
        )
    }
}

/// Tunables, with defaults from [`HandEyeOptions::default`].
#[derive(Debug, Clone)]
pub struct HandEyeOptions {
    /// Methods to run (default: all eight).
    pub methods: Vec<HandEyeMethod>,
    /// Which view pairs become AX = XB motions (default: all pairs).
    pub motion_pairs: MotionPairs,
    /// Input mistakes (units, inverted poses, shifted pairing) are errors
    /// when true (default), warnings when false.
    pub strict_checks: bool,
    /// Bootstrap resamples for repeatability (default
    /// [`DEFAULT_BOOTSTRAP_SAMPLES`]; 0 disables leave-one-out and bootstrap).
    pub bootstrap_samples: usize,
    /// Seed of the bootstrap resampling.
    pub seed: u64,
    /// Refine the closed forms by the maximum-likelihood pose refinement
    /// ([`crate::handeye::refine::over_poses`]; default true). The image path turns it off
    /// and refines over image points instead.
    pub refine_poses: bool,
}

impl Default for HandEyeOptions {
    fn default() -> Self {
        HandEyeOptions {
            methods: HandEyeMethod::ALL.to_vec(),
            motion_pairs: MotionPairs::All,
            strict_checks: true,
            bootstrap_samples: DEFAULT_BOOTSTRAP_SAMPLES,
            seed: 1,
            refine_poses: true,
        }
    }
}
