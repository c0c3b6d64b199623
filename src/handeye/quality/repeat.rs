//! Repeatability over poses (seed 004's box plots): leave-one-out and a
//! seeded bootstrap, each giving medians and inter-quartile ranges of the
//! summary errors and the standard deviation of every output parameter.

use crate::error::Result;
use crate::handeye::closed_form::solve_method;
use crate::handeye::quality::residuals::{errors, pose_difference, view_residuals, Errors};
use crate::handeye::{Chain, HandEyeMethod, HandEyeOptions, Pose};
use crate::rng::Rng;
use serde::{Deserialize, Serialize};

/// Median and inter-quartile range of one quantity.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, Default)]
pub struct Spread {
    /// Median.
    pub median: f64,
    /// Third quartile minus first quartile.
    pub iqr: f64,
}

/// Standard deviations of a pose's parameters: translation (mm) and rotation
/// vector of `reference^-1 * estimate` (degrees), per axis.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, Default)]
pub struct PoseStd {
    /// Translation x, y, z (mm).
    pub translation_mm: [f64; 3],
    /// Rotation about x, y, z (degrees).
    pub rotation_deg: [f64; 3],
}

/// Statistics over the runs of one resampling scheme.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, Default)]
pub struct RunStats {
    /// Runs that solved.
    pub runs: usize,
    /// Runs whose solve failed (e.g. a resample with too little rotation).
    pub failed: usize,
    /// Translation RMS of the closure residuals (mm).
    pub translation_rms_mm: Spread,
    /// Translation max (mm).
    pub translation_max_mm: Spread,
    /// Rotation RMS (degrees).
    pub rotation_rms_deg: Spread,
    /// Rotation max (degrees).
    pub rotation_max_deg: Spread,
    /// Standard deviation of the camera transform (`gripper_from_camera` or `base_from_camera`).
    pub camera_std: PoseStd,
    /// Standard deviation of the target transform.
    pub target_std: PoseStd,
    /// Per-run values of `translation_rms_mm`, in run order (for box plots).
    #[serde(default)]
    pub translation_rms_mm_samples: Vec<f64>,
    /// Per-run values of `translation_max_mm`.
    #[serde(default)]
    pub translation_max_mm_samples: Vec<f64>,
    /// Per-run values of `rotation_rms_deg`.
    #[serde(default)]
    pub rotation_rms_deg_samples: Vec<f64>,
    /// Per-run values of `rotation_max_deg`.
    #[serde(default)]
    pub rotation_max_deg_samples: Vec<f64>,
    /// Per run: translation distance of the camera transform from the
    /// full-data solution (mm).
    #[serde(default)]
    pub camera_translation_deviation_mm_samples: Vec<f64>,
    /// Per run: rotation angle between the camera transform and the
    /// full-data solution (degrees).
    #[serde(default)]
    pub camera_rotation_deviation_deg_samples: Vec<f64>,
}

/// Leave-one-out and bootstrap results.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq, Default)]
pub struct Repeatability {
    /// The method resampled: a closed form, or `refined from <closed form>`
    /// when every resample was re-solved with the pose refinement.
    pub method: String,
    /// Bootstrap resamples drawn.
    #[serde(default)]
    pub bootstrap_samples: usize,
    /// Seed of the bootstrap resampling.
    #[serde(default)]
    pub seed: u64,
    /// One run per left-out view; standard deviations use the jackknife
    /// scaling `sqrt((n-1)/n * sum d^2)`, which estimates the full-data spread.
    pub leave_one_out: RunStats,
    /// Resamples of the views with replacement.
    pub bootstrap: RunStats,
}

fn quartiles(mut v: Vec<f64>) -> Spread {
    if v.is_empty() {
        return Spread::default();
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| {
        let pos = p * (v.len() - 1) as f64;
        let lo = pos.floor() as usize;
        let hi = pos.ceil() as usize;
        v[lo] + (v[hi] - v[lo]) * (pos - lo as f64)
    };
    Spread {
        median: q(0.5),
        iqr: q(0.75) - q(0.25),
    }
}

fn pose_params(reference: &Pose, estimate: &Pose) -> [f64; 6] {
    let d = (reference.inverse() * estimate).rotation.scaled_axis();
    let t = estimate.translation.vector - reference.translation.vector;
    [
        t.x * 1e3,
        t.y * 1e3,
        t.z * 1e3,
        d.x.to_degrees(),
        d.y.to_degrees(),
        d.z.to_degrees(),
    ]
}

fn std_of(samples: &[[f64; 6]], jackknife: bool) -> PoseStd {
    let n = samples.len();
    let mut out = [0.0; 6];
    if n >= 2 {
        for (k, o) in out.iter_mut().enumerate() {
            let mean = samples.iter().map(|s| s[k]).sum::<f64>() / n as f64;
            let ss = samples.iter().map(|s| (s[k] - mean).powi(2)).sum::<f64>();
            *o = if jackknife {
                (ss * (n - 1) as f64 / n as f64).sqrt()
            } else {
                (ss / (n - 1) as f64).sqrt()
            };
        }
    }
    PoseStd {
        translation_mm: [out[0], out[1], out[2]],
        rotation_deg: [out[3], out[4], out[5]],
    }
}

/// A solver of the views at the given indices (repeats allowed).
pub type SubsetSolver<'a> = dyn Fn(&[usize]) -> Result<(Pose, Pose)> + 'a;

fn run_all(
    chain: &Chain,
    solve: &SubsetSolver,
    subsets: &[Vec<usize>],
    reference: (&Pose, &Pose),
    jackknife: bool,
) -> RunStats {
    let mut errs: Vec<Errors> = Vec::new();
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    let mut failed = 0;
    let mut deviations = Vec::new();
    for subset in subsets {
        let sub = chain.subset(subset);
        match solve(subset) {
            Ok((x, y)) => {
                errs.push(errors(&view_residuals(&sub, &x, &y)));
                deviations.push(pose_difference(reference.0, &x));
                xs.push(pose_params(reference.0, &x));
                ys.push(pose_params(reference.1, &y));
            }
            Err(_) => failed += 1,
        }
    }
    let samples = |f: fn(&Errors) -> f64| errs.iter().map(f).collect::<Vec<f64>>();
    let translation_rms_mm_samples = samples(|e| e.translation_rms_mm);
    let translation_max_mm_samples = samples(|e| e.translation_max_mm);
    let rotation_rms_deg_samples = samples(|e| e.rotation_rms_deg);
    let rotation_max_deg_samples = samples(|e| e.rotation_max_deg);
    RunStats {
        runs: errs.len(),
        failed,
        translation_rms_mm: quartiles(translation_rms_mm_samples.clone()),
        translation_max_mm: quartiles(translation_max_mm_samples.clone()),
        rotation_rms_deg: quartiles(rotation_rms_deg_samples.clone()),
        rotation_max_deg: quartiles(rotation_max_deg_samples.clone()),
        camera_std: std_of(&xs, jackknife),
        target_std: std_of(&ys, jackknife),
        translation_rms_mm_samples,
        translation_max_mm_samples,
        rotation_rms_deg_samples,
        rotation_max_deg_samples,
        camera_translation_deviation_mm_samples: deviations.iter().map(|d| d.0).collect(),
        camera_rotation_deviation_deg_samples: deviations.iter().map(|d| d.1).collect(),
    }
}

/// Leave-one-out over views and `options.bootstrap_samples` bootstrap
/// resamples (seeded by `options.seed`), solving with `method`; parameter
/// deviations are measured from the full-data solution `(x, y)`.
pub fn repeatability(
    chain: &Chain,
    method: HandEyeMethod,
    options: &HandEyeOptions,
    x: &Pose,
    y: &Pose,
) -> Repeatability {
    let solve = |indices: &[usize]| {
        solve_method(method, &chain.subset(indices), options.motion_pairs).map(|(x, y, _)| (x, y))
    };
    repeatability_with(chain, method.name(), &solve, options, x, y)
}

/// [`repeatability`] with any solver of a subset of the views, reported
/// under `method`: the same leave-one-out runs and the same seeded
/// bootstrap resamples (`options.bootstrap_samples`, `options.seed`).
pub fn repeatability_with(
    chain: &Chain,
    method: &str,
    solve: &SubsetSolver,
    options: &HandEyeOptions,
    x: &Pose,
    y: &Pose,
) -> Repeatability {
    let n = chain.len();
    let loo: Vec<Vec<usize>> = (0..n)
        .map(|skip| (0..n).filter(|&i| i != skip).collect())
        .collect();
    let mut rng = Rng::new(options.seed);
    let boot: Vec<Vec<usize>> = (0..options.bootstrap_samples)
        .map(|_| {
            let mut s: Vec<usize> = (0..n).map(|_| rng.below(n)).collect();
            s.sort_by(usize::cmp);
            s
        })
        .collect();
    Repeatability {
        method: method.to_string(),
        bootstrap_samples: options.bootstrap_samples,
        seed: options.seed,
        leave_one_out: run_all(chain, solve, &loo, (x, y), true),
        bootstrap: run_all(chain, solve, &boot, (x, y), false),
    }
}
