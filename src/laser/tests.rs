//! Seeded laser scenes: the plane fit exact without noise and within its
//! covariance with noise, its warnings and errors; the stripe extractors
//! against the renderer's truth.

use super::*;
use crate::camera::Camera;
use crate::rng::Rng;
use crate::synth::laser::{stripe_truth, LaserStripe};
use crate::synth::laser_scene::{example_plane, laser_board_poses, stripe_observations};
use crate::synth::{board_pose, render, RenderOptions};
use crate::target::Target;
use nalgebra::Vector3;

fn camera() -> Camera {
    Camera::pinhole(800.0, 800.0, 320.0, 240.0, 640, 480)
}

const EXTENT: (f64, f64) = (0.2, 0.15);

fn angle_deg(a: &LaserPlane, b: &LaserPlane) -> f64 {
    a.normal
        .dot(&b.normal.into_inner())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

#[test]
fn noise_free_fit_is_exact_with_both_residuals() {
    let truth = example_plane();
    let poses = laser_board_poses(3);
    let obs =
        stripe_observations(&camera(), &poses, &truth, EXTENT, 4, 0.0, &mut Rng::new(1)).unwrap();
    assert!(obs.len() > 100, "{} observations", obs.len());
    for residual in [PlaneResidual::ImagePx, PlaneResidual::PointToPlane] {
        let fit = fit_plane(&obs, &PlaneFitOptions { residual }).unwrap();
        assert!(
            angle_deg(&fit.estimate.plane, &truth) < 1e-5,
            "{residual:?}: {fit:?}"
        );
        assert!(
            (fit.estimate.plane.distance_m - truth.distance_m).abs() < 1e-8,
            "{fit:?}"
        );
        assert!(fit.warnings.is_empty(), "{:?}", fit.warnings);
        assert_eq!(fit.per_image.len(), 3);
    }
}

#[test]
fn noisy_fit_lies_within_its_covariance() {
    let truth = example_plane();
    let poses = laser_board_poses(4);
    let noise = 0.3;
    let obs = stripe_observations(
        &camera(),
        &poses,
        &truth,
        EXTENT,
        1,
        noise,
        &mut Rng::new(5),
    )
    .unwrap();
    let fit = fit_plane(&obs, &PlaneFitOptions::default()).unwrap();
    // The residual variance estimates the injected noise.
    assert!(
        (fit.variance_factor - 1.0).abs() < 0.1,
        "{}",
        fit.variance_factor
    );
    let e: Vector3<f64> = fit.estimate.plane.normal.into_inner() - truth.normal.into_inner();
    let covariance = fit.estimate.normal_distance_covariance();
    for k in 0..3 {
        assert!(
            e[k].abs() < 4.0 * covariance[(k, k)].sqrt(),
            "{k}: {e:?} {fit:?}"
        );
    }
    let dd = fit.estimate.plane.distance_m - truth.distance_m;
    assert!(dd.abs() < 4.0 * covariance[(3, 3)].sqrt(), "{dd}");
    assert!(angle_deg(&fit.estimate.plane, &truth) < 0.05);
    // The centres' variance from the residuals: the injected noise's.
    assert!(
        (fit.centre_floor_px - noise).abs() < 0.015,
        "{}",
        fit.centre_floor_px
    );
}

#[test]
fn the_reported_std_matches_the_error_over_seeded_trials() {
    // Independent 0.3 px noise on every 4th column's centre, exact board
    // poses, 2 poses (the stripes of ~60 centres each against the 20-line
    // Newey-West window): 100 trials. The RMS error over the RMS reported
    // std is 1 within 10 % (1.06 for both) and at least 95 of 100 errors
    // lie within 3 std (98, 98). With s27's scalar `m / (m - removed)`
    // correction the same trials gave 1.41 and 1.41, 88 and 95.
    let truth = example_plane();
    let poses = laser_board_poses(2);
    let mut rng = Rng::new(1002);
    let (mut error2, mut bound2, mut derror2, mut dbound2) = (0.0, 0.0, 0.0, 0.0);
    let (mut inside_n, mut inside_d) = (0, 0);
    let trials = 100;
    for _ in 0..trials {
        let obs = stripe_observations(&camera(), &poses, &truth, EXTENT, 4, 0.3, &mut rng).unwrap();
        let fit = fit_plane(&obs, &PlaneFitOptions::default()).unwrap();
        let c = fit.estimate.normal_distance_covariance();
        let n = fit.estimate.plane.normal.into_inner();
        let a = n.cross(&Vector3::x()).normalize();
        let b = n.cross(&a);
        let e = n - truth.normal.into_inner();
        let e2 = nalgebra::Vector2::new(e.dot(&a), e.dot(&b));
        let cnn = c.fixed_view::<3, 3>(0, 0).into_owned();
        let c2 = nalgebra::Matrix2::new(
            a.dot(&(cnn * a)),
            a.dot(&(cnn * b)),
            b.dot(&(cnn * a)),
            b.dot(&(cnn * b)),
        );
        error2 += e2.norm_squared();
        bound2 += c2.trace();
        // chi^2(2) at the 3-sigma probability 0.9973.
        if (e2.transpose() * c2.try_inverse().unwrap() * e2)[0] <= 11.829 {
            inside_n += 1;
        }
        let ed = fit.estimate.plane.distance_m - truth.distance_m;
        derror2 += ed * ed;
        dbound2 += c[(3, 3)];
        if ed.abs() <= 3.0 * c[(3, 3)].sqrt() {
            inside_d += 1;
        }
    }
    let normal = (error2 / bound2).sqrt();
    let distance = (derror2 / dbound2).sqrt();
    assert!((normal - 1.0).abs() < 0.1, "normal RMS / bound {normal}");
    assert!(
        (distance - 1.0).abs() < 0.1,
        "distance RMS / bound {distance}"
    );
    assert!(
        inside_n >= 95 && inside_d >= 95,
        "{inside_n}, {inside_d} of {trials}"
    );
}

/// Exact stripe centres of `poses` moved along their scan by seeded
/// Gaussian errors: on every 20th centre (a fallback) the extractor
/// reports 0.5 px and the centre errs 1.2 px; on the rest it reports
/// 0.03 and 0.13 px by turns (a bright and a dim stretch, BENCHMARKS.md
/// section 18) while every one errs 0.2 px. Also the mean squared error
/// drawn on the fallbacks and on the rest, px^2.
fn centres_with_misleading_stds(seed: u64) -> (Vec<StripeObservation>, f64, f64) {
    let truth = example_plane();
    let poses = laser_board_poses(4);
    let mut rng = Rng::new(seed);
    let mut obs = stripe_observations(&camera(), &poses, &truth, EXTENT, 1, 0.0, &mut rng).unwrap();
    let (mut poor, mut rest) = ((0.0, 0usize), (0.0, 0usize));
    for (k, o) in obs.iter_mut().enumerate() {
        let (std, error) = match k % 20 {
            0 => (0.5, 1.2),
            k if k % 2 == 0 => (0.03, 0.2),
            _ => (0.13, 0.2),
        };
        o.std_px = std;
        // Along the scan by `e` px (first order: the fit's own model).
        let e = rng.gaussian(error);
        o.point_camera += o.along_scan_m_per_px * e;
        let class = if std == 0.5 { &mut poor } else { &mut rest };
        class.0 += e * e;
        class.1 += 1;
    }
    (obs, poor.0 / poor.1 as f64, rest.0 / rest.1 as f64)
}

#[test]
fn centres_are_weighted_by_the_std_order_and_the_residuals_scale() {
    let truth = example_plane();
    let (mut e_rule, mut e_alike, mut d_rule, mut d_alike) = (0.0, 0.0, 0.0, 0.0);
    let trials = 20;
    for seed in 0..trials {
        let (obs, poor, rest) = centres_with_misleading_stds(100 + seed);
        let fit = fit_plane(&obs, &PlaneFitOptions::default()).unwrap();
        if seed == 0 {
            // The two stretches are pooled at their common error (0.2 px:
            // 0.04 px^2), the fallbacks get theirs (1.2 px: 1.44 px^2),
            // each within 10 % of the mean square actually drawn.
            let v = &fit.centre_variance;
            assert!(obs.len() > 1200, "{}", obs.len());
            assert!((rest - 0.04).abs() < 0.004 && (poor - 1.44).abs() < 0.5);
            for std in [0.03, 0.13] {
                assert!((v.variance(std) / rest - 1.0).abs() < 0.1, "{std}: {v:?}");
            }
            assert!((v.variance(0.5) / poor - 1.0).abs() < 0.1, "{poor} {v:?}");
            assert!((fit.centre_floor_px - rest.sqrt()).abs() < 0.01, "{fit:?}");
        }
        // Every centre alike: the stds all equal.
        let alike: Vec<StripeObservation> = obs
            .iter()
            .map(|o| StripeObservation { std_px: 1.0, ..*o })
            .collect();
        let flat = fit_plane(&alike, &PlaneFitOptions::default()).unwrap();
        e_rule += angle_deg(&fit.estimate.plane, &truth).powi(2);
        e_alike += angle_deg(&flat.estimate.plane, &truth).powi(2);
        d_rule += (fit.estimate.plane.distance_m - truth.distance_m).powi(2);
        d_alike += (flat.estimate.plane.distance_m - truth.distance_m).powi(2);
    }
    let n = trials as f64;
    let (e_rule, e_alike) = ((e_rule / n).sqrt(), (e_alike / n).sqrt());
    let (d_rule, d_alike) = ((d_rule / n).sqrt() * 1e3, (d_alike / n).sqrt() * 1e3);
    // The fallbacks' weight 36 times lower: the plane errs as if only the
    // 0.2 px centres were there, about 0.6 times the error with every
    // centre alike (0.95 x 0.04 + 0.05 x 1.44 = 0.11 px^2 against 0.04).
    assert!(e_rule < 0.75 * e_alike, "{e_rule} deg against {e_alike}");
    assert!(d_rule < 0.75 * d_alike, "{d_rule} mm against {d_alike}");
    assert!(e_rule < 0.01, "{e_rule} deg");
    // The point-to-plane model has no stds to weigh by.
    let (obs, _, _) = centres_with_misleading_stds(100);
    let point = fit_plane(
        &obs,
        &PlaneFitOptions {
            residual: PlaneResidual::PointToPlane,
        },
    )
    .unwrap();
    assert_eq!(point.centre_floor_px, 0.0);
}

#[test]
fn parallel_stripes_warn_and_one_line_is_an_error() {
    let truth = example_plane();
    let cam = camera();
    // The same board orientation at two depths: parallel stripe lines.
    let r = nalgebra::UnitQuaternion::from_euler_angles(0.3, 0.0, 0.0);
    let at =
        |z: f64| crate::geometry::Pose::from_parts(nalgebra::Translation3::new(-0.1, -0.07, z), r);
    let poses = [at(0.45), at(0.55)];
    let obs = stripe_observations(&cam, &poses, &truth, EXTENT, 4, 0.0, &mut Rng::new(2)).unwrap();
    let fit = fit_plane(&obs, &PlaneFitOptions::default()).unwrap();
    assert!(
        fit.warnings
            .iter()
            .any(|w| w.starts_with("all 2 stripe lines are parallel")),
        "{:?}",
        fit.warnings
    );
    // Two poses: the std may be too small, and the user is told how to fix it.
    assert!(
        fit.warnings.iter().any(|w| w.starts_with(
            "only 2 board poses: with two stripe lines each line is fitted by itself alone"
        ) && w.ends_with(
            "add board poses (4 or more, tilted about different axes) for a std that holds"
        )),
        "{:?}",
        fit.warnings
    );
    // Two images of one line (the same pose twice): no plane.
    let same = [at(0.5), at(0.5)];
    let obs = stripe_observations(&cam, &same, &truth, EXTENT, 4, 0.0, &mut Rng::new(2)).unwrap();
    let err = fit_plane(&obs, &PlaneFitOptions::default()).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("the stripe points of all 2 images lie on one line"),
        "{err}"
    );
}

#[test]
fn bad_input_errors_say_what_came() {
    let truth = example_plane();
    let poses = laser_board_poses(2);
    let obs =
        stripe_observations(&camera(), &poses, &truth, EXTENT, 4, 0.0, &mut Rng::new(1)).unwrap();
    let one: Vec<_> = obs.iter().filter(|o| o.image == 0).cloned().collect();
    let err = fit_plane(&one, &PlaneFitOptions::default()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "requires at least 2 images with a stripe on the board, got 1"
    );
    assert_eq!(
        plane_in_camera(Vector3::zeros(), 0.1)
            .unwrap_err()
            .to_string(),
        "laser_plane: needs a non-zero finite normal and a finite distance, got (0, 0, 0) and 0.1"
    );
    assert_eq!(
        PlaneResidual::from_name("ray").unwrap_err().to_string(),
        "residual: unknown residual 'ray' (expected image_px or point_to_plane)"
    );
    assert_eq!(
        StripeMethod::from_name("peak").unwrap_err().to_string(),
        "extractor: unknown extractor 'peak' (expected cog or ridge)"
    );
    let tiny = crate::image::GrayImage::new(4, 4, vec![0; 16]).unwrap();
    assert_eq!(
        extract_stripe(&tiny, None, &StripeOptions::default())
            .unwrap_err()
            .to_string(),
        "stripe image: needs at least 8x8 pixels, got 4x4"
    );
}

/// Mean and max |centre - truth| of a stripe, pixels, over the columns
/// where both exist.
fn centre_errors(stripe: &Stripe, truth: &[(usize, f64)]) -> (f64, f64, usize) {
    let (mut sum, mut max, mut n) = (0.0, 0.0f64, 0);
    for p in &stripe.points {
        let (idx, v) = match stripe.axis {
            ScanAxis::Columns => (p.x_px as usize, p.y_px),
            ScanAxis::Rows => (p.y_px as usize, p.x_px),
        };
        if let Some((_, t)) = truth.iter().find(|(i, _)| *i == idx) {
            let e = (v - t).abs();
            sum += e;
            max = max.max(e);
            n += 1;
        }
    }
    (sum / n.max(1) as f64, max, n)
}

fn stripe_render(
    width_px: f64,
    ambient: f64,
    noise: f64,
) -> (
    crate::image::GrayImage,
    crate::image::GrayImage,
    Vec<(usize, f64)>,
) {
    let cam = camera();
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    let pose = board_pose(&target, (0.2, -0.15, 0.1), (0.0, 0.0, 0.5));
    let mut laser = LaserStripe::new(example_plane());
    laser.width_px = width_px;
    laser.ambient = ambient;
    let off_options = RenderOptions {
        noise_sigma: noise,
        seed: 3,
        ..RenderOptions::default()
    };
    let on_options = RenderOptions {
        laser: Some(laser),
        seed: 4,
        ..off_options.clone()
    };
    let off = render(&cam, &target, &pose, &off_options).unwrap().image;
    let on = render(&cam, &target, &pose, &on_options).unwrap().image;
    let truth = stripe_truth(&cam, &pose, &example_plane(), true);
    (on, off, truth)
}

#[test]
fn both_extractors_find_the_rendered_centre() {
    let (on, off, truth) = stripe_render(5.0, 1.0, 2.0);
    // Tolerances (px) with and without the laser-off image: the ridge
    // detector's 2-D kernel spans the squares' edges under the stripe.
    for (method, tol_off, tol_alone) in [
        (StripeMethod::CentreOfGravity, 0.1, 0.15),
        (StripeMethod::Ridge, 0.25, 0.3),
    ] {
        let options = StripeOptions {
            method,
            ..StripeOptions::default()
        };
        let with_off = extract_stripe(&on, Some(&off), &options).unwrap();
        assert_eq!(with_off.axis, ScanAxis::Columns);
        let (mean, _, n) = centre_errors(&with_off, &truth);
        assert!(n > 550, "{method:?}: {n} centres");
        assert!(
            mean < tol_off,
            "{method:?} with the laser-off image: mean error {mean} px"
        );
        // Dark image (a filtered camera), no laser-off image.
        let (dark, _, truth) = stripe_render(5.0, 0.15, 2.0);
        let alone = extract_stripe(&dark, None, &options).unwrap();
        let (mean, _, n) = centre_errors(&alone, &truth);
        let mut worst: Vec<(f64, f64, f64)> = alone
            .points
            .iter()
            .filter_map(|p| {
                let t = truth.iter().find(|(i, _)| *i == p.x_px as usize)?;
                Some((p.x_px, p.y_px, t.1))
            })
            .collect();
        worst.sort_by(|a, b| (b.1 - b.2).abs().total_cmp(&(a.1 - a.2).abs()));
        worst.truncate(8);
        assert!(
            n > 550 && mean < tol_alone,
            "{method:?} dark: {:?} {n} centres, mean error {mean} px, worst {worst:?}",
            alone.axis
        );
    }
}

#[test]
fn the_laser_plane_keeps_its_json_keys_and_its_4x4_covariance() {
    // The plane serialises as {"normal_camera", "distance_m"} wherever a
    // report or the renderer's truth carries it.
    let stripe = LaserStripe::new(example_plane());
    let json = serde_json::to_value(&stripe).unwrap();
    let n = example_plane().normal;
    assert_eq!(
        json["plane"],
        serde_json::json!({"normal_camera": [n.x, n.y, n.z], "distance_m": example_plane().distance_m})
    );
    // The 4x4 over (nx, ny, nz, d) is rank 3 with the normal in its null
    // space, and the fit's covariance is symmetric positive definite.
    let obs = stripe_observations(
        &camera(),
        &laser_board_poses(3),
        &example_plane(),
        EXTENT,
        4,
        0.3,
        &mut Rng::new(9),
    )
    .unwrap();
    let fit = fit_plane(&obs, &PlaneFitOptions::default()).unwrap();
    let c4 = fit.estimate.normal_distance_covariance();
    let m = fit.estimate.plane.normal;
    let along = nalgebra::Vector4::new(m.x, m.y, m.z, 0.0);
    assert!((c4 * along).norm() < 1e-12 * c4.norm(), "{c4}");
    let eig = nalgebra::SymmetricEigen::new(fit.estimate.covariance);
    assert!(eig.eigenvalues.iter().all(|v| *v > 0.0), "{eig:?}");
}

#[test]
fn the_centre_of_gravity_is_unbiased_along_an_albedo_edge() {
    // A fronto-parallel board 0.5 m away (1 mm = 1.6 px) under a stripe
    // parallel to its rows, a black/white row edge `offset` px from the
    // stripe. The plain centre of gravity erred by up to 1.6 px here (0.4
    // px without saturation); the step model fitted across the edge stays
    // within 0.1 px, on both prints, with the white side clipped or not
    // (unclipped, the stripe on black is near the 20 grey contrast: gaps).
    let cam = camera();
    let target = Target::Chessboard {
        cols: 9,
        rows: 6,
        square_m: 0.025,
    };
    for saturate in [true, false] {
        for light in [false, true] {
            for offset in [-3.0, -2.0, -1.0, 1.0, 2.0, 3.0] {
                let pose = board_pose(
                    &target,
                    (0.0, 0.0, 0.0),
                    (0.0, -0.0125 + offset / 1600.0, 0.5),
                );
                let mut laser = LaserStripe::new(example_plane());
                let mut base = RenderOptions {
                    seed: 3,
                    ..RenderOptions::default()
                };
                if !saturate {
                    (base.black, base.white, laser.peak) = (20.0, 100.0, 120.0);
                }
                if light {
                    base = base.light_on_dark();
                }
                let on_options = RenderOptions {
                    laser: Some(laser),
                    seed: 4,
                    ..base.clone()
                };
                let off = render(&cam, &target, &pose, &base).unwrap().image;
                let on = render(&cam, &target, &pose, &on_options).unwrap().image;
                let truth = stripe_truth(&cam, &pose, &example_plane(), true);
                let options = StripeOptions {
                    axis: Some(ScanAxis::Columns),
                    ..StripeOptions::default()
                };
                let s = extract_stripe(&on, Some(&off), &options).unwrap();
                let errors: Vec<f64> = s
                    .points
                    .iter()
                    .filter(|p| (160.0..480.0).contains(&p.x_px))
                    .filter_map(|p| {
                        let t = truth.iter().find(|(i, _)| *i == p.x_px as usize)?;
                        Some(p.y_px - t.1)
                    })
                    .collect();
                let mean = errors.iter().sum::<f64>() / errors.len() as f64;
                assert!(
                    errors.len() > 150 && mean.abs() < 0.1,
                    "saturate {saturate}, light {light}, offset {offset}: {} centres, mean error {mean} px",
                    errors.len()
                );
            }
        }
    }
}
