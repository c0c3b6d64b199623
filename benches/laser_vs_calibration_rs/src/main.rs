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
//! distance's error (mm) against the truth.
//!
//! Not part of robocal's build or tests: run by hand,
//! `cd benches/laser_vs_calibration_rs && cargo run [TRIALS]` (default 20).

use nalgebra::{Point2, Vector3};
use robocal::api::laser::{
    laser_plane, laser_plane_refining_camera, LaserPlaneReport, LaserPlaneSettings, LaserView,
};
use robocal::calib::View as RobocalView;
use robocal::camera::Camera;
use robocal::detect::{detect, DetectOptions};
use robocal::laser::{extract_stripe, StripeOptions};
use robocal::synth::laser::LaserStripe;
use robocal::synth::laser_scene::{example_plane, laser_board_poses};
use robocal::synth::{render, RenderOptions};
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

/// The plane `n . X = d` (d >= 0) as normal angle (deg) and distance (mm)
/// errors against the truth.
fn errors(n: Vector3<f64>, d: f64) -> (f64, f64) {
    let truth = example_plane();
    let (n, d) = if d < 0.0 { (-n, -d) } else { (n, d) };
    let n = n.normalize();
    (
        n.dot(&truth.normal.into_inner())
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees(),
        (d - truth.distance_m) * 1e3,
    )
}

fn report_errors(r: &LaserPlaneReport) -> (f64, f64) {
    errors(
        Vector3::from(r.laser_plane.normal_camera),
        r.laser_plane.distance_m,
    )
}

/// calibration-rs's laserline device calibration of `views`; `intrinsics`:
/// seeded and held at these.
fn calibration_rs(
    views: Vec<View<LaserlineMeta>>,
    intrinsics: Option<FxFyCxCy<f64>>,
) -> Result<(f64, f64), Error> {
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
    Ok(errors(plane.normal.into_inner(), -plane.distance))
}

/// robocal's corners and on-board stripe centres as calibration-rs views.
fn measurements(
    camera: &Camera,
    target: &Target,
    views: &[LaserView],
    report: &LaserPlaneReport,
) -> Result<Vec<View<LaserlineMeta>>, Error> {
    let mut out = Vec::new();
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
        for p in &stripe.points {
            let ray = camera.unproject(&Point2::new(p.x_px, p.y_px))?;
            let on_board = pose.inverse() * nalgebra::Point3::from(ray * (e / m.dot(&ray)));
            if on_board.x >= lo[0]
                && on_board.x <= hi[0]
                && on_board.y >= lo[1]
                && on_board.y <= hi[1]
            {
                laser_pixels.push(Pt2::new(p.x_px, p.y_px));
            }
        }
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
    Ok(out)
}

fn rms(v: &[(f64, f64)]) -> (f64, f64) {
    let n = v.len().max(1) as f64;
    (
        (v.iter().map(|e| e.0 * e.0).sum::<f64>() / n).sqrt(),
        (v.iter().map(|e| e.1 * e.1).sum::<f64>() / n).sqrt(),
    )
}

fn main() -> Result<(), Error> {
    let trials: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20);
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
    println!("RMS normal error deg / distance error mm over the trials");
    for n_poses in [2usize, 4, 10] {
        let poses = laser_board_poses(n_poses);
        let (mut ours, mut theirs_fixed, mut ours_joint, mut theirs_full) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut failures = Vec::new();
        for trial in 0..trials {
            let mut views = Vec::new();
            for (i, pose) in poses.iter().enumerate() {
                let seed = 7_000_003 * n_poses as u64 + 1009 * trial as u64 + 17 * i as u64;
                let mut laser = LaserStripe::new(example_plane());
                laser.seed = seed ^ 0x5EED;
                let off = RenderOptions {
                    seed,
                    ..RenderOptions::default()
                };
                let on = RenderOptions {
                    seed: seed + 1,
                    laser: Some(laser),
                    ..RenderOptions::default()
                };
                views.push(LaserView {
                    name: format!("pose {i}"),
                    board: render(&camera, &target, pose, &off)?.image,
                    stripe: Some(render(&camera, &target, pose, &on)?.image),
                });
            }
            let settings = LaserPlaneSettings::default();
            let report = laser_plane(&camera, &target, &views, &settings)?;
            ours.push(report_errors(&report));
            let measured = measurements(&camera, &target, &views, &report)?;
            match calibration_rs(measured.clone(), Some(truth_k)) {
                Ok(e) => theirs_fixed.push(e),
                Err(e) => failures.push(format!("fixed intrinsics: {e}")),
            }
            if n_poses >= 4 {
                match laser_plane_refining_camera(&off_camera, &target, &views, &settings) {
                    Ok((r, _)) => ours_joint.push(report_errors(&r)),
                    Err(e) => failures.push(format!("robocal joint: {e}")),
                }
                match calibration_rs(measured, None) {
                    Ok(e) => theirs_full.push(e),
                    Err(e) => failures.push(format!("full workflow: {e}")),
                }
            }
        }
        let show = |name: &str, v: &[(f64, f64)]| {
            let (a, d) = rms(v);
            println!(
                "{n_poses:>3} poses  {name:<52} {a:>9.5} deg {d:>8.4} mm  ({} runs)",
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
        for f in failures.iter().take(3) {
            println!("      failure: {f}");
        }
    }
    Ok(())
}
