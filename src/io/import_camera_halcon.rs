//! Reading HALCON camera parameters: the HDevelop tuple robocal's `halcon`
//! export writes (`CameraParam := ['area_scan_division', Focus, ...]`),
//! the same tuple as HALCON scripts hold it (with or without the leading
//! type name, or as a `gen_cam_par_area_scan_*` call), and the `.dat`
//! file of HALCON's `write_cam_par` (`ParGroup: Camera: Parameter;`, then
//! one `Name:short: value;` entry per parameter).
//!
//! Units and conventions (HALCON's calibration chapter): `Focus` in
//! metres, `Sx`/`Sy` the pixel pitch in metres, `Cx`/`Cy` the principal
//! point in pixels with the pixel centre at integer coordinates (ours), so
//! `fx = Focus / Sx`, `fy = Focus / Sy`. Distortion acts on the metric
//! image plane in the undistorting direction:
//! - division: `undistorted = distorted / (1 + Kappa r^2)`, robocal's
//!   division model with `kappa = Kappa Focus^2` (exact);
//! - polynomial: `u~ = u (1 + K1 r^2 + K2 r^4 + K3 r^6) +
//!   P1 (r^2 + 2 u^2) + 2 P2 u v` (and `v~` alike, `P1`/`P2` swapped), also undistorting. No
//!   robocal model runs that way, so a HALCON polynomial becomes the
//!   Brown-Conrady model fitted to it over the image (linear least squares,
//!   refused when the fit is off by more than [`POLYNOMIAL_FIT_MAX_PX`]).
//!   robocal's `halcon` export writes the undistorting polynomial fitted to
//!   the camera's Brown model ([`undistorting_polynomial`], its header says
//!   so) and reads it back like HALCON's own. Exports of robocal 0.1 before
//!   that (a first comment line from robocal without the fit's words) held
//!   Brown's coefficients scaled by powers of Focus (`K1 = k1 / Focus^2`,
//!   `P1 = p2 / Focus`, `P2 = p1 / Focus`): wrong for HALCON, and read back
//!   with that exact mapping so that robocal's own camera comes back.
//!
//! Tilted, telecentric, hypercentric and line-scan cameras have no robocal
//! model: an error names the type.

use crate::camera::{Camera, Distortion};
use crate::error::{Error, Result};
use nalgebra::{Point2, SMatrix, SVector};

/// How far (pixels, anywhere in the image) the Brown-Conrady model fitted
/// to a HALCON polynomial may be from it.
pub const POLYNOMIAL_FIT_MAX_PX: f64 = 0.05;

/// Whether `text` looks like a HALCON `.dat` camera parameter file.
pub(super) fn is_halcon_dat(text: &str) -> bool {
    text.lines().any(|l| {
        let l = l.trim_start();
        l.starts_with("ParGroup:") || l.starts_with("Focus:foc:")
    })
}

/// Whether `text` looks like an HDevelop camera parameter tuple.
pub(super) fn is_halcon_tuple(text: &str) -> bool {
    text.contains("gen_cam_par_")
        || text.contains("'area_scan_")
        || text.contains("'line_scan_")
        || (text.contains(":=") && text.contains('['))
}

/// The parameters of one HALCON camera, in HALCON's units.
struct HalconParams {
    kind: String,
    /// Focus, the distortion coefficients, Sx, Sy, Cx, Cy, width, height.
    values: Vec<f64>,
    /// Written by robocal's export (its polynomial is robocal's mapping).
    by_robocal: bool,
}

/// A camera from an HDevelop tuple or `gen_cam_par_area_scan_*` call.
pub(super) fn from_halcon_tuple(text: &str) -> Result<Camera> {
    let by_robocal = is_old_robocal_export(text);
    // The first line holding the tuple (or the call), with its number.
    let Some((n, _)) = text.lines().enumerate().find(|(_, l)| {
        let l = l.trim_start();
        !l.starts_with('*') && (l.contains("gen_cam_par_") || l.contains('['))
    }) else {
        return Err(Error::parse(
            0,
            0,
            "the HALCON camera parameters have no tuple: expected \
             CameraParam := ['area_scan_division', Focus, Kappa, Sx, Sy, Cx, Cy, ImageWidth, ImageHeight]",
        ));
    };
    let line_no = n + 1;
    // The tuple may continue on the next lines (HDevelop's `...`-free
    // continuation is not allowed, but a pasted tuple may wrap).
    let rest: String = text.lines().skip(n).collect::<Vec<_>>().join(" ");
    let (kind_from_call, body) = if let Some(at) = rest.find("gen_cam_par_") {
        let call = &rest[at + "gen_cam_par_".len()..];
        let open = call.find('(').ok_or_else(|| {
            Error::parse(
                line_no,
                0,
                "expected gen_cam_par_...(arguments, CameraParam)",
            )
        })?;
        let close = call
            .find(')')
            .ok_or_else(|| Error::parse(line_no, 0, "the gen_cam_par_ call has no closing ')'"))?;
        let kind = call[..open].trim().to_string();
        // The last argument is the output variable.
        let args = &call[open + 1..close];
        let args = args.rsplit_once(',').map_or(args, |(a, _)| a);
        (Some(kind), args.to_string())
    } else {
        let open = rest.find('[').unwrap_or(0);
        let close = rest[open..].find(']').map(|c| open + c).ok_or_else(|| {
            Error::parse(
                line_no,
                0,
                "the camera parameter tuple has no closing ']': the file is truncated",
            )
        })?;
        (None, rest[open + 1..close].to_string())
    };
    let mut kind = kind_from_call;
    let mut values = Vec::new();
    for (i, token) in body.split(',').map(str::trim).enumerate() {
        if i == 0 && kind.is_none() && (token.starts_with('\'') || token.starts_with('"')) {
            kind = Some(token.trim_matches(|c| c == '\'' || c == '"').to_string());
            continue;
        }
        let value = token.parse::<f64>().map_err(|_| {
            Error::parse(
                line_no,
                0,
                format!(
                    "camera parameter {} is '{token}', not a number",
                    values.len() + 1
                ),
            )
        })?;
        values.push(value);
    }
    // HALCON before version 12 wrote the tuple without its type: 8 values
    // are the division model, 12 the polynomial one.
    let kind = match kind {
        Some(kind) => kind,
        None => match values.len() {
            8 => "area_scan_division".into(),
            12 => "area_scan_polynomial".into(),
            n => {
                return Err(Error::parse(
                    line_no,
                    0,
                    format!(
                        "a camera parameter tuple without its type has 8 values (division) or 12 \
                         (polynomial), this one has {n}"
                    ),
                ))
            }
        },
    };
    let params = HalconParams {
        kind,
        values,
        by_robocal,
    };
    camera_from(&params).map_err(|e| at_line(e, line_no))
}

/// A camera from the `.dat` file of HALCON's `write_cam_par`.
pub(super) fn from_halcon_dat(text: &str) -> Result<Camera> {
    let mut entries: Vec<(String, String, usize)> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.starts_with('#') || l.starts_with("ParGroup") {
            continue;
        }
        let mut parts = l.splitn(3, ':');
        let (Some(name), Some(_short), Some(value)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        let name = name.trim();
        if !name.chars().next().is_some_and(|c| c.is_ascii_uppercase())
            || ["DOUBLE", "INT", "FLOAT", "BOOL", "XBOOL", "STRING"].contains(&name)
        {
            continue;
        }
        let value = value.trim().trim_end_matches(';').trim();
        entries.push((name.to_string(), value.to_string(), n + 1));
    }
    let has = |name: &str| entries.iter().any(|(k, _, _)| k == name);
    let kind = if let Some((_, v, _)) = entries.iter().find(|(k, _, _)| k == "CameraType") {
        v.trim_matches('"').to_string()
    } else if has("Vx") || has("Vy") || has("Vz") {
        "line_scan".into()
    } else if has("Tilt") || has("Rot") || has("ImagePlaneDist") {
        "area_scan_tilt".into()
    } else if has("Magnification") {
        "area_scan_telecentric".into()
    } else if has("Poly1") || has("K1") {
        "area_scan_polynomial".into()
    } else {
        "area_scan_division".into()
    };
    let names: &[&str] = if kind.ends_with("polynomial") {
        &[
            "Focus",
            "Poly1",
            "Poly2",
            "Poly3",
            "Poly4",
            "Poly5",
            "Sx",
            "Sy",
            "Cx",
            "Cy",
            "ImageWidth",
            "ImageHeight",
        ]
    } else {
        &[
            "Focus",
            "Kappa",
            "Sx",
            "Sy",
            "Cx",
            "Cy",
            "ImageWidth",
            "ImageHeight",
        ]
    };
    if !matches!(kind.as_str(), "area_scan_division" | "area_scan_polynomial") {
        return camera_from(&HalconParams {
            kind,
            values: Vec::new(),
            by_robocal: false,
        });
    }
    // Poly1..Poly5 are K1, K2, K3, P1, P2 (some writers use those names).
    fn alias(name: &str) -> &str {
        match name {
            "Poly1" => "K1",
            "Poly2" => "K2",
            "Poly3" => "K3",
            "Poly4" => "P1",
            "Poly5" => "P2",
            other => other,
        }
    }
    let mut values = Vec::with_capacity(names.len());
    for name in names {
        let Some((_, value, line)) = entries
            .iter()
            .find(|(k, _, _)| k == name || k == alias(name))
        else {
            return Err(Error::parse(
                0,
                0,
                format!(
                    "the HALCON camera file ({kind}) has no {name} entry \
                     ('{name}:{}: <value>;'): the file is truncated or not from write_cam_par",
                    name.to_lowercase()
                ),
            ));
        };
        let number = value
            .parse::<f64>()
            .map_err(|_| Error::parse(*line, 0, format!("{name} is '{value}', not a number")))?;
        values.push(number);
    }
    camera_from(&HalconParams {
        kind,
        values,
        by_robocal: false,
    })
}

/// A position-less error of [`camera_from`] placed on the tuple's line.
fn at_line(e: Error, line: usize) -> Error {
    match e {
        Error::Parse {
            line: 0, message, ..
        } => Error::parse(line, 0, message),
        other => other,
    }
}

fn camera_from(p: &HalconParams) -> Result<Camera> {
    let kind = p.kind.as_str();
    let n_distortion = match kind {
        "area_scan_division" => 1,
        "area_scan_polynomial" => 5,
        other => {
            let what = if other.contains("tilt") {
                "a tilted (Scheimpflug) lens"
            } else if other.contains("telecentric") {
                "a telecentric lens"
            } else if other.contains("hypercentric") {
                "a hypercentric lens"
            } else if other.starts_with("line_scan") {
                "a line-scan camera"
            } else {
                "an unknown camera type"
            };
            return Err(Error::parse(
                0,
                0,
                format!(
                    "HALCON's {other} ({what}) has no robocal model: robocal reads \
                     area_scan_division and area_scan_polynomial"
                ),
            ));
        }
    };
    let want = n_distortion + 7;
    if p.values.len() != want {
        let names = if n_distortion == 1 {
            "Focus, Kappa, Sx, Sy, Cx, Cy, ImageWidth, ImageHeight"
        } else {
            "Focus, K1, K2, K3, P1, P2, Sx, Sy, Cx, Cy, ImageWidth, ImageHeight"
        };
        return Err(Error::parse(
            0,
            0,
            format!(
                "{kind} has {want} values ({names}), the tuple gives {}",
                p.values.len()
            ),
        ));
    }
    let v = &p.values;
    if let Some(bad) = v.iter().find(|x| !x.is_finite()) {
        return Err(Error::parse(
            0,
            0,
            format!("every camera parameter must be a finite number, got {bad}"),
        ));
    }
    let focus = v[0];
    let [sx, sy, cx, cy, w, h] = [
        v[want - 6],
        v[want - 5],
        v[want - 4],
        v[want - 3],
        v[want - 2],
        v[want - 1],
    ];
    if focus == 0.0 {
        return Err(Error::parse(
            0,
            0,
            "Focus is 0: a telecentric camera (HALCON before 12), which has no robocal model",
        ));
    }
    if !(focus > 0.0 && sx > 0.0 && sy > 0.0) {
        return Err(Error::parse(
            0,
            0,
            format!("Focus, Sx and Sy must be positive (metres), got {focus}, {sx}, {sy}"),
        ));
    }
    let size = |x: f64, name: &str| {
        (x >= 1.0 && x.fract() == 0.0 && x <= u32::MAX as f64)
            .then_some(x as u32)
            .ok_or_else(|| {
                Error::parse(
                    0,
                    0,
                    format!("{name} must be a whole number of pixels > 0, got {x}"),
                )
            })
    };
    let mut camera = Camera {
        fx: focus / sx,
        fy: focus / sy,
        cx,
        cy,
        skew: 0.0,
        width: size(w, "ImageWidth")?,
        height: size(h, "ImageHeight")?,
        distortion: Distortion::None,
    };
    let f2 = focus * focus;
    camera.distortion = if n_distortion == 1 {
        Distortion::Division { kappa: v[1] * f2 }
    } else {
        // In normalised units: K1 f^2, K2 f^4, K3 f^6, P1 f, P2 f.
        let scaled = [
            v[1] * f2,
            v[2] * f2 * f2,
            v[3] * f2 * f2 * f2,
            v[4] * focus,
            v[5] * focus,
        ];
        if p.by_robocal {
            let [k1, k2, k3, big_p1, big_p2] = scaled;
            Distortion::Brown {
                k1,
                k2,
                k3,
                p1: big_p2,
                p2: big_p1,
            }
        } else {
            brown_from_undistorting(&camera, scaled)?
        }
    };
    Ok(camera)
}

/// Grid points per image side of the polynomial fit.
const FIT_GRID: usize = 25;

/// The Brown-Conrady model nearest (least squares over a grid of image
/// points) to HALCON's undistorting polynomial with normalised
/// coefficients `[K1 f^2, K2 f^4, K3 f^6, P1 f, P2 f]`.
fn brown_from_undistorting(camera: &Camera, c: [f64; 5]) -> Result<Distortion> {
    let [a1, a2, a3, q1, q2] = c;
    let undistort = |x: f64, y: f64| {
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (a1 + r2 * (a2 + r2 * a3));
        (
            x * radial + q1 * (r2 + 2.0 * x * x) + 2.0 * q2 * x * y,
            y * radial + 2.0 * q1 * x * y + q2 * (r2 + 2.0 * y * y),
        )
    };
    // Pairs (undistorted, distorted) in normalised coordinates.
    let mut pairs = Vec::with_capacity(FIT_GRID * FIT_GRID);
    for i in 0..FIT_GRID {
        for j in 0..FIT_GRID {
            let col = (camera.width as f64 - 1.0) * i as f64 / (FIT_GRID - 1) as f64;
            let row = (camera.height as f64 - 1.0) * j as f64 / (FIT_GRID - 1) as f64;
            let d = ((col - camera.cx) / camera.fx, (row - camera.cy) / camera.fy);
            pairs.push((undistort(d.0, d.1), d));
        }
    }
    // Brown's distorted - undistorted is linear in (k1, k2, k3, p1, p2).
    let rows = |(x, y): (f64, f64)| {
        let r2 = x * x + y * y;
        let (r4, r6) = (r2 * r2, r2 * r2 * r2);
        (
            SVector::<f64, 5>::from([x * r2, x * r4, x * r6, 2.0 * x * y, r2 + 2.0 * x * x]),
            SVector::<f64, 5>::from([y * r2, y * r4, y * r6, r2 + 2.0 * y * y, 2.0 * x * y]),
        )
    };
    let mut normal = SMatrix::<f64, 5, 5>::zeros();
    let mut rhs = SVector::<f64, 5>::zeros();
    for &(u, d) in &pairs {
        let (jx, jy) = rows(u);
        normal += jx * jx.transpose() + jy * jy.transpose();
        rhs += jx * (d.0 - u.0) + jy * (d.1 - u.1);
    }
    let k = normal.cholesky().map(|ch| ch.solve(&rhs)).ok_or_else(|| {
        Error::parse(
            0,
            0,
            "the polynomial's distortion could not be fitted (degenerate image size)",
        )
    })?;
    let worst_px = pairs
        .iter()
        .map(|&(u, d)| {
            let (jx, jy) = rows(u);
            let ex = u.0 + jx.dot(&k) - d.0;
            let ey = u.1 + jy.dot(&k) - d.1;
            (ex * camera.fx).hypot(ey * camera.fy)
        })
        .fold(0.0, f64::max);
    if worst_px.is_nan() || worst_px > POLYNOMIAL_FIT_MAX_PX {
        return Err(Error::parse(
            0,
            0,
            format!(
                "HALCON's area_scan_polynomial maps distorted to undistorted points; the nearest \
                 Brown-Conrady model (robocal's, the other way) is off by {worst_px:.3} px in this \
                 image, more than {POLYNOMIAL_FIT_MAX_PX} px: calibrate with HALCON's \
                 area_scan_division, or read the calibration from robocal's own export"
            ),
        ));
    }
    Ok(Distortion::Brown {
        k1: k[0],
        k2: k[1],
        k3: k[2],
        p1: k[3],
        p2: k[4],
    })
}

/// Whether a robocal `halcon` export holds Brown's own coefficients (the
/// exports before HALCON's direction was honoured, read back with that
/// mapping) rather than a fitted undistorting polynomial (whose header
/// says [`FITTED_MARK`]).
fn is_old_robocal_export(text: &str) -> bool {
    text.trim_start().starts_with("* robocal") && !text.contains(FITTED_MARK)
}

/// How far (pixels, anywhere in the image) the undistorting polynomial
/// robocal's `halcon` export writes may be from the camera's own model;
/// beyond it the export is refused (the lens-model table says so).
pub const HALCON_EXPORT_MAX_PX: f64 = 0.5;

/// The words of the export's header that mark a fitted undistorting
/// polynomial.
pub(super) const FITTED_MARK: &str = "maps distorted to undistorted";

/// HALCON's undistorting polynomial nearest (least squares over a grid of
/// image points) to `camera`'s distorting model, in normalised units
/// `[K1 f^2, K2 f^4, K3 f^6, P1 f, P2 f]`, with its worst error over the
/// grid (pixels). What `robocal export --format halcon` writes for the
/// Brown-Conrady and k1 k2 k5 models: HALCON maps distorted to undistorted
/// points, robocal the other way, so no coefficient carries over as it is.
pub(super) fn undistorting_polynomial(camera: &Camera) -> Result<([f64; 5], f64)> {
    // Pairs (distorted, undistorted) in normalised coordinates.
    let mut pairs = Vec::with_capacity(FIT_GRID * FIT_GRID);
    for i in 0..FIT_GRID {
        for j in 0..FIT_GRID {
            let col = (camera.width as f64 - 1.0) * i as f64 / (FIT_GRID - 1) as f64;
            let row = (camera.height as f64 - 1.0) * j as f64 / (FIT_GRID - 1) as f64;
            let d = Point2::new((col - camera.cx) / camera.fx, (row - camera.cy) / camera.fy);
            let u = camera.undistort_normalized(&d).map_err(|e| {
                Error::invalid(
                    "format",
                    format!(
                        "HALCON's polynomial could not be fitted: pixel ({col:.0}, {row:.0}) does \
                         not undistort ({e})"
                    ),
                )
            })?;
            pairs.push((d, u));
        }
    }
    // HALCON's undistorted - distorted is linear in (K1 f^2, ..., P2 f).
    let rows = |d: &Point2<f64>| {
        let (x, y) = (d.x, d.y);
        let r2 = x * x + y * y;
        let (r4, r6) = (r2 * r2, r2 * r2 * r2);
        (
            SVector::<f64, 5>::from([x * r2, x * r4, x * r6, r2 + 2.0 * x * x, 2.0 * x * y]),
            SVector::<f64, 5>::from([y * r2, y * r4, y * r6, 2.0 * x * y, r2 + 2.0 * y * y]),
        )
    };
    let mut normal = SMatrix::<f64, 5, 5>::zeros();
    let mut rhs = SVector::<f64, 5>::zeros();
    for (d, u) in &pairs {
        let (jx, jy) = rows(d);
        normal += jx * jx.transpose() + jy * jy.transpose();
        rhs += jx * (u.x - d.x) + jy * (u.y - d.y);
    }
    let c = normal.cholesky().map(|ch| ch.solve(&rhs)).ok_or_else(|| {
        Error::invalid(
            "format",
            "HALCON's polynomial could not be fitted (degenerate image size)",
        )
    })?;
    let worst_px = pairs
        .iter()
        .map(|(d, u)| {
            let (jx, jy) = rows(d);
            let ex = d.x + jx.dot(&c) - u.x;
            let ey = d.y + jy.dot(&c) - u.y;
            (ex * camera.fx).hypot(ey * camera.fy)
        })
        .fold(0.0, f64::max);
    Ok(([c[0], c[1], c[2], c[3], c[4]], worst_px))
}
