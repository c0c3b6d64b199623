//! CSV inputs of the industrial workflows (`robocal planar`, `robocal
//! xytable`), parsed from `&str` into the workflows' plain data.
//!
//! - planar matrices: header `height_mm,a11,a12,tx,a21,a22,ty`;
//! - planar points: header `height_mm,u_px,v_px,x_mm,y_mm`.
//!
//! Extra columns are allowed and ignored (e.g. a `corner` label); column
//! order is free.

use super::csv_table::CsvTable;
use crate::error::Result;
use crate::workflows::planar::PlanarMatrix;
use crate::workflows::planar_api::HeightMatrix;
use crate::workflows::planar_solve::HeightPoint;

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
}
