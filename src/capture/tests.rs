//! Live-capture decisions on synthetic detections (exact projections of the
//! board-moving video's poses, with Gaussian pixel noise where stated) and
//! on rendered frames.

use super::*;
use crate::geometry::rotation_from_rotvec;
use crate::rng::Rng;
use crate::synth::{render, BoardVideo, RenderOptions, VideoOptions};
use crate::target::{DetectedPoint, Detection, Target};
use nalgebra::{Translation3, Vector3};
use wasm_bindgen_test::wasm_bindgen_test;

fn board() -> Target {
    Target::parse_spec("chessboard:9x6:30mm").unwrap()
}

fn video() -> BoardVideo {
    let camera = crate::synth::video_camera(640, 480);
    BoardVideo::new(&camera, &board(), &VideoOptions::default()).unwrap()
}

/// The exact points of the board at `pose` through the video's camera,
/// with N(0, noise_px^2) per coordinate.
fn detection(
    v: &BoardVideo,
    pose: &crate::geometry::Pose,
    noise_px: f64,
    rng: &mut Rng,
) -> Detection {
    let points = v
        .target
        .object_points()
        .into_iter()
        .map(|(id, p)| {
            let q = v.camera.project(&(pose * p)).unwrap();
            DetectedPoint {
                id,
                x_px: q.x + rng.gaussian(noise_px),
                y_px: q.y + rng.gaussian(noise_px),
                covariance_px2: None,
            }
        })
        .collect();
    Detection {
        image_size_px: [640, 480],
        target: v.target.clone(),
        points,
        centre_model: None,
        polarity: None,
    }
}

fn session() -> CaptureSession {
    CaptureSession::new(board(), 640, 480, CaptureConfig::default()).unwrap()
}

/// Feed every hold of the video as 6 frames at 15 fps (400 ms still),
/// with a moving frame between holds; returns the hold of each capture.
fn feed_holds(s: &mut CaptureSession, v: &BoardVideo, noise_px: f64) -> Vec<usize> {
    let mut rng = Rng::new(9);
    let mut t = 0.0;
    let mut captured = vec![];
    for (k, hold) in v.holds.iter().enumerate() {
        for _ in 0..6 {
            t += 66.7;
            let d = detection(v, &hold.camera_from_target, noise_px, &mut rng);
            let r = s.push_detection(Some(d), Some(1.0), t).unwrap();
            if r.keep {
                captured.push(k);
            }
        }
        t += 66.7;
        s.push_detection(None, None, t).unwrap();
    }
    captured
}

#[wasm_bindgen_test(unsupported = test)]
fn a_board_is_still_only_after_250_ms_under_1_5_px_and_moving_beyond() {
    let v = video();
    let mut s = session();
    let mut rng = Rng::new(1);
    let pose = v.holds[0].camera_from_target;
    let reasons: Vec<Reason> = (0..5)
        .map(|i| {
            let d = detection(&v, &pose, 0.05, &mut rng);
            s.push_detection(Some(d), Some(1.0), i as f64 * 66.7)
                .unwrap()
                .reason
        })
        .collect();
    // 0, 67, 133, 200 ms: fewer than 250 ms of history; 267 ms: kept.
    assert_eq!(reasons[..4], [Reason::Settling; 4]);
    assert_eq!(reasons[4], Reason::Kept);
    // A 3 px shift (twice the threshold) is motion.
    let moved = crate::geometry::Pose::from_parts(
        Translation3::from(pose.translation.vector + Vector3::new(0.003, 0.0, 0.0)),
        pose.rotation,
    );
    let r = s
        .push_detection(Some(detection(&v, &moved, 0.0, &mut rng)), Some(1.0), 400.0)
        .unwrap();
    assert_eq!(r.reason, Reason::Moving);
    assert!(r.motion_px.unwrap() > 1.5, "{:?} px", r.motion_px);
    // Not found clears the history: settling again.
    assert_eq!(
        s.push_detection(None, None, 500.0).unwrap().status,
        Status::NotFound
    );
    let r = s.push_detection(Some(detection(&v, &pose, 0.0, &mut rng)), Some(1.0), 566.0);
    assert_eq!(r.unwrap().reason, Reason::Settling);
    // Times must increase.
    let err = s.push_detection(None, None, 566.0).unwrap_err().to_string();
    assert!(
        err.contains("expected a time in ms after the previous frame's 566, got 566"),
        "{err}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn the_blur_measure_tells_a_focused_render_from_a_blurred_one() {
    let v = video();
    let pose = v.holds[1].camera_from_target;
    let measure_at = |sigma: f64| {
        let o = RenderOptions {
            blur_sigma_px: sigma,
            ..RenderOptions::default()
        };
        let r = render(&v.camera, &v.target, &pose, &o).unwrap();
        measure::blur_px(&r.image, &r.points).unwrap()
    };
    let (sharp, blurred) = (measure_at(0.7), measure_at(2.5));
    // Derivation in measure::blur_px's docs: ~1.0 px and ~2.6 px.
    assert!((0.8..1.3).contains(&sharp), "focused render: {sharp} px");
    assert!(
        (2.2..3.0).contains(&blurred),
        "sigma 2.5 render: {blurred} px"
    );
    let threshold = CaptureConfig::default().sharp_max_blur_px;
    assert!(sharp < threshold && blurred > threshold);
    // The session keeps the sharp view and says why not for the blurred one.
    let mut s = session();
    let mut rng = Rng::new(2);
    let mut last = None;
    for i in 0..6 {
        let d = detection(&v, &pose, 0.0, &mut rng);
        last = Some(
            s.push_detection(Some(d), Some(blurred), i as f64 * 66.7)
                .unwrap(),
        );
    }
    assert_eq!(last.unwrap().reason, Reason::Blurred);
}

#[wasm_bindgen_test(unsupported = test)]
fn coverage_grows_once_per_novel_hold_and_the_suggestion_follows() {
    let v = video();
    let mut s = session();
    let first = s.suggestion().unwrap().outline_px;
    let captured = feed_holds(&mut s, &v, 0.05);
    // One capture per hold at most, the first hold always, and most holds
    // add information by design (synth::video's keyframes).
    let mut unique = captured.clone();
    unique.dedup();
    assert_eq!(unique, captured, "a hold captured twice: {captured:?}");
    assert_eq!(captured.first(), Some(&0));
    assert!(captured.len() >= 8, "captured holds {captured:?}");
    let c = s.coverage();
    assert_eq!(c.kept, captured.len());
    assert!(
        c.tilt.iter().flatten().filter(|n| **n > 0).count() >= 7,
        "{:?}",
        c.tilt
    );
    assert!(c.distance.iter().all(|n| *n > 0), "{:?}", c.distance);
    assert!(
        c.cells.iter().filter(|n| **n > 0).count() >= 40,
        "{:?}",
        c.cells
    );
    assert_ne!(
        s.suggestion().unwrap().outline_px,
        first,
        "the suggestion moved"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn the_suggestion_changes_after_each_new_tilt() {
    let v = video();
    let mut s = session();
    let mut rng = Rng::new(3);
    let mut seen = vec![s.suggestion().unwrap().outline_px];
    for (k, hold) in v.holds.iter().take(3).enumerate() {
        for i in 0..6 {
            let d = detection(&v, &hold.camera_from_target, 0.05, &mut rng);
            s.push_detection(Some(d), Some(1.0), (k * 10 + i) as f64 * 66.7)
                .unwrap();
        }
        s.push_detection(None, None, (k * 10 + 8) as f64 * 66.7)
            .unwrap();
        let now = s.suggestion().unwrap();
        assert_eq!(now.rule, Rule::Coverage);
        assert!(
            !seen.contains(&now.outline_px),
            "hold {k}: the same suggestion again"
        );
        seen.push(now.outline_px);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_well_covered_set_is_good_enough_and_a_frontal_one_is_not() {
    // Detection noise 0.05 px: a calibration from the video's holds
    // predicts well under 0.2 px everywhere.
    let v = video();
    let mut good = session();
    feed_holds(&mut good, &v, 0.05);
    let mut rng = Rng::new(5);
    // Follow the guide: capture the suggested pose (its exact points with
    // the same noise) and recalibrate, until it says good enough.
    let mut followed = 0;
    good.calibrate().unwrap();
    while !good.good_enough() && followed < 30 {
        let next = good.suggestion().unwrap().clone();
        let pose = next.camera_from_target.to_pose().unwrap();
        let d = detection(&v, &pose, 0.05, &mut rng);
        good.push_detection(Some(d), Some(1.0), 100_000.0 + followed as f64 * 1000.0)
            .unwrap();
        good.keep_last().unwrap();
        let after = good.calibrate().unwrap().projection_uncertainty.max_std_px;
        // The prediction holds up to the change of the residual variance
        // estimate: within a factor 2.
        if let Some(p) = next.predicted_max_std_px {
            assert!(
                after < 2.0 * p,
                "{after} px after the view predicted at {p} px"
            );
        }
        followed += 1;
    }
    let cal = good.calibration().unwrap();
    let worst = cal.projection_uncertainty.max_std_px;
    assert!(
        (cal.camera.fx - v.camera.fx).abs() < 5.0 * cal.std["fx"],
        "fx {}",
        cal.camera.fx
    );
    assert!(
        worst < suggest::GOOD_MAX_STD_PX,
        "worst {worst} px after {followed} guided views"
    );
    assert!(good.good_enough());
    assert!(
        good.suggestion().is_none(),
        "no suggestion once good enough"
    );
    // Good enough: a still, sharp view the guide has not seen (the last one
    // turned 0.3 rad in its plane) is no longer kept.
    let kept = good.kept().len();
    let last = good.kept()[kept - 1].detection.clone();
    let pose = crate::capture::coverage::pose_of(&last, &v.camera).unwrap();
    let turned = crate::geometry::Pose::from_parts(
        pose.translation,
        pose.rotation * rotation_from_rotvec(&Vector3::new(0.0, 0.0, 0.3)),
    );
    let d = detection(&v, &turned, 0.05, &mut rng);
    let r = hold_at(&mut good, &d, 300_000.0);
    assert_eq!(r.last().unwrap().reason, Reason::GoodEnough);
    assert!(r.iter().all(|r| !r.keep));
    assert_eq!(good.kept().len(), kept);
    // Eight frontal views in the middle: the focal length is poorly fixed.
    let mut poor = session();
    let mut rng = Rng::new(4);
    let base = v.holds[0].camera_from_target;
    for i in 0..8 {
        let wobble = rotation_from_rotvec(&Vector3::new(0.0, 0.0, 0.05 * i as f64));
        let pose = crate::geometry::Pose::from_parts(
            Translation3::from(base.translation.vector + Vector3::new(0.004 * i as f64, 0.0, 0.0)),
            base.rotation * wobble,
        );
        let d = detection(&v, &pose, 0.05, &mut rng);
        poor.push_detection(Some(d), Some(1.0), i as f64 * 1000.0)
            .unwrap();
        poor.keep_last().unwrap();
    }
    assert_eq!(poor.kept().len(), 8);
    let now = poor.calibrate().unwrap().projection_uncertainty.max_std_px;
    assert!(now > suggest::GOOD_MAX_STD_PX, "frontal set: {now} px");
    assert!(!poor.good_enough());
    let next = poor.suggestion().unwrap();
    assert_eq!(next.rule, Rule::Uncertainty);
    let predicted = next.predicted_max_std_px.unwrap();
    assert!(predicted < now, "predicted {predicted} px from {now} px");
    assert!(
        next.tilt_x_deg.abs().max(next.tilt_y_deg.abs()) > 15.0,
        "a tilted view is what a frontal set lacks: {next:?}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn robot_rotations_about_one_axis_are_not_diverse_and_about_three_are() {
    let about = |axis: Vector3<f64>, n: usize| -> Vec<crate::geometry::Pose> {
        (0..n)
            .map(|i| {
                crate::geometry::Pose::from_parts(
                    Translation3::new(0.1 * i as f64, 0.0, 0.5),
                    rotation_from_rotvec(&(axis * (0.3 * i as f64))),
                )
            })
            .collect()
    };
    let one = handeye_guide(&about(Vector3::z(), 4));
    assert!(!one.enough);
    assert!(one.axis_spread_deg < 1e-6, "{}", one.axis_spread_deg);
    assert!(
        one.advice
            .starts_with("rotate the tool about an axis away from"),
        "{}",
        one.advice
    );
    let mut mixed = about(Vector3::z(), 2);
    mixed.extend(about(Vector3::x(), 3).into_iter().skip(1));
    mixed.extend(about(Vector3::y(), 3).into_iter().skip(1));
    let many = handeye_guide(&mixed);
    assert!(many.enough, "{many:?}");
    assert!(many.axis_spread_deg >= 30.0);
}

/// The board held still at `detection` (the same points) for six frames
/// from `t0` (66.7 ms apart, 400 ms), then a frame without it; returns the
/// reports of the six.
fn hold_at(s: &mut CaptureSession, detection: &Detection, t0: f64) -> Vec<FrameReport> {
    let reports = (1..=6)
        .map(|i| {
            s.push_detection(Some(detection.clone()), Some(1.0), t0 + i as f64 * 66.7)
                .unwrap()
        })
        .collect();
    s.push_detection(None, None, t0 + 7.0 * 66.7).unwrap();
    reports
}

#[wasm_bindgen_test(unsupported = test)]
fn a_view_that_lowers_the_uncertainty_is_kept_after_the_bins_are_full_and_a_repeat_is_not() {
    // Detection noise 0.5 px (one draw per hold: the board is still): the
    // video's holds fill the coverage bins but leave the worst projection
    // uncertainty above 0.2 px, so only the uncertainty rule keeps more.
    let v = video();
    let mut s = session();
    let mut rng = Rng::new(21);
    for (k, hold) in v.holds.iter().enumerate() {
        let d = detection(&v, &hold.camera_from_target, 0.5, &mut rng);
        hold_at(&mut s, &d, k as f64 * 1000.0);
    }
    let kept = s.kept().len();
    let now = s.calibrate().unwrap().projection_uncertainty.max_std_px;
    assert!(now > suggest::GOOD_MAX_STD_PX, "{now} px after the holds");
    // A kept view again (a video replayed): not a new measurement.
    let again = s.kept()[0].detection.clone();
    let r = hold_at(&mut s, &again, 1e5);
    let last = r.last().unwrap();
    assert_eq!(last.reason, Reason::NothingNew);
    assert_eq!(last.novelty.as_ref().unwrap().predicted_max_std_px, None);
    // The suggested pose: kept, by the predicted uncertainty, once.
    let next = s.suggestion().unwrap().clone();
    assert_eq!(next.rule, Rule::Uncertainty);
    let d = detection(
        &v,
        &next.camera_from_target.to_pose().unwrap(),
        0.5,
        &mut rng,
    );
    let r = hold_at(&mut s, &d, 2e5);
    let keeps: Vec<&FrameReport> = r.iter().filter(|r| r.keep).collect();
    assert_eq!(keeps.len(), 1, "one capture per hold");
    let n = keeps[0].novelty.as_ref().unwrap();
    let predicted = n.predicted_max_std_px.unwrap();
    assert!(
        n.lowers_uncertainty && predicted <= (1.0 - suggest::LOWERS_UNCERTAINTY_BY) * now,
        "predicted {predicted} px from {now} px"
    );
    assert_eq!(s.kept().len(), kept + 1);
}

#[wasm_bindgen_test(unsupported = test)]
fn an_excluded_capture_leaves_the_guide_and_comes_back_when_included() {
    let v = video();
    let mut s = session();
    let captured = feed_holds(&mut s, &v, 0.05);
    let n = captured.len();
    let all = s.coverage().clone();
    let views = s.calibrate().unwrap().views.len();
    assert_eq!(views, n);
    s.set_robot_pose(1, crate::geometry::Pose::identity())
        .unwrap();
    s.set_robot_pose(2, crate::geometry::Pose::identity())
        .unwrap();
    assert_eq!(s.handeye_guide().poses, 2);
    // Excluded: out of the coverage, the calibration and the hand-eye guide; the indices stay.
    s.set_included(1, false).unwrap();
    assert_eq!((s.kept().len(), s.used()), (n, n - 1));
    let c = s.coverage();
    assert_eq!(c.kept, n - 1);
    let removed: usize = s.kept()[1].cells.iter().sum();
    assert_eq!(
        c.cells.iter().sum::<usize>(),
        all.cells.iter().sum::<usize>() - removed
    );
    assert_eq!(s.handeye_guide().poses, 1);
    let names: Vec<String> = s
        .calibrate()
        .unwrap()
        .views
        .iter()
        .map(|r| r.name.clone())
        .collect();
    assert_eq!(names.len(), n - 1);
    assert!(!names.contains(&"capture_001".to_string()), "{names:?}");
    // Included again: as before.
    s.set_included(1, true).unwrap();
    assert_eq!(s.used(), n);
    assert_eq!(s.handeye_guide().poses, 2);
    s.calibrate().unwrap();
    let back = s.coverage();
    assert_eq!((back.kept, &back.cells), (all.kept, &all.cells));
    assert_eq!(back.tilt.iter().flatten().sum::<usize>(), n);
    let e = s.set_included(n, false).unwrap_err().to_string();
    assert_eq!(
        e,
        format!("capture: expected a capture index below {n}, got {n}")
    );
    // Too few included to calibrate: the message counts the excluded.
    for i in 0..n - 3 {
        s.set_included(i, false).unwrap();
    }
    let e = s.calibrate().unwrap_err().to_string();
    assert!(
        e.ends_with(&format!(
            "the running calibration needs at least 4 captures, got 3 ({} excluded): keep capturing",
            n - 3
        )),
        "{e}"
    );
}
