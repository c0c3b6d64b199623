//! Reading back every camera format robocal writes: a table of every
//! format x every lens model it holds (export then import is the same
//! camera to 1e-9 relative; HALCON's polynomial, fitted both ways, to
//! 0.55 px), HALCON's own files, and the errors of damaged files.

use super::export_camera::{export_camera, CameraExportInfo, CameraFormat};
use super::import_camera::{import_camera, CameraSource, NOT_A_CAMERA};
use crate::camera::{Camera, Distortion, LENS_MODELS};
use nalgebra::{Point2, Point3};

/// The model as a format without its own name for it stores it: radial
/// k1 k2 k5 is Brown with k3 = k5, an all-zero Brown or division is none.
fn canonical(d: &Distortion) -> Distortion {
    let d = match *d {
        Distortion::RadialK1K2K5 { k1, k2, k5 } => Distortion::Brown {
            k1,
            k2,
            k3: k5,
            p1: 0.0,
            p2: 0.0,
        },
        ref other => other.clone(),
    };
    if d.coefficients().iter().all(|c| *c == 0.0)
        && matches!(
            d,
            Distortion::Brown { .. } | Distortion::Division { .. } | Distortion::Rational { .. }
        )
    {
        Distortion::None
    } else {
        d
    }
}

/// Same camera: every number within 1e-9 relative, same size and model.
fn assert_same(back: &Camera, camera: &Camera, what: &str) {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-300);
    assert_eq!(
        (back.width, back.height),
        (camera.width, camera.height),
        "{what}"
    );
    let (a, b) = (canonical(&back.distortion), canonical(&camera.distortion));
    assert_eq!(a.model_name(), b.model_name(), "{what}");
    assert_eq!(
        a.coefficients().len(),
        b.coefficients().len(),
        "{what}: coefficient count"
    );
    if let (Distortion::Splined(x), Distortion::Splined(y)) = (&a, &b) {
        assert_eq!(
            (x.order, x.nx, x.ny, x.u_max, x.smoothness),
            (y.order, y.nx, y.ny, y.u_max, y.smoothness),
            "{what}: spline layout"
        );
    }
    let numbers = |c: &Camera, d: &Distortion| {
        let mut v = vec![c.fx, c.fy, c.cx, c.cy, c.skew];
        v.extend(d.coefficients());
        v
    };
    for (x, y) in numbers(back, &a).into_iter().zip(numbers(camera, &b)) {
        assert!(close(x, y), "{what}: {x} vs {y}\n{back:?}\n{camera:?}");
    }
}

/// Same camera up to HALCON's fitted polynomial: fx fy cx cy and the size
/// exact, every pixel of a grid projected within the export's bound plus
/// the reader's (the export's fit, then the reader's fit back).
fn assert_same_projection(back: &Camera, camera: &Camera, what: &str) {
    let linear = |c: &Camera| [c.fx, c.fy, c.cx, c.cy, c.skew];
    for (x, y) in linear(back).into_iter().zip(linear(camera)) {
        assert!(
            (x - y).abs() <= 1e-9 * x.abs().max(1.0),
            "{what}: {x} vs {y}"
        );
    }
    assert_eq!((back.width, back.height), (camera.width, camera.height));
    let bound = super::import_camera_halcon::HALCON_EXPORT_MAX_PX
        + super::import_camera_halcon::POLYNOMIAL_FIT_MAX_PX;
    for i in 0..=10 {
        for j in 0..=10 {
            let pixel = Point2::new(
                (camera.width as f64 - 1.0) * i as f64 / 10.0,
                (camera.height as f64 - 1.0) * j as f64 / 10.0,
            );
            let ray = camera.unproject(&pixel).unwrap();
            let again = back.project(&Point3::from(ray)).unwrap();
            assert!(
                (again - pixel).norm() < bound,
                "{what}: pixel {pixel} comes back at {again}"
            );
        }
    }
}

fn source_of(format: CameraFormat) -> CameraSource {
    match format {
        CameraFormat::Json => CameraSource::Json,
        CameraFormat::OpencvYaml => CameraSource::OpencvYaml,
        CameraFormat::OpencvXml => CameraSource::OpencvXml,
        CameraFormat::RosYaml => CameraSource::RosYaml,
        CameraFormat::Kalibr => CameraSource::Kalibr,
        CameraFormat::Mrcal => CameraSource::Mrcal,
        CameraFormat::Halcon => CameraSource::Halcon,
        CameraFormat::Matlab => CameraSource::Matlab,
        CameraFormat::Text => CameraSource::Text,
    }
}

/// Every format x every lens model of the lens-model table (its
/// `export_formats`, with their "held at 0" conditions; `text` for the
/// pinhole camera): export, import, the same camera.
#[test]
fn every_format_reads_back_every_lens_model_it_holds() {
    let mut pairs = 0;
    for example in Camera::examples() {
        let model = example.distortion.model_name();
        let row = LENS_MODELS.iter().find(|m| m.name == model).unwrap();
        let mut formats: Vec<&str> = row.export_formats.to_vec();
        if example.distortion == Distortion::None {
            formats.push("text");
        }
        for entry in formats {
            let name = entry.split(" (").next().unwrap();
            let format = CameraFormat::from_name(name).unwrap();
            let mut camera = example.clone();
            // Skew: only JSON, OpenCV, ROS and MATLAB hold it.
            if !matches!(
                format,
                CameraFormat::Json
                    | CameraFormat::OpencvYaml
                    | CameraFormat::OpencvXml
                    | CameraFormat::RosYaml
                    | CameraFormat::Matlab
                    | CameraFormat::Text
            ) {
                camera.skew = 0.0;
            }
            if let Some(condition) = entry.strip_suffix(" held at 0)") {
                let coefficient = condition.rsplit(' ').next().unwrap();
                let names = camera.distortion.coefficient_names();
                let mut values = camera.distortion.coefficients();
                let k = names.iter().position(|n| *n == coefficient).unwrap();
                values[k] = 0.0;
                camera.distortion = camera.distortion.with_coefficients(&values).unwrap();
            }
            milder_for_halcon(Some(entry), &mut camera);
            let text = export_camera(&camera, &CameraExportInfo::default(), format)
                .unwrap_or_else(|e| panic!("{model} to {name}: {e}"));
            let (back, seen) =
                import_camera(&text).unwrap_or_else(|e| panic!("{model} from {name}: {e}\n{text}"));
            assert_eq!(seen, source_of(format), "{model} as {name}:\n{text}");
            let fitted = format == CameraFormat::Halcon
                && matches!(canonical(&camera.distortion), Distortion::Brown { .. });
            if fitted {
                assert_same_projection(&back, &camera, &format!("{model} as {name}"));
            } else {
                assert_same(&back, &camera, &format!("{model} as {name}"));
            }
            pairs += 1;
        }
    }
    // 9 models: none in 9 formats, brown and radial_k1_k2_k5 in 8 each,
    // rational 5, division 2, kannala_brandt 5, eucm 2, tilted 3, splined 1.
    assert_eq!(pairs, 43);
}

/// HALCON's division model as `write_cam_par` writes it: Focus in metres,
/// Kappa in 1/m^2, Sx/Sy the pixel pitch.
const HALCON_DAT: &str = "\
#
# INTERNAL CAMERA PARAMETERS
#

ParGroup: Camera: Parameter;
\t\"Internal camera parameters\";

Focus:foc:\t0.008;
\tDOUBLE:0.0:;
\t\"Focal length of the lens [meter]\";

Kappa:kappa:\t-2500;
\tDOUBLE::;
\t\"Radial distortion coefficient [1/(meter*meter)]\";

Sx:sx:\t8.3e-06;
\tDOUBLE:0.0:;
\t\"Width of a cell on the sensor [meter]\";

Sy:sy:\t8.3e-06;
\tDOUBLE:0.0:;
\t\"Height of a cell on the sensor [meter]\";

Cx:cx:\t371.5;
\tDOUBLE::;
\t\"X-coordinate of the image center [pixel]\";

Cy:cy:\t243.25;
\tDOUBLE::;
\t\"Y-coordinate of the image center [pixel]\";

ImageWidth:imgw:\t752;
\tINT:1:32767;
\t\"Width of the images [pixel]\";

ImageHeight:imgh:\t480;
\tINT:1:32767;
\t\"Height of the images [pixel]\";
";

#[test]
fn halcon_dat_and_tuple_files_convert_units_and_signs() {
    let (c, seen) = import_camera(HALCON_DAT).unwrap();
    assert_eq!(seen, CameraSource::Halcon);
    let fx = 0.008 / 8.3e-6;
    assert!(
        (c.fx - fx).abs() < 1e-9 && (c.fy - fx).abs() < 1e-9,
        "{c:?}"
    );
    assert_eq!((c.cx, c.cy, c.width, c.height), (371.5, 243.25, 752, 480));
    // Barrel distortion keeps its sign: kappa = Kappa Focus^2.
    assert_eq!(
        c.distortion,
        Distortion::Division {
            kappa: -2500.0 * 0.008 * 0.008
        }
    );
    // The same camera as an HDevelop tuple, as a pre-12 tuple without its
    // type and as a gen_cam_par call.
    for text in [
        "CameraParam := ['area_scan_division', 0.008, -2500, 8.3e-06, 8.3e-06, 371.5, 243.25, 752, 480]\n",
        "CamParam := [0.008, -2500, 8.3e-06, 8.3e-06, 371.5, 243.25, 752, 480]\n",
        "gen_cam_par_area_scan_division (0.008, -2500, 8.3e-06, 8.3e-06, 371.5, 243.25, 752, 480, CamParam)\n",
    ] {
        let (t, seen) = import_camera(text).unwrap();
        assert_eq!((t, seen), (c.clone(), CameraSource::Halcon), "{text}");
    }
}

/// HALCON's polynomial undistorts (distorted -> undistorted): a genuine
/// HALCON file becomes the Brown-Conrady model fitted to it, which
/// projects every undistorted point where HALCON's model says.
#[test]
fn a_halcon_polynomial_becomes_the_brown_model_that_inverts_it() {
    let (focus, sx) = (0.008, 5e-6);
    let (k1, p1, p2) = (1500.0, 0.02, -0.01);
    let text = format!(
        "CameraParam := ['area_scan_polynomial', {focus}, {k1}, 0.0, 0.0, {p1}, {p2}, {sx}, {sx}, 640.0, 480.0, 1280, 960]\n"
    );
    let (c, _) = import_camera(&text).unwrap();
    let Distortion::Brown { k1: b1, .. } = c.distortion else {
        panic!("{c:?}")
    };
    // Undistorting with +K1 is distorting with about -K1 f^2.
    assert!(
        b1 < 0.0 && (b1 + k1 * focus * focus).abs() < 0.2 * k1 * focus * focus,
        "{b1}"
    );
    let mut worst: f64 = 0.0;
    for (col, row) in [
        (0.0, 0.0),
        (1279.0, 959.0),
        (200.0, 700.0),
        (640.0, 480.0),
        (1000.0, 100.0),
    ] {
        // HALCON: distorted metric (u, v) -> undistorted.
        let (u, v) = ((col - 640.0) * sx, (row - 480.0) * sx);
        let r2 = u * u + v * v;
        let uu = u * (1.0 + k1 * r2) + p1 * (r2 + 2.0 * u * u) + 2.0 * p2 * u * v;
        let vv = v * (1.0 + k1 * r2) + 2.0 * p1 * u * v + p2 * (r2 + 2.0 * v * v);
        let projected = c
            .project(&Point3::new(uu / focus, vv / focus, 1.0))
            .unwrap();
        worst = worst.max((projected - Point2::new(col, row)).norm());
    }
    assert!(
        worst < super::import_camera_halcon::POLYNOMIAL_FIT_MAX_PX,
        "{worst} px"
    );
}

#[test]
fn damaged_files_name_the_line_and_what_is_missing() {
    let err = |text: &str| import_camera(text).unwrap_err().to_string();
    assert_eq!(err("hello\n"), NOT_A_CAMERA);
    // .dat: a missing entry, a value that is no number (its line).
    let no_sy = HALCON_DAT.replace("Sy:sy:\t8.3e-06;", "");
    assert_eq!(
        err(&no_sy),
        "the HALCON camera file (area_scan_division) has no Sy entry ('Sy:sy: <value>;'): \
         the file is truncated or not from write_cam_par"
    );
    let bad_focus = HALCON_DAT.replace("Focus:foc:\t0.008;", "Focus:foc:\t0.0o8;");
    assert_eq!(err(&bad_focus), "line 8: Focus is '0.0o8', not a number");
    // Tuples: truncated, short, tilted, a word among the numbers.
    assert_eq!(
        err("* HDevelop\nCameraParam := ['area_scan_division', 0.008, -2500, 8.3e-06\n"),
        "line 2: the camera parameter tuple has no closing ']': the file is truncated"
    );
    assert_eq!(
        err("CameraParam := ['area_scan_division', 0.008, -2500, 8.3e-06, 8.3e-06, 371.5, 243.25, 752]\n"),
        "line 1: area_scan_division has 8 values (Focus, Kappa, Sx, Sy, Cx, Cy, ImageWidth, ImageHeight), the tuple gives 7"
    );
    assert_eq!(
        err("CameraParam := ['area_scan_tilt_division', 0.008, -2500, 0.1, 5, 30, 8.3e-06, 8.3e-06, 371.5, 243.25, 752, 480]\n"),
        "line 1: HALCON's area_scan_tilt_division (a tilted (Scheimpflug) lens) has no robocal model: robocal reads area_scan_division and area_scan_polynomial"
    );
    assert_eq!(
        err("\nCameraParam := ['area_scan_division', 0.008, kappa, 8.3e-06, 8.3e-06, 371.5, 243.25, 752, 480]\n"),
        "line 2: camera parameter 2 is 'kappa', not a number"
    );
    // MATLAB: a missing line, a damaged one.
    let m = export_camera(
        &Camera::example_brown(),
        &CameraExportInfo::default(),
        CameraFormat::Matlab,
    )
    .unwrap();
    let lines: Vec<&str> = m.lines().collect();
    let without = |prefix: &str| {
        lines
            .iter()
            .filter(|l| !l.starts_with(prefix))
            .map(|l| format!("{l}\n"))
            .collect::<String>()
    };
    assert_eq!(
        err(&without("imageSize")),
        "the MATLAB script has no 'imageSize = [rows, columns];' line"
    );
    assert_eq!(
        err(&m.replace("focalLength = [1000.0, 1002.0];", "focalLength = [1000.0];")),
        "line 2: focalLength has 1 numbers, expected [fx, fy]"
    );
    // Text: no size, a lens model left out.
    let k = export_camera(
        &Camera::example_pinhole(),
        &CameraExportInfo::default(),
        CameraFormat::Text,
    )
    .unwrap();
    assert!(err(&k
        .lines()
        .take(3)
        .map(|l| format!("{l}\n"))
        .collect::<String>())
    .starts_with(
        "a 3x3 camera matrix holds no image size: add the line '# image_size_px: WIDTH HEIGHT'"
    ));
    let k = export_camera(
        &Camera::example_brown(),
        &CameraExportInfo::default(),
        CameraFormat::Text,
    )
    .unwrap();
    assert!(
        err(&k).starts_with("line 5: this camera matrix was written from a camera with the brown lens model, which the text format does not hold"),
        "{}",
        err(&k)
    );
}

/// An export of robocal before the fitted polynomial (Brown's coefficients
/// scaled by powers of Focus, tangential terms swapped) reads back as the
/// camera it was written from, exactly.
#[test]
fn an_old_robocal_halcon_export_reads_back_exactly() {
    let (focus, sx) = (812.5 * 5e-6, 5e-6);
    let f2 = focus * focus;
    let (k1, k2, k3, p1, p2) = (-0.2286, 0.1904, -0.0123, 0.00123, -0.000456);
    let text = format!(
        "* robocal 0.1.0: Halcon camera parameters (Focus [m], K1, K2, K3, P1, P2, Sx [m], Sy [m], Cx [px], Cy [px], ImageWidth, ImageHeight).\n\
         * Sx is a nominal pixel size of 0.000005 m: only Focus/Sx is calibrated.\n\
         CameraParam := ['area_scan_polynomial', {focus}, {}, {}, {}, {}, {}, {sx}, {sx}, 320.5, 240.25, 640, 480]\n",
        k1 / f2,
        k2 / (f2 * f2),
        k3 / (f2 * f2 * f2),
        p2 / focus,
        p1 / focus
    );
    let (c, _) = import_camera(&text).unwrap();
    let Distortion::Brown {
        k1: b1,
        k2: b2,
        k3: b3,
        p1: q1,
        p2: q2,
    } = c.distortion
    else {
        panic!("{c:?}")
    };
    for (a, b) in [(b1, k1), (b2, k2), (b3, k3), (q1, p1), (q2, p2)] {
        assert!((a - b).abs() <= 1e-9 * b.abs(), "{a} vs {b}");
    }
}

/// HALCON's entry in the lens-model table holds Brown's model only where
/// its undistorting polynomial fits (the export refuses a lens it cannot
/// fit within 0.5 px, as the example's strong one): for `halcon` the
/// camera's lens is made ten times milder.
pub(super) fn milder_for_halcon(entry: Option<&str>, camera: &mut Camera) {
    if entry == Some("halcon") {
        let values: Vec<f64> = camera
            .distortion
            .coefficients()
            .iter()
            .map(|c| c * 0.1)
            .collect();
        camera.distortion = camera.distortion.with_coefficients(&values).unwrap();
    }
}

/// A splined calibration report (top-level `dx0 dy0 ...`, the layout only in
/// its `camera`): the JSON export keeps the spline, and mrcal's refusal says
/// why (the knot spacing), not that the field is unset.
#[test]
fn a_splined_report_exports_its_spline() {
    let camera = Camera::example_splined();
    let mut distortion = serde_json::Map::new();
    for (n, v) in camera
        .distortion
        .coefficient_names()
        .iter()
        .zip(camera.distortion.coefficients())
    {
        distortion.insert((*n).to_string(), serde_json::json!(v));
    }
    let report = serde_json::json!({
        "kind": "camera",
        "model": "splined",
        "image_size_px": [camera.width, camera.height],
        "camera_matrix": [[camera.fx, camera.skew, camera.cx], [0.0, camera.fy, camera.cy], [0.0, 0.0, 1.0]],
        "distortion": distortion,
        "camera": serde_json::to_value(&camera).unwrap(),
        "rms_px": 0.1,
    })
    .to_string();
    let json = super::export::export(&report, "json", None).unwrap();
    let (back, _) = import_camera(&json).unwrap();
    assert_same(&back, &camera, "splined report as json");
    let refused = super::export::export(&report, "mrcal", None)
        .unwrap_err()
        .to_string();
    assert!(refused.contains("its knot spacing is"), "{refused}");
}
