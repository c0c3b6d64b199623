//! robocal's laser plane against calibration-rs's laserline workflow
//! (crates.io `vision-calibration`, its `laserline_device` session) on the
//! same rendered scenes and the same measurements.
//!
//! Per scene (2, 4 or 10 board poses of `synth::laser_scene`) and trial:
//! a laser-off and a laser-on render per pose (new noise and speckle seeds
//! each trial). robocal runs its whole pipeline (`api::laser::laser_plane`:
//! detection, PnP, stripe extraction, plane fit) with the true camera.
//! calibration-rs gets robocal's detected corners and stripe centres (the
//! centres on the board) as its `LaserlineView`s and runs its laserline
//! device calibration: (a) with the intrinsics seeded at the truth and
//! held (the plane and the poses estimated: robocal's situation), and (b)
//! its full workflow, the intrinsics estimated too (4 or more poses), with
//! robocal's `--refine-intrinsics` beside it from a camera 2 % off.
//! Printed: RMS over the trials of the normal's angle (deg) and the
//! distance's error (mm) against the truth (the distance is the plane's
//! offset at the camera centre, 0.1 m from the plane, while the stripes lie
//! 0.45-0.55 m away: a tilted normal moves the two apart). Beside them the
//! plane where the sensor measures: over the working range (the true
//! plane's points seen by the camera at 0.40-0.60 m depth), the RMS
//! distance of those points to the estimated plane (mm), the RMS 3-D error
//! of the points each tool's own camera and plane give for their pixels
//! (mm: the profile-to-points error), and the correlation over the trials
//! between the distance error and the normal error's share at the range's
//! centre, `(n_est - n) . X_c`.
//!
//! With `diag`: per scene the centres' true error (against the renderer's
//! exact centre) by the std the extractor reported, and four more fits
//! with the intrinsics at the truth: robocal's with every centre's std 1
//! px, robocal's joint refinement with the camera held (the board poses
//! refined with the stripe; extractor stds, then 1 px), and calibration-rs
//! with robocal's `1 / std^2` weights.
//!
//! Not part of robocal's build or tests: run by hand,
//! `cd benches/laser_vs_calibration_rs && cargo run --release [TRIALS] [diag]`
//! (default 20 trials).

use nalgebra::{Point2, Vector3};
use robocal::api::laser::{
    laser_plane, laser_plane_refining_camera, LaserPlaneReport, LaserPlaneSettings, LaserView,
};
use robocal::calib::View as RobocalView;
use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::laser::joint::{refine_holding, JointImage};
use robocal::laser::{
    extract_stripe, fit_plane, plane_in_camera, PlaneFitOptions, StripeObservation, StripeOptions,
};
use robocal::synth::laser::{laser_pair, stripe_truth, LaserStripe};
use robocal::synth::laser_scene::{example_plane, laser_board_poses};
use robocal::target::Target;
use vision_calibration::common::config::CameraConfig;
use vision_calibration::core::{
    CameraModelSpec, CorrespondenceView, DistortionKind, FxFyCxCy, Pt2, Pt3, SensorKind, View,
};
use vision_calibration::laserline_device::{
    step_init_with_seed, step_optimize, DeviceManualInit, LaserlineDeviceConfig,
    LaserlineDeviceProblem, LaserlineMeta,
};
use vision_calibration::session::CalibrationSession;

type Error = Box<dyn std::error::Error>;

/// One trial's estimate: the plane `n . X = d` (d >= 0, n unit) and the
/// pinhole intrinsics `fx, fy, cx, cy` it goes with.
#[derive(Clone, Copy)]
struct Estimate {
    n: Vector3<f64>,
    d: f64,
    k: [f64; 4],
}

const TRUE_K: [f64; 4] = [800.0, 800.0, 320.0, 240.0];

fn estimate(n: Vector3<f64>, d: f64, k: [f64; 4]) -> Estimate {
    let (n, d) = if d < 0.0 { (-n, -d) } else { (n, d) };
    let s = n.norm();
    Estimate {
        n: n / s,
        d: d / s,
        k,
    }
}

fn report_estimate(r: &LaserPlaneReport, k: [f64; 4]) -> Estimate {
    estimate(
        Vector3::from(r.laser_plane.normal_camera),
        r.laser_plane.distance_m,
        k,
    )
}

/// The working range: pixels (every 8th column, every 2nd row) whose true
/// ray meets the true plane 0.40-0.60 m deep, with that point.
fn working_range() -> Vec<(Point2<f64>, Vector3<f64>)> {
    let truth = example_plane();
    let n = truth.normal.into_inner();
    let mut out = Vec::new();
    for v in (0..480).step_by(2) {
        for u in (0..640).step_by(8) {
            let px = Point2::new(u as f64, v as f64);
            let ray = ray_of(&TRUE_K, &px);
            let s = n.dot(&ray);
            if s <= 0.0 {
                continue;
            }
            let x = ray * (truth.distance_m / s);
            if (0.40..=0.60).contains(&x.z) {
                out.push((px, x));
            }
        }
    }
    out
}

fn ray_of(k: &[f64; 4], px: &Point2<f64>) -> Vector3<f64> {
    Vector3::new((px.x - k[2]) / k[0], (px.y - k[3]) / k[1], 1.0)
}

/// The metrics of a set of trials' estimates, see the file's doc.
struct Metrics {
    normal_deg: f64,
    distance_mm: f64,
    range_plane_mm: f64,
    range_points_mm: f64,
    centre_mm: f64,
    correlation: f64,
}

fn metrics(v: &[Estimate], range: &[(Point2<f64>, Vector3<f64>)]) -> Metrics {
    let truth = example_plane();
    let n0 = truth.normal.into_inner();
    let centre = range.iter().map(|(_, x)| x).sum::<Vector3<f64>>() / range.len().max(1) as f64;
    let trials = v.len().max(1) as f64;
    let points = (v.len() * range.len()).max(1) as f64;
    let (mut a, mut dd, mut plane, mut pts, mut c) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let (mut dds, mut ts) = (Vec::new(), Vec::new());
    for e in v {
        let ang = e.n.dot(&n0).clamp(-1.0, 1.0).acos().to_degrees();
        a += ang * ang;
        let delta_d = (e.d - truth.distance_m) * 1e3;
        dd += delta_d * delta_d;
        let t = (e.n - n0).dot(&centre) * 1e3;
        dds.push(delta_d);
        ts.push(t);
        let ec = (e.n.dot(&centre) - e.d) * 1e3;
        c += ec * ec;
        for (px, x) in range {
            let off = (e.n.dot(x) - e.d) * 1e3;
            plane += off * off;
            let ray = ray_of(&e.k, px);
            let p = ray * (e.d / e.n.dot(&ray));
            pts += ((p - x) * 1e3).norm_squared();
        }
    }
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len().max(1) as f64;
    let (md, mt) = (mean(&dds), mean(&ts));
    let cov: f64 = dds.iter().zip(&ts).map(|(a, b)| (a - md) * (b - mt)).sum();
    let vd: f64 = dds.iter().map(|a| (a - md).powi(2)).sum();
    let vt: f64 = ts.iter().map(|b| (b - mt).powi(2)).sum();
    Metrics {
        normal_deg: (a / trials).sqrt(),
        distance_mm: (dd / trials).sqrt(),
        range_plane_mm: (plane / points).sqrt(),
        range_points_mm: (pts / points).sqrt(),
        centre_mm: (c / trials).sqrt(),
        correlation: cov / (vd * vt).sqrt().max(1e-300),
    }
}

/// calibration-rs's laserline device calibration of `views`; `intrinsics`:
/// seeded and held at these.
fn calibration_rs(
    views: Vec<View<LaserlineMeta>>,
    intrinsics: Option<FxFyCxCy<f64>>,
) -> Result<Estimate, Error> {
    let mut config = LaserlineDeviceConfig::default();
    config.camera = CameraConfig::new(CameraModelSpec::pinhole(
        DistortionKind::None,
        SensorKind::Identity,
    ));
    let mut seed = DeviceManualInit::default();
    if let Some(k) = intrinsics {
        config.camera.fix.intrinsics = Some(
            ["fx", "fy", "cx", "cy"]
                .iter()
                .map(|s| s.to_string())
                .collect(),
        );
        seed.intrinsics = Some(k);
    }
    let mut session = CalibrationSession::<LaserlineDeviceProblem>::new();
    session.set_input(views)?;
    session.set_config(config)?;
    step_init_with_seed(&mut session, seed, None)?;
    step_optimize(&mut session, None)?;
    let export = session.export()?;
    // calibration-rs: n . X + distance = 0.
    let plane = &export.params.plane;
    let k = &export.params.camera.intrinsics;
    Ok(estimate(
        plane.normal.into_inner(),
        -plane.distance,
        [k.fx, k.fy, k.cx, k.cy],
    ))
}

/// One view's on-board stripe centres as robocal measured them: the PnP
/// pose, the centres with their std (px) and whether they were scanned
/// along columns; and the corners.
struct Centres {
    pose: robocal::geometry::Pose,
    centres: Vec<(Point2<f64>, f64)>,
    along_y: bool,
    object_m: Vec<nalgebra::Point3<f64>>,
    image_px: Vec<Point2<f64>>,
    board_rms_px: f64,
}

/// robocal's corners and on-board stripe centres as calibration-rs views
/// (and as robocal's own, for the diagnostic fits).
fn measurements(
    camera: &Camera,
    target: &Target,
    views: &[LaserView],
    report: &LaserPlaneReport,
) -> Result<(Vec<View<LaserlineMeta>>, Vec<Centres>), Error> {
    let mut out = Vec::new();
    let mut ours = Vec::new();
    for (v, image) in views.iter().zip(&report.images) {
        let detection = detect(&v.board, target, &DetectOptions::default())?;
        let view = RobocalView::from_detection(v.name.clone(), &detection);
        let pose = image.camera_from_target.to_pose()?;
        let (lo, hi) = view
            .object_m
            .iter()
            .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), p| {
                (
                    [lo[0].min(p.x), lo[1].min(p.y)],
                    [hi[0].max(p.x), hi[1].max(p.y)],
                )
            });
        let stripe_image = v.stripe.as_ref().ok_or("pairs expected")?;
        let stripe = extract_stripe(stripe_image, Some(&v.board), &StripeOptions::default())?;
        let m = pose.rotation * Vector3::z();
        let e = m.dot(&pose.translation.vector);
        let mut laser_pixels = Vec::new();
        let mut centres = Vec::new();
        for p in &stripe.points {
            let ray = camera.unproject(&Point2::new(p.x_px, p.y_px))?;
            let on_board = pose.inverse() * nalgebra::Point3::from(ray * (e / m.dot(&ray)));
            if on_board.x >= lo[0]
                && on_board.x <= hi[0]
                && on_board.y >= lo[1]
                && on_board.y <= hi[1]
            {
                laser_pixels.push(Pt2::new(p.x_px, p.y_px));
                centres.push((Point2::new(p.x_px, p.y_px), p.std_px));
            }
        }
        ours.push(Centres {
            pose,
            centres,
            along_y: stripe.axis == robocal::laser::ScanAxis::Columns,
            object_m: view.object_m.clone(),
            image_px: view.image_px.clone(),
            board_rms_px: image.board_rms_px,
        });
        let obs = CorrespondenceView::new(
            view.object_m
                .iter()
                .map(|p| Pt3::new(p.x, p.y, p.z))
                .collect(),
            view.image_px.iter().map(|p| Pt2::new(p.x, p.y)).collect(),
        )?;
        out.push(View::new(
            obs,
            LaserlineMeta {
                laser_pixels,
                laser_weights: Vec::new(),
            },
        ));
    }
    Ok((out, ours))
}

/// Diagnostics with the intrinsics at the truth: robocal's plane fit on
/// its PnP poses with every centre's std set to 1 px (unweighted), and
/// robocal's joint refinement with every camera parameter held (the board
/// poses refined with the stripe, as calibration-rs does).
fn robocal_unweighted(camera: &Camera, c: &[Centres]) -> Result<Estimate, Error> {
    let mut obs = Vec::new();
    for (i, v) in c.iter().enumerate() {
        for (px, _) in &v.centres {
            obs.push(StripeObservation::new(
                camera, &v.pose, px, v.along_y, 1.0, i,
            )?);
        }
    }
    let fit = fit_plane(&obs, &PlaneFitOptions::default())?;
    let p = fit.estimate.plane;
    Ok(estimate(p.normal.into_inner(), p.distance_m, TRUE_K))
}

fn robocal_poses_refined(
    camera: &Camera,
    c: &[Centres],
    start: &Estimate,
    unit_stripe: bool,
) -> Result<Estimate, Error> {
    let images: Vec<JointImage> = c
        .iter()
        .map(|v| JointImage {
            object_m: v.object_m.clone(),
            image_px: v.image_px.clone(),
            corner_std_px: (v.board_rms_px / 2f64.sqrt()).max(1e-3),
            camera_from_target: v.pose,
            stripe: v
                .centres
                .iter()
                .map(|(p, s)| (*p, if unit_stripe { 1.0 } else { *s }))
                .collect(),
            scan_along_y: v.along_y,
        })
        .collect();
    let plane = plane_in_camera(start.n, start.d)?;
    let all = camera.param_names();
    let j = refine_holding(camera, &images, &plane, &all)?;
    Ok(estimate(
        j.plane.normal.into_inner(),
        j.plane.distance_m,
        TRUE_K,
    ))
}

/// calibration-rs with robocal's per-centre weights (1 / std^2, mean 1).
fn with_weights(mut views: Vec<View<LaserlineMeta>>, c: &[Centres]) -> Vec<View<LaserlineMeta>> {
    let all: Vec<f64> = c
        .iter()
        .flat_map(|v| v.centres.iter().map(|(_, s)| 1.0 / (s * s)))
        .collect();
    let mean = all.iter().sum::<f64>() / all.len().max(1) as f64;
    for (view, v) in views.iter_mut().zip(c) {
        view.meta.laser_weights = v
            .centres
            .iter()
            .map(|(_, s)| 1.0 / (s * s) / mean)
            .collect();
    }
    views
}

fn main() -> Result<(), Error> {
    let trials: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20);
    let diag = std::env::args().any(|a| a == "diag");
    let camera = Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480);
    let off_camera = Camera::pinhole(816.0, 816.0, 325.0, 236.0, 640, 480);
    let truth_k = FxFyCxCy {
        fx: 800.0,
        fy: 800.0,
        cx: 320.0,
        cy: 240.0,
    };
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    println!("laser plane, robocal vs calibration-rs (vision-calibration 0.12 laserline_device), {trials} trials per scene");
    println!(
        "RMS over the trials: normal error deg, distance error at the camera centre mm; over the \
         working range (0.40-0.60 m deep): plane offset mm, 3-D point error mm; offset at the \
         range's centre mm; corr(distance error, (n_est - n) . X_c)"
    );
    let range = working_range();
    for n_poses in [2usize, 4, 10] {
        let poses = laser_board_poses(n_poses);
        let (mut ours, mut theirs_fixed, mut ours_joint, mut theirs_full) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut failures = Vec::new();
        let (mut d_unw, mut d_joint, mut d_joint_unw, mut d_crs_w) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        // Per std bin: count, sum std^2, sum err, sum err^2.
        let edges = [0.02, 0.05, 0.1, 0.2, 0.5, f64::MAX];
        let mut bins = [[0.0f64; 4]; 6];
        for trial in 0..trials {
            let mut views = Vec::new();
            for (i, pose) in poses.iter().enumerate() {
                let seed = 7_000_003 * n_poses as u64 + 1009 * trial as u64 + 17 * i as u64;
                let mut laser = LaserStripe::new(example_plane());
                laser.seed = seed ^ 0x5EED;
                let (board, stripe) = laser_pair(&camera, &target, pose, &laser, seed)?;
                views.push(LaserView {
                    name: format!("pose {i}"),
                    board,
                    stripe: Some(stripe),
                });
            }
            let settings = LaserPlaneSettings::default();
            let report = laser_plane(&camera, &target, &views, &settings)?;
            ours.push(report_estimate(&report, TRUE_K));
            let (measured, centres) = measurements(&camera, &target, &views, &report)?;
            if diag {
                for (i, v) in centres.iter().enumerate() {
                    let truth: std::collections::HashMap<usize, f64> =
                        stripe_truth(&camera, &poses[i], &example_plane(), v.along_y)
                            .into_iter()
                            .collect();
                    for (px, sd) in &v.centres {
                        let (idx, at) = if v.along_y {
                            (px.x, px.y)
                        } else {
                            (px.y, px.x)
                        };
                        let Some(t) = truth.get(&(idx.round() as usize)) else {
                            continue;
                        };
                        let e = at - t;
                        let b = edges.iter().position(|&x| *sd < x).unwrap_or(5);
                        bins[b][0] += 1.0;
                        bins[b][1] += sd * sd;
                        bins[b][2] += e;
                        bins[b][3] += e * e;
                    }
                }
                let start = report_estimate(&report, TRUE_K);
                match robocal_unweighted(&camera, &centres) {
                    Ok(e) => d_unw.push(e),
                    Err(e) => failures.push(format!("unweighted: {e}")),
                }
                if n_poses >= 3 {
                    match robocal_poses_refined(&camera, &centres, &start, false) {
                        Ok(e) => d_joint.push(e),
                        Err(e) => failures.push(format!("poses refined: {e}")),
                    }
                    match robocal_poses_refined(&camera, &centres, &start, true) {
                        Ok(e) => d_joint_unw.push(e),
                        Err(e) => failures.push(format!("poses refined unweighted: {e}")),
                    }
                    match calibration_rs(with_weights(measured.clone(), &centres), Some(truth_k)) {
                        Ok(e) => d_crs_w.push(e),
                        Err(e) => failures.push(format!("weighted crs: {e}")),
                    }
                }
            }
            match calibration_rs(measured.clone(), Some(truth_k)) {
                Ok(e) => theirs_fixed.push(e),
                Err(e) => failures.push(format!("fixed intrinsics: {e}")),
            }
            if n_poses >= 4 {
                match laser_plane_refining_camera(&off_camera, &target, &views, &settings) {
                    Ok((r, c)) => {
                        let p = c.params();
                        ours_joint.push(report_estimate(&r, [p[0], p[1], p[2], p[3]]))
                    }
                    Err(e) => failures.push(format!("robocal joint: {e}")),
                }
                match calibration_rs(measured, None) {
                    Ok(e) => theirs_full.push(e),
                    Err(e) => failures.push(format!("full workflow: {e}")),
                }
            }
        }
        let show = |name: &str, v: &[Estimate]| {
            let m = metrics(v, &range);
            println!(
                "{n_poses:>3} poses  {name:<52} {:>8.4} deg {:>7.3} mm | range {:>7.3} mm points {:>7.3} mm centre {:>7.3} mm corr {:>6.3} ({} runs)",
                m.normal_deg,
                m.distance_mm,
                m.range_plane_mm,
                m.range_points_mm,
                m.centre_mm,
                m.correlation,
                v.len()
            );
        };
        show("robocal, true camera", &ours);
        show(
            "calibration-rs, intrinsics held at the truth",
            &theirs_fixed,
        );
        if n_poses >= 4 {
            show(
                "robocal --refine-intrinsics, start 2 % / 5 px off",
                &ours_joint,
            );
            show(
                "calibration-rs full workflow (intrinsics estimated)",
                &theirs_full,
            );
        }
        if diag {
            let mut lo = 0.0;
            for (b, hi) in bins.iter().zip(edges) {
                if b[0] > 0.0 {
                    println!(
                        "      centres with std {lo:.2}-{hi:.2} px: {:>6} ({:.0} %), RMS std {:.3} px, true error RMS {:.3} px, mean {:+.3} px",
                        b[0],
                        100.0 * b[0] / bins.iter().map(|b| b[0]).sum::<f64>(),
                        (b[1] / b[0]).sqrt(),
                        (b[3] / b[0]).sqrt(),
                        b[2] / b[0]
                    );
                }
                lo = hi;
            }
            show("diag: robocal fit, centres unweighted (std 1 px)", &d_unw);
            if n_poses >= 3 {
                show("diag: robocal, poses refined with the stripe", &d_joint);
                show(
                    "diag: robocal, poses refined, centres unweighted",
                    &d_joint_unw,
                );
                show(
                    "diag: calibration-rs held, robocal's 1/std^2 weights",
                    &d_crs_w,
                );
            }
        }
        for f in failures.iter().take(3) {
            println!("      failure: {f}");
        }
    }
    Ok(())
}
