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
//! With `parts` after the poses, two more rows split the error: `centres`
//! (the plane refitted to the same centres with the board poses at the
//! truth, against the covariance without the board poses) and `boards`
//! (the PnP poses' share: the plane with them less the one with the truth,
//! against the board poses' part of the covariance).
//!
//! `cargo run --release --example laser_mc [TRIALS] [POSES,...] [parts]`
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
use robocal::synth::laser::LaserStripe;
use robocal::synth::laser_scene::{example_plane, laser_board_poses};
use robocal::synth::{render, RenderOptions};
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
        self.se_d += ed * ed;
        self.sb_d += c[(3, 3)];
        if ed.abs() <= 3.0 * c[(3, 3)].sqrt() {
            self.cover_d += 1;
        }
        self.trials += 1;
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

fn main() -> Result<(), robocal::Error> {
    let mut args = std::env::args().skip(1);
    let trials: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(200);
    let poses: Vec<usize> = args
        .next()
        .map(|a| a.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![2, 4, 10]);
    let breakdown = args.next().as_deref() == Some("parts");
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    // The truth of synth::laser_scene::example_plane, written out.
    let truth_n = Vector3::new(0.0, -0.5, 0.1).normalize();
    let truth_d = 0.1 * 0.5 / 0.26f64.sqrt();
    println!("laser plane Monte Carlo on renders: {trials} trials, pairs, cog, image_px");
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
        for trial in 0..trials {
            let mut views = Vec::new();
            for (i, pose) in board_poses.iter().enumerate() {
                let seed = 1_000_003 * n_poses as u64 + 1009 * trial as u64 + 17 * i as u64;
                let off_options = RenderOptions {
                    seed,
                    ..RenderOptions::default()
                };
                let mut laser = LaserStripe::new(example_plane());
                laser.seed = seed ^ 0x5EED;
                let on_options = RenderOptions {
                    seed: seed + 1,
                    laser: Some(laser),
                    ..RenderOptions::default()
                };
                views.push(LaserView {
                    name: format!("pose {i}"),
                    board: render(&camera, &target, pose, &off_options)?.image,
                    stripe: Some(render(&camera, &target, pose, &on_options)?.image),
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
            let truth_poses = breakdown.then_some(board_poses.as_slice());
            let measured = measure(&camera, &target, &views, truth_poses)?;
            let old = previous_covariance(&measured, &n, p.distance_m);
            previous.add(&n, p.distance_m, (&truth_n, truth_d), &old);
            vf += report.variance_factor;
            if breakdown {
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
        if breakdown {
            println!("{}", centres.row(n_poses, "centres", vf, failed));
            println!("{}", boards.row(n_poses, "boards", vf, failed));
        }
    }
    Ok(())
}
