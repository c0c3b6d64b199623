//! A seeded Monte Carlo of `robocal laser sphere` (src/laser/sphere.rs) on
//! renders: the 60 mm sphere of `synth::laser_sphere` scanned at N robot
//! poses (640x480, f 800, mild barrel; noise 2 grey, new noise seeds every
//! trial), the stripe extracted (centre of gravity), the plane, mounting
//! and sphere centre refined from starts 1 deg / 2 mm (plane) and 2 deg /
//! 5 mm (mounting) off. Each estimate's error against the truth is
//! compared with the reported covariance: RMS over the trials against the
//! RMS of the reported std (the bound; vectors: the root of the mean
//! trace), and the share of trials within 3 std (chi^2 of the error with
//! the reported covariance below the 99.73 % quantile of its dof).
//!
//! Each robot pose is moved a little every trial (up to 2 mm and 0.5 deg;
//! `fixed` after the scans keeps them): with the poses fixed, the
//! extractor's systematic error on the rendered sphere is the same draw
//! in every trial and the trials only vary the image noise (s27: the
//! estimates' scatter about their mean was 1/8 of their RMS error).
//! The table also gives each estimate's mean error over the trials and
//! the RMS scatter about it.
//!
//! `cargo run --release --example laser_sphere_mc [TRIALS] [SCANS] [fixed]`
//! (default 200 and 8).

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use robocal::geometry::{tangent_basis, Pose};
use robocal::laser::sphere::calibrate_on_sphere;
use robocal::rng::Rng;
use robocal::synth::laser_scene::example_plane;
use robocal::synth::laser_sphere::{
    example_mounting, example_sensor_camera, example_sphere, example_starts, rendered_scans,
    sphere_scan_poses,
};

/// chi^2 quantiles at 0.9973 (3 sigma) for 1, 2 and 3 dof.
const CHI2_3SIGMA: [f64; 3] = [9.0, 11.829, 14.156];

#[derive(Default)]
struct Score {
    se: f64,
    sb: f64,
    cover: usize,
    trials: usize,
    /// The errors' sum (the bias: the mean error over the trials).
    sum: Vec<f64>,
}

impl Score {
    /// One trial: the error (in the covariance's coordinates) and the
    /// reported covariance.
    fn add(&mut self, e: &DVector<f64>, c: &DMatrix<f64>) {
        self.se += e.norm_squared();
        if self.sum.len() != e.len() {
            self.sum = vec![0.0; e.len()];
        }
        for (s, v) in self.sum.iter_mut().zip(e.iter()) {
            *s += v;
        }
        self.sb += c.trace();
        if let Some(inv) = c.clone().try_inverse() {
            if (e.transpose() * inv * e)[0] <= CHI2_3SIGMA[e.len() - 1] {
                self.cover += 1;
            }
        }
        self.trials += 1;
    }

    fn row(&self, name: &str, unit: f64, unit_name: &str) -> String {
        let t = self.trials.max(1) as f64;
        let (r, b) = ((self.se / t).sqrt() * unit, (self.sb / t).sqrt() * unit);
        let mean2 = self.sum.iter().map(|s| (s / t).powi(2)).sum::<f64>();
        let scatter = (self.se / t - mean2).max(0.0).sqrt() * unit;
        format!(
            "| {name} | {r:.4} | {b:.4} | {:.2} | {:.1} % | {:.4} | {scatter:.4} | {unit_name} |",
            r / b,
            100.0 * self.cover as f64 / t,
            mean2.sqrt() * unit
        )
    }
}

/// Each robot pose's move per trial (without `fixed`): uniform in +-2 mm
/// along and +-0.5 deg about each flange axis.
const JITTER_M: f64 = 0.002;
const JITTER_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;

fn main() -> Result<(), robocal::Error> {
    let mut args = std::env::args().skip(1);
    let trials: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(200);
    let n_scans: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(8);
    let fixed = args.any(|a| a == "fixed");
    let (plane, mount, scene) = (example_plane(), example_mounting(), example_sphere());
    let cam = example_sensor_camera();
    let poses = sphere_scan_poses(n_scans, &scene, &mount, &plane);
    // The starts of the sphere tests (src/laser/sphere_tests.rs).
    let (start_plane, start_mount) = example_starts(&plane, &mount);
    let mut scores: [Score; 5] = Default::default();
    let mut failed = 0;
    for trial in 0..trials {
        let first_seed = 1_000_003 * trial as u64 + 11;
        // Each robot pose moved a little (without `fixed`): the stripe
        // crosses the sphere at new pixels, so the extractor's systematic
        // error there is a new draw each trial, as between two real runs.
        let mut jitter = Rng::new(first_seed ^ 0x0005_1DE5);
        let trial_poses: Vec<Pose> = poses
            .iter()
            .map(|p| {
                if fixed {
                    return *p;
                }
                let mut u = |h: f64| jitter.range(-h, h);
                let w = Vector3::new(u(JITTER_RAD), u(JITTER_RAD), u(JITTER_RAD));
                let v = Vector3::new(u(JITTER_M), u(JITTER_M), u(JITTER_M));
                p * Pose::from_parts(v.into(), nalgebra::UnitQuaternion::from_scaled_axis(w))
            })
            .collect();
        let scans = rendered_scans(&cam, &trial_poses, &mount, &plane, &scene, first_seed)?;
        let c = match calibrate_on_sphere(&cam, &scans, scene.radius_m, &start_plane, &start_mount)
        {
            Ok(c) => c,
            Err(e) => {
                eprintln!("trial {trial}: {e}");
                failed += 1;
                continue;
            }
        };
        // The plane: (a, b) in the estimate's tangent basis, then d.
        let p = &c.plane_camera;
        let (e1, e2) = tangent_basis(&p.plane.normal);
        let dn = p.plane.normal.into_inner() - plane.normal.into_inner();
        let cov = DMatrix::from_fn(3, 3, |r, k| p.covariance[(r, k)]);
        scores[0].add(
            &DVector::from_vec(vec![-dn.dot(&e2), dn.dot(&e1)]),
            &cov.view((0, 0), (2, 2)).into_owned(),
        );
        scores[1].add(
            &DVector::from_vec(vec![p.plane.distance_m - plane.distance_m]),
            &cov.view((2, 2), (1, 1)).into_owned(),
        );
        // The mounting's right perturbation: truth^-1 * estimate.
        let diff: Pose = mount.inverse() * c.gripper_from_camera;
        let m = &c.gripper_from_camera_covariance;
        let w = diff.rotation.scaled_axis();
        scores[2].add(
            &DVector::from_column_slice(w.as_slice()),
            &DMatrix::from_fn(3, 3, |r, k| m[(r, k)]),
        );
        let v = diff.translation.vector;
        scores[3].add(
            &DVector::from_column_slice(v.as_slice()),
            &DMatrix::from_fn(3, 3, |r, k| m[(3 + r, 3 + k)]),
        );
        let e: Vector3<f64> = c.centre_base - scene.centre_base;
        let cc: Matrix3<f64> = c.centre_covariance;
        scores[4].add(
            &DVector::from_column_slice(e.as_slice()),
            &DMatrix::from_fn(3, 3, |r, k| cc[(r, k)]),
        );
    }
    println!(
        "laser sphere Monte Carlo: {} trials ({failed} failed), {n_scans} scans, robot poses {}",
        scores[0].trials,
        if fixed {
            "fixed"
        } else {
            "moved a little each trial"
        }
    );
    println!(
        "| estimate | RMS error | RMS std (bound) | RMS / bound | within 3 std | mean error | scatter about it | unit |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let deg = 1f64.to_degrees();
    println!("{}", scores[0].row("plane normal", deg, "deg"));
    println!("{}", scores[1].row("plane distance", 1e3, "mm"));
    println!("{}", scores[2].row("mounting rotation", deg, "deg"));
    println!("{}", scores[3].row("mounting translation", 1e3, "mm"));
    println!("{}", scores[4].row("sphere centre", 1e3, "mm"));
    Ok(())
}
