//! The summary `robocal rig` writes on standard error.

use robocal::calib::multi::rig_report::RigCalibration;

/// The summary on standard error: per camera views, rms, extrinsics with
/// std; the co-observation table; warnings.
pub fn summary(r: &RigCalibration) -> String {
    let seen = r
        .frames
        .iter()
        .filter(|f| f.rig_from_target.is_some())
        .count();
    let mut s = format!(
        "robocal rig: {} cameras, {seen} frames used, rms {:.4} px, rig frame {}\n",
        r.cameras.len(),
        r.rms_px,
        r.rig_frame
    );
    let width = r
        .cameras
        .iter()
        .map(|c| c.name.len())
        .max()
        .unwrap_or(4)
        .max(6);
    s += &format!(
        "  {:width$}  views  rms_px  translation_m (std mm)                        rotation_deg (std)\n",
        "camera"
    );
    for c in &r.cameras {
        if c.name == r.rig_frame {
            s += &format!(
                "  {:width$}  {:5}  {:6.4}  identity (the rig frame){}\n",
                c.name,
                c.frames_seen.len(),
                c.rms_px,
                if c.intrinsics_held {
                    "  (intrinsics held)"
                } else {
                    ""
                }
            );
            continue;
        }
        let t = c.camera_from_rig.translation_m;
        let rv = rotvec_deg(c.camera_from_rig.quaternion_xyzw);
        let (st, sr) = match &c.camera_from_rig_std {
            Some(sd) => (
                sd.translation_m.map(|v| v * 1e3),
                sd.rotation_rad.map(f64::to_degrees),
            ),
            None => ([0.0; 3], [0.0; 3]),
        };
        s += &format!(
            "  {:width$}  {:5}  {:6.4}  [{:8.5} ({:.2}) {:8.5} ({:.2}) {:8.5} ({:.2})]  [{:7.3} ({:.3}) {:7.3} ({:.3}) {:7.3} ({:.3})]{}\n",
            c.name,
            c.frames_seen.len(),
            c.rms_px,
            t[0], st[0], t[1], st[1], t[2], st[2],
            rv[0], sr[0], rv[1], sr[1], rv[2], sr[2],
            if c.intrinsics_held { "  (intrinsics held)" } else { "" }
        );
    }
    s += "  frames seen together:\n";
    s += &format!("  {:width$}", "");
    for c in &r.co_observation.cameras {
        s += &format!(" {:>width$}", c);
    }
    s += "\n";
    for (name, row) in r
        .co_observation
        .cameras
        .iter()
        .zip(&r.co_observation.frames)
    {
        s += &format!("  {name:width$}");
        for n in row {
            s += &format!(" {n:>width$}");
        }
        s += "\n";
    }
    for w in &r.warnings {
        s += &format!("robocal rig: warning: {w}\n");
    }
    s
}

/// The rotation vector of a quaternion (x, y, z, w), degrees.
fn rotvec_deg(q: [f64; 4]) -> [f64; 3] {
    let rotation = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        q[3], q[0], q[1], q[2],
    ));
    let v = robocal::geometry::rotvec_from_rotation(&rotation);
    [v.x.to_degrees(), v.y.to_degrees(), v.z.to_degrees()]
}
