//! KUKA KRL pose data as a pose file: the `E6POS`, `POS` and `FRAME`
//! aggregates of a `.dat` or `.src` file (`DECL E6POS XP1={X 1034.5,Y
//! -12.3,Z 876.0,A -178.2,B 2.1,C 179.0,S 6,T 27,E1 0.0}`), the variable
//! display of the pendant or a log (`{E6POS: X 1034.5, Y -12.3, ...}`),
//! and the `{X .., Y .., Z .., A .., B .., C ..}` that `robocal export
//! --format kuka` writes. Each aggregate with all of X Y Z A B C is one pose
//! in the `kuka` format (mm, degrees, `R = Rz(A) Ry(B) Rx(C)`), in the
//! order of the file: the variable names (`XP1`) name no image, so the
//! poses pair with the images in their numeric order, as any nameless
//! table does (or by `--pair-by`); the status and turn (`S`, `T`), the external axes (`E1`..`E6`)
//! and aggregates without a Cartesian pose (`FDAT`, `PDAT`, `E6AXIS`) are
//! left out. Comments run from `;` to the end of the line.

use super::pose_table::{Origin, Row, Table};
use crate::error::{Error, Result};

/// The Cartesian components of a KRL pose, in the `kuka` format's order.
const POSE_KEYS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// The table of a KRL text, or `None` when the text holds no KRL
/// aggregate with a Cartesian pose (it is then read as any other pose
/// file). An aggregate with some of X Y Z A B C but not all is an error at
/// its line.
pub(crate) fn table_from_krl(text: &str) -> Option<Result<Table>> {
    let mut rows = Vec::new();
    for (line_no, raw) in text.lines().enumerate() {
        let line = raw.split(';').next().unwrap_or_default();
        let mut rest = line;
        while let Some(open) = rest.find('{') {
            let Some(close) = rest[open..].find('}') else {
                break;
            };
            let body = &rest[open + 1..open + close];
            rest = &rest[open + close + 1..];
            let items = match aggregate_items(body) {
                Some(items) => items,
                None => continue,
            };
            let found: Vec<Option<&str>> = POSE_KEYS
                .iter()
                .map(|k| {
                    items
                        .iter()
                        .find(|(key, _)| key.eq_ignore_ascii_case(k))
                        .map(|(_, v)| *v)
                })
                .collect();
            let count = found.iter().filter(|v| v.is_some()).count();
            if count == 0 {
                continue;
            }
            if count < POSE_KEYS.len() {
                let missing: Vec<&str> = POSE_KEYS
                    .iter()
                    .zip(&found)
                    .filter(|(_, v)| v.is_none())
                    .map(|(k, _)| *k)
                    .collect();
                return Some(Err(Error::parse(
                    line_no + 1,
                    0,
                    format!(
                        "a KUKA pose needs X, Y, Z, A, B and C; this one has no {}",
                        missing.join(", ")
                    ),
                )));
            }
            rows.push(Row {
                origin: Origin::Line(line_no + 1),
                fields: found
                    .iter()
                    .map(|v| v.unwrap_or_default().to_string())
                    .collect(),
                field_lines: Vec::new(),
            });
        }
    }
    if rows.is_empty() {
        return None;
    }
    let header: Vec<String> = POSE_KEYS.iter().map(|k| k.to_string()).collect();
    Some(Ok(Table {
        header: Some((header, 0)),
        rows,
    }))
}

/// The `KEY value` items of an aggregate's body (`X 1.0,Y 2.0` or, after a
/// type, `E6POS: X 1.0, Y 2.0`), or `None` when the body is not a KRL
/// aggregate (e.g. JSON: quoted keys, colons between key and value).
fn aggregate_items(body: &str) -> Option<Vec<(&str, &str)>> {
    let body = match body.split_once(':') {
        Some((kind, rest)) if is_identifier(kind.trim()) => rest,
        Some(_) => return None,
        None => body,
    };
    let mut items = Vec::new();
    for item in body.split(',') {
        let mut parts = item.split_whitespace();
        let (Some(key), Some(value), None) = (parts.next(), parts.next(), parts.next()) else {
            // `POINT2[] " "` and other values with spaces: not a pose item.
            continue;
        };
        if !is_identifier(key) {
            return None;
        }
        items.push((key, value));
    }
    Some(items)
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_' || c == '$')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$')
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::poses::{parse_poses, PoseFileOptions};
    use crate::io::PoseFormat;
    use wasm_bindgen_test::wasm_bindgen_test;

    const DAT: &str = "DEFDAT CALIB
;FOLD EXTERNAL DECLARATIONS
DECL E6POS XP1={X 1034.5,Y -12.25,Z 876.0,A 90.0,B 0.0,C 180.0,S 6,T 27,E1 0.0,E2 0.0}
DECL FDAT FP1={TOOL_NO 1,BASE_NO 0,IPO_FRAME #BASE,POINT2[] \" \",TQ_STATE FALSE}
DECL E6POS XP2={X 1000.0,Y 0.0,Z 900.0,A 0.0,B 30.0,C 0.0,S 2,T 35} ; taught 2026-12-01
DECL E6AXIS XA3={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 0.0,A6 0.0}
ENDDAT
";

    #[wasm_bindgen_test(unsupported = test)]
    fn a_dat_file_gives_its_cartesian_poses_in_order() {
        let parsed = parse_poses(DAT, &PoseFileOptions::default()).unwrap();
        assert_eq!(parsed.format, PoseFormat::Kuka);
        assert_eq!(parsed.poses.len(), 2);
        let first = &parsed.poses[0];
        assert_eq!(first.name, None);
        assert_eq!(first.line, 3);
        let t = first.base_from_gripper.translation.vector;
        assert!(
            (t - nalgebra::Vector3::new(1.0345, -0.01225, 0.876)).norm() < 1e-12,
            "{t}"
        );
        // A 90, B 0, C 180: x -> y, y -> x, z -> -z.
        let r = first.base_from_gripper.rotation.to_rotation_matrix();
        let want = nalgebra::Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
        assert!((r.matrix() - want).norm() < 1e-12, "{r}");
        assert_eq!(parsed.poses[1].line, 5);
    }

    /// What `robocal export --format kuka` writes, and the pendant's
    /// variable display, read back.
    #[wasm_bindgen_test(unsupported = test)]
    fn robocal_s_kuka_export_and_the_pendant_display_read_back() {
        let export = "; gripper_from_camera for TOOL_DATA / BASE_DATA: mm, deg (A about Z, B about Y', C about X'')\n{X 10, Y 20, Z 30, A 0, B 0, C 90}\n";
        let parsed = parse_poses(export, &PoseFileOptions::default()).unwrap();
        assert_eq!(parsed.poses.len(), 1);
        assert_eq!(parsed.poses[0].name, None);
        let t = parsed.poses[0].base_from_gripper.translation.vector;
        assert!((t - nalgebra::Vector3::new(0.01, 0.02, 0.03)).norm() < 1e-12);
        let display = "{E6POS: X 10.0, Y 20.0, Z 30.0, A 0.0, B 0.0, C 90.0, S 2, T 35, E1 0.0}";
        let shown = parse_poses(display, &PoseFileOptions::default()).unwrap();
        assert_eq!(
            shown.poses[0].base_from_gripper,
            parsed.poses[0].base_from_gripper
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn a_pose_missing_a_component_is_named_at_its_line() {
        let text = "DECL E6POS XP1={X 1,Y 2,Z 3,A 0,B 0,C 0}\nDECL POS XP2={X 1,Y 2,Z 3,A 0}\n";
        let err = parse_poses(text, &PoseFileOptions::default()).unwrap_err();
        assert_eq!(
            err.to_string(),
            "line 2: a KUKA pose needs X, Y, Z, A, B and C; this one has no B, C"
        );
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn json_is_not_krl() {
        assert!(table_from_krl(r#"{"x": 1, "y": 2}"#).is_none());
        assert!(table_from_krl("x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1\n").is_none());
    }
}
