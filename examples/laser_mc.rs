//! A seeded Monte Carlo of the laser plane on rendered images: per trial
//! and board pose a laser-off and a laser-on image (new noise and speckle
//! seeds every trial; speckle 0.2, a 5 px stripe that saturates on the
//! white squares), then the whole `robocal laser plane --pairs` pipeline
//! (board detection, PnP, stripe extraction, fit). The normal (deg) and
//! distance (mm) errors against the truth are compared with the reported
//! covariance: RMS over the trials against the RMS of the reported std
//! (the bound), and the share of trials within 3 std (normal: chi^2(2) <
//! 11.83, distance: |e| < 3 std).
//!
//! Beside the reported covariance, the previous model is scored on the same
//! trials: `s^2 (J^T J)^-1` (the residual variance times the inverse, the
//! centres independent, the board poses exact), recomputed here from the
//! same measurements (corners detected, PnP pose, centres on the board).
//!
//! Every trial each board is slid in its own plane by a new random offset
//! of up to a square along each board axis (`fixed` after the poses keeps
//! them where `laser_board_poses` puts them): the stripe's 3-D line, the
//! geometry that fixes the plane, stays; the squares under the stripe and
//! its pixel phase change. The centres' error is mostly the extractor's
//! systematic error over the pattern (0.2-0.5 px RMS against the
//! renderer's exact centres), not the image noise: with the boards fixed
//! it is the same draw in every trial and the trials only vary the noise
//! (s27: at 4 poses the mean error was 0.079 deg, the scatter about it
//! 0.008 deg). The covariance, estimated from the residuals, describes
//! that error over the pattern's draws, which only the slid boards vary.
//! Each model's row is followed by its mean error and the scatter about it.
//!
//! With `parts` after the poses, two more rows split the error: `centres`
//! (the plane refitted to the same centres with the board poses at the
//! truth, against the covariance without the board poses) and `boards`
//! (the PnP poses' share: the plane with them less the one with the truth,
//! against the board poses' part of the covariance), the bias rows of
//! both and per image the centres' mean and RMS error against the truth
//! (px along the scan); `trials` with `parts` prints each trial; `z`
//! prints each trial's normal chi^2 and distance error over its std.
//!
//! `cargo run --release --example laser_mc [TRIALS] [POSES,...] [parts]
//! [trials] [z] [fixed]`
//! (default 200 and 2,4,10).

use nalgebra::{Matrix2, Matrix3, Matrix4, Point2, Vector2, Vector3};
use robocal::api::laser::{laser_plane, LaserPlaneSettings, LaserView};
use robocal::calib::{pnp, View};
use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::geometry::Pose;
use robocal::laser::{
    extract_stripe, fit_plane_with_boards, BoardPose, PlaneFitOptions, StripeObservation,
    StripeOptions,
};
use robocal::rng::Rng;
use robocal::synth::laser::{laser_pair, LaserStripe};
use robocal::synth::laser_scene::{example_plane, laser_board_poses};
use robocal::target::Target;

/// One trial's measurements as the pipeline makes them: per view the board
/// detected, its pose by PnP, the stripe extracted and its centres met with
/// the board, those inside the detected corners' extent kept.
#[derive(Default)]
struct Measured {
    /// The centres kept, through the PnP poses.
    centres: Vec<StripeObservation>,
    /// With the truth (`parts`): the same centres through the true poses
    /// (those that meet them).
    at_truth: Vec<StripeObservation>,
    /// With the truth (`parts`): the PnP poses and their covariances.
    boards: Vec<BoardPose>,
}

/// [`Measured`] for `views`; with `truth_poses` (the `parts` breakdown)
/// also the board poses' covariances and the centres at the true poses.
fn measure(
    camera: &Camera,
    target: &Target,
    views: &[LaserView],
    truth_poses: Option<&[Pose]>,
) -> Result<Measured, robocal::Error> {
    let mut out = Measured::default();
    for (i, v) in views.iter().enumerate() {
        let detection = detect(&v.board, target, &DetectOptions::default())?;
        let view = View::from_detection(v.name.clone(), &detection);
        let pose = if truth_poses.is_some() {
            let (pose, rms, unit) = pnp::camera_from_target_with_covariance(camera, &view)?;
            let n = view.image_px.len() as f64;
            out.boards.push(BoardPose {
                image: i,
                camera_from_target: pose,
                covariance: unit * (rms * rms * n / (2.0 * n - 6.0)),
            });
            pose
        } else {
            pnp::camera_from_target(camera, &view)?.0
        };
        let truth = truth_poses.and_then(|t| t.get(i));
        let (lo, hi) = view
            .object_m
            .iter()
            .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
                (
                    [lo[0].min(p.x), lo[1].min(p.y)],
                    [hi[0].max(p.x), hi[1].max(p.y)],
                )
            });
        let on = v.stripe.as_ref().unwrap_or(&v.board);
        let stripe = extract_stripe(on, Some(&v.board), &StripeOptions::default())?;
        let along_y = stripe.axis == robocal::laser::ScanAxis::Columns;
        for p in &stripe.points {
            let px = Point2::new(p.x_px, p.y_px);
            let Ok(o) = StripeObservation::new(camera, &pose, &px, along_y, p.std_px, i) else {
                continue;
            };
            let q = pose.inverse() * o.point_camera;
            if q.x < lo[0] || q.x > hi[0] || q.y < lo[1] || q.y > hi[1] {
                continue;
            }
            out.centres.push(o);
            if let Some(truth) = truth {
                if let Ok(t) = StripeObservation::new(camera, truth, &px, along_y, p.std_px, i) {
                    out.at_truth.push(t);
                }
            }
        }
    }
    Ok(out)
}

/// The previous covariance model at the plane `(n, d)`: `s^2 (J^T J)^-1`
/// over `(nx, ny, nz, d)` from the image-space residuals of the measured
/// centres (board poses from PnP, centres inside the corners' extent).
fn previous_covariance(measured: &Measured, n: &Vector3<f64>, d: f64) -> Matrix4<f64> {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let a = n.cross(&helper).normalize();
    let b = n.cross(&a);
    let (mut jtj, mut chi2) = (Matrix3::zeros(), 0.0);
    for o in &measured.centres {
        let x = o.point_camera.coords;
        let t = o.along_scan_m_per_px;
        let nt = n.dot(&t);
        let e = n.dot(&x) - d;
        let w = 1.0 / o.std_px;
        let dn = w * (x * nt - t * e) / (nt * nt);
        let j = Vector3::new(dn.dot(&a), dn.dot(&b), -w / nt);
        jtj += j * j.transpose();
        chi2 += (w * e / nt).powi(2);
    }
    let s2 = chi2 / (measured.centres.len().max(4) - 3) as f64;
    let inv = jtj.try_inverse().unwrap_or_else(Matrix3::zeros) * s2;
    let mut map = nalgebra::Matrix4x3::zeros();
    for r in 0..3 {
        map[(r, 0)] = a[r];
        map[(r, 1)] = b[r];
    }
    map[(3, 2)] = 1.0;
    map * inv * map.transpose()
}

/// The error's parts on one trial: the plane fitted to the same centres
/// with the board poses at the truth (the centres' share of the error) and
/// its covariance, and the board poses' share of the reported covariance
/// (with the PnP poses and their covariance less without them).
struct Parts {
    truth_pose_plane: (Vector3<f64>, f64),
    measured_plane: (Vector3<f64>, f64),
    stripe_cov: Matrix4<f64>,
    board_cov: Matrix4<f64>,
}

/// [`Parts`] from measurements made with the truth ([`measure`]).
fn parts(measured: &Measured) -> Result<Parts, robocal::Error> {
    let options = PlaneFitOptions::default();
    let t = fit_plane_with_boards(&measured.at_truth, &[], &options)?;
    let s = fit_plane_with_boards(&measured.centres, &[], &options)?;
    let b = fit_plane_with_boards(&measured.centres, &measured.boards, &options)?;
    let sc = s.estimate.normal_distance_covariance();
    Ok(Parts {
        truth_pose_plane: (
            t.estimate.plane.normal.into_inner(),
            t.estimate.plane.distance_m,
        ),
        measured_plane: (
            b.estimate.plane.normal.into_inner(),
            b.estimate.plane.distance_m,
        ),
        stripe_cov: sc,
        board_cov: b.estimate.normal_distance_covariance() - sc,
    })
}

/// Normal error (2-D, in the tangent plane of `n`) and its 2x2 covariance.
fn normal_error(
    n: &Vector3<f64>,
    truth: &Vector3<f64>,
    c: &Matrix4<f64>,
) -> (Vector2<f64>, Matrix2<f64>) {
    let a = n.cross(&Vector3::x()).normalize();
    let b = n.cross(&a);
    let e = n - truth;
    let cnn = c.fixed_view::<3, 3>(0, 0).into_owned();
    (
        Vector2::new(e.dot(&a), e.dot(&b)),
        Matrix2::new(
            a.dot(&(cnn * a)),
            a.dot(&(cnn * b)),
            b.dot(&(cnn * a)),
            b.dot(&(cnn * b)),
        ),
    )
}

/// Sums over the trials for one covariance model.
#[derive(Default)]
struct Score {
    se_n: f64,
    sb_n: f64,
    se_d: f64,
    sb_d: f64,
    cover_n: usize,
    cover_d: usize,
    trials: usize,
    /// Sums of the errors themselves (normal: `n - truth`), for the bias.
    sum_n: Vector3<f64>,
    sum_d: f64,
}

impl Score {
    fn add(&mut self, n: &Vector3<f64>, d: f64, truth: (&Vector3<f64>, f64), c: &Matrix4<f64>) {
        let (e2, c2) = normal_error(n, truth.0, c);
        self.se_n += e2.norm_squared();
        self.sb_n += c2.trace();
        if let Some(inv) = c2.try_inverse() {
            // chi^2(2) at the 3-sigma probability 0.9973.
            if (e2.transpose() * inv * e2)[0] <= 11.829 {
                self.cover_n += 1;
            }
        }
        let ed = d - truth.1;
        self.sum_n += n - truth.0;
        self.sum_d += ed;
        self.se_d += ed * ed;
        self.sb_d += c[(3, 3)];
        if ed.abs() <= 3.0 * c[(3, 3)].sqrt() {
            self.cover_d += 1;
        }
        self.trials += 1;
    }

    /// The mean error (bias) and the RMS about it: normal deg, distance mm.
    fn bias(&self, poses: usize, name: &str) -> String {
        let t = self.trials.max(1) as f64;
        let (mn, md) = (self.sum_n / t, self.sum_d / t);
        let sn = (self.se_n / t - mn.norm_squared()).max(0.0).sqrt();
        let sd = (self.se_d / t - md * md).max(0.0).sqrt();
        format!(
            "{poses:>5} {name:<9} | mean {:>9.5} deg, scatter {:>9.5} deg | mean {:>8.4} mm, scatter {:>8.4} mm",
            mn.norm().to_degrees(),
            sn.to_degrees(),
            md * 1e3,
            sd * 1e3
        )
    }

    fn row(&self, poses: usize, name: &str, variance_factor: f64, failed: usize) -> String {
        let t = self.trials.max(1) as f64;
        let (rn, bn) = (
            (self.se_n / t).sqrt().to_degrees(),
            (self.sb_n / t).sqrt().to_degrees(),
        );
        let (rd, bd) = ((self.se_d / t).sqrt() * 1e3, (self.sb_d / t).sqrt() * 1e3);
        format!(
            "{poses:>5} {name:<9} | {rn:>9.5} {bn:>9.5} {:>6.2} | {rd:>8.4} {bd:>8.4} {:>6.2} | {:>6.1}% {:>6.1}% | {variance_factor:>6.1} | {failed:>6}",
            rn / bn,
            rd / bd,
            100.0 * self.cover_n as f64 / t,
            100.0 * self.cover_d as f64 / t,
        )
    }
}

/// How far each board slides in its own plane per trial (uniform in
/// `+-SLIDE_M` along both board axes; without `fixed`): the pattern's
/// period (two squares), so the squares under the stripe and the stripe's
/// pixel phase are new every trial while the stripe's 3-D line (the
/// geometry that fixes the plane) stays.
const SLIDE_M: f64 = 0.025;

fn main() -> Result<(), robocal::Error> {
    let mut args = std::env::args().skip(1);
    let trials: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(200);
    let poses: Vec<usize> = args
        .next()
        .map(|a| a.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![2, 4, 10]);
    let flags: Vec<String> = args.collect();
    let breakdown = flags.iter().any(|f| f == "parts");
    let fixed = flags.iter().any(|f| f == "fixed");
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    // The truth of synth::laser_scene::example_plane, written out.
    let truth_n = Vector3::new(0.0, -0.5, 0.1).normalize();
    let truth_d = 0.1 * 0.5 / 0.26f64.sqrt();
    println!(
        "laser plane Monte Carlo on renders: {trials} trials, pairs, cog, image_px, boards {}",
        if fixed {
            "fixed"
        } else {
            "slid in their plane"
        }
    );
    println!("model: reported = the sandwich + board poses; previous = s^2 (J^T J)^-1");
    println!(
        "{:>5} {:<9} | {:>9} {:>9} {:>6} | {:>8} {:>8} {:>6} | {:>7} {:>7} | {:>6} | {:>6}",
        "poses",
        "model",
        "RMS deg",
        "bound",
        "ratio",
        "RMS mm",
        "bound",
        "ratio",
        "cov n",
        "cov d",
        "var f",
        "failed"
    );
    for &n_poses in &poses {
        let board_poses = laser_board_poses(n_poses);
        let (mut reported, mut previous) = (Score::default(), Score::default());
        let (mut centres, mut boards) = (Score::default(), Score::default());
        let (mut vf, mut failed) = (0.0, 0usize);
        // Per image (`parts`): the centres' residuals against the true
        // plane, px along the scan: through the true pose (sum, sum of
        // squares, count) and through PnP's (sum).
        let mut per_image = vec![(0.0, 0.0, 0usize, 0.0, 0usize); n_poses];
        for trial in 0..trials {
            let mut views = Vec::new();
            let mut slide = Rng::new(7_000_003 * n_poses as u64 + 31 * trial as u64 + 5);
            let trial_poses: Vec<Pose> = board_poses
                .iter()
                .map(|pose| {
                    if fixed {
                        return *pose;
                    }
                    // The board slid in its own plane: the stripe's 3-D
                    // line is unchanged, the pattern under it is not.
                    let v = Vector3::new(
                        slide.range(-SLIDE_M, SLIDE_M),
                        slide.range(-SLIDE_M, SLIDE_M),
                        0.0,
                    );
                    pose * Pose::from_parts(v.into(), nalgebra::UnitQuaternion::identity())
                })
                .collect();
            for (i, pose) in trial_poses.iter().enumerate() {
                let seed = 1_000_003 * n_poses as u64 + 1009 * trial as u64 + 17 * i as u64;
                let mut laser = LaserStripe::new(example_plane());
                laser.seed = seed ^ 0x5EED;
                let (board, stripe) = laser_pair(&camera, &target, pose, &laser, seed)?;
                views.push(LaserView {
                    name: format!("pose {i}"),
                    board,
                    stripe: Some(stripe),
                });
            }
            let report = match laser_plane(&camera, &target, &views, &LaserPlaneSettings::default())
            {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("{n_poses} poses, trial {trial}: {e}");
                    failed += 1;
                    continue;
                }
            };
            let p = &report.laser_plane;
            let n = Vector3::from(p.normal_camera);
            let c = Matrix4::from_fn(|r, k| p.covariance[r][k]);
            reported.add(&n, p.distance_m, (&truth_n, truth_d), &c);
            if flags.iter().any(|f| f == "z") {
                // Per trial: the errors in units of their reported std.
                let (e2, c2) = normal_error(&n, &truth_n, &c);
                let chi2 = c2
                    .try_inverse()
                    .map_or(f64::NAN, |inv| (e2.transpose() * inv * e2)[0]);
                println!(
                    "z {n_poses} {trial} {chi2:.3} {:.3}",
                    (p.distance_m - truth_d) / c[(3, 3)].sqrt()
                );
            }
            let truth_poses = breakdown.then_some(trial_poses.as_slice());
            let measured = measure(&camera, &target, &views, truth_poses)?;
            if flags.iter().any(|f| f == "z") {
                // Per image: centres kept, and those the step model could
                // not fit (the centre of gravity kept, std 0.5 px or more).
                let per: Vec<String> = (0..n_poses)
                    .map(|i| {
                        let c = measured.centres.iter().filter(|o| o.image == i);
                        let all = c.clone().count();
                        let wide = c.filter(|o| o.std_px >= 0.5).count();
                        format!("{wide}/{all}")
                    })
                    .collect();
                println!("fallbacks {n_poses} {trial} {}", per.join(" "));
            }
            let old = previous_covariance(&measured, &n, p.distance_m);
            previous.add(&n, p.distance_m, (&truth_n, truth_d), &old);
            vf += report.variance_factor;
            if breakdown {
                let along = |o: &StripeObservation| {
                    (truth_n.dot(&o.point_camera.coords) - truth_d)
                        / truth_n.dot(&o.along_scan_m_per_px)
                };
                for o in &measured.at_truth {
                    let e = &mut per_image[o.image];
                    let r = along(o);
                    e.0 += r;
                    e.1 += r * r;
                    e.2 += 1;
                }
                for o in &measured.centres {
                    let e = &mut per_image[o.image];
                    e.3 += along(o);
                    e.4 += 1;
                }
                if flags.iter().any(|f| f == "trials") {
                    let mut line = format!(
                        "trial {trial}: normal {:.4} deg, d {:+.3} mm;",
                        (n - truth_n).norm().to_degrees(),
                        (p.distance_m - truth_d) * 1e3
                    );
                    for i in 0..n_poses {
                        let r: Vec<f64> = measured
                            .at_truth
                            .iter()
                            .filter(|o| o.image == i)
                            .map(along)
                            .collect();
                        let big = r.iter().filter(|v| v.abs() > 1.0).count();
                        let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                        let mean = r.iter().sum::<f64>() / r.len().max(1) as f64;
                        line += &format!(
                            " img{i} n {} mean {mean:+.3} >1px {big} max {worst:.2};",
                            r.len()
                        );
                    }
                    println!("{line}");
                }
                let q = parts(&measured)?;
                let (tn, td) = q.truth_pose_plane;
                centres.add(&tn, td, (&truth_n, truth_d), &q.stripe_cov);
                let (mn, md) = q.measured_plane;
                boards.add(&mn, md, (&tn, td), &q.board_cov);
            }
        }
        let vf = vf / reported.trials.max(1) as f64;
        println!("{}", reported.row(n_poses, "reported", vf, failed));
        println!("{}", previous.row(n_poses, "previous", vf, failed));
        println!("{}", reported.bias(n_poses, "reported"));
        if breakdown {
            println!("{}", centres.row(n_poses, "centres", vf, failed));
            println!("{}", boards.row(n_poses, "boards", vf, failed));
            println!("{}", centres.bias(n_poses, "centres"));
            println!("{}", boards.bias(n_poses, "boards"));
            for (i, e) in per_image.iter().enumerate() {
                let k = e.2.max(1) as f64;
                println!(
                    "      image {i}: centres at the true pose: mean {:+.4} px, RMS {:.4} px ({} per trial); through PnP: mean {:+.4} px",
                    e.0 / k,
                    (e.1 / k).sqrt(),
                    e.2 / reported.trials.max(1),
                    e.3 / e.4.max(1) as f64
                );
            }
        }
    }
    Ok(())
}
