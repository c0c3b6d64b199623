//! CSV inputs of the industrial workflows (`robocal planar`, `robocal
//! xytable`), parsed from `&str` into the workflows' plain data.
//!
//! - planar matrices: header `height_mm,a11,a12,tx,a21,a22,ty`;
//! - planar points: header `height_mm,u_px,v_px,x_mm,y_mm`;
//! - XY-table positions: header `x_mm,y_mm,z_mm,u_px,v_px`, optional `role`
//!   column: empty or `calibration`, `verify` (the four extra positions A, B,
//!   C, D in order) or `still` (repeated images of the still target; only
//!   u, v are used);
//! - known motions: header `dx_mm,dy_mm,dz_mm,x_cam_mm,y_cam_mm,z_cam_mm`.
//!
//! Extra columns are allowed and ignored (e.g. a `corner` label); column
//! order is free.

use super::csv_table::CsvTable;
use crate::calib::dlt_kalman::KalmanMode;
use crate::error::{Error, Result};
use crate::workflows::known_motion::KnownMotionRequest;
use crate::workflows::planar::HeightMatrix;
use crate::workflows::planar::PlanarMatrix;
use crate::workflows::planar_solve::HeightPoint;
use crate::workflows::xytable::{StageObservation, XyTableRequest};

/// Header of the planar matrices file.
pub const PLANAR_MATRICES_HEADER: [&str; 7] = ["height_mm", "a11", "a12", "tx", "a21", "a22", "ty"];
/// Header of the planar points file.
pub const PLANAR_POINTS_HEADER: [&str; 5] = ["height_mm", "u_px", "v_px", "x_mm", "y_mm"];

/// Parse a planar matrices file (one 2x3 image->robot matrix per height).
pub fn parse_planar_matrices(text: &str) -> Result<Vec<HeightMatrix>> {
    let table = CsvTable::parse(text)?;
    let cols = table.require_columns(&PLANAR_MATRICES_HEADER)?;
    Ok(table
        .numbers(&cols)?
        .into_iter()
        .map(|r| HeightMatrix {
            height_mm: r[0],
            robot_from_image: PlanarMatrix::from_array([r[1], r[2], r[3], r[4], r[5], r[6]]),
        })
        .collect())
}

/// Parse a planar points file (image <-> robot pairs at several heights).
pub fn parse_planar_points(text: &str) -> Result<Vec<HeightPoint>> {
    let table = CsvTable::parse(text)?;
    let cols = table.require_columns(&PLANAR_POINTS_HEADER)?;
    Ok(table
        .numbers(&cols)?
        .into_iter()
        .map(|r| HeightPoint {
            height_mm: r[0],
            image_px: [r[1], r[2]],
            robot_mm: [r[3], r[4]],
        })
        .collect())
}

/// Header of the XY-table positions file.
pub const XYTABLE_HEADER: [&str; 5] = ["x_mm", "y_mm", "z_mm", "u_px", "v_px"];
/// Header of the known-motion file.
pub const KNOWN_MOTION_HEADER: [&str; 6] = [
    "dx_mm", "dy_mm", "dz_mm", "x_cam_mm", "y_cam_mm", "z_cam_mm",
];

/// Parse an XY-table positions file into a request (extended Kalman mode,
/// noise from the `still` rows when there are any). A file with an `image`
/// column instead of `u_px,v_px` needs [`parse_xytable_with`].
pub fn parse_xytable(text: &str) -> Result<XyTableRequest> {
    parse_xytable_with(text, &mut |name| {
        Err(Error::invalid(
            "image",
            format!("the row names image '{name}': give the target centres as u_px,v_px columns, or run 'robocal xytable', which detects the circle in the image files"),
        ))
    })
}

/// [`parse_xytable`] where an `image` column (instead of `u_px,v_px`)
/// names image files: `centre_of(name)` returns the target centre in that
/// image, pixels (the caller reads and detects; this stays host-free).
pub fn parse_xytable_with(
    text: &str,
    centre_of: &mut dyn FnMut(&str) -> Result<[f64; 2]>,
) -> Result<XyTableRequest> {
    let table = CsvTable::parse(text)?;
    let image_col = table
        .column("image")
        .filter(|_| table.column("u_px").is_none());
    let cols = match image_col {
        Some(_) => table.require_columns(&XYTABLE_HEADER[..3])?,
        None => table.require_columns(&XYTABLE_HEADER)?,
    };
    let role = table.column("role");
    let mut request = XyTableRequest {
        observations: Vec::new(),
        verification: Vec::new(),
        still_target_px: Vec::new(),
        measurement_noise_px2: None,
        kalman_mode: KalmanMode::Extended,
    };
    for row in 0..table.len() {
        let v: Vec<f64> = cols
            .iter()
            .map(|&c| table.number(row, c))
            .collect::<Result<_>>()?;
        let image_px = match image_col {
            Some(c) => centre_of(table.text(row, c)).map_err(|e| {
                Error::parse(
                    table.line_of(row),
                    c + 1,
                    format!("{}: {e}", table.text(row, c)),
                )
            })?,
            None => [v[3], v[4]],
        };
        let obs = StageObservation {
            stage_mm: [v[0], v[1], v[2]],
            image_px,
        };
        match role.map_or("", |c| table.text(row, c)) {
            "" | "calibration" => request.observations.push(obs),
            "verify" => request.verification.push(obs),
            "still" => request.still_target_px.push(obs.image_px),
            other => {
                return Err(Error::parse(
                    table.line_of(row),
                    role.map_or(0, |c| c + 1),
                    format!("role: expected calibration, verify or still, got '{other}'"),
                ))
            }
        }
    }
    Ok(request)
}

/// Parse a known-motion file (increments in the reference frame and the
/// point in the camera frame, mm).
pub fn parse_known_motion(text: &str) -> Result<KnownMotionRequest> {
    let table = CsvTable::parse(text)?;
    let cols = table.require_columns(&KNOWN_MOTION_HEADER)?;
    let rows = table.numbers(&cols)?;
    Ok(KnownMotionRequest {
        increments_mm: rows.iter().map(|r| [r[0], r[1], r[2]]).collect(),
        points_camera_mm: rows.iter().map(|r| [r[3], r[4], r[5]]).collect(),
        start_reference_mm: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn planar_files_parse_with_clear_errors() {
        let pts =
            parse_planar_points("corner,height_mm,u_px,v_px,x_mm,y_mm\nA,15,1,2,3,4\n").unwrap();
        assert_eq!(pts[0].image_px, [1.0, 2.0]);
        assert_eq!(pts[0].robot_mm, [3.0, 4.0]);
        assert_eq!(
            parse_planar_points("height_mm,u_px,v_px,x_mm\n")
                .unwrap_err()
                .to_string(),
            "line 1: missing column(s) y_mm (expected header height_mm,u_px,v_px,x_mm,y_mm, \
             got height_mm,u_px,v_px,x_mm)"
        );
        let m = parse_planar_matrices("height_mm,a11,a12,tx,a21,a22,ty\n15,1,2,3,4,5,6\n").unwrap();
        assert_eq!(m[0].robot_from_image.ty, 6.0);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn xytable_roles_and_image_column() {
        let r = parse_xytable(
            "x_mm,y_mm,z_mm,u_px,v_px,role\n1,2,3,4,5,\n1,2,3,4,5,verify\n0,0,0,6,7,still\n",
        )
        .unwrap();
        assert_eq!((r.observations.len(), r.verification.len()), (1, 1));
        assert_eq!(r.still_target_px, vec![[6.0, 7.0]]);
        assert_eq!(
            parse_xytable("x_mm,y_mm,z_mm,u_px,v_px,role\n1,2,3,4,5,spare\n")
                .unwrap_err()
                .to_string(),
            "line 2, column 6: role: expected calibration, verify or still, got 'spare'"
        );
        assert!(parse_xytable("x_mm,y_mm,z_mm,image\n1,2,3,a.png\n")
            .unwrap_err()
            .to_string()
            .starts_with("line 2, column 4: a.png: image: the row names image 'a.png'"));
        let m = parse_known_motion("dx_mm,dy_mm,dz_mm,x_cam_mm,y_cam_mm,z_cam_mm\n0,0,0,1,2,3\n")
            .unwrap();
        assert_eq!(m.points_camera_mm, vec![[1.0, 2.0, 3.0]]);
    }
}
