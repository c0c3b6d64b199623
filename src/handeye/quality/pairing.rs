//! Is each robot pose paired with the right camera pose? Proven from the
//! data, before any solve.
//!
//! # The test
//!
//! For two views `i`, `j` the chain `robot[i] * x * camera[i] = y`
//! ([`Chain`]) gives `robot[j]^-1 * robot[i] = x * (camera[j] *
//! camera[i]^-1) * x^-1`: the robot motion and the camera motion are
//! conjugate, so their **rotation angles are equal whatever `x` is**. A
//! pairing's mismatch is the median, over motion pairs, of the absolute
//! difference of the two angles (degrees): noise-level (hundredths to tenths
//! of a degree) when the pairing is right, degrees to tens of degrees when a
//! pose meets another view's image. Pairs where neither motion rotates
//! [`MIN_ANGLE_DEG`] are left out (they say nothing about the pairing).
//!
//! A pairing *rule* (pose i with the i-th image in numeric order of the
//! file names, shifted by k, reversed, ...) is a list of `(robot index,
//! camera index)`. [`better_rule`] compares the given pairing with the
//! rules and names the one that fits when the given one does not: the rule
//! must fit [`RATIO`] times better and the given pairing be off by at least
//! [`MIN_MISMATCH_DEG`], the same bar as the other input mistakes of
//! [`crate::handeye::quality::checks`].
//!
//! Cost: at most [`MAX_PAIRS_PER_VIEW`] motion pairs per view, so the test
//! is linear in the number of poses.

use crate::handeye::{Chain, Pose, Setup};

/// Motions rotating less than this (both sides) are left out of the test.
pub const MIN_ANGLE_DEG: f64 = 1.0;
/// A rule must fit this many times better than the given pairing ...
pub const RATIO: f64 = 5.0;
/// ... and the given pairing must be off by at least this (degrees).
pub const MIN_MISMATCH_DEG: f64 = 0.5;
/// Motion pairs per view beyond which the pairs are thinned.
pub const MAX_PAIRS_PER_VIEW: usize = 8;
/// Fewest pairs a rule needs to be judged.
const MIN_RULE_PAIRS: usize = 3;

/// One way of pairing robot poses with camera poses.
#[derive(Debug, Clone, PartialEq)]
pub struct PairingRule {
    /// What the rule is, as the user would say it ("pose i with image i+1").
    pub name: String,
    /// What it means when it fits ("the pose file looks shifted by one
    /// against the images").
    pub finding: String,
    /// What to do when this rule is the one that fits.
    pub fix: String,
    /// `(robot index, camera index)` pairs.
    pub pairs: Vec<(usize, usize)>,
}

/// How a rule fits: the rule and its mismatch beside the given pairing's.
#[derive(Debug, Clone, PartialEq)]
pub struct RuleFit {
    /// The rule that fits.
    pub rule: PairingRule,
    /// Its median rotation-angle mismatch (degrees).
    pub mismatch_deg: f64,
    /// The given pairing's (degrees).
    pub given_mismatch_deg: f64,
}

/// The median absolute difference between the rotation angles of robot and
/// camera motions over `pairs` (degrees), or `None` when fewer than three
/// poses are paired or no motion rotates.
pub fn angle_mismatch_deg(
    setup: Setup,
    base_from_gripper: &[Pose],
    camera_from_target: &[Pose],
    pairs: &[(usize, usize)],
) -> Option<f64> {
    if pairs.len() < MIN_RULE_PAIRS
        || pairs
            .iter()
            .any(|&(r, c)| r >= base_from_gripper.len() || c >= camera_from_target.len())
    {
        return None;
    }
    let robot: Vec<Pose> = pairs.iter().map(|&(r, _)| base_from_gripper[r]).collect();
    let camera: Vec<Pose> = pairs.iter().map(|&(_, c)| camera_from_target[c]).collect();
    let chain = Chain::new(setup, &robot, &camera).ok()?;
    let n = chain.len();
    let mut diffs = Vec::new();
    for i in 0..n {
        for j in crate::geometry::motion_partners(i, n, MAX_PAIRS_PER_VIEW) {
            let a = (chain.robot[j].inverse() * chain.robot[i]).rotation.angle();
            let b = (chain.camera[j] * chain.camera[i].inverse())
                .rotation
                .angle();
            let (a, b) = (a.to_degrees(), b.to_degrees());
            if a.max(b) >= MIN_ANGLE_DEG && a.is_finite() && b.is_finite() {
                diffs.push((a - b).abs());
            }
        }
    }
    if diffs.is_empty() {
        return None;
    }
    diffs.sort_by(f64::total_cmp);
    Some(diffs[diffs.len() / 2])
}

/// The rules for two lists paired by position (robot `i` with camera `i`):
/// shifted by 1 to 3 either way, and reversed.
pub fn position_rules(n_robot: usize, n_camera: usize) -> Vec<PairingRule> {
    let mut rules = Vec::new();
    for k in 1..=3usize {
        let robot_ahead: Vec<(usize, usize)> = (0..n_camera)
            .filter(|&i| i + k < n_robot)
            .map(|i| (i + k, i))
            .collect();
        let camera_ahead: Vec<(usize, usize)> = (0..n_robot)
            .filter(|&i| i + k < n_camera)
            .map(|i| (i, i + k))
            .collect();
        let (first_robot, first_images) = if k == 1 {
            ("robot pose".to_string(), "image".to_string())
        } else {
            (format!("{k} robot poses"), format!("{k} images"))
        };
        let by = ["", "one", "two", "three"][k];
        let finding = format!("the pose file looks shifted by {by} against the images");
        rules.push(PairingRule {
            name: format!("robot pose i+{k} with image i"),
            finding: finding.clone(),
            fix: format!("remove the extra first {first_robot} so that the lists pair up"),
            pairs: robot_ahead,
        });
        rules.push(PairingRule {
            name: format!("robot pose i with image i+{k}"),
            finding,
            fix: format!("remove the extra first {first_images} so that the lists pair up"),
            pairs: camera_ahead,
        });
    }
    let n = n_robot.min(n_camera);
    rules.push(PairingRule {
        name: "robot pose i with image n-1-i (the reverse order)".to_string(),
        finding: "the poses and the images are listed in opposite orders".to_string(),
        fix: "reverse one list so that they pair up".to_string(),
        pairs: (0..n).map(|i| (i, n - 1 - i)).collect(),
    });
    rules
}

/// The rule that fits when the given pairing does not (module docs), or
/// `None` when the given pairing fits or no rule fits clearly better.
pub fn better_rule(
    setup: Setup,
    base_from_gripper: &[Pose],
    camera_from_target: &[Pose],
    given: &[(usize, usize)],
    rules: &[PairingRule],
) -> Option<RuleFit> {
    let given_deg = angle_mismatch_deg(setup, base_from_gripper, camera_from_target, given)?;
    if given_deg < MIN_MISMATCH_DEG {
        return None;
    }
    rules
        .iter()
        .filter(|r| r.pairs != given)
        .filter_map(|r| {
            angle_mismatch_deg(setup, base_from_gripper, camera_from_target, &r.pairs)
                .map(|d| (r, d))
        })
        .filter(|&(_, d)| d * RATIO < given_deg)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(r, d)| RuleFit {
            rule: r.clone(),
            mismatch_deg: d,
            given_mismatch_deg: given_deg,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The partners of the pairing test (its bound of pairs per view).
    fn motion_partners(i: usize, n: usize) -> Vec<usize> {
        crate::geometry::motion_partners(i, n, MAX_PAIRS_PER_VIEW)
    }
    use crate::synth::handeye::{handeye_scene, HandEyeScene, HandEyeSceneConfig};
    use wasm_bindgen_test::wasm_bindgen_test;

    fn scene(seed: u64, setup: Setup) -> HandEyeScene {
        handeye_scene(&HandEyeSceneConfig::noise_free(setup, 12), seed)
    }

    fn identity(n: usize) -> Vec<(usize, usize)> {
        (0..n).map(|i| (i, i)).collect()
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn right_pairing_fits_and_a_shift_or_reversal_is_named() {
        for setup in [Setup::EyeInHand, Setup::EyeToHand] {
            for seed in [3, 17, 40] {
                let s = scene(seed, setup);
                let (r, c) = (&s.base_from_gripper, &s.camera_from_target);
                let n = r.len();
                let d = angle_mismatch_deg(setup, r, c, &identity(n)).unwrap();
                assert!(d < 1e-6, "noise-free right pairing off by {d} deg");
                assert!(better_rule(setup, r, c, &identity(n), &position_rules(n, n)).is_none());
                // The robot list lost its first pose: pose i+1 meets image i.
                let fit = better_rule(
                    setup,
                    &r[1..],
                    c,
                    &identity(n - 1),
                    &position_rules(n - 1, n),
                )
                .expect("a shift is found");
                assert_eq!(fit.rule.name, "robot pose i with image i+1");
                assert!(
                    fit.mismatch_deg < 1e-6 && fit.given_mismatch_deg > 2.0,
                    "{fit:?}"
                );
                // Two poses lost: a shift by 2.
                let fit = better_rule(
                    setup,
                    &r[2..],
                    c,
                    &identity(n - 2),
                    &position_rules(n - 2, n),
                )
                .expect("a shift by two is found");
                assert_eq!(fit.rule.name, "robot pose i with image i+2");
                // The camera list reversed.
                let reversed: Vec<Pose> = c.iter().rev().copied().collect();
                let fit = better_rule(setup, r, &reversed, &identity(n), &position_rules(n, n))
                    .expect("the reversal is found");
                assert!(fit.rule.name.contains("reverse order"), "{}", fit.rule.name);
            }
        }
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_permutation_no_rule_explains_is_not_blamed_on_a_rule() {
        let s = scene(5, Setup::EyeInHand);
        let (r, c) = (&s.base_from_gripper, &s.camera_from_target);
        let n = r.len();
        // Swap two pairs in the middle: the given pairing is off but no
        // shift or reversal fits either.
        let mut given = identity(n);
        given.swap(4, 7);
        given[4].0 = 4;
        given[7].0 = 7;
        let d = angle_mismatch_deg(Setup::EyeInHand, r, c, &given).unwrap();
        assert!(d >= 0.0);
        assert!(better_rule(Setup::EyeInHand, r, c, &given, &position_rules(n, n)).is_none());
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn large_sets_use_a_linear_number_of_motion_pairs() {
        assert_eq!(motion_partners(0, 5), vec![1, 2, 3, 4]);
        let far = motion_partners(10, 1000);
        assert!(far.len() <= MAX_PAIRS_PER_VIEW, "{far:?}");
        assert!(far.iter().all(|&j| j > 10 && j < 1000));
        assert!(motion_partners(999, 1000).is_empty());
    }
}
