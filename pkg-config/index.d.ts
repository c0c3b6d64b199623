// Types of the robocal npm package (node entry). Functions come from the
// wasm-bindgen declarations; the JSON shapes they exchange are below, one
// per serde type of the Rust core (the doc comments say where each comes
// from). `RobocalJson` maps every function to its [input, output] JSON.
//
// Conventions (src/lib.rs): `a_from_b` maps b-frame coordinates to a:
// `p_a = a_from_b * p_b`; lengths in metres unless the key says `_mm`;
// pixels with (0, 0) at the centre of the top-left pixel; quaternions
// x, y, z, w; angles in radians unless the key says `_deg`.
//
// Optional keys: `k?: T` is a key the Rust side leaves out (or, on input,
// one with a default); `k: T | null` is a key always written, null when
// there is no value.
export * from './node/robocal.js';

// ---------------------------------------------------------------------------
// Small building blocks

/** `[x, y]` or `[u, v]`. */
export type Vec2 = [number, number];
/** `[x, y, z]`. */
export type Vec3 = [number, number, number];
/** `[x, y, z, w]` (quaternions: unit, scalar last). */
export type Vec4 = [number, number, number, number];
/** A 3x3 matrix as 3 rows. */
export type Matrix3Rows = [Vec3, Vec3, Vec3];
/** A 4x4 homogeneous matrix as 4 rows. */
export type Matrix4Rows = [Vec4, Vec4, Vec4, Vec4];
/** A 2x2 matrix as 2 rows. */
export type Matrix2Rows = [Vec2, Vec2];
/** A 3x3 matrix flattened row by row (9 numbers). */
export type Matrix3Flat = [number, number, number, number, number, number, number, number, number];
/** A 3x4 matrix flattened row by row (12 numbers). */
export type Matrix3x4Flat = [
  number, number, number, number,
  number, number, number, number,
  number, number, number, number,
];
/** `[width, height]` of an image, px. */
export type ImageSize = [number, number];

/**
 * A rigid transform as every report writes it (calib `PoseReport`, hand-eye
 * `PoseJson`, `transform_json`): `p_a = a_from_b * p_b`.
 */
export interface PoseReport {
  /** The 4x4 homogeneous matrix, row by row; translation in metres. */
  matrix_row_major: Matrix4Rows;
  /** Translation, metres. */
  translation_m: Vec3;
  /** Unit quaternion, component order x, y, z, w. */
  quaternion_xyzw: Vec4;
}

/** A rigid transform without the matrix: metres, quaternion x y z w (an input form of `geometry::pose_serde::PoseInput`; reports write `PoseReport`). */
export interface PoseQuaternion {
  /** Translation, metres. */
  translation_m: Vec3;
  /** Unit quaternion, component order x, y, z, w (normalised when read). */
  quaternion_xyzw: Vec4;
}

/**
 * A pose as the hand-eye inputs read it: the matrix (translation in metres;
 * the other two keys are then ignored, so a `PoseReport` works as is), or
 * translation plus quaternion.
 */
export type PoseInput =
  | { matrix_row_major: Matrix4Rows; translation_m?: Vec3; quaternion_xyzw?: Vec4 }
  | PoseQuaternion;

/** Why the Levenberg-Marquardt solver stopped (`optim::Termination`). */
export type Termination =
  | 'cost_tolerance'
  | 'gradient_tolerance'
  | 'step_tolerance'
  | 'no_decrease'
  | 'max_iterations';

/** Euler axis sequences: 6 Tait-Bryan, then 6 proper Euler. */
export type EulerOrder =
  | 'xyz' | 'xzy' | 'yxz' | 'yzx' | 'zxy' | 'zyx'
  | 'xyx' | 'xzx' | 'yxy' | 'yzy' | 'zxz' | 'zyz';
/** Rotating (intrinsic) or fixed (extrinsic) axes. */
export type EulerKind = 'intrinsic' | 'extrinsic';

// ---------------------------------------------------------------------------
// Images (src/image)

/** What `image_info` returns (and `decode_image_preview(...).info_json` holds). */
export interface ImageInfo {
  /** Container format, lower case. */
  format: 'png' | 'jpeg' | 'tiff' | 'bmp' | 'pnm' | 'gif';
  /** Upper-case display name, e.g. "PNG". */
  format_name: 'PNG' | 'JPEG' | 'TIFF' | 'BMP' | 'PNM' | 'GIF';
  /** Width, px (after the EXIF orientation). */
  width: number;
  /** Height, px (after the EXIF orientation). */
  height: number;
  /** Channels in the file: 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA. */
  channels: number;
  /** Bits per channel in the file: 8 or 16, 32 for float TIFF. */
  bits_per_channel: number;
  /**
   * The EXIF Orientation (2-8) applied to the pixels, as OpenCV's `imread`
   * and image viewers apply it; absent when the file has none. `width` and
   * `height` are the size after it.
   */
  exif_orientation?: number;
}

/** `undistort_preview(...).info_json`: the preview's size, px. */
export interface UndistortPreviewInfo {
  width: number;
  height: number;
}

// ---------------------------------------------------------------------------
// Targets and detections (src/target.rs, docs/detection-json.md)

/** Which way round a circle target is printed. */
export type Polarity = 'dark_on_light' | 'light_on_dark';

/**
 * The fields of each target kind, keyed by `kind` (the serde tag). Board
 * frame: x along a row, y from row to row, z = 0 on the board, metres;
 * point ids `i + j * cols`, row by row. A new kind is one more entry here.
 */
export interface TargetKinds {
  /** A chessboard counted by inner corners (a 10 x 7 squares board is 9 x 6); points at `(i, j) * square_m`. */
  chessboard: { cols: number; rows: number; /** Side of one square, metres. */ square_m: number };
  /** A grid of circles (OpenCV's layouts): symmetric `(i, j) * spacing_m`, asymmetric `(2 i + j % 2, j) * spacing_m`. */
  circle_grid: { cols: number; rows: number; /** Grid unit, metres (asymmetric: half the centre distance within a row). */ spacing_m: number; asymmetric: boolean; polarity: Polarity };
  /** Dark dots on a light plate, at `(i, j) * pitch_m`. */
  dot_plate: { cols: number; rows: number; /** Centre distance, metres. */ pitch_m: number; /** Dot diameter, metres (< pitch). */ dot_diameter_m: number };
  /** One dark circle on a light background; one point, id 0, its centre. */
  single_circle: { /** Circle diameter, metres. */ diameter_m: number };
  /** `cols x rows` separate dark squares (Zhang's 1998 target), 4 corners each: id = `4 (i + j * cols) + k`; square `(i, j)` spans `(i, j) * pitch_m` to that `+ side_m`, corner k = 0 (x0, y0), 1 (x0 + side, y0), 2 (x0 + side, y0 + side), 3 (x0, y0 + side). */
  square_grid: { cols: number; rows: number; /** Side of one square, metres (< pitch). */ side_m: number; /** Distance between the origins of neighbouring squares, metres. */ pitch_m: number };
  /**
   * OpenCV's ChArUco board (4.6+ layout unless `legacy`) of `squares_x x squares_y` squares:
   * points are the `(squares_x - 1) x (squares_y - 1)` inner chessboard corners,
   * `id = i + j (squares_x - 1)` (OpenCV's ChArUco corner ids); a detection holds the
   * corners seen (any subset; docs/detection-json.md).
   */
  charuco: {
    /** Squares along a row (OpenCV's squaresX). */ squares_x: number;
    /** Squares along a column (OpenCV's squaresY). */ squares_y: number;
    /** Side of one square, metres. */ square_m: number;
    /** Side of one marker, its black border included, metres (< square_m). */ marker_m: number;
    dictionary: ArucoDictionary;
    /** Id of the first marker, the others following (0 by default; serialised always). */ first_id?: number;
    /** Explicit marker ids in board order, instead of `first_id`. */ marker_ids?: number[];
    /** The layout of boards made before OpenCV 4.6 (differs for an even `squares_y`); false by default. */ legacy?: boolean;
  };
  /**
   * Kalibr's AprilGrid of tag36h11 tags: 4 points per tag with Kalibr's point ids
   * (`r * 2 tag_cols + c`, corner row r from the bottom of the print, column c from the left;
   * docs/detection-json.md); a detection holds the corners seen (any subset).
   */
  aprilgrid: {
    /** Tags along a row (Kalibr's tagCols). */ tag_cols: number;
    /** Rows of tags (Kalibr's tagRows). */ tag_rows: number;
    /** Side of one tag, edge to edge, metres (Kalibr's tagSize). */ tag_m: number;
    /** Gap between tags over the tag side, in (0, 1] (Kalibr's tagSpacing). */ spacing_ratio: number;
    /** Id of tag 0 (0 in Kalibr; serialised always). */ first_id?: number;
  };
  /**
   * OpenCV's ArUco GridBoard (markers only): 4 points per marker, id `4 k + c` for corner c
   * (0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left) of marker k (row by row from the
   * top left, dictionary id `first_id + k`); OpenCV 4.6+'s board frame (origin at marker 0's
   * top-left corner, y down). A detection holds the corners seen (any subset).
   */
  aruco_grid: {
    /** Markers along a row (OpenCV's markersX). */ markers_x: number;
    /** Rows of markers (OpenCV's markersY). */ markers_y: number;
    /** Side of one marker, its black border included, metres. */ marker_m: number;
    /** Gap between neighbouring markers, metres (OpenCV's markerSeparation). */ separation_m: number;
    dictionary: ArucoDictionary;
    /** Id of the top-left marker (0 by default; serialised always). */ first_id?: number;
  };
  /**
   * ROS-Industrial's modified circle grid: dark dots 0.4 spacing across, the origin dot twice
   * that; ids ROS-Industrial's (`i + j * cols`, row 0 farthest from the big dot, which is id
   * `(rows - 1) * cols`), points at `(i, j) * spacing_m` (ROS-Industrial's frame:
   * `(x, (rows - 1) spacing_m - y, -z)`).
   */
  origin_dot_grid: { cols: number; rows: number; /** Centre distance, metres. */ spacing_m: number };
}

/** OpenCV's predefined ArUco dictionaries, by their OpenCV names. */
export type ArucoDictionary =
  | 'DICT_4X4_50' | 'DICT_4X4_100' | 'DICT_4X4_250' | 'DICT_4X4_1000'
  | 'DICT_5X5_50' | 'DICT_5X5_100' | 'DICT_5X5_250' | 'DICT_5X5_1000'
  | 'DICT_6X6_50' | 'DICT_6X6_100' | 'DICT_6X6_250' | 'DICT_6X6_1000'
  | 'DICT_7X7_50' | 'DICT_7X7_100' | 'DICT_7X7_250' | 'DICT_7X7_1000'
  | 'DICT_ARUCO_ORIGINAL'
  | 'DICT_APRILTAG_16h5' | 'DICT_APRILTAG_25h9' | 'DICT_APRILTAG_36h10' | 'DICT_APRILTAG_36h11'
  | 'DICT_ARUCO_MIP_36h12';

/** A target kind name. */
export type TargetKind = keyof TargetKinds;
/** The target of one kind, e.g. `TargetOf<'chessboard'>`. */
export type TargetOf<K extends TargetKind> = { kind: K } & TargetKinds[K];
/** A calibration target's geometry: a union discriminated by `kind`. */
export type Target = { [K in TargetKind]: TargetOf<K> }[TargetKind];

/**
 * A CLI target spec, the other form `detect_target` takes: `chessboard:9x6:30mm`,
 * `circles:4x11:20mm[:asymmetric|symmetric][:dark-on-light|light-on-dark]`,
 * `dots:7x7:25mm[:12.5mm]` (dot diameter defaults to half the pitch),
 * `circle:10mm`, `squares:8x8:12.7mm:22.5778mm` (side, then pitch),
 * `charuco:12x9:20mm:15mm:DICT_5X5_100[:first=N][:ids=A,B,...][:legacy]` (squares, square side,
 * marker side, dictionary), `aprilgrid:6x6:88mm:0.3[:first=N]` (tags, tag size, spacing ratio);
 * lengths in mm, cm or m. Any spec may end in `:dark-on-light` or `:light-on-dark` to force
 * that print (without, either print is found).
 */
export type TargetSpec =
  | `chessboard:${number}x${number}:${string}`
  | `circles:${number}x${number}:${string}`
  | `dots:${number}x${number}:${string}`
  | `circle:${string}`
  | `squares:${number}x${number}:${string}:${string}`
  | `charuco:${number}x${number}:${string}:${string}:${ArucoDictionary}${string}`
  | `aprilgrid:${number}x${number}:${string}:${number}${string}`;

/** One detected target point. */
export interface DetectedPoint {
  /**
   * Board id (`i + j * cols`; square grids: `4 (i + j * cols) + k`; ChArUco: OpenCV's corner id
   * `i + j (squares_x - 1)`; AprilGrid: Kalibr's point id, four per tag).
   */
  id: number;
  /** Column coordinate, px. */
  x_px: number;
  /** Row coordinate, px. */
  y_px: number;
  /** Covariance `[xx, xy, yy]`, px^2, when the detector estimates it (circle centres). */
  covariance_px2?: Vec3;
}

/** What `detect_target` returns: a target found in one image. */
export interface Detection {
  /** `[width, height]` of the image, px. */
  image_size_px: ImageSize;
  /** The target that was searched for. */
  target: Target;
  /**
   * Detected points, sorted by id: any subset of the target's points (ids missing from a
   * partial detection are absent). The solvers use a view whose points fix a homography
   * (at least 4, not all but one on a line) and leave the others out with a warning
   * (docs/detection-json.md, "Partial views").
   */
  points: DetectedPoint[];
  /**
   * Circle grids and dot plates: which point of each imaged circle `points` are
   * (`perspective_pole`, the default: the image of the circle's centre; `local_quadratic`;
   * `ellipse_centre`: uncorrected). Absent for other targets and in older files.
   */
  centre_model?: CentreModel;
  /**
   * The print the detector found the target in: `dark_on_light` (the usual print) or
   * `light_on_dark` (the board inverted). Every target is found in either print without
   * an option; a spec's `:dark-on-light` / `:light-on-dark` forces one
   * (docs/detection-json.md, "Print polarity"). Absent in older files.
   */
  polarity?: Polarity;
}

/** How circle centres are estimated (docs/detection-json.md). */
export type CentreModel = 'perspective_pole' | 'local_quadratic' | 'ellipse_centre';

// ---------------------------------------------------------------------------
// Camera and lens models (src/camera)

/**
 * The coefficients of each lens model, keyed by `model` (the serde tag).
 * All act on normalised coordinates (X/Z, Y/Z) or, for the wide-angle
 * models, on the ray.
 */
export interface DistortionModels {
  /** The ideal pinhole camera. */
  none: Record<never, never>;
  /** Brown-Conrady, OpenCV's 5 coefficients (OpenCV order k1 k2 p1 p2 k3). */
  brown: { k1: number; k2: number; k3: number; p1: number; p2: number };
  /** OpenCV's rational model with thin-prism terms (k4..k6 denominator, s1..s4 prism). */
  rational: {
    k1: number; k2: number; k3: number; k4: number; k5: number; k6: number;
    p1: number; p2: number; s1: number; s2: number; s3: number; s4: number;
  };
  /** Division model: `undistorted = distorted / (1 + kappa r_d^2)`, normalised units. */
  division: { kappa: number };
  /** Radial-only Brown (Bouguet's kc naming): `x_d = x (1 + k1 r^2 + k2 r^4 + k5 r^6)`. */
  radial_k1_k2_k5: { k1: number; k2: number; k5: number };
  /** Kannala-Brandt equidistant fisheye: `theta_d = theta (1 + k1 theta^2 + ... + k4 theta^8)`. */
  kannala_brandt: { k1: number; k2: number; k3: number; k4: number };
  /** Enhanced unified camera model: alpha in [0, 1), beta > 0. */
  eucm: { alpha: number; beta: number };
  /** Scheimpflug (tilted sensor): OpenCV's rational + thin prism then the sensor tilt tau_x tau_y in radians (CALIB_TILTED_MODEL, OpenCV's 14 coefficients). */
  tilted: {
    k1: number; k2: number; k3: number; k4: number; k5: number; k6: number;
    p1: number; p2: number; s1: number; s2: number; s3: number; s4: number;
    tau_x: number; tau_y: number;
  };
  /** Splined stereographic (after mrcal): the stereographic projection plus a B-spline correction of degree `order` over `nx x ny` control points spanning `u_max` (stereographic units) each way; `control` = `[dx0, dy0, dx1, dy1, ...]`, `2 nx ny` values; `smoothness` the calibration's prior weight. */
  splined: {
    order: number; nx: number; ny: number; u_max: [number, number];
    smoothness: number; control: number[];
  };
}

/** A lens model name (`model` of the calibration inputs and reports). */
export type LensModel = keyof DistortionModels;
/** A camera export format that holds a lens model, with the condition on its coefficients when there is one, e.g. `kalibr (with k3 held at 0)`. */
export type LensExportFormat = CameraExportFormat | `${CameraExportFormat} (${string})`;
/** One row of the core's lens-model table (src/camera/models.rs), as `lens_models()` lists it. */
export interface LensModelInfo {
  /** The `model` of the JSON and `--model`. */
  name: LensModel;
  /** Other names accepted for the model (`brown5` for `brown`), each with what it means. */
  aliases: { name: string; means: string }[];
  /** The short name the model advice writes ("Brown-Conrady"). */
  label: string;
  /** The text of the page's lens list: the label with the coefficients and the tools that know the model. */
  description: string;
  /** Coefficient names, in the order of the camera's parameter vector. */
  coefficients: string[];
  /** Where the solvers start each coefficient (same order). */
  start_values: number[];
  /** The camera export formats that hold the model (`json` always first). */
  export_formats: LensExportFormat[];
  /** A model for lenses past 90 degrees (always compared for a wide-angle lens). */
  wide_angle: boolean;
}
/** A lens model with its coefficients: `{"model": "brown", "k1": -0.2, ...}`. */
export type Distortion = { [M in LensModel]: { model: M } & DistortionModels[M] }[LensModel];

/**
 * A camera (`camera::Camera`): `u = fx m_x + skew m_y + cx`, `v = fy m_y + cy`
 * for the distorted normalised point m; camera frame x right, y down, z forward.
 * The `camera` of a calibration report; what `undistort_preview` takes.
 */
export interface Camera {
  /** Focal length along x, px. */
  fx: number;
  /** Focal length along y, px. */
  fy: number;
  /** Principal point x, px. */
  cx: number;
  /** Principal point y, px. */
  cy: number;
  /** Skew, px (the (0, 1) entry of the camera matrix); usually 0. */
  skew: number;
  /** Image width, px. */
  width: number;
  /** Image height, px. */
  height: number;
  /** The lens model. */
  distortion: Distortion;
}

// ---------------------------------------------------------------------------
// Reports (src/report_kind.rs, docs/report-json.md)

/**
 * What a report is: every report says it in `kind`, and which robocal wrote
 * it in `robocal_version`. Reports written before `kind` existed have none
 * (and camera and rig reports said `crate_version`); `export_report` still
 * reads them, by their keys.
 */
export type ReportKind = 'camera' | 'stereo' | 'rig' | 'handeye' | 'rig_handeye' | 'check' | 'diff';

// ---------------------------------------------------------------------------
// Camera calibration (src/api/camera.rs, src/calib/report.rs, compare.rs)

/** A calibration method; `all` (input only) runs every one and compares. */
export type CalibrationMethod = 'zhang' | 'dlt' | 'tsai' | 'ekf';

/** The `options` object of `calibrate_camera` and `calibrate_stereo` (every key optional). */
export interface CalibrationOptions {
  /** Hold the principal point at the image centre (default false). */
  fix_principal_point?: boolean;
  /** Hold fy / fx at its closed-form value, or at `aspect_ratio` (default false). */
  fix_aspect_ratio?: boolean;
  /** Hold fx / fy at this value (OpenCV's aspectRatio; 1 = square pixels); implies `fix_aspect_ratio`. */
  aspect_ratio?: number | null;
  /** Hold the skew at 0 (default true). */
  zero_skew?: boolean;
  /** Huber loss (1 px) and rejection beyond 3 robust sigmas, reported per view as `outliers` (default false). */
  robust?: boolean;
  /** Coefficient names of the model held at 0, e.g. `["k3"]`. */
  fixed_coefficients?: string[];
}

/**
 * One view of a calibration input: a `detect_target` detection, or explicit
 * correspondences (board points in metres, pixels in the same order).
 */
export type CalibrationView =
  | { name: string; detection: Detection; object_m?: never; image_px?: never }
  | { name: string; object_m: Vec3[]; image_px: Vec2[]; detection?: never };

/** The input JSON of `calibrate_camera`. Unknown keys are rejected. */
export interface CalibrationInput {
  /** Lens model (default `brown`). */
  model?: LensModel;
  /** Method (default `zhang`); `all` runs every method and fills `comparison`. */
  method?: CalibrationMethod | 'all';
  options?: CalibrationOptions;
  /** At least 3 views. */
  views: CalibrationView[];
  /** `[width, height]`, px; optional when the views are detections (which must agree). */
  image_size_px?: ImageSize;
}

/** A robust loss on a residual block's norm (`optim::Loss`), tagged by `kind`; scale in px. */
export type Loss =
  | { kind: 'squared' }
  | { kind: 'huber'; scale: number }
  | { kind: 'cauchy'; scale: number };

/** The solver options a report records (`calib::CalibrationOptions`, all keys written). */
export interface CalibrationSolverOptions {
  /** The lens model and its initial (and held) coefficients. */
  model: Distortion;
  /** The camera the solver started from instead of the closed form. */
  initial_camera: Camera | null;
  fix_principal_point: boolean;
  fix_aspect_ratio: boolean;
  /** The held fx / fy, when given. */
  aspect_ratio: number | null;
  zero_skew: boolean;
  fixed_coefficients: string[];
  loss: Loss;
  /** Outlier rejection threshold, robust sigmas; null without rejection. */
  outlier_sigma: number | null;
  max_outlier_rounds: number;
  max_iterations: number;
}

/** A point dropped by outlier rejection. */
export interface Outlier {
  /** Index of the point in its view. */
  index: number;
  /** The target's id of the point (the detection's id; the index for explicit correspondences). */
  id: number;
  /** Its residual norm when dropped, px. */
  residual_px: number;
  /** Where it was observed, px. */
  x_px: number;
  y_px: number;
  reason: string;
}

/** With the robust option: the points rejected over all views. */
export interface RejectedPoints {
  count: number;
  /** Points detected (used plus rejected). */
  of_points: number;
  /** Views with a rejected point, most rejections first. */
  views: { name: string; count: number }[];
  /** Rejected points within 10 % of the image size from an edge. */
  near_border: number;
  /** The same in one sentence. */
  summary: string;
}

/** A vector anchored at a pixel, px. */
export interface PixelVector {
  x: number;
  y: number;
  dx: number;
  dy: number;
  /** Residuals only: the target's id of the point (which corner of the view is off). */
  id?: number;
}

/** Per-view results of a calibration. */
export interface ViewReport {
  name: string;
  /** RMS of the residual norms of the used points, px. */
  rms_px: number;
  /** Points used. */
  n_points: number;
  /** Pose of the target in the camera frame: `p_camera = camera_from_target * p_target`. */
  camera_from_target: PoseReport;
  outliers: Outlier[];
  /** Observed minus predicted pixel of every point (outliers included), anchored at the observed pixel. */
  residuals_px: PixelVector[];
}

/** The calibration report (`calib::CameraCalibration`): the `report` of `calibrate_camera`. */
export interface CameraCalibration {
  kind: 'camera';
  /** robocal version that produced the report. */
  robocal_version: string;
  /** `[width, height]`, px. */
  image_size_px: ImageSize;
  model: LensModel;
  /** The calibrated camera. */
  camera: Camera;
  /** `[[fx, skew, cx], [0, fy, cy], [0, 0, 1]]`, px. */
  camera_matrix: Matrix3Rows;
  /** Distortion coefficients by name (the keys of the model in `camera.distortion`). */
  distortion: Record<string, number>;
  /** sqrt(sum of squared residual norms / number of points), px (OpenCV's RMS). */
  rms_px: number;
  /** Standard deviation of every camera parameter by name (fx, fy, cx, cy, skew, coefficients; 0 if held); empty when not all are determined. */
  std: Record<string, number>;
  views: ViewReport[];
  /** Parameter correlations: `matrix` rows follow `names`; empty matrix when not all are determined. */
  correlation: { names: string[]; matrix: number[][] };
  /** 1-sigma projection uncertainty (px, worst direction) on a grid over the image, for points at the median target distance. */
  projection_uncertainty: {
    /** Distance of the points from the camera, metres. */
    reference_depth_m: number;
    /** Grid x coordinates, px. */
    x_px: number[];
    /** Grid y coordinates, px. */
    y_px: number[];
    /** Per row (y), per column (x), px; null where the camera cannot unproject. */
    std_px: (number | null)[][];
    max_std_px: number;
  };
  /** Distorted minus undistorted pixel positions on a 16 x 12 grid, px. */
  distortion_field: { vectors: PixelVector[] };
  /** Coverage, tilt, correlation and plausibility warnings; error-level ones come first and begin with "error: " (see `severity`). */
  warnings: string[];
  /** Solver iterations in the last round. */
  iterations: number;
  termination: Termination;
  /** Points used in total. */
  n_points: number;
  /** The options used. */
  options: CalibrationSolverOptions;
  /** Present with the robust option. */
  rejected?: RejectedPoints;
  /** The worst level of `warnings`: "error" means the result is not a calibration (the fit did not converge from any start) and the first warning, beginning with "error: ", says why. */
  severity?: "ok" | "warning" | "error";
  /** Zhang's method: the start the result came from ("closed_form", "given", "tsai", "dlt", "square_pixels", "centred_principal_point", "square_pixels_centred", "distortion_held_then_freed", "comparison:METHOD"). */
  start?: string;
  /** Every start tried, when the first did not converge or gave an implausible camera (the lowest cost wins). */
  starts?: StartOutcome[];
}

/** One start of Zhang's bundle adjustment and where it ended. */
export interface StartOutcome {
  start: string;
  /** sqrt(2 cost / points), px: the RMS residual norm for the squared loss. */
  rms_px: number;
  iterations: number;
  /** "max_iterations": this start did not converge. */
  termination: Termination;
  fx: number;
  fy: number;
  cx: number;
  cy: number;
}

/** One method's row of the `method: "all"` comparison (values null when it failed). */
export interface ComparisonRow {
  method: CalibrationMethod;
  fx: number | null;
  fy: number | null;
  cx: number | null;
  cy: number | null;
  /** First radial coefficient, when the model has one. */
  k1: number | null;
  rms_px: number | null;
  /** Standard deviation of the u residuals of the used points, px. */
  std_u_px: number | null;
  std_v_px: number | null;
  /** Why the method failed or does not apply; null on success. */
  error: string | null;
}

/** The output JSON of `calibrate_camera`. */
export interface CalibrationOutput {
  /** The report of the chosen method (Zhang's for `all`). */
  report: CameraCalibration;
  /** With method `all`: one row per method that applies; otherwise null. */
  comparison: ComparisonRow[] | null;
  /** With method `all`: why methods were left out of `comparison` (the DLT when every view is a flat board); absent when none was. */
  comparison_note?: string;
  /** Circle grids and dot plates: the centre model of the views' detections (`ellipse_centre` for detections written before the key existed), or `mixed`; absent when no view is a circle or dot detection. */
  centre_model?: CentreModel | 'mixed';
  /** With `centre_model` `mixed`: the views of each model. */
  centre_models?: { centre_model: CentreModel; views: string[] }[];
}

/** The input JSON of `calibrate_stereo`: `left[i]` and `right[i]` saw the same board pose. */
export interface StereoInput {
  /** Lens model of both cameras (default `brown`). */
  model?: LensModel;
  /** Options of both cameras. */
  options?: CalibrationOptions;
  /** At least 3 pairs. */
  left: CalibrationView[];
  right: CalibrationView[];
  /** Optional when the views are detections. */
  left_image_size_px?: ImageSize;
  right_image_size_px?: ImageSize;
}

/** The output JSON of `calibrate_stereo` (the report `robocal stereo` writes). */
export interface StereoCalibration {
  kind: 'stereo';
  /** The left camera at the joint optimum. */
  left: CameraCalibration;
  /** The right camera; its views' `camera_from_target` is `right_from_left * left camera_from_target`. */
  right: CameraCalibration;
  /** `p_right = right_from_left * p_left`. */
  right_from_left: PoseReport;
  /** The averaged single-camera estimate the refinement started from. */
  initial_right_from_left: PoseReport;
  /** Distance between the camera centres, metres. */
  baseline_m: number;
  /** Standard deviations (rotation: small-angle vector, radians; translation, metres); null when singular. */
  right_from_left_std: { rotation_rad: Vec3; translation_m: Vec3 } | null;
  /** RMS reprojection error over every point of both cameras, px. */
  rms_px: number;
  iterations: number;
  termination: Termination;
  /** Pairs left out (`pair N left out: left|right NAME: REASON`: a side whose points cannot fix a homography), and each camera's lens-model advice (`left camera: ...`). */
  warnings: string[];
  /** The lens-model advice of each camera (absent in older reports). */
  model_advice?: { left: ModelAdvice; right: ModelAdvice };
}

/** The advice on a camera's lens model (src/calib/model_advice.rs). */
export interface ModelAdvice {
  /** The model to use: the calibrated one unless another fitted model is named. */
  recommended: string;
  /** Every model fitted to the same views, the calibrated one first. */
  compared: { model: string; rms_px: number; coefficients: number }[];
  /** The camera export formats that hold the recommended model, with conditions, e.g. `kalibr (with k3 held at 0)`. */
  export_formats: string[];
  /** Half the diagonal field of view, degrees (above 50: kannala_brandt and eucm are compared). */
  half_diagonal_fov_deg: number;
  /** One line: recommendation, comparison, formats. */
  summary: string;
  warnings: string[];
}

// ---------------------------------------------------------------------------
// Camera rigs (src/api/rig.rs, src/calib/rig_report.rs)

/** One view of a rig camera: `key` names its frame (views with one key saw one board pose). */
export interface RigInputView {
  key: string;
  name: string;
  detection?: Detection;
  /** Target points, metres (with `image_px`, instead of `detection`). */
  object_m?: Vec3[];
  image_px?: Vec2[];
}

/** One camera of `calibrate_rig`'s input. */
export interface RigInputCamera {
  /** Unique in the rig. */
  name: string;
  views: RigInputView[];
  /** Optional for detections or a given camera. */
  image_size_px?: ImageSize;
  /** Intrinsics given and held (a report's `camera`). */
  camera?: Camera;
}

/** The input JSON of `calibrate_rig`. */
export interface RigInput {
  /** Lens model of the solved cameras (default `brown`). */
  model?: LensModel;
  options?: CalibrationOptions;
  cameras: RigInputCamera[];
  /** The target spec, carried into the report. */
  target?: string;
  /** The camera whose frame is the rig frame (default: the first). */
  rig_frame?: string;
  /** How the caller grouped the images into frames (default `number`). */
  grouping?: string;
  /**
   * Keys of frames in which no camera found the board, beside those of the
   * views (a rig on a robot pairs one robot pose with each frame).
   */
  frame_keys?: string[];
}

/** One camera of a rig report. */
export interface RigCamera {
  name: string;
  /** Its intrinsics at the joint optimum; `views` are the frames it saw. */
  calibration: CameraCalibration;
  intrinsics_held: boolean;
  /** Rig frame -> this camera (`p_cam = camera_from_rig * p_rig`); the identity for the rig camera. */
  camera_from_rig: PoseReport;
  /** Standard deviations (rotation: small-angle vector, radians; translation, metres); null for the rig camera or when singular. */
  camera_from_rig_std: { rotation_rad: Vec3; translation_m: Vec3 } | null;
  rms_px: number;
  /** Indices into `frames`. */
  frames_seen: number[];
}

/** One synchronised frame (a board pose) of a rig report. */
export interface RigFrame {
  key: string;
  /** The board in the rig frame; null when no camera used the frame. */
  rig_from_target: PoseReport | null;
  /** Cameras whose view of this frame was used. */
  cameras: string[];
  rms_px: number;
}

/** The output JSON of `calibrate_rig` (the report `robocal rig` writes). */
export interface RigCalibration {
  /** `rig_handeye` when the report carries `handeye` (a rig on a robot). */
  kind: 'rig' | 'rig_handeye';
  /** robocal version that produced the report. */
  robocal_version: string;
  /** Name of the camera whose frame is the rig frame. */
  rig_frame: string;
  target: string;
  grouping: string;
  cameras: RigCamera[];
  frames: RigFrame[];
  co_observation: {
    cameras: string[];
    /** `frames[i][j]`: frames seen by both camera i and j (diagonal: by camera i). */
    frames: number[][];
    /** The pairs the initialisation chained, parent first. */
    spanning_tree: [number, number][];
  };
  rms_px: number;
  iterations: number;
  termination: Termination;
  warnings: string[];
  /** The joint covariance of the solved rig parameters (absent in older files, or when singular). */
  covariance?: RigCovariance;
}

/** One solved rig parameter: an intrinsic (`fx`, `fy`, `cx`, `cy`, `skew`, a distortion coefficient) or a `camera_from_rig` component (`rotation_x|y|z`, rad, left perturbation; `translation_x|y|z`, m). */
export interface RigParameter {
  camera: string;
  parameter: string;
}

/** The covariance of the rig's solved parameters, rows and columns in the order of `parameters`. */
export interface RigCovariance {
  parameters: RigParameter[];
  matrix: number[][];
}

/** Whether the rig hand-eye's std include the rig calibration's own uncertainty. */
export interface RigUncertainty {
  /** `false`: the std are conditional on the rig (no rig covariance). */
  included: boolean;
  note: string;
  /** Hand-eye re-solves at the rig moved by one std along each principal axis. */
  sigma_points: number;
  /** The std with the rig held, when the rig's uncertainty was added. */
  conditional_camera_transform_std?: TransformStd;
  conditional_target_transform_std?: TransformStd;
}

/** One frame of the rig hand-eye. */
export interface RigHandEyeFrame {
  key: string;
  pose_index: number;
  used: boolean;
  cameras: string[];
  pose_fit_rms_px?: number;
  reason?: string;
}

/** A hand-eye method's result with the rig in its keys. */
export type RigHandEyeMethodResult = Omit<HandEyeMethodResult, 'gripper_from_camera' | 'base_from_camera'> & {
  gripper_from_rig?: PoseReport;
  base_from_rig?: PoseReport;
};

/** The `handeye` of a rig report: the hand-eye report with the rig in its keys. */
export type RigHandEyeReport = Omit<HandEyeReportBase, 'methods'> & {
  methods: RigHandEyeMethodResult[];
  /** Each camera's own transform (`x * camera_from_rig^-1`). */
  cameras: { name: string; gripper_from_camera?: PoseReport; base_from_camera?: PoseReport }[];
  frames: RigHandEyeFrame[];
  rig_uncertainty: RigUncertainty;
} & (
  | { setup: 'eye-in-hand'; gripper_from_rig: PoseReport; base_from_target: PoseReport }
  | { setup: 'eye-to-hand'; base_from_rig: PoseReport; gripper_from_target: PoseReport }
);

/** The input JSON of `calibrate_rig_handeye`: a camera rig on a robot. */
export interface RigHandEyeInput {
  /** `eye-in-hand` (the rig on the gripper) or `eye-to-hand` (the rig fixed, the target on the gripper). */
  setup: 'eye-in-hand' | 'eye-to-hand';
  /** One robot pose per frame, in the order of the frame keys. */
  base_from_gripper: PoseInput[];
  /** The cameras and their views (the input of `calibrate_rig`). */
  calibration: RigInput;
  /** A calibrated rig to hold (its intrinsics and `camera_from_rig`); absent: calibrated first. */
  rig?: RigCalibration;
  /** Report suspected pose mistakes as warnings instead of errors. */
  lenient?: boolean;
}

/** The output of `robocal rig --setup` (a camera rig on a robot): the rig report with `handeye`. */
export interface RigOnRobotReport extends RigCalibration {
  kind: 'rig_handeye';
  handeye: RigHandEyeReport;
}

/** The formats of a rig report (`rig_export_formats`). */
export type RigExportFormat = 'kalibr' | 'opencv-yaml' | 'ros' | 'urdf' | 'mrcal';

/** One file of `export_report_files`. */
export interface ExportFile {
  /** A file name without folder (e.g. `front.yaml`, `rig_tf.launch.py`). */
  name: string;
  text: string;
}

// ---------------------------------------------------------------------------
// Hand-eye (src/api/handeye.rs, src/handeye/report.rs)

/** Camera on the gripper (`eye-in-hand`) or fixed in the robot's world (`eye-to-hand`). */
export type Setup = 'eye-in-hand' | 'eye-to-hand';
/** The closed-form solvers, in report order (input also accepts `_` or spaces and any case). */
export type HandEyeMethod =
  | 'tsai-lenz' | 'park-martin' | 'horaud' | 'andreff'
  | 'daniilidis' | 'chou-kamel' | 'shah' | 'li';
/** The refinement over the image points (input also accepts `-` for `_`). */
export type RefineMode = 'none' | 'trusted' | 'stochastic' | 'joint_intrinsics';

/** Explicit image points of one pose: board points (target frame, metres) and their pixels. */
export interface HandEyeView {
  object_m: Vec3[];
  image_px: Vec2[];
}

/**
 * A camera as `solve_handeye` reads it: the Camera JSON, a calibration
 * report or `calibrate_camera` output, any object with a `camera` key
 * (e.g. the demo truth), or a string in a format the camera import reads
 * (robocal JSON, OpenCV YAML/XML, ROS camera_info YAML).
 */
export type HandEyeCamera = Camera | CameraCalibration | CalibrationOutput | { camera: Camera } | string;

export interface HandEyeInputBase {
  setup: Setup;
  /** Robot poses, one per view: `p_base = base_from_gripper * p_gripper`. */
  base_from_gripper: PoseInput[];
  /** Target poses seen by the camera, same order; optional with image points (then solved per view by PnP). */
  camera_from_target?: PoseInput[];
  /** The camera of the image points (required with `views` or `detections`). */
  camera?: HandEyeCamera;
  /** Default `none`: with image points the maximum likelihood over the poses (each view's PnP covariance, robot noise estimated). */
  refine?: RefineMode;
  /** Expected pixel noise of the refinement, px (default 0.5). */
  pixel_sigma_px?: number;
  /**
   * The camera calibration's standard deviations, px (e.g. `{fx: 0.5, fy: 0.5, cx: 0.8, cy: 0.7}`;
   * read from `camera` when that is a calibration report). With `refine: 'joint_intrinsics'`, an
   * intrinsic moved by more than 10 of them is warned about.
   */
  camera_std?: Record<string, number> | null;
  /** One method or `all` (default `all`: every solver side by side). */
  method?: HandEyeMethod | 'all';
  /** Bootstrap resamples for the repeatability (default 100; 0 = none). */
  bootstrap_samples?: number;
  /** Seed of the bootstrap (default 1). */
  seed?: number;
  /** Stop on failed consistency checks (default true). */
  strict_checks?: boolean;
  /**
   * Maximum-likelihood pose refinement of the closed forms (default true;
   * ignored with image points, where `refine` applies).
   */
  refine_poses?: boolean;
  /** The tool centre point in the flange frame (m): the report's `tcp_error`. */
  tcp_m?: Vec3;
  /** Hold the last N pose pairs out of the solve: the report's `holdout`. */
  holdout?: number;
  /** Points touched with the tool centre point (base frame, m) and seen at `image_px` from robot pose `view` (needs image points and the camera). */
  touch?: { base_m: Vec3; image_px: [number, number]; view?: number }[];
}

/**
 * The input JSON of `solve_handeye` (unknown keys are rejected). Image points
 * are given either as `views` or as `detections` (one `detect_target`
 * Detection per pose, board points from each detection's target), not both.
 * A view may hold any subset of the board's points; one whose points cannot fix
 * a pose (fewer than 4, or all but one on a line) is left out with its robot
 * pose and the warning `view I left out with its robot pose: REASON`.
 */
export type HandEyeInput =
  | (HandEyeInputBase & { views?: HandEyeView[]; detections?: never })
  | (HandEyeInputBase & { detections?: Detection[]; views?: never });

/** Closure errors of a solution (the report's `errors`). */
export interface HandEyeErrors {
  /** RMS of the per-view translation residuals, mm. */
  translation_rms_mm: number;
  translation_max_mm: number;
  /** RMS of the per-view rotation residuals, degrees. */
  rotation_rms_deg: number;
  rotation_max_deg: number;
  /** Reprojection RMS, px, when image points were given (of the main transforms, refined or closed form, through x^-1 * robot_i^-1 * y). */
  reprojection_rms_px: number | null;
}

/** One solver of the side-by-side comparison: its transforms (keys of the setup) and errors, or `error`. */
export interface HandEyeMethodResult {
  method: HandEyeMethod;
  gripper_from_camera?: PoseReport;
  base_from_camera?: PoseReport;
  base_from_target?: PoseReport;
  gripper_from_target?: PoseReport;
  errors?: HandEyeErrors;
  /** Translation distance of its camera transform from the primary one, mm. */
  disagreement_translation_mm?: number;
  /** Rotation distance from the primary one, degrees. */
  disagreement_rotation_deg?: number;
  /** Why the method failed. */
  error?: string;
  /** Robust cost of this solution under the pose refinement's noise model (when it ran). */
  pose_cost?: number;
}

/** How far `robot[i] * x * camera[i]` lands from the solved target pose. */
export interface HandEyeViewResidual {
  view: number;
  translation_mm: number;
  rotation_deg: number;
}

/** Residual of one motion pair, and |robot angle - camera angle|. */
export interface HandEyeMotionResidual {
  from: number;
  to: number;
  translation_mm: number;
  rotation_deg: number;
  angle_mismatch_deg: number;
}

/** How diverse the robot motions are. */
export interface MotionStats {
  motions: number;
  /** Motion pairs discarded for too little rotation. */
  discarded_small_rotation: number;
  angle_min_deg: number;
  angle_median_deg: number;
  angle_max_deg: number;
  /** Largest angle between a motion axis and the dominant one (0..90 degrees; near 0: all parallel). */
  axis_spread_deg: number;
  /** Unit dominant rotation axis of the robot motions. */
  dominant_axis: Vec3;
}

/** Median and inter-quartile range. */
export interface Spread {
  median: number;
  iqr: number;
}

/** Standard deviations of a pose: translation (mm) and rotation vector (degrees) per axis. */
export interface PoseStd {
  translation_mm: Vec3;
  rotation_deg: Vec3;
}

/** Statistics over the runs of one resampling scheme. */
export interface RunStats {
  runs: number;
  failed: number;
  translation_rms_mm: Spread;
  translation_max_mm: Spread;
  rotation_rms_deg: Spread;
  rotation_max_deg: Spread;
  /** Of the camera transform (`gripper_from_camera` or `base_from_camera`). */
  camera_std: PoseStd;
  target_std: PoseStd;
  translation_rms_mm_samples: number[];
  translation_max_mm_samples: number[];
  rotation_rms_deg_samples: number[];
  rotation_max_deg_samples: number[];
  camera_translation_deviation_mm_samples: number[];
  camera_rotation_deviation_deg_samples: number[];
}

/** Leave-one-out (jackknife-scaled) and bootstrap. */
export interface Repeatability {
  /** The method resampled: `refined from <closed form>` when the pose refinement is on (each resample re-solved the way the main estimate was), else the closed form. */
  method: string;
  /** Bootstrap resamples drawn (absent in reports before it was added). */
  bootstrap_samples?: number;
  /** Seed of the bootstrap resampling (absent in reports before it was added). */
  seed?: number;
  leave_one_out: RunStats;
  bootstrap: RunStats;
}

/** What the image-based refinement did. */
export interface RefinementSummary {
  mode: RefineMode;
  /** The closed form it started from. */
  started_from: string;
  closed_form_reprojection_rms_px: number;
  reprojection_rms_px: number;
  per_view_reprojection_rms_px: number[];
  /** Estimated robot rotation noise per component, degrees (stochastic mode). */
  robot_rotation_noise_deg?: number;
  /** Estimated robot translation noise per component, mm (stochastic mode). */
  robot_translation_noise_mm?: number;
  /** The refined camera (joint_intrinsics mode). */
  camera?: Camera;
}

/** Estimated noise levels (standard deviations) of the robot and camera poses. */
export interface PoseNoiseLevels {
  /** Robot rotation noise per axis of base_from_gripper, degrees. */
  robot_rotation_deg: number;
  /** Robot translation noise per axis, mm. */
  robot_translation_mm: number;
  /** Camera rotation noise about the camera's x, y, z axes, degrees (diagonal model). */
  camera_rotation_deg?: Vec3;
  /** Camera translation noise along the camera's x, y, z axes, mm (diagonal model). */
  camera_translation_mm?: Vec3;
  /** Per-view model: square root of the estimated covariance scale (px for PnP covariances; predicted_pnp: pixel noise over focal length, radians). */
  camera_covariance_sigma?: number;
}

/** Per-axis standard deviations of a refined transform. */
export interface TransformStd {
  /** About the x, y, z axes of the transform's left frame, degrees. */
  rotation_deg: Vec3;
  /** Of translation_m's x, y, z, mm. */
  translation_mm: Vec3;
}

/** What the maximum-likelihood pose refinement did (pose input). */
export interface PoseRefinementSummary {
  /** The closed form with the lowest pose_cost, where the refinement started. */
  started_from: string;
  closed_form_cost: number;
  /** 0.5 * sum of Huber(|whitened residual|^2) over the views after refinement. */
  cost: number;
  /** diagonal or predicted_pnp (chosen by likelihood, pose input); per_view with per-view covariances. */
  camera_noise_model: 'diagonal' | 'predicted_pnp' | 'per_view';
  noise: PoseNoiseLevels;
  /** Diagonal model: target point (m, target frame) the camera rotation noise pivots about, when chosen over the origin. */
  camera_noise_pivot_m?: Vec3;
  /** predicted_pnp: the nominal planar target (m, target frame, z = 0) whose PnP covariance shape is predicted per view. */
  camera_noise_nominal_target_m?: { centre: [number, number]; half_extent: [number, number] };
  /** False with fewer than 8 inlier poses: the default levels were scaled by one factor. */
  noise_estimated_per_component: boolean;
  /** Of gripper_from_camera / base_from_camera. */
  camera_transform_std: TransformStd;
  /** Of base_from_target / gripper_from_target. */
  target_transform_std: TransformStd;
  /** 12 x 12 rows: [camera rx, ry, rz (rad), tx, ty, tz (m), target rx, ry, rz, tx, ty, tz]. */
  covariance: number[][];
  whitened_residual_norms: number[];
  /** Views down-weighted as outliers (whitened residual norm above 4.1). */
  outlier_views: number[];
  /** With image points: reprojection RMS (px) of the refined transforms over every point, each view's points projected through camera_from_target = x^-1 * robot_i^-1 * y (the robot pose and the two refined transforms); also errors.reprojection_rms_px. */
  reprojection_rms_px?: number;
  /** With image points: the same per view, px. */
  per_view_reprojection_rms_px?: number[];
  /** With image points: reprojection RMS of the closed form it started from, px. */
  closed_form_reprojection_rms_px?: number;
  /** Present when the leave-one-out solutions spread wider than the noise model predicts, or the noise scale rests on fewer than 8 poses (the Student-t factor of its degrees of freedom): the factor the std (and the covariance's square root) were widened by, the product of both. */
  std_widened_by?: number;
  /** The working distance: the mean distance from the camera to the target's centre over the views, m (to the target origin with camera poses only). */
  work_distance_m?: number;
  /** The std at the default work point (work_point_error.rms_mm), mm (root-sum-square over the axes): the hand-eye error where the camera looks. */
  work_point_std_mm?: number;
  /** With image points: present when the camera's focal length disagrees with the robot's motion (fitted scale more than 3 of its jackknife std and 0.1 % from 1); the std then include the shift to the solution with the focal length freed. */
  focal_check?: FocalCheck;
}

/** The focal length checked against the robot's motion (image path). */
export interface FocalCheck {
  /** The scale of fx and fy that fits the image points through the robot poses. */
  scale: number;
  /** Its jackknife std over the views. */
  scale_std: number;
  /** How far the solution with the focal length so scaled lies from the reported one: [mm, deg] of the camera transform; absent when that refit failed. */
  freed_moves?: [number, number];
}

/** One robot pose and the image paired with it (`robocal handeye` with images only). */
export interface PairAudit {
  pose_index: number;
  image: string | null;
  used: boolean;
  view?: number;
  reason?: string;
  pose_fit_rms_px?: number;
}

export interface HandEyeReportBase {
  kind: 'handeye';
  /** The primary solution's method: a solver name, `scara`, or `refined from <name>`. */
  method: string;
  errors: HandEyeErrors;
  methods: HandEyeMethodResult[];
  /** Largest disagreement of any solver from the primary, mm. */
  methods_max_disagreement_translation_mm: number;
  /** ... and degrees. */
  methods_max_disagreement_rotation_deg: number;
  per_view: HandEyeViewResidual[];
  per_motion: HandEyeMotionResidual[];
  motion: MotionStats;
  /** Unit directions along which the camera transform's translation is unobservable. */
  unobservable_translation_axes: Vec3[];
  /** Absent when no resampling ran. */
  repeatability?: Repeatability;
  warnings: string[];
  /** Pairing audit (image input of the CLI only). */
  pairs?: PairAudit[];
  /** Present when a refinement ran (the primary transforms are then the refined ones). */
  refinement?: RefinementSummary;
  /** Present when the pose refinement ran (pose input; the primary transforms are then the refined ones). */
  pose_refinement?: PoseRefinementSummary;
  /** The hand-eye error at the work point (by default the target's centre where the views see it, at their mean distance; docs/handeye-field.md); with the pose refinement. */
  work_point_error?: WorkPointError;
  /** The same at the tool centre point (`tcp_m` given). */
  tcp_error?: WorkPointError;
  /** Held-out poses (`holdout` given). */
  holdout?: HoldoutReport;
  /** Touch test (`touch` given). */
  touch_test?: TouchReport;
  robocal_version: string;
}

/** The hand-eye error at one point (docs/handeye-field.md). */
export interface WorkPointError {
  /** `target centre` or `tool centre point`. */
  point: string;
  /** How the point was chosen: the default at the board points' centre (image input) or the target origin (camera poses only), or the tool centre point given. */
  placement?: 'board-centre' | 'target-origin' | 'tool-centre-point';
  /** The point (m) in `frame`. */
  point_m: Vec3;
  /** `gripper` (eye-in-hand) or `base` (eye-to-hand). */
  frame: 'gripper' | 'base';
  point_camera_m: Vec3;
  rms_mm: number;
  /** sqrt(7.815 * largest eigenvalue of the point covariance): holds the 95 % ellipsoid. */
  bound95_mm: number;
  worst_direction_camera: Vec3;
  rotation_share: number;
  verdict: string;
  shrink_by: string[];
}

/** One held-out pose: predicted against observed target position. */
export interface HoldoutPose {
  view: number;
  translation_mm: number;
  rotation_deg: number;
}

/** The report's `holdout`. */
export interface HoldoutReport {
  target_point_m: Vec3;
  per_pose: HoldoutPose[];
  rms_mm: number;
  max_mm: number;
  rotation_rms_deg: number;
  in_sample_rms_mm: number;
  expected_rms_mm: number;
  verdict: string;
}

/** The report's `touch_test`. */
export interface TouchReport {
  points: { distance_mm: number; pixel_error_px: number; depth_m: number }[];
  rms_mm: number;
  max_mm: number;
}

/** Eye-in-hand report: the camera on the gripper, the target fixed in the base. */
export interface EyeInHandReport extends HandEyeReportBase {
  setup: 'eye-in-hand';
  /** `p_gripper = gripper_from_camera * p_camera`. */
  gripper_from_camera: PoseReport;
  /** `p_base = base_from_target * p_target`. */
  base_from_target: PoseReport;
  base_from_camera?: never;
  gripper_from_target?: never;
}

/** Eye-to-hand report: the camera fixed in the base, the target on the gripper. */
export interface EyeToHandReport extends HandEyeReportBase {
  setup: 'eye-to-hand';
  /** `p_base = base_from_camera * p_camera`. */
  base_from_camera: PoseReport;
  /** `p_gripper = gripper_from_target * p_target`. */
  gripper_from_target: PoseReport;
  gripper_from_camera?: never;
  base_from_target?: never;
}

/** The output JSON of `solve_handeye`, discriminated by `setup`. */
export type HandEyeReport = EyeInHandReport | EyeToHandReport;

/** The input JSON of `rank_pose_conventions`: candidate readings of the robot poses. */
export interface RankPoseInput {
  setup: Setup;
  /** At least one candidate, e.g. the `candidates` of `read_robot_poses`. */
  candidates: { name: string; base_from_gripper: PoseInput[] }[];
  camera_from_target: PoseInput[];
}

/** How well robot poses fit the camera motion. */
export interface Consistency {
  /** RMS rotation residual of the motions, degrees. */
  rotation_rms_deg: number;
  /** RMS translation residual of the motions, mm. */
  translation_rms_mm: number;
  /** Scale of the robot translations that best fits the camera motion (1: same unit). */
  robot_translation_scale: number;
}

/** The output JSON of `rank_pose_conventions`. */
export interface RankedCandidates {
  /** Every candidate, best first; `consistency` null when it could not be scored. */
  scores: { name: string; consistency: Consistency | null }[];
  /** What to use and how clear the choice is, when any candidate scored. */
  recommendation: string | null;
}

// ---------------------------------------------------------------------------
// Robot pose files (src/io/poses.rs, pose_formats.rs, pose_candidates.rs, src/api/poses.rs)

/**
 * A pose file layout: vendor formats (`kuka` mm/deg A B C intrinsic ZYX,
 * `ur` m/rotation vector, `abb` mm/quaternion w first, `fanuc` and
 * `yaskawa` mm/deg extrinsic XYZ, `staubli` mm/deg intrinsic XYZ) and
 * generic ones (default metres and radians).
 */
export type PoseFormat =
  | 'ur' | 'kuka' | 'abb' | 'fanuc' | 'yaskawa' | 'staubli'
  | 'xyz_quat_xyzw' | 'xyz_quat_wxyz' | 'xyz_rotvec'
  | `xyz_euler_${EulerKind}_${EulerOrder}`
  | 'matrix4' | 'matrix3x4';
export type LengthUnit = 'mm' | 'm';
export type AngleUnit = 'deg' | 'rad';
/** Which transform a file holds (poses are always returned as `base_from_gripper`). */
export type PoseDirection = 'base_from_gripper' | 'gripper_from_base';

/** The options JSON of `read_robot_poses` (or `""`): what the caller knows; the rest comes from the header or the format. */
export interface PoseFileOptions {
  /** Case-insensitive; `motoman` = `yaskawa`. */
  format?: PoseFormat | 'motoman' | null;
  length_unit?: LengthUnit | null;
  angle_unit?: AngleUnit | null;
  /** Default `base_from_gripper`. */
  direction?: PoseDirection;
}

/** One pose file as the caller read it (`read_robot_pose_files`): its name (the stem names the pose) and text. */
export interface PoseFileText {
  name: string;
  text: string;
}

/** One robot pose from a file. */
export interface RobotPose {
  /** The `name`/`image` column, to pair the pose with an image. */
  name: string | null;
  /** 1-based line of a text file, 1-based element of a JSON array, or (one pose per file) the file's place in numeric order of the names. */
  line: number;
  /** The gripper (TCP) pose in the robot base frame (`geometry::pose_serde::PoseJson`): matrix, translation in metres, quaternion x y z w with w >= 0. */
  base_from_gripper: PoseReport;
}

/** Poses and everything assumed to read them. */
export interface ParsedPoses {
  poses: RobotPose[];
  format: PoseFormat;
  length_unit: LengthUnit;
  /** Meaningless for quaternion and matrix formats. */
  angle_unit: AngleUnit;
  direction: PoseDirection;
  /** How format and units were chosen and what was ignored. */
  notes: string[];
}

/** One plausible reading of an ambiguous pose file. */
export interface PoseCandidate {
  format: PoseFormat;
  length_unit: LengthUnit;
  angle_unit: AngleUnit;
  /** The poses under this reading, as `base_from_gripper`. */
  poses: RobotPose[];
  /** Other format names giving exactly the same poses. */
  same_as: string[];
  /** Implausibility, 0 = nothing suspicious; candidates are sorted by it. */
  penalty: number;
  reasons: string[];
}

/** The output JSON of `read_robot_poses`: the poses, or ranked readings when the layout is ambiguous. */
export type PoseReading =
  | { parsed: ParsedPoses; ambiguity: null; candidates: [] }
  | { parsed: null; ambiguity: string; candidates: PoseCandidate[] };

// ---------------------------------------------------------------------------
// Exports (src/io/export.rs, export_camera.rs, export_transform.rs)

/** Camera formats (need a camera calibration report). */
export type CameraExportFormat =
  | 'json' | 'opencv-yaml' | 'opencv-xml' | 'ros-yaml' | 'kalibr'
  | 'mrcal' | 'halcon' | 'matlab' | 'text';
/** Transform formats with a fixed name. */
export type SimpleTransformFormat =
  | 'matrix4' | 'xyz-quat-xyzw' | 'xyz-quat-wxyz' | 'urdf' | 'urdf-robot' | 'ros2-static-tf'
  | 'ros1-static-tf' | 'ros1-launch' | 'ros2-launch'
  | 'ur' | 'kuka' | 'abb-tooldata' | 'abb-wobjdata' | 'fanuc';
/** Transform formats (need a transform such as `gripper_from_camera`). */
export type TransformExportFormat =
  | SimpleTransformFormat
  | `euler-${EulerKind}-${EulerOrder}-${AngleUnit}`;
/** The `format` of `export_report`; `report` writes the report itself, pretty-printed; a rig report takes a `RigExportFormat`. */
export type ExportFormat = CameraExportFormat | 'report' | TransformExportFormat | RigExportFormat;
/** What `export_formats` lists: every name, the euler family as one pattern. */
export type ExportFormatListEntry =
  | CameraExportFormat
  | 'report'
  | SimpleTransformFormat
  | 'euler-<intrinsic|extrinsic>-<order>-<deg|rad>';
/** A transform key of a report, `parent_from_child` (the `transform` of `export_report`; `""` = the first present of gripper_from_camera, base_from_camera, right_from_left, base_from_target). */
export type TransformName = `${string}_from_${string}`;
/** What `export_report` reads: camera formats need a camera report; transform formats a report with the transform. An optional `frame_names` object (`{"gripper": "tool0", "camera": "camera_optical_frame"}`) names the frames of a transform's key in the output. */
/** A laser plane report exports as `halcon` (HALCON-style sheet-of-light parameters), as its plane frame `camera_from_laser_plane` in a transform format, or as `report`; a laser points report only as `report`. */
export type ExportableReport = CameraCalibration | HandEyeReport | StereoCalibration | RigCalibration | LaserPlaneReport | LaserPointsReport;

// ---------------------------------------------------------------------------
// Planar workflow (src/workflows/planar*.rs)

/** The matrix parameter names (the article's Table 4). */
export type PlanarParameter = 'a11' | 'a12' | 'tx' | 'a21' | 'a22' | 'ty';
/** One value per matrix parameter. */
export type ByParameter<T> = { [P in PlanarParameter]: T };

/** `robot_from_image`: `x_mm = a11 u + a12 v + tx`, `y_mm = a21 u + a22 v + ty`, (u, v) in px. */
export interface PlanarMatrix {
  /** mm of robot x per px of u. */
  a11: number;
  /** mm of robot x per px of v. */
  a12: number;
  /** Robot x of the image origin, mm. */
  tx: number;
  a21: number;
  a22: number;
  /** Robot y of the image origin, mm. */
  ty: number;
}

/** One per-height matrix (the matrix keys flattened in). */
export interface HeightMatrix extends PlanarMatrix {
  /** Calibration height, mm. */
  height_mm: number;
}

/** A pixel to map at some height. */
export interface PredictRequest {
  /** Height of the plane, mm. */
  height_mm: number;
  /** Image point, px. */
  image_px: Vec2;
}

/** The input JSON of `planar_fit`. */
export interface PlanarFitRequest {
  matrices: HeightMatrix[];
  /** Rejection threshold, standard deviations (externally studentized); default none. */
  reject_threshold?: number | null;
  predict?: PredictRequest[];
}

/** A fitted line `value = intercept + slope * height_mm` and its statistics. */
export interface LinearFit {
  intercept: number;
  slope: number;
  /** 1 - RSS/TSS; null when y is constant. */
  r2: number | null;
  pearson_r: number | null;
  /** null for n < 3 or constant y. */
  adj_r2: number | null;
  /** Residual sum of squares. */
  rss: number;
  /** Points used. */
  n: number;
  intercept_std: number;
  slope_std: number;
  intercept_slope_cov: number;
}

/** An image point mapped to the robot plane at some height. */
export interface MappedPoint {
  height_mm: number;
  image_px: Vec2;
  /** Robot X, Y, mm. */
  robot_mm: Vec2;
  /** One-sigma error of robot X, Y from the fitted lines, mm. */
  std_mm: Vec2;
  /** The interpolated matrix at this height. */
  robot_from_image: PlanarMatrix;
}

/** The output JSON of `planar_fit`. */
export interface PlanarFitReport {
  fit: ByParameter<LinearFit>;
  /** Heights rejected before the final fit, mm. */
  rejected_heights_mm: ByParameter<number[]>;
  /** In request order. */
  predictions: MappedPoint[];
  /** The request with its defaults, for re-solving. */
  input: Required<PlanarFitRequest>;
}

/** One observed point of the planar workflow. */
export interface HeightPoint {
  /** Calibration height, mm. */
  height_mm: number;
  /** Undistorted image point, px. */
  image_px: Vec2;
  /** Robot X, Y, mm. */
  robot_mm: Vec2;
}

/** The options of `planar_solve` (missing keys take their defaults). */
export interface PlanarSolveOptions {
  /** The per-height transform model (default `affine`). */
  transform?: 'rigid' | 'similarity' | 'affine';
  /** Rejection threshold, standard deviations; default none. */
  reject_threshold?: number | null;
  /** Plate length |AB| and width |BC|, mm (four-corner plates; default the robot-measured sides). */
  plate_size_mm?: Vec2 | null;
  /** A calibrated camera: image points are undistorted first. */
  camera?: Camera | null;
}

/** The input JSON of `planar_solve`; equal `height_mm` values form one height. */
export interface PlanarSolveRequest {
  points: HeightPoint[];
  options?: PlanarSolveOptions;
  predict?: PredictRequest[];
}

/** The transform fitted at one height. */
export interface PlanarHeightResult {
  height_mm: number;
  kind: 'rigid' | 'similarity' | 'affine';
  robot_from_image: PlanarMatrix;
  /** The linear part has a negative determinant. */
  reflected: boolean;
  /** Per point: fitted minus given robot X, Y, mm. */
  residuals_mm: Vec2[];
  rms_mm: number;
}

/** Pixel density of a four-corner plate at one height (Eq. 15). */
export interface PixelDensity {
  height_mm: number;
  length_px_per_mm: number;
  width_px_per_mm: number;
}

/** The exact height-dependent homography family (DLT). */
export interface PlaneFamily {
  /** Projects `[x_mm, y_mm, z_mm, 1]` to homogeneous pixels, row-major; third row = depth, mm. */
  projection_matrix: Matrix3x4Flat;
  rms_px: number;
}

/** The output JSON of `planar_solve`. */
export interface PlanarSolveResponse {
  /** Per height, sorted by height. */
  heights: PlanarHeightResult[];
  fit: ByParameter<LinearFit>;
  rejected_heights_mm: ByParameter<number[]>;
  /** Four-corner plates only. */
  pixel_density: PixelDensity[] | null;
  density_fit: { length: LinearFit; width: LinearFit } | null;
  /** null with fewer than 6 points. */
  exact_family: PlaneFamily | null;
  /** The points solved (undistorted when a camera was given). */
  points: HeightPoint[];
  options: Required<PlanarSolveOptions>;
  predictions: MappedPoint[];
  /** The pixels mapped by the exact family (robot X, Y, mm), when it was fitted. */
  exact_predictions_mm: Vec2[] | null;
}

// ---------------------------------------------------------------------------
// XY-table and known-motion workflows (src/workflows/xytable.rs, known_motion.rs)

/** One stage position and the target's image centre there. */
export interface StageObservation {
  /** Stage (world) position of the target centre, mm. */
  stage_mm: Vec3;
  /** Image centre of the target, px. */
  image_px: Vec2;
}

/** The input JSON of `xytable_solve`. */
export interface XyTableRequest {
  /** At least 6 non-coplanar positions, in filter order. */
  observations: StageObservation[];
  /** Exactly four extra positions A, B, C, D around a quadrilateral, or none. */
  verification?: StageObservation[];
  /** Repeated image centres of the still target, px (the filter's noise). */
  still_target_px?: Vec2[];
  /** Noise covariance R, px^2, rows (when there is no still target). */
  measurement_noise_px2?: Matrix2Rows | null;
  /** Default `extended`. */
  kalman_mode?: 'extended' | 'linearized';
}

/** One Kalman filter step. */
export interface KalmanStep {
  /** 0-based observation just processed. */
  observation: number;
  projection_row_major: Matrix3x4Flat;
  /** Reprojection RMS of all observations with this estimate, px. */
  rms_px: number;
  /** Trace of the state covariance (normalised units). */
  covariance_trace: number;
}

/** One method's projection matrix, decomposition and residuals. */
export interface XyTableMethodResult {
  /** Maps `[x_mm, y_mm, z_mm, 1]` to homogeneous px; third row = depth, mm. */
  projection_matrix: Matrix3x4Flat;
  /** K, px. */
  camera_matrix: Matrix3Flat;
  /** The stage frame in the camera frame, metres. */
  camera_from_world: PoseReport;
  /** Per calibration position: projected minus measured, px. */
  residuals_px: Vec2[];
  rms_px: number;
  /** Kalman only: the estimate after each observation. */
  history?: KalmanStep[];
}

/** The verification point from the four extra positions. */
export interface XyTableVerification {
  /** Intersection of the image diagonals, px. */
  measured_px: Vec2;
  /** Intersection of the stage diagonals, mm. */
  stage_mm: Vec3;
  /** Distance between the two stage diagonals, mm. */
  diagonal_gap_mm: number;
  batch_predicted_px: Vec2;
  batch_error_px: number;
  kalman_predicted_px: Vec2;
  kalman_error_px: number;
}

/** The output JSON of `xytable_solve`. */
export interface XyTableReport {
  batch: XyTableMethodResult;
  kalman: XyTableMethodResult & { history: KalmanStep[] };
  /** R used by the filter, px^2, rows. */
  measurement_noise_px2: Matrix2Rows;
  noise_source: 'still_target' | 'given' | 'batch_residuals';
  verification: XyTableVerification | null;
  input: Required<XyTableRequest>;
}

/** The input JSON of `known_motion_solve`: `P_i = R (P_ref + d_i) + T`. */
export interface KnownMotionRequest {
  /** Increment of every position from the start, reference frame, mm (first usually 0). */
  increments_mm: Vec3[];
  /** The point seen by the camera at each position, camera frame, mm. */
  points_camera_mm: Vec3[];
  /** The start position in the reference frame, mm; default: the origin is the start. */
  start_reference_mm?: Vec3 | null;
}

/** The output JSON of `known_motion_solve`. */
export interface KnownMotionReport {
  /** The reference frame in the camera frame: translation in metres. */
  camera_from_reference: PoseReport;
  /** The start point in the camera frame, mm. */
  start_camera_mm: Vec3;
  /** The start point in the reference frame, mm (zero when not given). */
  start_reference_mm: Vec3;
  reference_origin_given: boolean;
  /** Per position: predicted minus observed camera point, mm. */
  residuals_mm: Vec3[];
  rms_mm: number;
  input: Required<KnownMotionRequest>;
}

/** What `workflow_csv(kind, text)` returns, per `kind`. */
export interface WorkflowCsvKinds {
  /** Header `height_mm,a11,a12,tx,a21,a22,ty`; the `planar_fit` request. */
  'planar-matrices': { matrices: HeightMatrix[] };
  /** Header `height_mm,u_px,v_px,x_mm,y_mm`; the `planar_solve` request. */
  'planar-points': { points: HeightPoint[] };
  /** Header `x_mm,y_mm,z_mm,u_px,v_px[,role]`; the `xytable_solve` request. */
  xytable: Required<XyTableRequest>;
  /** Header `dx_mm,dy_mm,dz_mm,x_cam_mm,y_cam_mm,z_cam_mm`; the `known_motion_solve` request. */
  'known-motion': Required<KnownMotionRequest>;
}
export type WorkflowCsvKind = keyof WorkflowCsvKinds;

// ---------------------------------------------------------------------------
// The demo session (src/synth/demo.rs)

/** `render_demo(seed).json`; the PNGs are `bytes.subarray(offset, offset + length)`. */
export interface DemoIndex {
  target: Target;
  target_spec: TargetSpec;
  images: { name: string; offset: number; length: number }[];
  /** The robot's `base_from_gripper` poses: UR-style CSV (metres, rotation vectors) with an `image` column. */
  poses_csv: string;
  truth: { camera: Camera; gripper_from_camera: PoseReport; base_from_target: PoseReport };
}

// ---------------------------------------------------------------------------
// The check of a saved calibration and the projection difference
// (src/api/check.rs, src/calib/check.rs, src/calib/projection_diff.rs; docs/check.md)

/** The thresholds of the check's verdict (every key optional; defaults in docs/check.md). */
export interface CheckThresholds {
  /** Drifted when the worst projection shift exceeds this many projection std (default 3) ... */
  shift_sigma?: number;
  /** ... or this many px, whichever is larger (default 1). */
  shift_floor_px?: number;
  /** The projection-shift threshold itself, px (replaces the two above). */
  shift_px?: number | null;
  /** A parameter moved beyond this many of its std (default 3) ... */
  param_sigma?: number;
  /** ... and at least this, px (default 0.5). */
  param_floor_px?: number;
  /** Broken above this reprojection RMS of the saved model, px (default max(10 x saved RMS, 3 px)). */
  broken_rms_px?: number | null;
  /** With `camera_from_target`: moved beyond this translation, mm (default 2) ... */
  pose_mm?: number;
  /** ... or this rotation, degrees (default 0.2). */
  pose_deg?: number;
}

/** The input JSON of `check_camera`. */
export interface CheckRequest {
  /** The saved calibration file's text: a robocal report or camera JSON, OpenCV YAML/XML or ROS camera_info. */
  calibration: string;
  /** Detections of the target in the new images (none reads broken). */
  views?: CalibrationView[];
  thresholds?: CheckThresholds;
  /** Where the fixed camera saw the fixed target at calibration time. */
  camera_from_target?: PoseInput | null;
}

/** The projection difference of two cameras (`calib::projection_diff::ProjectionDiff`), px. */
export interface ProjectionDiff {
  image_size_px: ImageSize;
  /** Grid columns and rows. */
  grid: [number, number];
  x_px: number[];
  y_px: number[];
  /** Per grid row, per column: the shift, px (null where a model is not defined). */
  map: (number | null)[][];
  worst: number;
  worst_at_px: [number, number];
  median: number;
  rms: number;
  /** The fitted implied rotation b_from_a. */
  b_from_a_quaternion_xyzw: [number, number, number, number];
  implied_rotation_deg: number;
  n_points: number;
  n_fit: number;
}

/** The thresholds the verdict used. */
export interface CheckUsedThresholds {
  shift_px: number;
  projection_std_px: number | null;
  shift_sigma: number;
  shift_floor_px: number;
  param_sigma: number;
  param_floor_px: number;
  broken_rms_px: number;
  pose_mm: number;
  pose_deg: number;
}

/** One refitted parameter of the check. */
export interface CheckParameter {
  name: 'fx' | 'fy' | 'cx' | 'cy';
  saved: number;
  refit: number;
  shift_px: number;
  saved_std_px: number | null;
  refit_std_px: number | null;
  /** The shift in std (saved and refit std combined). */
  shift_std: number | null;
  moved: boolean;
}

/** The output JSON of `check_camera` (what `robocal check` writes). */
export interface CheckReport {
  kind: 'check';
  robocal_version: string;
  verdict: 'ok' | 'drifted' | 'broken';
  reasons: string[];
  image_size_px: ImageSize;
  views: { name: string; n_points: number; rms_px: number | null; error: string | null }[];
  reprojection_rms_px: number | null;
  refit: { camera: Camera; rms_px: number; projection_std_px: number } | null;
  parameters: CheckParameter[];
  moved: string[];
  projection_shift_px: ProjectionDiff | null;
  pose_shift: { translation_mm: number; rotation_deg: number; moved: boolean } | null;
  thresholds: CheckUsedThresholds;
  warnings: string[];
}

/** The input JSON of `diff_cameras`. */
export interface DiffRequest {
  /** The first calibration file's text. */
  a: string;
  /** The second calibration file's text. */
  b: string;
  options?: {
    /** Grid columns and rows (default [60, 40]). */
    grid?: [number, number];
    /** Pixels where data were: the rotation fit weighs each grid cell by the points in it. */
    fit_px?: [number, number][];
    /** Fit the rotation only within this distance of the image centre, px. */
    focus_radius_px?: number | null;
  };
}

/** The output JSON of `diff_cameras` (what `robocal diff` writes). */
export interface DiffReport {
  kind: 'diff';
  robocal_version: string;
  a: Camera;
  b: Camera;
  projection_shift_px: ProjectionDiff;
}

/** The input JSON of `plan_handeye_poses` (docs/pose-plan.md; `robocal plan`'s flags as keys). */
export interface PlanRequest {
  setup: 'eye-in-hand' | 'eye-to-hand';
  /** The robot's current pose. */
  base_from_gripper: PoseInput;
  /** The camera's view of the target from the current pose (e.g. a calibration report view's, or PnP). */
  camera_from_target: PoseInput;
  /** The camera: its JSON, or a camera file's text (robocal JSON, OpenCV YAML/XML, ROS camera_info). */
  camera: Camera | string;
  /** The board points in the target frame, metres (e.g. from `target_points`, z = 0). */
  board_m: Vec3[];
  /** A rough gripper_from_camera (eye-in-hand) or gripper_from_target (eye-to-hand); default identity. */
  guess?: PoseInput;
  /** Number of poses (default 15). */
  poses?: number;
  /** Largest tilt of the board against the camera's view, degrees (default 40). */
  max_tilt_deg?: number;
  /** Largest roll about the optical axis from the current view, degrees (default 60). */
  max_roll_deg?: number;
  /** Working distance range, camera to board centre, metres (default the current distance -20 % .. +20 %). */
  distance_m?: [number, number];
  /** Box the flange stays in, base frame, metres: two opposite corners. */
  flange_box_m?: [Vec3, Vec3];
  /** Every board point at least this far inside the image, px (default 20). */
  margin_px?: number;
  /** Corner noise the prediction assumes, px per axis (default: measured on `view_px`, else 0.3). */
  pixel_sigma_px?: number;
  /** The current view's detected pixels of the `board_m` points, same order: the corner noise is measured on them (their PnP residual) when `pixel_sigma_px` is not given. */
  view_px?: [number, number][];
}

/** One planned pose, in visiting order from the current pose. */
export interface PlanPose {
  base_from_gripper: PoseReport;
  /** The camera's predicted view of the target there. */
  camera_from_target: PoseReport;
  tilt_deg: number;
  distance_m: number;
  roll_deg: number;
}

/** The output JSON of `plan_handeye_poses` (what `robocal plan` writes). */
export interface PlanReport {
  kind: 'handeye-plan';
  poses: PlanPose[];
  /** The hand-eye error at the work point these poses reach. */
  predicted: WorkPointError;
  motion: MotionStats;
  /** Flange travel along the tour from the current pose, metres. */
  travel_m: number;
  /** Candidates that passed the limits. */
  candidates: number;
  notes: string[];
  /** The noise the prediction assumed; `pixel_sigma_from`: `default` (0.3 px), `given` or `measured-on-view`. */
  noise: {
    pixel_sigma_px: number;
    pixel_sigma_from: 'default' | 'given' | 'measured-on-view';
    robot_rotation_deg: number;
    robot_translation_mm: number;
  };
  robocal_version: string;
}

// ---------------------------------------------------------------------------
// Laser-line sensors (src/api/laser.rs, src/api/laser_json.rs; docs/laser.md)

/** The stripe extractor's settings (the flags of `robocal laser`); every key may be left out. */
export interface LaserStripeSettings {
  /** `cog` (centre of gravity, default) or `ridge` (Steger's ridge detector). */
  extractor?: 'cog' | 'ridge' | 'centre_of_gravity' | 'steger';
  /** `auto` (default), `columns` (a roughly horizontal stripe) or `rows`. */
  axis?: 'auto' | 'columns' | 'rows';
  /** Smallest peak contrast above the local background, grey levels (default 20). */
  min_contrast?: number;
  /** Widest stripe expected, pixels (default 24). */
  max_width_px?: number;
}

/** The input JSON of `laser_plane` (the images go beside it: one per pose, or board then stripe per pose with `pairs`). */
export interface LaserPlaneRequest {
  /** The calibrated camera file's text: a robocal report or camera JSON, OpenCV YAML/XML or ROS camera_info. */
  camera: string;
  /** The board: a CLI spec or a target JSON object. */
  target: Target | TargetSpec;
  /** The images alternate board (laser off) and stripe (laser on). */
  pairs?: boolean;
  /** A name per pose (default `pose_1`, ...). */
  names?: string[];
  /** The fit's residual: `image_px` (default: pixels along the scan, weighted by each centre's std) or `point_to_plane` (metres). */
  residual?: 'image_px' | 'point_to_plane';
  stripe?: LaserStripeSettings;
}

/** The plane `normal_camera . X = distance_m` (camera frame, metres; the normal points away from the camera centre). */
export interface LaserPlane {
  normal_camera: Vec3;
  distance_m: number;
}

/** The fitted plane and its uncertainty. */
export interface LaserPlaneFit extends LaserPlane {
  /** Covariance of (nx, ny, nz, distance_m), row by row (rank 3: the normal stays unit). */
  covariance: [Vec4, Vec4, Vec4, Vec4];
  /** The normal's angular std (RMS over its two tilt axes), degrees. */
  normal_std_deg: number;
  /** The distance's std, millimetres. */
  distance_std_mm: number;
}

/** One pose of the laser plane fit. */
export interface LaserImageReport {
  name: string;
  /** The board's pose from its corners (PnP with the calibrated camera). */
  camera_from_target: PoseReport;
  board_rms_px: number;
  stripe_axis: 'columns' | 'rows';
  /** Stripe centres found in the image. */
  stripe_points: number;
  /** Centres on the board, used by the fit. */
  n_points: number;
  /** Residual RMS along the scan, pixels. */
  rms_px: number;
  /** Point-to-plane RMS, millimetres. */
  rms_mm: number;
  /** Scan lines without a centre between found ones, `[first, last]`. */
  gaps: [number, number][];
}

/** The output JSON of `laser_plane` (what `robocal laser plane` writes). */
export interface LaserPlaneReport {
  kind: 'laser_plane';
  robocal_version: string;
  laser_plane: LaserPlaneFit;
  residual: 'image_px' | 'point_to_plane';
  extractor: 'cog' | 'ridge';
  /** The residual variance that scaled the covariance (near 1 when the centres' std are right). */
  variance_factor: number;
  images: LaserImageReport[];
  /** Singular values of the stripe points' scatter, metres. */
  singular_values_m: Vec3;
  /** Weak geometry (stripes nearly parallel or on one line) and images that added nothing. */
  warnings: string[];
}

/** The input JSON of `laser_points` (the stripe image, and the laser-off image when given, go beside it). */
export interface LaserPointsRequest {
  /** The calibrated camera file's text. */
  camera: string;
  /** A `laser_plane` report, `{laser_plane: {...}}` or the bare plane. */
  plane: LaserPlaneReport | { laser_plane: LaserPlane } | LaserPlane;
  /** The camera's mounting on the flange: adds `flange_m` to every point. */
  gripper_from_camera?: PoseInput | null;
  /** The flange's pose for this image (needs `gripper_from_camera`): adds `base_m`. */
  base_from_gripper?: PoseInput | null;
  stripe?: LaserStripeSettings;
}

/** One profile point: a stripe centre's ray met with the plane. */
export interface LaserProfilePoint {
  pixel: Vec2;
  camera_m: Vec3;
  flange_m?: Vec3;
  base_m?: Vec3;
}

/** The output JSON of `laser_points` (what `robocal laser points` writes). */
export interface LaserPointsReport {
  kind: 'laser_points';
  robocal_version: string;
  laser_plane: LaserPlane;
  stripe_axis: 'columns' | 'rows';
  extractor: 'cog' | 'ridge';
  points: LaserProfilePoint[];
  /** Centres whose ray missed the plane. */
  missed: number;
  gaps: [number, number][];
  /** The two ends of every continuous piece of the stripe, pixels. */
  ends: Vec2[];
}

/** One stripe centre (`laser::StripePoint`). */
export interface LaserStripePoint {
  x_px: number;
  y_px: number;
  /** Full width at half the contrast, pixels. */
  width_px: number;
  /** Brightest grey level of the peak (after the laser-off subtraction). */
  peak: number;
  /** Peak above the local background, grey levels. */
  contrast: number;
  /** The centre's std along the scan, pixels. */
  std_px: number;
  /** A pixel of the window is at 255. */
  saturated: boolean;
}

/** The output JSON of `laser_stripe`: one image's stripe (`laser::Stripe`). */
export interface LaserStripe {
  axis: 'columns' | 'rows';
  method: 'centre_of_gravity' | 'ridge';
  points: LaserStripePoint[];
  gaps: [number, number][];
  ends: Vec2[];
  /** The image's noise estimate, grey levels. */
  noise_grey: number;
  /** The ridge detector's Gaussian sigma, pixels (ridge only). */
  ridge_sigma_px?: number;
}

// ---------------------------------------------------------------------------
// Function -> JSON map

/**
 * Every function's JSON: `[input, output]`, `never` where the function takes
 * or returns no JSON. With it, `JSON.parse(robocal.detect_target(png, spec))
 * as JsonOutput<'detect_target'>` is a `Detection`.
 */
export interface RobocalJson {
  /** `image_info(bytes)` -> ImageInfo. */
  image_info: [never, ImageInfo];
  /** `decode_image_preview(bytes, max_side).info_json` -> ImageInfo. */
  decode_image_preview: [never, ImageInfo];
  /** `detect_target(bytes, JSON.stringify(target) or a TargetSpec)` -> Detection. */
  detect_target: [Target, Detection];
  /**
   * `detect_boards(bytes, JSON.stringify(target) or a TargetSpec)` -> Detection[]: every board
   * of a marker board's layout in the image, the target's own first (when in view), then boards
   * printed with other blocks of ids (each one's `target.first_id` says which); other targets
   * give their one detection.
   */
  detect_boards: [Target, Detection[]];
  /** `calibrate_camera(input)` -> `{report, comparison}`. */
  calibrate_camera: [CalibrationInput, CalibrationOutput];
  /** `calibrate_stereo(input)` -> the stereo report. */
  calibrate_stereo: [StereoInput, StereoCalibration];
  /** `undistort_preview(bytes, JSON.stringify(camera), max_side)` returns an `ImageData` (grey RGBA), not JSON. */
  undistort_preview: [Camera, never];
  /** `solve_handeye(input)` -> the hand-eye report. */
  solve_handeye: [HandEyeInput, HandEyeReport];
  /** `rank_pose_conventions(input)` -> scores, best first. */
  rank_pose_conventions: [RankPoseInput, RankedCandidates];
  /** `read_robot_poses(text, JSON.stringify(options) or "")` -> the poses or candidates. */
  read_robot_poses: [PoseFileOptions, PoseReading];
  /** `read_robot_pose_files(JSON.stringify(files), JSON.stringify(options) or "")` -> the poses or candidates, one pose per file (read in numeric order of the names, each named by its file's stem; docs/pose-formats.md). */
  read_robot_pose_files: [PoseFileText[], PoseReading];
  /** `export_report(JSON.stringify(report), format, transform or "")` returns the file's text, not JSON. */
  export_report: [ExportableReport, never];
  /** `export_formats()` -> the format names. */
  export_formats: [never, ExportFormatListEntry[]];
  /** `lens_models()` -> the lens-model table, in menu order (the default, `brown`, first). */
  lens_models: [never, LensModelInfo[]];
  /** `calibrate_rig(input)` -> the rig report. */
  calibrate_rig: [RigInput, RigCalibration];
  /** `calibrate_rig_handeye(input)` -> the rig report with `handeye` (a rig on a robot). */
  calibrate_rig_handeye: [RigHandEyeInput, RigOnRobotReport];
  /** `export_report_files(JSON.stringify(report), format, transform or "", JSON.stringify(frames) or "")` -> the files (several for a rig's `ros` and `mrcal` and a stereo pair's `ros`, as `robocal export -o DIR` writes them); `frames` names frames by role, e.g. `{"rig": "camera_rig"}`. */
  export_report_files: [ExportableReport, ExportFile[]];
  /** `rig_export_formats()` -> the rig format names. */
  rig_export_formats: [never, RigExportFormat[]];
  /** `planar_fit(request)` -> the height model and predictions. */
  planar_fit: [PlanarFitRequest, PlanarFitReport];
  /** `planar_solve(request)` -> the planar workflow report. */
  planar_solve: [PlanarSolveRequest, PlanarSolveResponse];
  /** `xytable_solve(request)` -> batch and Kalman projection matrices. */
  xytable_solve: [XyTableRequest, XyTableReport];
  /** `known_motion_solve(request)` -> camera_from_reference. */
  known_motion_solve: [KnownMotionRequest, KnownMotionReport];
  /** `workflow_csv(kind, text)` -> the request of the matching solver (see WorkflowCsvKinds). */
  workflow_csv: [never, WorkflowCsvKinds[WorkflowCsvKind]];
  /** `render_demo(seed).json` -> the demo index. */
  render_demo: [never, DemoIndex];
  /** `parse_target(spec or JSON.stringify(target))` -> the target, checked by the core. */
  parse_target: [Target, Target];
  /** `read_kalibr_target(yamlText)` -> the target of a Kalibr target YAML (`target_type: aprilgrid` or `checkerboard`). */
  read_kalibr_target: [never, Target];
  /** `target_points(spec or target JSON)` -> the board points in id order, metres. */
  target_points: [Target, TargetPoint[]];
  /** `target_svg(spec or target JSON)` returns the printable sheet (SVG text, mm at true scale), not JSON. */
  target_svg: [Target, never];
  /** `target_spec(spec or target JSON)` returns the canonical CLI spec (e.g. `chessboard:9x6:30mm`), not JSON. */
  target_spec: [Target, never];
  /** `pair_images(JSON.stringify(leftNames), JSON.stringify(rightNames))` -> the pairs (robocal::io::pairing). */
  pair_images: [string[], ImagePairing];
  /** `rig_frame_keys(JSON.stringify(cameras), groupBy)` (groupBy `'number'` or `'last'` (the last number in the name), `'first'`, `'order'`, a pattern with one `(\\d+)` such as `'sync(\\d+)'`, or `''`: by number unless no name has one) -> each image's frame key, as `robocal rig --group-by` groups them. */
  rig_frame_keys: [RigCameraNames[], RigFrameGrouping];
  /** `video_timestamps(text)` -> caliscope's `timestamps.csv` (sync_index, cam_id, frame_index, frame_time) per camera in video frame order, as `robocal rig --timestamps` reads it. */
  video_timestamps: [never, VideoTimestamps];
  /** `video_frame_name(video, index)` returns the name of frame `index` (0 first) of the video file `video`, not JSON: `cam_0.mp4#frame0123`, as `robocal` names the frames it takes from a video. */
  video_frame_name: [never, never];
  /** `read_camera_file(text)` -> the camera of any camera format robocal exports (robocal JSON camera export or calibration report, OpenCV YAML/XML, ROS camera_info, Kalibr, mrcal, HALCON tuple or .dat, MATLAB script, text matrix), as `robocal rig --camera-file` reads it. */
  read_camera_file: [never, CameraFileReading];
  /** `check_camera(request)` -> the check of a saved calibration against new views: ok, drifted or broken (docs/check.md). */
  check_camera: [CheckRequest, CheckReport];
  /** `diff_cameras(request)` -> the projection difference of two calibration files. */
  diff_cameras: [DiffRequest, DiffReport];
  /** `plan_handeye_poses(request)` -> robot poses for a hand-eye calibration from one view of the target, with the predicted error at the work point (docs/pose-plan.md). */
  plan_handeye_poses: [PlanRequest, PlanReport];
  /** `plan_move_list(JSON.stringify(plan), format)` returns the text for the robot, not JSON: a program (`ur-script`, `kuka-krl`, `abb-rapid`) or a pose table in a pose format robocal reads (`ur`, `kuka`, `abb`, `fanuc`, `yaskawa`, `staubli`, `xyz_quat_xyzw`, ...), as `robocal plan --export --format` writes it. */
  plan_move_list: [PlanReport, never];
  /** `laser_plane(JSON.stringify(request), images, options?)` -> the laser plane in the camera frame from board images with the stripe (`images`: Uint8Array per image, one per pose or board then stripe per pose with `pairs`), as `robocal laser plane` (docs/laser.md). */
  laser_plane: [LaserPlaneRequest, LaserPlaneReport];
  /** `laser_points(JSON.stringify(request), stripeImage, offImage or undefined, options?)` -> the stripe as 3-D points (camera, flange, base), as `robocal laser points`. */
  laser_points: [LaserPointsRequest, LaserPointsReport];
  /** `laser_stripe(image, offImage or undefined, JSON.stringify(settings) or "", options?)` -> one image's stripe centres, gaps and ends. */
  laser_stripe: [LaserStripeSettings, LaserStripe];
}

/** What `read_camera_file` returns: the camera (what a rig input's `cameras[i].camera` takes to hold its intrinsics) and the format it was read as. */
export interface CameraFileReading {
  camera: Camera;
  format: 'json' | 'opencv-yaml' | 'opencv-xml' | 'ros-yaml' | 'kalibr' | 'mrcal' | 'halcon' | 'matlab' | 'text';
}

/** One camera's image names, the input of `rig_frame_keys`. */
export interface RigCameraNames {
  name: string;
  images: string[];
}

/** What `rig_frame_keys` returns: the rule used, each image's frame key per camera (input order), and every key sorted. */
export interface RigFrameGrouping {
  /** The rule: `number`, `last`, `first`, `order` or the pattern. */
  grouped_by: string;
  keys: string[][];
  frames: string[];
}

/** What `video_timestamps` returns: per cam_id (the N of `cam_N.mp4`), the sync index and capture time of each video frame (entry k is the video's frame k). */
export interface VideoTimestamps {
  cameras: Record<string, { sync_index: number[]; time_s: number[] }>;
}

/** One board point of `target_points`: id and position in the board frame (z = 0), metres. */
export interface TargetPoint {
  id: number;
  x_m: number;
  y_m: number;
}

/** What `pair_images` returns: how the names paired and `[left index, right index]` pairs in left order. */
export interface ImagePairing {
  paired_by: 'number' | 'order';
  pairs: [number, number][];
}

/**
 * The optional `options_json` argument of `image_info`, `decode_image_preview`,
 * `detect_target`, `detect_boards` and `undistort_preview` (their last but for
 * `decode_image_preview`'s `keep_grey`), as JSON text: the largest image
 * accepted, pixels (default 64 MP in wasm). Over it the error names the
 * image size and the limit.
 */
export interface ImageOptions {
  max_pixels?: number;
}

// ---------------------------------------------------------------------------
// Live capture (`LiveCapture`, docs/live-capture.md; robocal::capture)

/** What the kept frames cover (capture::Coverage). */
export interface LiveCoverage {
  /** `[columns, rows]` of the image cell grid (8 x 6). */
  grid: [number, number];
  /** Points of kept frames per cell, row-major. */
  cells: number[];
  /** Kept frames per tilt bin, `[bin about x][bin about y]`; bins: 0 below -15 deg, 1 within, 2 above 15 deg. */
  tilt: [[number, number, number], [number, number, number], [number, number, number]];
  /** Kept frames per distance bin: far, middle, near. */
  distance: [number, number, number];
  /** Frames counted: the kept frames not excluded (`set_included`). */
  kept: number;
}

/** What a frame covers (capture::Signature). */
export interface LiveSignature {
  cells: number[];
  tilt_x_deg: number;
  tilt_y_deg: number;
  tilt_bin: [number, number];
  /** Board side over image width were it facing the camera at its distance. */
  span: number;
  /** 0 far, 1 middle, 2 near. */
  distance_bin: number;
}

/** What a frame would add (capture::Novelty). */
export interface LiveNovelty {
  new_cells: number;
  new_tilt: boolean;
  new_distance: boolean;
  /** Under a running calibration not yet good enough: the worst projection uncertainty predicted after adding this frame, px (null otherwise, or for a repeat of a kept view). */
  predicted_max_std_px: number | null;
  /** That prediction is at least 5 % below the calibration's worst: the frame adds information. */
  lowers_uncertainty: boolean;
}

/** The next pose to show (capture::Suggestion): the board outline to match. */
export interface LiveSuggestion {
  rule: 'coverage' | 'uncertainty';
  /** The board print's four corners in the image, px. */
  outline_px: [Vec2, Vec2, Vec2, Vec2];
  camera_from_target: PoseReport;
  tilt_x_deg: number;
  tilt_y_deg: number;
  span: number;
  /** With the uncertainty rule: the worst projection uncertainty predicted after adding this view, px. */
  predicted_max_std_px: number | null;
  why: string;
}

/** The robot-motion diversity of the captures with robot poses (capture::HandEyeGuide). */
export interface LiveHandEyeGuide {
  poses: number;
  motions: number;
  axis_spread_deg: number;
  dominant_axis: Vec3;
  enough: boolean;
  advice: string;
}

/** Why a frame was kept or not. */
export type LiveReason = 'not_found' | 'too_few_points' | 'settling' | 'moving' | 'blurred' | 'good_enough' | 'nothing_new' | 'kept' | 'kept_manually';

/** `LiveCapture.push_frame / push_rgba / push_grey` (capture::FrameReport). */
export interface LiveFrameReport {
  status: 'found' | 'partial' | 'not_found';
  /** Detected pixels in id order. */
  points: Vec2[];
  ids: number[];
  still: boolean;
  /** Largest point motion over the compared frames, px. */
  motion_px: number | null;
  sharp: boolean;
  /** Blur measure: equivalent Gaussian sigma of the board's edges, px. */
  blur_px: number | null;
  novel: boolean;
  novelty: LiveNovelty | null;
  signature: LiveSignature | null;
  keep: boolean;
  reason: LiveReason;
  /** The reason as a sentence. */
  message: string;
  /** Frames kept (excluded ones too): the next capture's index. */
  kept: number;
  /** Kept frames not excluded. */
  used: number;
  coverage: LiveCoverage;
  suggestion: LiveSuggestion | null;
  good_enough: boolean;
}

/** `LiveCapture.state()`, `remove`, `set_included`, `set_robot_pose`; `capture()` adds `index`. */
export interface LiveState {
  /** Frames kept (excluded ones too). */
  kept: number;
  /** Kept frames not excluded: what the coverage, the running calibration and the hand-eye guide use. */
  used: number;
  coverage: LiveCoverage;
  suggestion: LiveSuggestion | null;
  good_enough: boolean;
  handeye: LiveHandEyeGuide;
  /** Only from `capture()`: the index of the kept frame. */
  index?: number;
}

/** `LiveCapture.calibrate()`. */
export interface LiveCalibrated extends LiveState {
  calibration: CameraCalibration;
  max_std_px: number;
}

/** A function that exchanges JSON. */
export type JsonFunction = keyof RobocalJson;
/** The JSON a function reads (serialise it with JSON.stringify). */
export type JsonInput<F extends JsonFunction> = RobocalJson[F][0];
/** The JSON a function returns (the type of JSON.parse of its result). */
export type JsonOutput<F extends JsonFunction> = RobocalJson[F][1];
