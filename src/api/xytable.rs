//! The requests and reports of the seed workflows with a stage or a robot
//! moving one point: the XY-table camera calibration (seed 002: batch DLT
//! and the Kalman filter, `xytable_solve`, `robocal xytable`) and the
//! camera-to-reference frame from known motions (seed 000,
//! `known_motion_solve`, `robocal xytable --known-motion`). The solvers and
//! their serde types live in [`crate::workflows`]; this file is the one
//! entry point the wasm boundary and the CLI call, so both read a request
//! the same way (the CSV readers of `io::workflow_csv` make the same
//! requests from files).

use crate::error::Result;
pub use crate::workflows::known_motion::{KnownMotionReport, KnownMotionRequest};
pub use crate::workflows::xytable::{
    MethodResult, NoiseSource, StageObservation, Verification, XyTableReport, XyTableRequest,
};

/// XY-table calibration: the batch DLT, the Kalman filter and the
/// verification point ([`crate::workflows::xytable::solve_xytable`]).
pub fn xytable(request: &XyTableRequest) -> Result<XyTableReport> {
    crate::workflows::xytable::solve_xytable(request)
}

/// The camera-to-reference frame from known motions of one point
/// ([`crate::workflows::known_motion::solve_known_motion`]).
pub fn known_motion(request: &KnownMotionRequest) -> Result<KnownMotionReport> {
    crate::workflows::known_motion::solve_known_motion(request)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// The request read from JSON as the page sends it gives the report of
    /// the solver: a camera that sees the stage points exactly.
    #[wasm_bindgen_test(unsupported = test)]
    fn a_json_request_solves_to_the_exact_camera() {
        // A pinhole camera 1 m above the stage looking down (turned half a
        // turn about the stage's x axis): u = 800 x/z + 320, v = -800 y/z + 240.
        let project = |p: [f64; 3]| {
            let z = 1000.0 - p[2];
            [800.0 * p[0] / z + 320.0, -800.0 * p[1] / z + 240.0]
        };
        let stage: Vec<[f64; 3]> = (0..8)
            .map(|i| {
                let i = i as f64;
                [
                    20.0 * (i % 3.0) - 20.0,
                    15.0 * (i % 4.0) - 20.0,
                    10.0 * (i % 2.0) + 5.0 * i,
                ]
            })
            .collect();
        let observations: Vec<_> = stage
            .iter()
            .map(|p| serde_json::json!({"stage_mm": p, "image_px": project(*p)}))
            .collect();
        let text = serde_json::json!({
            "observations": observations,
            "measurement_noise_px2": [[0.01, 0.0], [0.0, 0.01]]
        })
        .to_string();
        let request: XyTableRequest = serde_json::from_str(&text).unwrap();
        let report = xytable(&request).unwrap();
        assert!(
            report.batch.rms_px < 1e-6,
            "batch rms {}",
            report.batch.rms_px
        );
        let k = report.batch.camera_matrix;
        assert!((k[0] / k[8] - 800.0).abs() < 1e-4, "fx {}", k[0] / k[8]);
        assert_eq!(report.noise_source, NoiseSource::Given);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn known_motions_give_the_start_point() {
        let request = KnownMotionRequest {
            increments_mm: vec![
                [0.0; 3],
                [10.0, 0.0, 0.0],
                [0.0, 10.0, 0.0],
                [0.0, 0.0, 10.0],
            ],
            points_camera_mm: vec![
                [1.0, 2.0, 500.0],
                [11.0, 2.0, 500.0],
                [1.0, 12.0, 500.0],
                [1.0, 2.0, 510.0],
            ],
            start_reference_mm: None,
        };
        let report = known_motion(&request).unwrap();
        assert!(report.rms_mm < 1e-9, "rms {}", report.rms_mm);
        for (got, want) in report.start_camera_mm.iter().zip([1.0, 2.0, 500.0]) {
            assert!((got - want).abs() < 1e-9, "start {got} vs {want}");
        }
        assert!(!report.reference_origin_given);
    }
}
