// Compile-time check of the package's declarations (tsc --noEmit --strict,
// run by smoke.mjs against the installed tarball): realistic values of
// every JSON shape as typed literals, the calls typed through RobocalJson,
// and `@ts-expect-error` lines proving wrong keys and kinds are rejected.
import * as robocal from 'robocal';
import type {
  CalibrationInput, CalibrationOutput, Camera, CameraCalibration, Detection, DemoIndex,
  Distortion, ExportableReport, ExportFormat, HandEyeInput, HandEyeReport, ImageInfo,
  JsonInput, JsonOutput, KnownMotionReport, KnownMotionRequest, PlanarFitReport,
  PlanarFitRequest, PlanarSolveRequest, PlanarSolveResponse, PoseFileOptions, PoseReading,
  PoseReport, RankedCandidates, RankPoseInput, StereoCalibration, StereoInput, Target,
  TargetOf, TargetSpec, WorkflowCsvKinds, XyTableReport, XyTableRequest,
  LaserPlaneRequest, LaserPlaneReport, LaserStripeSettings,
} from 'robocal';

declare const png: Uint8Array;

// --- Targets, detections, images
const chessboard: Target = { kind: 'chessboard', cols: 9, rows: 6, square_m: 0.03 };
const circles: TargetOf<'circle_grid'> = { kind: 'circle_grid', cols: 4, rows: 11, spacing_m: 0.02, asymmetric: true, polarity: 'dark_on_light' };
const dots: Target = { kind: 'dot_plate', cols: 7, rows: 7, pitch_m: 0.025, dot_diameter_m: 0.0125 };
const circle: Target = { kind: 'single_circle', diameter_m: 0.01 };
const squares: TargetOf<'square_grid'> = { kind: 'square_grid', cols: 8, rows: 8, side_m: 0.0127, pitch_m: 0.0225778 };
const squaresSpec: TargetSpec = 'squares:8x8:12.7mm:22.5778mm';
const charuco: TargetOf<'charuco'> = { kind: 'charuco', squares_x: 12, squares_y: 9, square_m: 0.02, marker_m: 0.015, dictionary: 'DICT_5X5_100', first_id: 0, legacy: false };
const charucoIds: Target = { kind: 'charuco', squares_x: 3, squares_y: 3, square_m: 0.02, marker_m: 0.015, dictionary: 'DICT_ARUCO_ORIGINAL', marker_ids: [7, 8, 9, 10] };
const aprilgrid: TargetOf<'aprilgrid'> = { kind: 'aprilgrid', tag_cols: 6, tag_rows: 6, tag_m: 0.088, spacing_ratio: 0.3, first_id: 36 };
const charucoSpec: TargetSpec = 'charuco:12x9:20mm:15mm:DICT_5X5_100:first=4:legacy';
const aprilgridSpec: TargetSpec = 'aprilgrid:6x6:88mm:0.3';
// @ts-expect-error: OpenCV spells the dictionary DICT_5X5_100
const wrongDictionary: Target = { ...charuco, dictionary: '5X5_100' };
// @ts-expect-error: an AprilGrid's tag side is tag_m
const wrongTagKey: Target = { kind: 'aprilgrid', tag_cols: 6, tag_rows: 6, tag_size_m: 0.088, spacing_ratio: 0.3 };
// @ts-expect-error: a chessboard has no spacing_m
const wrongKey: Target = { kind: 'chessboard', cols: 9, rows: 6, spacing_m: 0.03 };
// @ts-expect-error: no such target kind (yet)
const wrongKind: Target = { kind: 'hexagons', cols: 9, rows: 6 };
// @ts-expect-error: polarity is snake_case in JSON
const wrongPolarity: Target = { ...circles, polarity: 'dark-on-light' };
const spec: TargetSpec = 'circles:4x11:20mm:asymmetric';
// @ts-expect-error: not a target spec
const wrongSpec: TargetSpec = 'board 9x6';

const detection: Detection = JSON.parse(robocal.detect_target(png, JSON.stringify(chessboard)));
const detectionLiteral: JsonOutput<'detect_target'> = {
  image_size_px: [640, 480],
  target: circle,
  points: [{ id: 0, x_px: 244.21, y_px: 94.53, covariance_px2: [0.001, 0, 0.001] }],
};
// @ts-expect-error: image_size_px is [width, height]
const wrongSize: Detection = { ...detectionLiteral, image_size_px: [640, 480, 3] };
const info: ImageInfo = { format: 'png', format_name: 'PNG', width: 64, height: 48, channels: 3, bits_per_channel: 8 };
// @ts-expect-error: formats are lower case
const wrongFormat: ImageInfo = { ...info, format: 'PNG' };
const preview: ImageData = robocal.undistort_preview(png, '{}', 256);

// --- Cameras and calibration
const brown: Distortion = { model: 'brown', k1: -0.18, k2: 0.05, k3: 0, p1: 0.0005, p2: -0.0003 };
const none: Distortion = { model: 'none' };
const eucm: Distortion = { model: 'eucm', alpha: 0.5, beta: 1 };
// @ts-expect-error: the division model has kappa only
const wrongCoefficient: Distortion = { model: 'division', kappa: -0.1, k1: 0 };
const camera: Camera = { fx: 900, fy: 900, cx: 511.5, cy: 383.5, skew: 0, width: 1024, height: 768, distortion: brown };
const calibrationInput: CalibrationInput = {
  model: 'brown',
  method: 'all',
  options: { fix_principal_point: false, aspect_ratio: null, zero_skew: true, robust: true, fixed_coefficients: ['k3'] },
  views: [
    { name: 'left01.jpg', detection },
    { name: 'rig', object_m: [[0, 0, 0], [0.03, 0, 0]], image_px: [[320.5, 240.1], [350.2, 240.3]] },
  ],
  image_size_px: [640, 480],
};
// @ts-expect-error: a view is a detection or point pairs, not both
const wrongView: CalibrationInput = { views: [{ name: 'x', detection, object_m: [], image_px: [] }] };
// @ts-expect-error: unknown method
const wrongMethod: CalibrationInput = { method: 'opencv', views: [] };
const pose: PoseReport = {
  matrix_row_major: [[1, 0, 0, 0.1], [0, 1, 0, 0], [0, 0, 1, 0.5], [0, 0, 0, 1]],
  translation_m: [0.1, 0, 0.5],
  quaternion_xyzw: [0, 0, 0, 1],
};
const calibration: CameraCalibration = {
  kind: 'camera',
  robocal_version: '0.1.0',
  image_size_px: [1024, 768],
  model: 'brown',
  camera,
  camera_matrix: [[900, 0, 511.5], [0, 900, 383.5], [0, 0, 1]],
  distortion: { k1: -0.18, k2: 0.05, p1: 0.0005, p2: -0.0003, k3: 0 },
  rms_px: 0.05,
  std: { fx: 0.1, fy: 0.1, cx: 0.2, cy: 0.2, skew: 0 },
  views: [{ name: 'demo_00.png', rms_px: 0.05, n_points: 54, camera_from_target: pose, outliers: [{ index: 3, id: 3, residual_px: 4.2, x_px: 301.5, y_px: 120.25, reason: 'beyond 3 robust sigmas' }], residuals_px: [{ x: 244.2, y: 94.5, dx: 0.01, dy: -0.02, id: 0 }] }],
  correlation: { names: ['fx', 'fy'], matrix: [[1, 0.99], [0.99, 1]] },
  projection_uncertainty: { reference_depth_m: 0.6, x_px: [0, 1023], y_px: [0, 767], std_px: [[0.1, null], [0.1, 0.2]], max_std_px: 0.2 },
  distortion_field: { vectors: [{ x: 0, y: 0, dx: -30, dy: -22 }] },
  warnings: [],
  iterations: 7,
  termination: 'cost_tolerance',
  n_points: 648,
  options: {
    model: brown, initial_camera: null, fix_principal_point: false, fix_aspect_ratio: false, aspect_ratio: null,
    zero_skew: true, fixed_coefficients: [], loss: { kind: 'huber', scale: 1 }, outlier_sigma: 3, max_outlier_rounds: 5, max_iterations: 200,
  },
};
const output: CalibrationOutput = {
  report: calibration,
  comparison: [{ method: 'tsai', fx: null, fy: null, cx: null, cy: null, k1: null, rms_px: null, std_u_px: null, std_v_px: null, error: 'tsai needs ...' }],
};
// @ts-expect-error: termination values are snake_case
const wrongTermination: CameraCalibration = { ...calibration, termination: 'CostTolerance' };
const stereoInput: StereoInput = { model: 'brown', left: calibrationInput.views, right: calibrationInput.views, left_image_size_px: [640, 480] };
const stereo: StereoCalibration = {
  kind: 'stereo', left: calibration, right: calibration, right_from_left: pose, initial_right_from_left: pose, baseline_m: 0.1,
  right_from_left_std: null, rms_px: 0.2, iterations: 5, termination: 'gradient_tolerance',
  warnings: ['pair 3 left out: right r03.png: 3 points: a homography needs at least 4'],
};
const fx: number = (JSON.parse(robocal.calibrate_camera(JSON.stringify(calibrationInput))) as JsonOutput<'calibrate_camera'>).report.camera.fx;

// --- Robot poses and hand-eye
const options: PoseFileOptions = { format: 'xyz_euler_intrinsic_zyx', length_unit: 'mm', angle_unit: 'deg', direction: 'gripper_from_base' };
// @ts-expect-error: not a pose format
const wrongPoseFormat: PoseFileOptions = { format: 'xyz_euler_zyx' };
const reading: PoseReading = JSON.parse(robocal.read_robot_poses('X,Y,Z,A,B,C\n100,0,500,90,0,0\n', JSON.stringify(options)));
if (reading.parsed) {
  const first = reading.parsed.poses[0].base_from_gripper.translation_m;
  const matrix = reading.parsed.poses[0].base_from_gripper.matrix_row_major;
} else {
  const why: string = reading.ambiguity;
  const best = reading.candidates[0]?.format;
}
const ambiguous: PoseReading = {
  parsed: null,
  ambiguity: 'the file has 6 values per row and no header',
  candidates: [{ format: 'ur', length_unit: 'm', angle_unit: 'rad', poses: [{ name: null, line: 1, base_from_gripper: pose }], same_as: ['xyz_rotvec'], penalty: 0, reasons: [] }],
};
// @ts-expect-error: read poses are written with their matrix (geometry::pose_serde::PoseJson)
const noMatrix: JsonOutput<'read_robot_poses'> = { ...ambiguous, candidates: [{ ...ambiguous.candidates[0], poses: [{ name: null, line: 1, base_from_gripper: { translation_m: [0.1, 0, 0.5], quaternion_xyzw: [0, 0, 0, 1] } }] }] };
const handeyeInput: HandEyeInput = {
  setup: 'eye-in-hand',
  base_from_gripper: [pose, { translation_m: [0.1, 0, 0.5], quaternion_xyzw: [0, 0, 0, 1] }],
  detections: [detection, detection],
  camera: output,
  refine: 'stochastic',
  pixel_sigma_px: 0.5,
  method: 'park-martin',
  bootstrap_samples: 100,
  seed: 1,
  strict_checks: true,
};
// @ts-expect-error: views or detections, not both
const bothImages: HandEyeInput = { ...handeyeInput, views: [{ object_m: [[0, 0, 0]], image_px: [[1, 2]] }] };
// @ts-expect-error: setups are kebab-case
const wrongSetup: HandEyeInput = { setup: 'eye_in_hand', base_from_gripper: [] };
const errors = { translation_rms_mm: 0.4, translation_max_mm: 0.9, rotation_rms_deg: 0.02, rotation_max_deg: 0.05, reprojection_rms_px: 0.1 };
const runStats = {
  runs: 12, failed: 0,
  translation_rms_mm: { median: 0.4, iqr: 0.1 }, translation_max_mm: { median: 0.9, iqr: 0.2 },
  rotation_rms_deg: { median: 0.02, iqr: 0.01 }, rotation_max_deg: { median: 0.05, iqr: 0.01 },
  camera_std: { translation_mm: [0.1, 0.1, 0.2], rotation_deg: [0.01, 0.01, 0.02] } as const,
  target_std: { translation_mm: [0.1, 0.1, 0.2], rotation_deg: [0.01, 0.01, 0.02] } as const,
  translation_rms_mm_samples: [0.4], translation_max_mm_samples: [0.9], rotation_rms_deg_samples: [0.02],
  rotation_max_deg_samples: [0.05], camera_translation_deviation_mm_samples: [0.1], camera_rotation_deviation_deg_samples: [0.01],
};
const report: HandEyeReport = {
  kind: 'handeye',
  setup: 'eye-in-hand',
  method: 'refined from park-martin',
  gripper_from_camera: pose,
  base_from_target: pose,
  errors,
  methods: [{ method: 'park-martin', gripper_from_camera: pose, base_from_target: pose, errors, disagreement_translation_mm: 0, disagreement_rotation_deg: 0 }, { method: 'li', error: 'degenerate motions' }],
  methods_max_disagreement_translation_mm: 0.3,
  methods_max_disagreement_rotation_deg: 0.01,
  per_view: [{ view: 0, translation_mm: 0.3, rotation_deg: 0.01 }],
  per_motion: [{ from: 0, to: 1, translation_mm: 0.2, rotation_deg: 0.01, angle_mismatch_deg: 0.001 }],
  motion: { motions: 66, discarded_small_rotation: 0, angle_min_deg: 10, angle_median_deg: 40, angle_max_deg: 90, axis_spread_deg: 80, dominant_axis: [0, 0, 1] },
  unobservable_translation_axes: [],
  repeatability: { method: 'park-martin', leave_one_out: { ...runStats, camera_std: { translation_mm: [0.1, 0.1, 0.2], rotation_deg: [0.01, 0.01, 0.02] }, target_std: { translation_mm: [0.1, 0.1, 0.2], rotation_deg: [0.01, 0.01, 0.02] } }, bootstrap: { ...runStats, camera_std: { translation_mm: [0.1, 0.1, 0.2], rotation_deg: [0.01, 0.01, 0.02] }, target_std: { translation_mm: [0.1, 0.1, 0.2], rotation_deg: [0.01, 0.01, 0.02] } } },
  warnings: [],
  refinement: { mode: 'stochastic', started_from: 'park-martin', closed_form_reprojection_rms_px: 0.3, reprojection_rms_px: 0.1, per_view_reprojection_rms_px: [0.1], robot_rotation_noise_deg: 0.01, robot_translation_noise_mm: 0.1 },
  robocal_version: '0.1.0',
};
// @ts-expect-error: an eye-in-hand report has no base_from_camera
const wrongKeyForSetup: HandEyeReport = { ...report, base_from_camera: pose };
const solved = JSON.parse(robocal.solve_handeye(JSON.stringify(handeyeInput))) as JsonOutput<'solve_handeye'>;
const cameraPose: PoseReport = solved.setup === 'eye-in-hand' ? solved.gripper_from_camera : solved.base_from_camera;
const rank: RankPoseInput = { setup: 'eye-to-hand', candidates: [{ name: 'kuka', base_from_gripper: [pose] }], camera_from_target: [pose] };
const ranked: RankedCandidates = { scores: [{ name: 'kuka', consistency: { rotation_rms_deg: 0.1, translation_rms_mm: 0.5, robot_translation_scale: 1 } }, { name: 'fanuc', consistency: null }], recommendation: null };

// --- Exports
const formats: JsonOutput<'export_formats'> = JSON.parse(robocal.export_formats());
const format: ExportFormat = 'euler-extrinsic-xyz-deg';
// @ts-expect-error: unknown export format
const wrongExport: ExportFormat = 'yaml';
const exportable: ExportableReport[] = [calibration, report, stereo];
const urdf: string = robocal.export_report(JSON.stringify(report), 'urdf', 'gripper_from_camera');

// --- Workflows
const matrices: WorkflowCsvKinds['planar-matrices'] = JSON.parse(robocal.workflow_csv('planar-matrices', 'height_mm,a11,a12,tx,a21,a22,ty\n15,0,0.7,-1700,0.7,0,700\n'));
const fitRequest: PlanarFitRequest = { ...matrices, reject_threshold: 3, predict: [{ height_mm: 60, image_px: [1000, 1000] }] };
const line = { intercept: 0.7, slope: -0.0002, r2: 0.99, pearson_r: -0.99, adj_r2: 0.98, rss: 1e-6, n: 8, intercept_std: 1e-4, slope_std: 1e-6, intercept_slope_cov: 0 };
const byParameter = { a11: line, a12: line, tx: line, a21: line, a22: line, ty: line };
const noRejects = { a11: [], a12: [], tx: [], a21: [], a22: [], ty: [45] };
const matrix = { a11: 0, a12: 0.7, tx: -1700, a21: 0.7, a22: 0, ty: 700 };
const mapped = { height_mm: 60, image_px: [1000, 1000] as [number, number], robot_mm: [-1000, 1400] as [number, number], std_mm: [0.1, 0.1] as [number, number], robot_from_image: matrix };
const fit: PlanarFitReport = { fit: byParameter, rejected_heights_mm: noRejects, predictions: [mapped], input: { matrices: [{ height_mm: 15, ...matrix }], reject_threshold: null, predict: [] } };
const solveRequest: PlanarSolveRequest = { points: [{ height_mm: 15, image_px: [1284.8, 432.0], robot_mm: [-1449.7, 1585.93] }], options: { transform: 'similarity', plate_size_mm: [2000, 1200], camera } };
// @ts-expect-error: transform models are lower case names
const wrongTransform: PlanarSolveRequest = { points: [], options: { transform: 'Affine' } };
const solvedPlanar: PlanarSolveResponse = {
  heights: [{ height_mm: 15, kind: 'affine', robot_from_image: matrix, reflected: false, residuals_mm: [[0.1, -0.1]], rms_mm: 0.14 }],
  fit: byParameter, rejected_heights_mm: noRejects,
  pixel_density: [{ height_mm: 15, length_px_per_mm: 1.43, width_px_per_mm: 1.43 }],
  density_fit: { length: line, width: line },
  exact_family: { projection_matrix: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1], rms_px: 0.3 },
  points: solveRequest.points,
  options: { transform: 'affine', reject_threshold: null, plate_size_mm: null, camera: null },
  predictions: [mapped],
  exact_predictions_mm: null,
};
const xyRequest: XyTableRequest = { observations: [{ stage_mm: [0, 0, 0], image_px: [640, 480] }], still_target_px: [[640.1, 480]], kalman_mode: 'linearized' };
const xyStep = { observation: 0, projection_row_major: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1] as JsonOutput<'xytable_solve'>['batch']['projection_matrix'], rms_px: 0.1, covariance_trace: 3 };
const xyMethod = { projection_matrix: xyStep.projection_row_major, camera_matrix: [1200, 0, 640, 0, 1200, 480, 0, 0, 1] as JsonOutput<'xytable_solve'>['batch']['camera_matrix'], camera_from_world: pose, residuals_px: [], rms_px: 0.1 };
const xyReport: XyTableReport = {
  batch: xyMethod, kalman: { ...xyMethod, history: [xyStep] }, measurement_noise_px2: [[0.01, 0], [0, 0.01]], noise_source: 'still_target', verification: null,
  input: { observations: xyRequest.observations, verification: [], still_target_px: [], measurement_noise_px2: null, kalman_mode: 'extended' },
};
// @ts-expect-error: the Kalman result always has its history
const noHistory: XyTableReport = { ...xyReport, kalman: xyMethod };
const motion: KnownMotionRequest = { increments_mm: [[0, 0, 0], [50, 0, 0], [0, 50, 0]], points_camera_mm: [[100, 200, 1000], [100, 250, 1000], [50, 200, 1000]] };
const motionReport: KnownMotionReport = {
  camera_from_reference: pose, start_camera_mm: [100, 200, 1000], start_reference_mm: [0, 0, 0],
  reference_origin_given: false, residuals_mm: [[0, 0, 0]], rms_mm: 0, input: { ...motion, start_reference_mm: null },
};

// --- Laser-line sensors: the images go beside the request as Uint8Array[]
const laserRequest: LaserPlaneRequest = { camera: '{}', target: 'chessboard:9x6:30mm', pairs: true, names: ['view_000'], residual: 'image_px', stripe: { extractor: 'ridge', axis: 'auto' } };
const laserPlane: LaserPlaneReport = JSON.parse(robocal.laser_plane(JSON.stringify(laserRequest), [png, png]));
const laserExportable: ExportableReport = laserPlane;
const laserPoints: JsonInput<'laser_points'> = { camera: '{}', plane: laserPlane, gripper_from_camera: pose };
const laserStripe: JsonOutput<'laser_stripe'> = JSON.parse(robocal.laser_stripe(png, undefined, ''));
// @ts-expect-error: no such extractor
const wrongExtractor: LaserStripeSettings = { extractor: 'sobel' };

// --- The demo and the map
const demo = robocal.render_demo(1);
const index: DemoIndex = JSON.parse(demo.json);
const spec2: TargetSpec = index.target_spec;
const firstPng: Uint8Array = demo.bytes.subarray(index.images[0].offset, index.images[0].offset + index.images[0].length);
const targetInput: JsonInput<'detect_target'> = chessboard;
const handeyeAgain: JsonInput<'solve_handeye'> = handeyeInput;
// @ts-expect-error: image_info takes no JSON
const noJson: JsonInput<'image_info'> = {};
// @ts-expect-error: not a function of the package
type NoSuch = JsonOutput<'calibrate_lidar'>;

export {
  dots, squares, squaresSpec, charuco, charucoIds, aprilgrid, charucoSpec, aprilgridSpec, wrongDictionary, wrongTagKey, wrongKey, wrongKind, wrongPolarity, spec, wrongSpec, wrongSize, wrongFormat, preview, none, eucm, wrongCoefficient,
  wrongView, wrongMethod, wrongTermination, stereoInput, fx, wrongPoseFormat, ambiguous, bothImages, wrongSetup,
  wrongKeyForSetup, cameraPose, rank, ranked, formats, format, wrongExport, exportable, urdf, fitRequest, fit, wrongTransform,
  solvedPlanar, xyReport, noHistory, motionReport, spec2, firstPng, targetInput, handeyeAgain, noJson,
  laserExportable, laserPoints, laserStripe, wrongExtractor,
};
