// Types of the robocal npm package (node entry). Functions come from the
// wasm-bindgen declarations; the JSON shapes they exchange are below.
export * from './node/robocal.js';

/** What `image_info` returns (and `ImagePreview.info_json` holds), as JSON. */
export interface ImageInfo {
  /** Container format, lower case. */
  format: 'png' | 'jpeg' | 'tiff' | 'bmp' | 'pnm' | 'gif';
  /** Upper-case display name, e.g. "PNG". */
  format_name: string;
  width: number;
  height: number;
  /** 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA. */
  channels: number;
  bits_per_channel: number;
}

/** A rigid transform as the reports write it: `p_a = a_from_b * p_b`, metres. */
export interface PoseReport {
  matrix_row_major: number[][];
  translation_m: [number, number, number];
  /** Unit quaternion, component order x, y, z, w. */
  quaternion_xyzw: [number, number, number, number];
}

/** A calibration target as JSON (`Detection.target`; `detect_target` also
 * takes a CLI spec such as `chessboard:9x6:30mm` or
 * `squares:8x8:12.7mm:22.5778mm`). Lengths in metres; docs/detection-json.md
 * gives each kind's point order. */
export type Target =
  | { kind: 'chessboard'; cols: number; rows: number; square_m: number }
  | { kind: 'circle_grid'; cols: number; rows: number; spacing_m: number; asymmetric: boolean; polarity: 'dark_on_light' | 'light_on_dark' }
  | { kind: 'dot_plate'; cols: number; rows: number; pitch_m: number; dot_diameter_m: number }
  | { kind: 'single_circle'; diameter_m: number }
  /** `cols x rows` separate dark squares, 4 corners each: id = 4 (i + j cols) + k. */
  | { kind: 'square_grid'; cols: number; rows: number; side_m: number; pitch_m: number };

/** What `detect_target` returns, as JSON. Pixels: (0, 0) is the centre of the top-left pixel. */
export interface Detection {
  image_size_px: [number, number];
  target: Target;
  /** Sorted by id; `covariance_px2` is `[xx, xy, yy]` when estimated. */
  points: { id: number; x_px: number; y_px: number; covariance_px2?: [number, number, number] }[];
}

/** One view of a calibration input: a `detect_target` detection, or explicit correspondences. */
export type CalibrationView =
  | { name: string; detection: Detection | object }
  | { name: string; object_m: [number, number, number][]; image_px: [number, number][] };

/** The options object of `calibrate_camera` and `calibrate_stereo`. */
export interface CalibrationOptions {
  fix_principal_point?: boolean;
  fix_aspect_ratio?: boolean;
  /** Default true. */
  zero_skew?: boolean;
  /** Huber loss (1 px) and rejection beyond 3 robust sigmas. */
  robust?: boolean;
  fixed_coefficients?: string[];
}

/** The input JSON of `calibrate_stereo`: `left[i]` and `right[i]` saw the same board pose. */
export interface StereoInput {
  /** brown (default), radial_k1_k2_k5, rational, division, kannala_brandt, eucm, none. */
  model?: string;
  options?: CalibrationOptions;
  left: CalibrationView[];
  right: CalibrationView[];
  /** Optional when the views are detections. */
  left_image_size_px?: [number, number];
  right_image_size_px?: [number, number];
}

/** The output JSON of `calibrate_stereo` (the report `robocal stereo` writes). */
export interface StereoCalibration {
  /** Camera calibration reports (as `calibrate_camera`'s `report`). */
  left: object;
  right: object;
  /** `p_right = right_from_left * p_left`. */
  right_from_left: PoseReport;
  initial_right_from_left: PoseReport;
  /** Distance between the camera centres, metres. */
  baseline_m: number;
  /** Standard deviations (rotation: small-angle vector); null when singular. */
  right_from_left_std: { rotation_rad: [number, number, number]; translation_m: [number, number, number] } | null;
  /** RMS reprojection error over every point of both cameras, px. */
  rms_px: number;
  iterations: number;
  termination: string;
}
