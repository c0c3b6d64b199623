//! Camera model tests over every example parameter set: round trips,
//! analytic Jacobians against central differences, domain errors.

use super::*;
use crate::rng::Rng;
use wasm_bindgen_test::wasm_bindgen_test;

/// Pixels spread over the image: every 16th border pixel, the four
/// corners and seeded random interior pixels.
fn sample_pixels(camera: &Camera, rng: &mut Rng, n_random: usize) -> Vec<Point2<f64>> {
    let (w, h) = (camera.width as f64 - 1.0, camera.height as f64 - 1.0);
    let mut pixels = vec![
        Point2::new(0.0, 0.0),
        Point2::new(w, 0.0),
        Point2::new(0.0, h),
        Point2::new(w, h),
    ];
    for x in (0..camera.width).step_by(16) {
        pixels.push(Point2::new(x as f64, 0.0));
        pixels.push(Point2::new(x as f64, h));
    }
    for y in (0..camera.height).step_by(16) {
        pixels.push(Point2::new(0.0, y as f64));
        pixels.push(Point2::new(w, y as f64));
    }
    for _ in 0..n_random {
        pixels.push(Point2::new(rng.range(0.0, w), rng.range(0.0, h)));
    }
    pixels
}

#[wasm_bindgen_test(unsupported = test)]
fn every_pixel_unprojects_and_projects_back() {
    let mut rng = Rng::new(1);
    for camera in Camera::examples() {
        let name = camera.distortion.model_name();
        for pixel in sample_pixels(&camera, &mut rng, 2000) {
            let ray = camera
                .unproject(&pixel)
                .unwrap_or_else(|e| panic!("{name} {pixel}: {e}"));
            assert!((ray.norm() - 1.0).abs() < 1e-14, "{name}: bearing not unit");
            let depth = rng.range(0.1, 20.0);
            let back = camera
                .project(&Point3::from(ray * depth))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            // Exact inverse: the tolerance is the Newton tolerance, ~1e-10 px.
            assert!(
                (back - pixel).norm() < 1e-8,
                "{name}: {pixel} -> {back}, error px"
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn rays_project_and_unproject_to_the_same_bearing() {
    let mut rng = Rng::new(2);
    for camera in Camera::examples() {
        let name = camera.distortion.model_name();
        let mut checked = 0;
        while checked < 500 {
            let p = Point3::new(
                rng.range(-3.0, 3.0),
                rng.range(-2.0, 2.0),
                rng.range(0.3, 4.0),
            );
            let Ok(pixel) = camera.project(&p) else {
                continue;
            };
            let inside = pixel.x >= 0.0
                && pixel.y >= 0.0
                && pixel.x <= camera.width as f64 - 1.0
                && pixel.y <= camera.height as f64 - 1.0;
            if !inside {
                continue;
            }
            let ray = camera
                .unproject(&pixel)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let angle = ray.cross(&p.coords.normalize()).norm();
            assert!(angle < 1e-11, "{name}: bearing off by {angle} rad");
            checked += 1;
        }
    }
}

/// A point that the camera sees inside its image, at a random depth.
fn visible_point(camera: &Camera, rng: &mut Rng) -> Point3<f64> {
    let pixel = Point2::new(
        rng.range(0.0, camera.width as f64 - 1.0),
        rng.range(0.0, camera.height as f64 - 1.0),
    );
    let ray = camera.unproject(&pixel).unwrap_or_else(|e| panic!("{e}"));
    Point3::from(ray * rng.range(0.5, 5.0))
}

#[wasm_bindgen_test(unsupported = test)]
fn analytic_jacobians_match_central_differences() {
    let mut rng = Rng::new(3);
    for camera in Camera::examples() {
        let name = camera.distortion.model_name();
        let params = camera.params();
        let names = camera.param_names();
        for _ in 0..40 {
            let p = visible_point(&camera, &mut rng);
            let (pixel, d_point, d_params) = camera
                .project_with_jacobians(&p)
                .unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(pixel, camera.project(&p).unwrap_or_else(|e| panic!("{e}")));
            assert_eq!(d_params.ncols(), params.len());
            for axis in 0..3 {
                let h = 1e-6 * p.coords.norm();
                let (mut plus, mut minus) = (p, p);
                plus[axis] += h;
                minus[axis] -= h;
                let fd = (camera.project(&plus).unwrap_or_else(|e| panic!("{e}"))
                    - camera.project(&minus).unwrap_or_else(|e| panic!("{e}")))
                    / (2.0 * h);
                let err = (fd - d_point.column(axis)).norm();
                // Central differences are accurate to ~h^2 * f''' + eps/h.
                assert!(
                    err < 1e-5 * (1.0 + fd.norm()),
                    "{name} d/dp{axis}: {err} px/m"
                );
            }
            for (i, param) in names.iter().enumerate() {
                let h = 1e-7 * (1.0 + params[i].abs());
                let (mut plus, mut minus) = (params.clone(), params.clone());
                plus[i] += h;
                minus[i] -= h;
                let project = |ps: &[f64]| {
                    camera
                        .with_params(ps)
                        .and_then(|c| c.project(&p))
                        .unwrap_or_else(|e| panic!("{e}"))
                };
                let fd = (project(&plus) - project(&minus)) / (2.0 * h);
                let err = (fd - d_params.column(i)).norm();
                assert!(
                    err < 1e-5 * (1.0 + fd.norm()),
                    "{name} d/d{param}: {err} px"
                );
            }
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn normalized_distortion_round_trips() {
    let mut rng = Rng::new(4);
    for camera in Camera::examples() {
        let name = camera.distortion.model_name();
        for _ in 0..200 {
            let n = Point2::new(rng.range(-0.6, 0.6), rng.range(-0.45, 0.45));
            let d = camera
                .distort_normalized(&n)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let back = camera
                .undistort_normalized(&d)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!((back - n).norm() < 1e-12, "{name}: {n} -> {back}");
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn params_round_trip_and_bad_input_is_rejected() {
    for camera in Camera::examples() {
        let p = camera.params();
        assert_eq!(p.len(), camera.param_names().len());
        assert_eq!(camera.with_params(&p), Ok(camera.clone()));
        let json = serde_json::to_string(&camera).unwrap_or_default();
        let back: Camera = serde_json::from_str(&json).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(back, camera);
    }
    let brown = Camera::example_brown();
    assert_eq!(
        brown.param_names(),
        ["fx", "fy", "cx", "cy", "skew", "k1", "k2", "p1", "p2", "k3"]
    );
    assert_eq!(
        brown.with_params(&[1.0; 4]).map_err(|e| e.to_string()),
        Err("params: a camera with the brown model has 10 parameters, got 4".to_string())
    );
    let mut bad = brown.params();
    bad[1] = -5.0;
    assert_eq!(
        brown.with_params(&bad).map_err(|e| e.to_string()),
        Err("fy: focal length must be > 0 px, got -5".to_string())
    );
    assert_eq!(
        brown
            .project(&Point3::new(0.1, 0.2, -1.0))
            .map_err(|e| e.to_string()),
        Err(
            "point: point (0.1000, 0.2000, -1.0000) is not in front of the camera (needs z > 0)"
                .to_string()
        )
    );
    let json = serde_json::to_value(&brown.distortion).unwrap_or_default();
    assert_eq!(json["model"], "brown");
    assert_eq!(json["k1"], -0.28);
}

#[wasm_bindgen_test(unsupported = test)]
fn fisheye_sees_behind_90_degrees_and_reports_its_limits() {
    let fisheye = Camera::example_kannala_brandt();
    // 100 degrees off axis: behind the image plane, still in the fisheye's view.
    let angle = 100f64.to_radians();
    let p = Point3::new(angle.sin(), 0.0, angle.cos());
    let pixel = fisheye.project(&p).unwrap_or_else(|e| panic!("{e}"));
    let ray = fisheye.unproject(&pixel).unwrap_or_else(|e| panic!("{e}"));
    assert!((ray - p.coords).norm() < 1e-12);
    assert!(fisheye
        .undistort_normalized(&Point2::new(2.0, 0.0))
        .is_err());
    // The Brown inverse refuses radii beyond the fold of the polynomial.
    let brown = Camera::example_brown();
    let far = brown.unproject(&Point2::new(brown.cx + 5000.0, brown.cy));
    assert!(matches!(far, Err(Error::NoConvergence { .. })), "{far:?}");
    let eucm = Camera::example_eucm();
    assert_eq!(
        eucm.project(&Point3::new(0.0, 0.0, -1.0))
            .map_err(|e| e.to_string()),
        Err("point: point (0.0000, 0.0000, -1.0000) is outside the EUCM field of view".to_string())
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn undistortion_map_samples_where_the_distorted_camera_images_each_ray() {
    let camera = Camera::example_brown();
    let small = Camera {
        width: 64,
        height: 48,
        fx: 50.0,
        fy: 50.1,
        cx: 31.5,
        cy: 23.5,
        ..camera
    };
    let target = small.without_distortion();
    let map = small
        .undistort_map(&target)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(map.map_x.len(), 64 * 48);
    // Output pixel (5, 7): the source is where the distorted camera images its ray.
    let ray = target
        .unproject(&Point2::new(5.0, 7.0))
        .unwrap_or_else(|e| panic!("{e}"));
    let src = small
        .project(&Point3::from(ray))
        .unwrap_or_else(|e| panic!("{e}"));
    let i = 7 * 64 + 5;
    assert!(
        (map.map_x[i] as f64 - src.x).abs() < 1e-4 && (map.map_y[i] as f64 - src.y).abs() < 1e-4
    );
}

/// The tilted model is OpenCV's `CALIB_TILTED_MODEL`: pixels of
/// `cv2.projectPoints` (opencv-python-headless 4.14.0.94) with 14
/// coefficients, every term non-zero, printed by benches/tilted_opencv.py.
#[wasm_bindgen_test(unsupported = test)]
// The pixels as OpenCV printed them (17 significant digits).
#[allow(clippy::excessive_precision)]
fn the_tilted_model_projects_as_opencv() {
    let camera = Camera {
        distortion: Distortion::Tilted {
            k1: -0.21,
            k2: 0.07,
            p1: 0.0008,
            p2: -0.0005,
            k3: -0.008,
            k4: 0.02,
            k5: -0.003,
            k6: 0.001,
            s1: 0.0011,
            s2: -0.0002,
            s3: 0.0006,
            s4: 0.0001,
            tau_x: 0.052,
            tau_y: -0.035,
        },
        ..Camera::example_pinhole()
    };
    let opencv: [([f64; 3], [f64; 2]); 5] = [
        ([0.0, 0.0, 1.0], [641.5, 478.25]),
        ([0.3, -0.2, 1.0], [933.0176463966875, 284.13830096408731]),
        ([-0.25, 0.35, 0.8], [344.18145257617556, 895.73635551702489]),
        ([0.5, 0.4, 2.0], [890.706116860983, 678.71549696719876]),
        ([-0.6, -0.45, 1.5], [272.90480244924731, 200.62004940675837]),
    ];
    for (p, want) in opencv {
        let got = camera
            .project(&Point3::new(p[0], p[1], p[2]))
            .unwrap_or_else(|e| panic!("{e}"));
        let err = (got - Point2::new(want[0], want[1])).norm();
        assert!(err < 1e-9, "{p:?}: {got} vs OpenCV {want:?} ({err} px)");
        let back = camera.unproject(&got).unwrap_or_else(|e| panic!("{e}"));
        let bearing = Vector3::new(p[0], p[1], p[2]).normalize();
        assert!((back - bearing).norm() < 1e-10, "{p:?}: unprojection");
    }
}
