//! `robocal render`: synthetic calibration images from the project's seeded
//! generator, with their exact ground truth.

use super::CliError;
use robocal::camera::Camera;
use robocal::io::export_transform::transform_json;
use robocal::synth::demo::{demo_camera, demo_session};
use robocal::synth::effects::{Bayer, Effects, MotionBlur, Optics, Paper, SensorNoise};
use robocal::synth::{render, RenderOptions, Scene};
use robocal::target::{Polarity, Target};
use std::path::Path;

#[derive(clap::Args)]
#[command(
    about = "synthetic target images with exact ground truth (and the demo session)",
    long_about = "synthetic target images with exact ground truth

  robocal render --out DIR [--target SPEC] [--views N] [--seed N]
                 [--camera camera.json] [--noise GREY] [--blur PX]
                 [--effects realistic] [--gamma G] [--defocus PX] ...
  robocal render --out DIR --demo [--seed N]
  robocal render --out DIR --rig [--views N] [--side-frames N] [--seed N]
  robocal render --video board.y4m [--size WxH] [--fps N] [--target SPEC]
                 [--seed N] [--truth FILE] [--camera camera.json]

Renders N views of the target (random poses: tilt up to 45 degrees, the
target spanning 35-60 % of the image width) through the camera, supersampled,
with blur, vignetting and Gaussian grey-level noise, and writes
DIR/view_000.png ... plus DIR/truth.json: {\"camera\", \"target\",
\"views\": [{\"image\", \"camera_from_target\", \"points\": [{id, x_px, y_px}]}]}
with the exact projection of every target point (pixel centres at integer
coordinates).

Camera effects (image sets only; default none, and renders without them
are unchanged): --effects realistic turns on a cheap camera's gamma, lens
blur growing to the corners, motion blur, Bayer mosaic and demosaic, shot
and read noise, JPEG and paper texture; each effect flag sets or overrides
one of them. The truth stays the ideal projection (with --rolling-shutter,
the sheared position where the point is imaged).

--laser-plane nx,ny,nz,d renders each view twice: view_NNN.png with the
laser off and view_NNN_laser.png with a laser stripe (the plane n . X = d
in the camera frame met with the board: a Gaussian cross-profile of
--laser-width px FWHM, speckle, clipping at 255; docs/laser.md); truth.json
gains \"laser_plane\": {\"normal_camera\", \"distance_m\"} and per view
\"stripe_image\", \"stripe_axis\" and \"stripe_px\" (the exact centre per
column or row).

--demo writes the web app's demo session instead: 12 chessboard images, the
robot poses that go with them (DIR/poses.csv, Universal Robots format with an
image column) and truth.json with gripper_from_camera and base_from_target.

--rig writes a four-camera rig (robocal::synth::rig: two pairs of 1280x960
cameras facing each other across a 1.2 m circle) seeing a 10x7 chessboard
(60 mm squares): N frames facing each pair, --side-frames frames (default 4)
facing half-way between cam1 and cam2, the only frames that link the two
pairs (0: two groups no frame connects). Each camera's images go to
DIR/camK/camK_FFF.png (FFF: the frame), only where the camera faces the
board; DIR/truth.json: {\"target\", \"rig_frame\", \"cameras\": [{name,
camera, camera_from_rig, images: [{image, frame}]}], \"frames\": [{key,
rig_from_target}]}.

--video writes a Y4M video (4:2:0, 8-bit; 640x480 at 15 fps by default,
about 28 s) of the board sliding into view, then holding still for 1 s at
each of 12 poses (the nine regions of the image, tilts about both axes,
near and far) with smooth 1.2 s moves between them: what Chromium's fake
camera plays (--use-fake-device-for-media-stream
--use-file-for-fake-video-capture=board.y4m). Grey levels are written as
video-range luma (16 + 219 g / 255). The truth goes beside it (board.json,
or --truth FILE): {\"camera\", \"target\", \"options\", \"video\", \"size_px\",
\"frames\": [{index, time_ms, camera_from_target, hold, points}],
\"holds\": [{first_frame, last_frame, camera_from_target}]}; hold is the
frame's hold index or null while the board moves.",
    after_help = "Examples:
  robocal render --out renders --views 20 --seed 7
  robocal render --out real --views 20 --effects realistic --noise 0
  robocal render --out coma --coma 1.5 --astigmatism 1 --gamma 2.2
  robocal render --out demo --demo
  robocal render --out laser --views 4 --laser-plane 0,-0.98,0.196,0.098
  robocal render --out rig --rig --views 5 --side-frames 3
  robocal render --video board.y4m --size 1280x720 --target charuco:12x9:20mm:15mm:DICT_5X5_100",
    args_override_self = true
)]
pub struct RenderArgs {
    /// The folder to write into (created if missing)
    #[arg(long, value_name = "DIR")]
    out: Option<String>,
    /// chessboard:9x6:30mm (default), circles:..., dots:..., squares:...;
    /// add :light-on-dark for the print inverted (any kind)
    #[arg(long, value_name = "SPEC")]
    target: Option<String>,
    /// Number of images
    #[arg(long, value_name = "N", default_value_t = 12)]
    views: usize,
    /// Random seed; equal seeds give equal files
    #[arg(long, value_name = "N", default_value_t = 1)]
    seed: u64,
    /// The camera (robocal/OpenCV/ROS camera file; default: a 1024x768 camera
    /// with barrel distortion)
    #[arg(long, value_name = "FILE")]
    camera: Option<String>,
    /// Grey-level noise sigma
    #[arg(
        long,
        value_name = "GREY",
        default_value_t = 2.0,
        allow_negative_numbers = true
    )]
    noise: f64,
    /// Gaussian blur sigma in pixels
    #[arg(
        long,
        value_name = "PX",
        default_value_t = 0.7,
        allow_negative_numbers = true
    )]
    blur: f64,
    /// Write the web app's demo session instead
    #[arg(long)]
    demo: bool,
    /// Write a four-camera rig's images instead (--views: frames facing each pair)
    #[arg(long, conflicts_with = "demo")]
    rig: bool,
    /// With --rig: frames seen by cam1 and cam2 that link the two pairs
    #[arg(long, value_name = "N", default_value_t = 4, requires = "rig")]
    side_frames: usize,
    /// Write a Y4M video of the board moving through poses with holds
    #[arg(long, value_name = "FILE", conflicts_with_all = ["out", "demo", "views", "rig"])]
    video: Option<String>,
    /// With --video: frame size WIDTHxHEIGHT (even sides)
    #[arg(
        long,
        value_name = "WxH",
        default_value = "640x480",
        requires = "video"
    )]
    size: String,
    /// With --video: frames per second
    #[arg(long, value_name = "N", default_value_t = 15.0, requires = "video")]
    fps: f64,
    /// With --video: the truth file (default: the video's name with .json)
    #[arg(long, value_name = "FILE", requires = "video")]
    truth: Option<String>,
    /// Render through a lens no parametric model fits: the camera's own
    /// projection as a 12x8 splined lens plus smooth bumps of PX pixels
    /// (truth.json holds that splined camera)
    #[arg(long, value_name = "PX")]
    bumpy_lens: Option<f64>,
    /// Bow the board: mrcal's paraboloid factors X,Y in mm along the board's
    /// normal (the centre moves X+Y, the edges stay; truth.json says
    /// board_warp_mm)
    #[arg(long, value_name = "X,Y", allow_negative_numbers = true)]
    board_warp_mm: Option<String>,
    #[command(flatten)]
    effects: EffectArgs,
    #[command(flatten)]
    laser: super::render_laser::LaserArgs,
}

/// Camera effects (robocal::synth::effects); each flag overrides the preset.
#[derive(clap::Args)]
#[command(next_help_heading = "Camera effects (default: none)")]
struct EffectArgs {
    /// Preset: none, or realistic (gamma 2.2, lens blur growing to the
    /// corners, 0.5 px motion, Bayer + bilinear demosaic, shot + read noise,
    /// JPEG 90, paper texture; see robocal::synth::Effects::realistic)
    #[arg(long, value_name = "PRESET", default_value = "none")]
    effects: String,
    /// Camera response: encoded = 255 (linear / 255)^(1 / GAMMA)
    #[arg(long, value_name = "GAMMA")]
    gamma: Option<f64>,
    /// Defocus disc radius at the image centre, pixels
    #[arg(long, value_name = "PX")]
    defocus: Option<f64>,
    /// Extra defocus radius at the image corners (field curvature), pixels
    #[arg(long, value_name = "PX")]
    field_curvature: Option<f64>,
    /// Extra radial blur radius at the image corners, pixels
    #[arg(long, value_name = "PX")]
    astigmatism: Option<f64>,
    /// Comatic flare at the image corners, pixels
    #[arg(long, value_name = "PX")]
    coma: Option<f64>,
    /// Motion blur length, pixels
    #[arg(long, value_name = "PX")]
    motion: Option<f64>,
    /// Motion direction, degrees from the image x axis towards y
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 30.0,
        allow_negative_numbers = true
    )]
    motion_angle: f64,
    /// Rolling shutter: x shift of the scene per image row, pixels per row
    #[arg(long, value_name = "PX", allow_negative_numbers = true)]
    rolling_shutter: Option<f64>,
    /// Bayer mosaic (RGGB) with 5 % white-balance residuals, bilinear demosaic
    #[arg(long)]
    bayer: bool,
    /// Sensor noise: full well in electrons (255 grey levels at the full
    /// well, 4 e- read noise)
    #[arg(long, value_name = "ELECTRONS")]
    full_well: Option<f64>,
    /// JPEG quality 1-100
    #[arg(long, value_name = "Q", value_parser = clap::value_parser!(u8).range(1..=100))]
    jpeg: Option<u8>,
    /// Paper texture, relative RMS of the albedo
    #[arg(long, value_name = "RMS")]
    paper_texture: Option<f64>,
}

fn effects_of(a: &EffectArgs) -> Result<Effects, CliError> {
    let mut fx = match a.effects.as_str() {
        "none" => Effects::default(),
        "realistic" => Effects::realistic(),
        other => {
            return Err(CliError::usage(
                "render",
                format!("--effects must be none or realistic, got '{other}'"),
            ))
        }
    };
    for (flag, value) in [
        ("--gamma", a.gamma),
        ("--defocus", a.defocus),
        ("--field-curvature", a.field_curvature),
        ("--astigmatism", a.astigmatism),
        ("--coma", a.coma),
        ("--motion", a.motion),
        ("--full-well", a.full_well),
        ("--paper-texture", a.paper_texture),
    ] {
        if value.is_some_and(|v| !(v.is_finite() && v >= 0.0)) {
            return Err(CliError::usage(
                "render",
                format!("{flag} must be a number >= 0, got {}", value.unwrap_or(0.0)),
            ));
        }
    }
    if let Some(g) = a.gamma {
        fx.gamma = (g > 0.0).then_some(g);
    }
    if a.defocus.is_some()
        || a.field_curvature.is_some()
        || a.astigmatism.is_some()
        || a.coma.is_some()
    {
        let o = fx.optics.get_or_insert(Optics {
            defocus_px: 0.0,
            field_curvature_px: 0.0,
            astigmatism_px: 0.0,
            coma_px: 0.0,
        });
        o.defocus_px = a.defocus.unwrap_or(o.defocus_px);
        o.field_curvature_px = a.field_curvature.unwrap_or(o.field_curvature_px);
        o.astigmatism_px = a.astigmatism.unwrap_or(o.astigmatism_px);
        o.coma_px = a.coma.unwrap_or(o.coma_px);
    }
    if let Some(m) = a.motion {
        fx.motion = (m > 0.0).then(|| MotionBlur {
            length_px: m,
            angle_rad: a.motion_angle.to_radians(),
        });
    }
    if let Some(r) = a.rolling_shutter {
        fx.rolling_shutter_px_per_row = r;
    }
    if a.bayer {
        fx.bayer = Some(Bayer {
            channel_gain: [0.95, 1.0, 1.05],
        });
    }
    if let Some(fw) = a.full_well {
        fx.sensor = (fw > 0.0).then(|| SensorNoise {
            full_well_e: fw,
            gain_dn_per_e: 255.0 / fw,
            read_noise_e: 4.0,
        });
    }
    if let Some(q) = a.jpeg {
        fx.jpeg_quality = Some(q);
    }
    if let Some(t) = a.paper_texture {
        fx.paper = (t > 0.0).then_some(Paper {
            rms: t,
            wavelength_m: 0.04,
            seed: 17,
        });
    }
    Ok(fx)
}

pub fn run(args: RenderArgs) -> Result<(), CliError> {
    if let Some(video) = args.video.as_deref() {
        return run_video(&args, video);
    }
    let out = args
        .out
        .as_deref()
        .ok_or_else(|| CliError::usage("render", "--out DIR is required"))?;
    std::fs::create_dir_all(out)
        .map_err(|e| CliError::Io(format!("cannot create '{out}': {e}")))?;
    let out = Path::new(out);
    if args.demo {
        return write_demo(out, args.seed);
    }
    if args.rig {
        check_sigmas(&args)?;
        return super::render_rig::write_rig(super::render_rig::RigArgs {
            out,
            pair_frames: args.views,
            side_frames: args.side_frames,
            seed: args.seed,
            render: render_options(&args),
        });
    }
    let (target, print) =
        Target::parse_spec_print(args.target.as_deref().unwrap_or("chessboard:9x6:30mm"))?;
    if args.views == 0 || args.views > 1000 {
        return Err(CliError::usage(
            "render",
            "--views must be between 1 and 1000",
        ));
    }
    check_sigmas(&args)?;
    let camera = match args.camera.as_deref() {
        Some(file) => robocal::io::import_camera::import_camera(&super::read_text(file)?)?.0,
        None => demo_camera(),
    };
    let camera = match args.bumpy_lens {
        Some(px) => robocal::synth::lens::bumpy_lens(&camera, px)?,
        None => camera,
    };
    let board_warp_m = match args.board_warp_mm.as_deref() {
        Some(text) => {
            let bad = || {
                CliError::usage(
                    "render",
                    format!("--board-warp-mm takes X,Y in mm, e.g. 0.5,0.5, got '{text}'"),
                )
            };
            let (x, y) = text.split_once(',').ok_or_else(bad)?;
            let x: f64 = x.trim().parse().map_err(|_| bad())?;
            let y: f64 = y.trim().parse().map_err(|_| bad())?;
            if !(x.is_finite() && y.is_finite()) {
                return Err(bad());
            }
            [x * 1e-3, y * 1e-3]
        }
        None => [0.0, 0.0],
    };
    let options = RenderOptions {
        effects: effects_of(&args.effects)?,
        board_warp_m,
        ..render_options(&args)
    };
    let options = board_print(options, &target, print);
    let laser = super::render_laser::laser_of(&args.laser, args.seed)?;
    write_set(
        out,
        &camera,
        &target,
        (args.views, args.seed),
        &options,
        laser,
    )
}

/// The print a spec's `:light-on-dark` asks for (a circle grid draws its
/// own `polarity`).
fn board_print(options: RenderOptions, target: &Target, print: Option<Polarity>) -> RenderOptions {
    match (target, print) {
        (Target::CircleGrid { .. }, _) | (_, None) => options,
        (_, Some(print)) => options.printed(print),
    }
}

fn render_options(args: &RenderArgs) -> RenderOptions {
    RenderOptions {
        noise_sigma: args.noise,
        blur_sigma_px: args.blur,
        vignetting: 0.2,
        ..RenderOptions::default()
    }
}

fn run_video(args: &RenderArgs, video: &str) -> Result<(), CliError> {
    check_sigmas(args)?;
    let (target, print) =
        Target::parse_spec_print(args.target.as_deref().unwrap_or("chessboard:9x6:30mm"))?;
    let camera = match args.camera.as_deref() {
        Some(file) => Some(robocal::io::import_camera::import_camera(&super::read_text(file)?)?.0),
        None => None,
    };
    super::render_video::write_video(super::render_video::VideoArgs {
        video,
        truth: args.truth.as_deref(),
        size: &args.size,
        fps: args.fps,
        camera,
        seed: args.seed,
        render: board_print(render_options(args), &target, print),
        target,
    })
}

fn check_sigmas(args: &RenderArgs) -> Result<(), CliError> {
    for (flag, value, unit) in [
        ("--noise", args.noise, "grey levels"),
        ("--blur", args.blur, "px"),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(CliError::usage(
                "render",
                format!(
                    "{flag} must be a sigma >= 0 in {unit}, got {}",
                    robocal::error::compact(value)
                ),
            ));
        }
    }
    Ok(())
}

/// Grid of the target's points, as the scene generator places poses.
fn grid_of(target: &Target) -> ((usize, usize), f64) {
    match target {
        Target::Chessboard {
            cols,
            rows,
            square_m,
        } => ((*cols, *rows), *square_m),
        Target::CircleGrid {
            cols,
            rows,
            spacing_m,
            asymmetric,
            ..
        } => {
            let cols = if *asymmetric { 2 * cols } else { *cols };
            ((cols, *rows), *spacing_m)
        }
        Target::DotPlate {
            cols,
            rows,
            pitch_m,
            ..
        } => ((*cols, *rows), *pitch_m),
        Target::SingleCircle { diameter_m } => ((2, 2), *diameter_m),
        // The squares' origins (the grid is half a side off centre).
        Target::SquareGrid {
            cols,
            rows,
            pitch_m,
            ..
        } => ((*cols, *rows), *pitch_m),
        // Inner corners at one square's pitch.
        Target::Charuco {
            squares_x,
            squares_y,
            square_m,
            ..
        } => ((*squares_x - 1, *squares_y - 1), *square_m),
        // Tags at the tag pitch.
        Target::Aprilgrid {
            tag_cols,
            tag_rows,
            tag_m,
            spacing_ratio,
            ..
        } => ((*tag_cols, *tag_rows), (1.0 + spacing_ratio) * tag_m),
        // Markers at the marker pitch.
        Target::ArucoGrid {
            markers_x,
            markers_y,
            marker_m,
            separation_m,
            ..
        } => ((*markers_x, *markers_y), marker_m + separation_m),
        Target::OriginDotGrid {
            cols,
            rows,
            spacing_m,
        } => ((*cols, *rows), *spacing_m),
    }
}

fn write_set(
    out: &Path,
    camera: &Camera,
    target: &Target,
    (views, seed): (usize, u64),
    options: &RenderOptions,
    laser: Option<robocal::synth::laser::LaserStripe>,
) -> Result<(), CliError> {
    let (grid, pitch) = grid_of(target);
    let scene = Scene::calibration(seed, camera, grid, pitch, views, 0.0)?;
    let mut truth_views = Vec::with_capacity(views);
    for (i, pose) in scene.camera_from_target.iter().enumerate() {
        let opts = RenderOptions {
            seed: seed.wrapping_mul(1000).wrapping_add(i as u64),
            ..options.clone()
        };
        let rendered = render(camera, target, pose, &opts)?;
        let name = format!("view_{i:03}.png");
        write_png(&out.join(&name), &rendered.image)?;
        let mut view = serde_json::json!({
            "image": name,
            "camera_from_target": transform_json(pose),
            "points": rendered.points,
        });
        if let Some(laser) = &laser {
            let on = RenderOptions {
                laser: Some(laser.clone()),
                seed: opts.seed ^ 0x1A5E,
                ..opts.clone()
            };
            let stripe = render(camera, target, pose, &on)?;
            let stripe_name = format!("view_{i:03}_laser.png");
            write_png(&out.join(&stripe_name), &stripe.image)?;
            view["stripe_image"] = serde_json::json!(stripe_name);
            let truth = super::render_laser::stripe_truth_json(camera, pose, &laser.plane);
            view["stripe_axis"] = truth["stripe_axis"].clone();
            view["stripe_px"] = truth["stripe_px"].clone();
        }
        truth_views.push(view);
    }
    let mut truth = serde_json::json!({ "camera": camera, "target": target, "seed": seed, "views": truth_views });
    if let Some(laser) = &laser {
        let n = laser.plane.normal;
        truth["laser_plane"] = serde_json::json!({
            "normal_camera": [n.x, n.y, n.z],
            "distance_m": laser.plane.distance_m,
        });
        truth["laser"] = serde_json::json!(laser);
    }
    if options.board_warp_m != [0.0, 0.0] {
        truth["board_warp_mm"] = serde_json::json!(options.board_warp_m.map(|w| w * 1e3));
    }
    write_json(&out.join("truth.json"), &truth)?;
    eprintln!(
        "robocal render: wrote {views} images and truth.json to {}",
        out.display()
    );
    Ok(())
}

fn write_demo(out: &Path, seed: u64) -> Result<(), CliError> {
    let demo = demo_session(seed)?;
    for (name, image) in &demo.images {
        write_png(&out.join(name), image)?;
    }
    super::output::write_file(&out.join("poses.csv"), demo.poses_csv.as_bytes())?;
    let truth = serde_json::json!({
        "camera": demo.camera,
        "target": demo.target,
        "gripper_from_camera": transform_json(&demo.gripper_from_camera),
        "base_from_target": transform_json(&demo.base_from_target),
    });
    write_json(&out.join("truth.json"), &truth)?;
    eprintln!(
        "robocal render: wrote the demo session ({} images, poses.csv, truth.json) to {}",
        demo.images.len(),
        out.display()
    );
    Ok(())
}

pub(super) fn write_png(path: &Path, image: &robocal::image::GrayImage) -> Result<(), CliError> {
    let png = robocal::image::encode_png(image)?;
    super::output::write_file(path, &png)
}

pub(super) fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value).map_err(|e| CliError::Io(e.to_string()))? + "\n";
    super::output::write_file(path, text.as_bytes())
}
