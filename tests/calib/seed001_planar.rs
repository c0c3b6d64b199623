//! The seed-001 article's published tables, reproduced (fixtures/seed001,
//! see PROVENANCE.md there).
//!
//! Tolerances and why:
//! - Table 4 -> Table 5: the fit is plain least squares on the printed
//!   Table 4 values. The article fitted unrounded values, and Table 4 prints
//!   some columns (a11, a22) to only 5 decimals, so each intercept, slope and
//!   RSS must agree with Table 5 within half a unit of Table 5's last printed
//!   digit plus the worst-case effect of Table 4's rounding of that column
//!   (half a unit of its coarsest printed digit, propagated exactly through
//!   the least-squares formulas); R^2, adjusted R^2 and Pearson's r to 3
//!   decimals, as the issue asks. Measured: every value except a11's
//!   intercept, slope and RSS agrees to every printed digit.
//! - Table 3 -> Table 4: an *affine* least-squares fit of the four corners
//!   per height reproduces Table 4 to its printed digits (the article's
//!   "rigid" matrix is affine: a12 != a21). Differences come only from the
//!   rounding of Table 3 (pixels to 3-4 decimals, robot to 0.01 mm), so the
//!   linear part must agree within one unit of Table 4's last printed digit
//!   (at least 1e-6 mm/px) and the translation within 1e-3 mm. At 105 mm
//!   corner B's printed u = 145.789 px is a typo (see PROVENANCE.md): with
//!   all four corners the fit is off by more than 0.1 mm/px; with the three
//!   good corners (an exact, non-averaged fit) within 2e-4 mm/px and 0.3 mm.
//! - Table 6 from Table 3 corners: same formula as the article's Eq. (15), to
//!   its 6 printed decimals (1e-6 px/mm), at the heights whose corners are
//!   printed consistently (15, 45, 75 mm).
//! - Table 7: the article prints no pixel coordinates for its verification
//!   points. We recover them by inverting the article's own Eq. (11)
//!   (Table 5 coefficients) at the calculated X, Y, map them with robocal's
//!   fit of Table 4, and require the article's stated bound: error < 0.08 %
//!   of the measured coordinate; and agreement with the article's calculated
//!   X, Y within one unit of the last printed digit of every Table 5
//!   coefficient propagated through (u, v, H) (Table 5 is rounded).

use robocal::io::csv_table::CsvTable;
use robocal::workflows::linear_fit::LinearFit;
use robocal::workflows::planar::{fit_transform, PlanarMatrix, PointPair, TransformKind};
use robocal::workflows::planar_height::{pixel_density, HeightModel};

const TABLE3: &str = include_str!("../../fixtures/seed001/table3_four_points.csv");
const TABLE4: &str = include_str!("../../fixtures/seed001/table4_matrices.csv");
const TABLE5: &str = include_str!("../../fixtures/seed001/table5_linear_fit.csv");
const TABLE6: &str = include_str!("../../fixtures/seed001/table6_pixel_ratio.csv");
const TABLE7: &str = include_str!("../../fixtures/seed001/table7_verification.csv");

fn table4() -> (Vec<f64>, Vec<PlanarMatrix>) {
    let t = CsvTable::parse(TABLE4).unwrap();
    let cols = t
        .require_columns(&["height_mm", "a11", "a12", "tx", "a21", "a22", "ty"])
        .unwrap();
    let rows = t.numbers(&cols).unwrap();
    let h = rows.iter().map(|r| r[0]).collect();
    let m = rows
        .iter()
        .map(|r| PlanarMatrix::from_array([r[1], r[2], r[3], r[4], r[5], r[6]]))
        .collect();
    (h, m)
}

/// One unit of the last printed digit of a number written like "-0.00561"
/// or "1.16124e-5".
fn last_digit_unit(text: &str) -> f64 {
    let (mantissa, exp) = match text.split_once(['e', 'E']) {
        Some((m, e)) => (m, e.parse::<i32>().unwrap()),
        None => (text, 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    10f64.powi(exp - decimals)
}

/// Half a unit of the coarsest printed digit of column `col` of `table`.
fn half_unit_of_column(table: &CsvTable, col: usize) -> f64 {
    (0..table.len())
        .map(|r| last_digit_unit(table.text(r, col)))
        .fold(0.0, f64::max)
        / 2.0
}

/// Worst-case change of (intercept, slope, RSS) of a line fit when every y
/// moves by at most `delta`: the fitted coefficients are linear in y, and
/// |dRSS| <= 2 sqrt(RSS) |e| + |e|^2 with |e| <= sqrt(n) delta.
fn rounding_bounds(x: &[f64], rss: f64, delta: f64) -> [f64; 3] {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let slope: f64 = x.iter().map(|v| ((v - mx) / sxx).abs()).sum::<f64>() * delta;
    let intercept: f64 = x
        .iter()
        .map(|v| (1.0 / n - mx * (v - mx) / sxx).abs())
        .sum::<f64>()
        * delta;
    let e = n.sqrt() * delta;
    [intercept, slope, 2.0 * rss.sqrt() * e + e * e]
}

#[test]
fn table4_fit_reproduces_table5() {
    let (h, m) = table4();
    let t4 = CsvTable::parse(TABLE4).unwrap();
    let model = HeightModel::fit(&h, &m, None).unwrap();
    let t5 = CsvTable::parse(TABLE5).unwrap();
    let fits = model.fit.to_array();
    for row in 0..t5.len() {
        let name = t5.text(row, 0);
        let k = PlanarMatrix::NAMES.iter().position(|n| *n == name).unwrap();
        let f: &LinearFit = fits[k];
        let bounds = rounding_bounds(&h, f.rss, half_unit_of_column(&t4, k + 1));
        for (col, ours, what, extra) in [
            (1, f.intercept, "intercept", bounds[0]),
            (2, f.slope, "slope", bounds[1]),
            (3, f.rss, "RSS", bounds[2]),
        ] {
            let text = t5.text(row, col);
            let published: f64 = text.parse().unwrap();
            let tol = last_digit_unit(text) / 2.0 + extra;
            assert!(
                (ours - published).abs() <= tol * (1.0 + 1e-9),
                "{name} {what}: ours {ours:e}, Table 5 {text} (tolerance {tol:e})"
            );
        }
        for (col, ours, what) in [
            (4, f.pearson_r.unwrap(), "Pearson r"),
            (5, f.r2.unwrap(), "R^2"),
            (6, f.adj_r2.unwrap(), "adj R^2"),
        ] {
            let published: f64 = t5.text(row, col).parse().unwrap();
            assert!(
                (ours - published).abs() < 5e-4,
                "{name} {what}: ours {ours:.5}, Table 5 {published} (3 decimals)"
            );
        }
    }
}

#[test]
fn rejection_drops_the_dispersed_heights_of_a11_and_a22() {
    // The article: "except for A11 and A22 ... the points with high
    // dispersion can be eliminated and refitted"; it also flags H = 105 mm.
    let (h, m) = table4();
    let model = HeightModel::fit(&h, &m, Some(3.0)).unwrap();
    let r = &model.rejected_heights_mm;
    assert_eq!(r.a11, vec![55.0, 105.0]);
    assert_eq!(r.a22, vec![55.0, 105.0]);
    assert!(r.a12.is_empty() && r.tx.is_empty() && r.a21.is_empty() && r.ty.is_empty());
    // After the refit a11 and a22 are clearly linear (R^2 0.58 and 0.49
    // before; measured after: 0.982 and 0.995).
    assert!(
        model.fit.a11.r2.unwrap() > 0.95,
        "a11 R^2 {:?}",
        model.fit.a11.r2
    );
    assert!(
        model.fit.a22.r2.unwrap() > 0.95,
        "a22 R^2 {:?}",
        model.fit.a22.r2
    );
}

fn table3_groups() -> Vec<(f64, Vec<PointPair>)> {
    let t = CsvTable::parse(TABLE3).unwrap();
    let cols = t
        .require_columns(&["height_mm", "x_mm", "y_mm", "u_px", "v_px"])
        .unwrap();
    let rows = t.numbers(&cols).unwrap();
    rows.chunks(4)
        .map(|g| {
            let pairs = g
                .iter()
                .map(|r| PointPair {
                    image_px: [r[3], r[4]],
                    robot_mm: [r[1], r[2]],
                })
                .collect();
            (g[0][0], pairs)
        })
        .collect()
}

fn table4_row(height: f64) -> (PlanarMatrix, Vec<f64>) {
    let t4 = CsvTable::parse(TABLE4).unwrap();
    let (h, m) = table4();
    let i = h.iter().position(|v| *v == height).unwrap();
    let units = (1..=6).map(|c| last_digit_unit(t4.text(i, c))).collect();
    (m[i], units)
}

#[test]
fn table3_corners_give_table4_matrices() {
    for (height, pairs) in table3_groups() {
        let (published, units) = table4_row(height);
        let p = published.to_array();
        if height == 105.0 {
            let all = fit_transform(&pairs, TransformKind::Affine)
                .unwrap()
                .robot_from_image
                .to_array();
            assert!(
                (all[3] - p[3]).abs() > 0.1,
                "the typo in corner B should show: a21 {}",
                all[3]
            );
            let good = [pairs[0], pairs[2], pairs[3]];
            let ours = fit_transform(&good, TransformKind::Affine)
                .unwrap()
                .robot_from_image
                .to_array();
            for k in 0..6 {
                let tol = if k == 2 || k == 5 { 0.3 } else { 2e-4 };
                assert!(
                    (ours[k] - p[k]).abs() < tol,
                    "105 mm {}: ours {} vs {}",
                    PlanarMatrix::NAMES[k],
                    ours[k],
                    p[k]
                );
            }
            continue;
        }
        let ours = fit_transform(&pairs, TransformKind::Affine)
            .unwrap()
            .robot_from_image
            .to_array();
        for k in 0..6 {
            let tol = if k == 2 || k == 5 {
                1e-3
            } else {
                units[k].max(1e-6)
            };
            assert!(
                (ours[k] - p[k]).abs() <= tol,
                "{height} mm {}: ours {} vs Table 4 {} (tolerance {tol:e})",
                PlanarMatrix::NAMES[k],
                ours[k],
                p[k]
            );
        }
    }
}

#[test]
fn table3_corners_give_table6_pixel_ratios() {
    let t6 = CsvTable::parse(TABLE6).unwrap();
    let cols = t6
        .require_columns(&[
            "height_mm",
            "length_mm",
            "width_mm",
            "pr_length_px_per_mm",
            "pr_width_px_per_mm",
        ])
        .unwrap();
    let rows = t6.numbers(&cols).unwrap();
    for (height, p) in table3_groups().into_iter().filter(|(h, _)| *h != 105.0) {
        let r = rows.iter().find(|r| r[0] == height).unwrap();
        let corners = [p[0].image_px, p[1].image_px, p[2].image_px, p[3].image_px];
        let d = pixel_density(height, &corners, r[1], r[2]).unwrap();
        assert!(
            (d.length_px_per_mm - r[3]).abs() < 1e-6,
            "{height} mm length: {} vs {}",
            d.length_px_per_mm,
            r[3]
        );
        assert!(
            (d.width_px_per_mm - r[4]).abs() < 1e-6,
            "{height} mm width: {} vs {}",
            d.width_px_per_mm,
            r[4]
        );
    }
}

#[test]
fn table7_points_map_within_the_reported_error() {
    let (h, m) = table4();
    let model = HeightModel::fit(&h, &m, None).unwrap();
    let t5 = CsvTable::parse(TABLE5).unwrap();
    let coef = |k: usize, col: usize| -> (f64, f64) {
        let text = t5.text(k, col);
        (text.parse().unwrap(), last_digit_unit(text))
    };
    let t7 = CsvTable::parse(TABLE7).unwrap();
    let cols = t7
        .require_columns(&[
            "height_mm",
            "measured_x_mm",
            "measured_y_mm",
            "calculated_x_mm",
            "calculated_y_mm",
        ])
        .unwrap();
    for r in t7.numbers(&cols).unwrap() {
        let height = r[0];
        // The article's Eq. (11) at this height, from Table 5 (rows in a11..ty order).
        let paper = PlanarMatrix::from_array(std::array::from_fn(|k| {
            coef(k, 1).0 + coef(k, 2).0 * height
        }));
        let px = paper.apply_inverse([r[3], r[4]]).unwrap();
        let ours = model.map(height, px);
        // One unit of every printed Table 5 digit, through x = a11 u + a12 v + tx.
        let w = [px[0].abs(), px[1].abs(), 1.0];
        let tol: [f64; 2] = std::array::from_fn(|axis| {
            (0..3)
                .map(|j| (coef(3 * axis + j, 1).1 + coef(3 * axis + j, 2).1 * height) * w[j])
                .sum()
        });
        for axis in 0..2 {
            let (measured, calculated) = (r[1 + axis], r[3 + axis]);
            let err_percent = 100.0 * (ours.robot_mm[axis] - measured).abs() / measured.abs();
            assert!(
                err_percent < 0.08,
                "{height} mm axis {axis}: error {err_percent:.4} % >= 0.08 %"
            );
            assert!(
                (ours.robot_mm[axis] - calculated).abs() < tol[axis],
                "{height} mm axis {axis}: ours {} mm vs article {calculated} mm (tolerance {} mm)",
                ours.robot_mm[axis],
                tol[axis]
            );
        }
    }
}
