//! `robocal export --format remap`: a dense undistortion map for OpenCV's
//! `cv2.remap`, for any lens model (the splined one included, which no
//! other tool's camera format holds).
//!
//! OpenCV FileStorage YAML: `image_width`, `image_height`, `camera_matrix`
//! (the distortion-free camera of the output image: the calibrated
//! `fx fy cx cy`, skew 0 dropped as OpenCV's), and `mapx`, `mapy`
//! (`!!opencv-matrix`, `rows` = height, `cols` = width, `dt: f`): output
//! pixel `(x, y)` samples the calibrated camera's image at
//! `(mapx[y][x], mapy[y][x])`, so
//!
//! ```python
//! fs = cv2.FileStorage("remap.yaml", cv2.FILE_STORAGE_READ)
//! undistorted = cv2.remap(image, fs.getNode("mapx").mat(), fs.getNode("mapy").mat(),
//!                         cv2.INTER_LINEAR)
//! ```
//!
//! Pixel centres at integers on both sides (OpenCV's and robocal's
//! convention). Output pixels whose ray the lens model cannot image get
//! `-1` (outside every image: `cv2.remap`'s border value). Values are
//! written with 3 decimals (1/1000 px); at 1280 x 960 the file is about
//! 20 MB.

use super::export_camera::float;
use crate::camera::Camera;
use crate::error::Result;
use std::fmt::Write;

/// The value of an output pixel without a source.
pub const NO_SOURCE: f32 = -1.0;

/// The remap YAML of `camera`, onto its distortion-free camera.
pub fn remap_yaml(camera: &Camera) -> Result<String> {
    let pinhole = camera.without_distortion();
    let map = camera.undistort_map(&pinhole)?;
    let (w, h) = (map.width as usize, map.height as usize);
    let mut out = String::with_capacity(2 * 9 * w * h + 1024);
    out += "%YAML:1.0\n---\n";
    let _ = writeln!(
        out,
        "image_width: {}\nimage_height: {}",
        map.width, map.height
    );
    let k = [
        pinhole.fx,
        pinhole.skew,
        pinhole.cx,
        0.0,
        pinhole.fy,
        pinhole.cy,
        0.0,
        0.0,
        1.0,
    ];
    let k: Vec<String> = k.iter().map(|v| float(*v)).collect();
    let _ = writeln!(
        out,
        "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ {} ]",
        k.join(", ")
    );
    for (name, values) in [("mapx", &map.map_x), ("mapy", &map.map_y)] {
        let _ = write!(
            out,
            "{name}: !!opencv-matrix\n   rows: {h}\n   cols: {w}\n   dt: f\n   data: ["
        );
        for (i, v) in values.iter().enumerate() {
            let v = if v.is_finite() { *v } else { NO_SOURCE };
            let sep = if i == 0 { " " } else { ", " };
            // A line per image row keeps the file readable by line tools.
            let sep = if i > 0 && i % w == 0 {
                ",\n      "
            } else {
                sep
            };
            let _ = write!(out, "{sep}{v:.3}");
        }
        out += " ]\n";
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Distortion, UndistortMap};
    use crate::image::remap_gray;
    use crate::synth::render::{render, RenderOptions};
    use crate::target::Target;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    /// The values of matrix `name` in a remap YAML.
    fn matrix(yaml: &str, name: &str) -> Vec<f32> {
        let start = yaml
            .find(&format!("{name}: !!opencv-matrix"))
            .expect("matrix");
        let rest = &yaml[start..];
        let open = rest.find('[').expect("[");
        let close = rest.find(']').expect("]");
        rest[open + 1..close]
            .split(',')
            .map(|v| v.trim().parse().expect("number"))
            .collect()
    }

    /// A 320x240 wide-angle lens with 1.5 px bumps (no parametric model
    /// fits it).
    fn lens() -> Camera {
        let base = Camera {
            distortion: Distortion::Brown {
                k1: -0.3,
                k2: 0.1,
                k3: 0.0,
                p1: 0.001,
                p2: -0.0005,
            },
            ..Camera::pinhole(240.0, 241.0, 160.4, 119.7, 320, 240)
        };
        crate::synth::lens::bumpy_lens(&base, 1.5).expect("lens")
    }

    #[test]
    fn remapping_a_rendered_image_through_the_export_matches_the_undistorted_truth() {
        let camera = lens();
        let yaml = remap_yaml(&camera).expect("export");
        assert!(yaml.starts_with("%YAML:1.0\n---\nimage_width: 320\nimage_height: 240\n"));
        let map = UndistortMap {
            width: 320,
            height: 240,
            map_x: matrix(&yaml, "mapx"),
            map_y: matrix(&yaml, "mapy"),
        };
        assert_eq!(map.map_x.len(), 320 * 240);
        let target = Target::parse_spec("chessboard:9x6:30mm").expect("target");
        let pose = Isometry3::from_parts(
            Translation3::new(-0.14, -0.09, 0.42),
            UnitQuaternion::from_euler_angles(0.25, -0.2, 0.1),
        );
        let options = RenderOptions {
            noise_sigma: 0.0,
            blur_sigma_px: 1.0,
            ..RenderOptions::default()
        };
        let seen = render(&camera, &target, &pose, &options)
            .expect("render")
            .image;
        let truth = render(&camera.without_distortion(), &target, &pose, &options)
            .expect("render")
            .image;
        let mean_abs = |img: &crate::image::GrayImage| {
            let (mut sum, mut n) = (0.0, 0usize);
            for y in 10..230usize {
                for x in 10..310usize {
                    let i = y * 320 + x;
                    if map.map_x[i] < 1.0 || map.map_y[i] < 1.0 {
                        continue;
                    }
                    sum += (img.pixels[i] as f64 - truth.pixels[i] as f64).abs();
                    n += 1;
                }
            }
            sum / n.max(1) as f64
        };
        let remapped = remap_gray(&seen, &map);
        let through_map = mean_abs(&remapped);
        let as_seen = mean_abs(&seen);
        assert!(through_map < 2.0, "mean |remapped - truth| {through_map}");
        assert!(
            as_seen > 3.0 * through_map,
            "distorted {as_seen}, remapped {through_map}"
        );
    }
}
