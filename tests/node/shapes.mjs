// Node tier: the JSON the package really returns must match the types its
// index.d.ts declares. Run by smoke.mjs as `node shapes.mjs WORK_DIR`, where
// WORK_DIR has the packed package installed. The declarations are read with
// the TypeScript compiler (tests/node/node_modules/typescript) and every
// value below is walked against its declared type: required keys present,
// JS types right, no undeclared key at any depth, literals and unions
// honoured. So the .d.ts cannot drift from the Rust serde output unnoticed.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { rigInput, rigOnRobot } from './rig_scene.mjs';
import { laserScene } from './laser_scene.mjs';

// Node has no ImageData; the previews need one (pkg-config/README.md).
globalThis.ImageData = class ImageData { constructor(data, width, height) { Object.assign(this, { data, width, height }); } };

const here = dirname(fileURLToPath(import.meta.url));
const root = join(here, '..', '..');
const work = process.argv[2];
if (!work) throw new Error('usage: node shapes.mjs WORK_DIR (with robocal installed)');
const ts = createRequire(join(here, 'package.json'))('typescript');
const robocal = createRequire(join(work, 'package.json'))('robocal');
const dts = join(work, 'node_modules', 'robocal', 'index.d.ts');

// 1. The declarations.
const program = ts.createProgram([dts], {
  strict: true,
  noEmit: true,
  target: ts.ScriptTarget.ES2022,
  lib: ['lib.es2022.d.ts', 'lib.esnext.disposable.d.ts', 'lib.dom.d.ts'],
});
const diagnostics = ts.getPreEmitDiagnostics(program);
assert.equal(diagnostics.length, 0, ts.formatDiagnostics(diagnostics, ts.createCompilerHost({})));
const checker = program.getTypeChecker();
const moduleSymbol = checker.getSymbolAtLocation(program.getSourceFile(dts));
const exported = new Map(checker.getExportsOfModule(moduleSymbol).map((s) => [s.name, s]));
const declared = (name) => {
  const symbol = exported.get(name);
  assert.ok(symbol, `index.d.ts exports no ${name}`);
  return checker.getDeclaredTypeOfSymbol(symbol);
};
const propertyType = (type, name) => {
  const p = checker.getPropertyOfType(type, name);
  assert.ok(p, `no property ${name}`);
  return checker.getTypeOfSymbol(p);
};
const map = declared('RobocalJson');
const mapped = (fn, i) => checker.getTypeArguments(propertyType(map, fn))[i];

// 2. A small structural checker: value against a ts.Type.
const F = ts.TypeFlags;
function validate(value, type, path, errors) {
  const f = type.flags;
  const fail = (what) => errors.push(`${path}: ${what} (declared ${checker.typeToString(type)})`);
  if (f & (F.Any | F.Unknown)) return;
  if (type.isUnion()) {
    // Passes if one member does; otherwise report the member that got
    // deepest (a discriminated union's right member), or the value itself.
    let best = null;
    for (const member of type.types) {
      const e = [];
      validate(value, member, path, e);
      if (e.length === 0) return;
      const deep = e.every((m) => !m.startsWith(`${path}: `));
      if (deep && (!best || e.length < best.length)) best = e;
    }
    if (best) errors.push(...best);
    else fail(`got ${JSON.stringify(value)?.slice(0, 80)}`);
    return;
  }
  if (f & F.Never) return fail('a value where none is declared');
  if (f & F.Null) return value === null || fail(`got ${JSON.stringify(value)}`);
  if (f & (F.Undefined | F.Void)) return value === undefined || fail('an undeclared key');
  if (f & F.StringLiteral) return value === type.value || fail(`got ${JSON.stringify(value)}`);
  if (f & F.NumberLiteral) return value === type.value || fail(`got ${JSON.stringify(value)}`);
  if (f & F.BooleanLiteral) return value === (type.intrinsicName === 'true') || fail(`got ${value}`);
  if (f & F.String) return typeof value === 'string' || fail(`got ${typeof value}`);
  if (f & F.Number) return (typeof value === 'number' && Number.isFinite(value)) || fail(`got ${JSON.stringify(value)}`);
  if (f & F.Boolean) return typeof value === 'boolean' || fail(`got ${typeof value}`);
  if (f & F.TemplateLiteral) {
    if (typeof value !== 'string') return fail(`got ${typeof value}`);
    return checker.isTypeAssignableTo(checker.getStringLiteralType(value), type) || fail(`got ${JSON.stringify(value)}`);
  }
  if (!(f & (F.Object | F.Intersection))) return fail('a type this checker does not know');
  if (checker.isTupleType(type)) {
    const elements = checker.getTypeArguments(type);
    if (!Array.isArray(value) || value.length !== elements.length) {
      return fail(`expected ${elements.length} elements, got ${Array.isArray(value) ? value.length : typeof value}`);
    }
    value.forEach((v, i) => validate(v, elements[i], `${path}[${i}]`, errors));
    return;
  }
  if (checker.isArrayType(type)) {
    if (!Array.isArray(value)) return fail(`got ${value === null ? 'null' : typeof value}`);
    const element = checker.getTypeArguments(type)[0];
    value.forEach((v, i) => validate(v, element, `${path}[${i}]`, errors));
    return;
  }
  if (value === null || typeof value !== 'object' || Array.isArray(value)) {
    return fail(`got ${Array.isArray(value) ? 'an array' : value === null ? 'null' : typeof value}`);
  }
  const properties = checker.getPropertiesOfType(type);
  const names = new Set(properties.map((p) => p.name));
  for (const p of properties) {
    const optional = (p.flags & ts.SymbolFlags.Optional) !== 0;
    if (!(p.name in value)) {
      if (!optional) errors.push(`${path}.${p.name}: missing (declared required)`);
      continue;
    }
    validate(value[p.name], checker.getTypeOfSymbol(p), `${path}.${p.name}`, errors);
  }
  const index = checker.getIndexInfosOfType(type).find((i) => i.keyType.flags & F.String);
  for (const key of Object.keys(value)) {
    if (names.has(key)) continue;
    if (index) validate(value[key], index.type, `${path}.${key}`, errors);
    else errors.push(`${path}.${key}: not declared`);
  }
}

const checked = { input: new Set(), output: new Set() };
function check(label, value, type) {
  const errors = [];
  validate(value, type, label, errors);
  assert.deepEqual(errors, [], `${label} does not match index.d.ts:\n  ${errors.join('\n  ')}`);
}
/** The JSON `fn` returned must be its declared output. */
const output = (fn, value, label = fn) => (check(`${label} output`, value, mapped(fn, 1)), checked.output.add(fn), value);
/** The JSON sent to `fn` must be its declared input (the typed literals of types-check.ts stay honest). */
const input = (fn, value, label = fn) => (check(`${label} input`, value, mapped(fn, 0)), checked.input.add(fn), value);
const call = (fn, request, ...rest) => output(fn, JSON.parse(robocal[fn](JSON.stringify(input(fn, request)), ...rest)));

// 3. Real inputs and outputs.
const demo = robocal.render_demo(1);
const meta = output('render_demo', JSON.parse(demo.json));
const png = (im) => demo.bytes.subarray(im.offset, im.offset + im.length);
output('image_info', JSON.parse(robocal.image_info(png(meta.images[0]))));
output('decode_image_preview', JSON.parse(robocal.decode_image_preview(png(meta.images[0]), 128).info_json));
input('detect_target', meta.target);
const detections = meta.images.map((im) => output('detect_target', JSON.parse(robocal.detect_target(png(im), JSON.stringify(meta.target)))));
const views = meta.images.map((im, i) => ({ name: im.name, detection: detections[i] }));
input('detect_boards', meta.target);
// A chessboard is one board: detect_boards gives detect_target's detection alone.
assert.deepEqual(output('detect_boards', JSON.parse(robocal.detect_boards(png(meta.images[0]), JSON.stringify(meta.target)))), [detections[0]]);
// A preview that keeps the grey image detects in it what detect_target finds in the file, without a second decode.
{
  const kept = robocal.decode_image_preview(png(meta.images[1]), 128, undefined, true);
  assert.equal(kept.keeps_grey, true);
  assert.deepEqual(JSON.parse(kept.detect_target(JSON.stringify(meta.target))), detections[1]);
  assert.deepEqual(JSON.parse(kept.detect_boards(JSON.stringify(meta.target))), [detections[1]]);
  kept.free();
  const plainPreview = robocal.decode_image_preview(png(meta.images[1]), 128);
  assert.equal(plainPreview.keeps_grey, false);
  assert.throws(() => plainPreview.detect_target(JSON.stringify(meta.target)), { message: 'this preview kept no grey image: call decode_image_preview with keep_grey = true' });
  plainPreview.free();
}

const all = call('calibrate_camera', { model: 'brown', method: 'all', views }, 'calibrate_camera all');
// A flat board: the DLT is left out and the note says why.
assert.deepEqual(all.comparison.map((r) => r.method), ['zhang', 'tsai', 'ekf']);
assert.match(all.comparison_note, /^dlt left out: /);
const robust = call('calibrate_camera', { model: 'rational', options: { robust: true, aspect_ratio: 1, fixed_coefficients: ['s1', 's2', 's3', 's4'] }, views });
assert.equal(robust.comparison, null);
// Explicit correspondences: the board points of a 9x6 board of 30 mm squares.
const board = (d) => d.points.map((p) => [(p.id % 9) * 0.03, Math.floor(p.id / 9) * 0.03, 0]);
const pixels = (d) => d.points.map((p) => [p.x_px, p.y_px]);
const pairs = views.slice(0, 4).map((v) => ({ name: v.name, object_m: board(v.detection), image_px: pixels(v.detection) }));
call('calibrate_camera', { model: 'kannala_brandt', method: 'zhang', views: pairs, image_size_px: [1024, 768] }, 'calibrate_camera points');
{
  // A real pair (the same images on both sides are refused): the rig scene's
  // left and middle cameras over the frames both see (1-7).
  const [left, middle] = rigInput().cameras;
  const strip = (v) => ({ name: v.name, object_m: v.object_m, image_px: v.image_px });
  call('calibrate_stereo', { model: 'division', left: left.views.map(strip), right: middle.views.slice(0, 7).map(strip), left_image_size_px: [1280, 960], right_image_size_px: [1280, 960] });
}
{
  const rig = call('calibrate_rig', rigInput());
  call('calibrate_rig_handeye', rigOnRobot().input);
  output('rig_export_formats', JSON.parse(robocal.rig_export_formats()));
  output('export_report_files', JSON.parse(robocal.export_report_files(JSON.stringify(input('export_report_files', rig)), 'ros', '', '')));
}
const report = all.report;
{
  const image = robocal.undistort_preview(png(meta.images[0]), JSON.stringify(input('undistort_preview', report.camera)), 200);
  if (image.width !== 200 || image.data.length !== 4 * image.width * image.height) throw new Error(`undistort_preview: ${image.width}x${image.height}`);
}
// Camera files (robocal rig --camera-file): a calibration report, and its OpenCV YAML export.
{
  const fromReport = output('read_camera_file', JSON.parse(robocal.read_camera_file(JSON.stringify(report))), 'read_camera_file report');
  assert.equal(fromReport.format, 'json');
  assert.deepEqual(fromReport.camera, report.camera);
  const yaml = output('read_camera_file', JSON.parse(robocal.read_camera_file(robocal.export_report(JSON.stringify(report), 'opencv-yaml', ''))), 'read_camera_file opencv-yaml');
  assert.equal(yaml.format, 'opencv-yaml');
  assert.throws(() => robocal.read_camera_file('hello'), { message: /not a camera file: expected robocal JSON, OpenCV YAML\/XML/ });
  // The check (docs/check.md): the saved report against five of its own views reads ok.
  const checked = call('check_camera', { calibration: JSON.stringify(report), views: views.slice(0, 5), thresholds: { param_sigma: 3 } });
  assert.equal(checked.verdict, 'ok', checked.reasons.join('; '));
  const yamlText = robocal.export_report(JSON.stringify(report), 'opencv-yaml', '');
  const diff = call('diff_cameras', { a: JSON.stringify(report), b: yamlText, options: { grid: [30, 20] } });
  assert.ok(diff.projection_shift_px.worst < 1e-3, `diff of a camera with its export: ${diff.projection_shift_px.worst}`);
}

const poses = JSON.parse(robocal.read_robot_poses(meta.poses_csv, JSON.stringify(input('read_robot_poses', {}))));
output('read_robot_poses', poses);
assert.ok(poses.parsed, 'the demo CSV has a header');
// The hand-eye pose plan (docs/pose-plan.md): from the first view and its robot pose; its UR script.
{
  const boardM = JSON.parse(robocal.target_points(meta.target_spec)).map((p) => [p.x_m, p.y_m, 0]);
  const plan = call('plan_handeye_poses', { setup: 'eye-in-hand', base_from_gripper: poses.parsed.poses[0].base_from_gripper, camera_from_target: report.views[0].camera_from_target, camera: report.camera, board_m: boardM, poses: 6, max_tilt_deg: 35 });
  assert.equal(plan.poses.length, 6);
  const script = robocal.plan_move_list(JSON.stringify(input('plan_move_list', plan)), 'ur-script');
  assert.equal(script.split('\n').filter((l) => l.trim().startsWith('movel(')).length, 6);
}
output('read_robot_poses', JSON.parse(robocal.read_robot_poses(meta.poses_csv, JSON.stringify(input('read_robot_poses', { format: 'ur', length_unit: 'm', angle_unit: null, direction: 'base_from_gripper' })))), 'read_robot_poses ur');
const bare = meta.poses_csv.trim().split('\n').slice(1).map((l) => l.split(',').slice(1).join(' ')).join('\n');
const ambiguous = output('read_robot_poses', JSON.parse(robocal.read_robot_poses(bare, '')), 'read_robot_poses bare');
assert.ok(ambiguous.parsed === null && ambiguous.candidates.length > 1, 'a bare 6-column file is ambiguous');

// One pose per file: the demo rows as files named by their images, given in reverse.
const perFileInput = meta.poses_csv.trim().split('\n').slice(1).map((l) => {
  const [name, ...v] = l.split(',');
  return { name: name.replace(/\.png$/, '.txt'), text: `x y z rx ry rz\n${v.join(' ')}\n` };
}).reverse();
const perFile = output('read_robot_pose_files', JSON.parse(robocal.read_robot_pose_files(JSON.stringify(input('read_robot_pose_files', perFileInput)), '')));
assert.deepEqual(perFile.parsed.poses.map((p) => p.base_from_gripper.translation_m), poses.parsed.poses.map((p) => p.base_from_gripper.translation_m));
assert.deepEqual(perFile.parsed.poses.map((p) => p.name), poses.parsed.poses.map((p) => p.name.replace(/\.png$/, '')));

const base_from_gripper = poses.parsed.poses.map((p) => p.base_from_gripper);
const eyeInHand = call('solve_handeye', { setup: 'eye-in-hand', base_from_gripper, detections, camera: all, bootstrap_samples: 5 }, 'solve_handeye detections');
assert.equal(eyeInHand.setup, 'eye-in-hand');
// The default with image points: the pose refinement with each view's PnP covariance.
assert.ok(eyeInHand.pose_refinement?.camera_noise_model === 'per_view' && !eyeInHand.refinement && eyeInHand.repeatability, 'refined over the poses, with repeatability');
const camera_from_target = report.views.map((v) => v.camera_from_target);
const viewsIn = detections.map((d) => ({ object_m: board(d), image_px: pixels(d) }));
const joint = call('solve_handeye', { setup: 'eye-in-hand', base_from_gripper, camera_from_target, views: viewsIn, camera: report.camera, refine: 'joint_intrinsics', method: 'park-martin', bootstrap_samples: 0 }, 'solve_handeye joint');
assert.ok(joint.refinement?.camera, 'joint_intrinsics reports its camera');
// Eye-to-hand from the same data: the inverted robot poses.
const inverse = ({ translation_m: t, quaternion_xyzw: [x, y, z, w] }) => {
  const q = [-x, -y, -z, w];
  const r = rotate(q, t);
  return { translation_m: [-r[0], -r[1], -r[2]], quaternion_xyzw: q };
};
const eyeToHand = call('solve_handeye', { setup: 'eye-to-hand', base_from_gripper: base_from_gripper.map(inverse), camera_from_target, strict_checks: false, seed: 3, bootstrap_samples: 4 }, 'solve_handeye eye-to-hand');
assert.equal(eyeToHand.setup, 'eye-to-hand');
const ranked = call('rank_pose_conventions', {
  setup: 'eye-in-hand',
  candidates: ambiguous.candidates.map((c) => ({ name: c.format, base_from_gripper: c.poses.map((p) => p.base_from_gripper) })),
  camera_from_target,
});
assert.equal(ranked.scores[0].name, 'ur');

const formats = output('export_formats', JSON.parse(robocal.export_formats()));
// The lens-model table: its rows are LensModelInfo, and its names are
// exactly the models the types declare (DistortionModels' keys), so a model
// added to the core without its types (or the other way) fails here.
const lensModels = output('lens_models', JSON.parse(robocal.lens_models()));
const declaredModels = checker.getPropertiesOfType(declared('DistortionModels')).map((p) => p.name).sort();
assert.deepEqual(lensModels.map((m) => m.name).sort(), declaredModels, 'lens_models() and index.d.ts DistortionModels list the same models');
assert.equal(lensModels[0].name, 'brown', 'the default model first');
for (const m of lensModels) assert.equal(m.coefficients.length, m.start_values.length, `${m.name}: a start value per coefficient`);
assert.ok(formats.includes('urdf') && formats.includes('opencv-yaml'));
for (const r of [report, eyeInHand, eyeToHand]) input('export_report', r);
assert.match(robocal.export_report(JSON.stringify(eyeInHand), 'euler-intrinsic-zyx-deg', 'gripper_from_camera'), /gripper/);

const fixture = (name) => readFileSync(join(root, 'fixtures', 'seed001', name), 'utf8');
const matrices = output('workflow_csv', JSON.parse(robocal.workflow_csv('planar-matrices', fixture('table4_matrices.csv'))), 'workflow_csv planar-matrices');
check('workflow_csv planar-matrices', matrices, propertyType(declared('WorkflowCsvKinds'), 'planar-matrices'));
call('planar_fit', { ...matrices, reject_threshold: 3, predict: [{ height_mm: 60, image_px: [1000, 1000] }] });
const points = output('workflow_csv', JSON.parse(robocal.workflow_csv('planar-points', fixture('table3_four_points.csv'))), 'workflow_csv planar-points');
check('workflow_csv planar-points', points, propertyType(declared('WorkflowCsvKinds'), 'planar-points'));
const planar = call('planar_solve', { ...points, options: { transform: 'affine', plate_size_mm: [2000, 1200] }, predict: [{ height_mm: 60, image_px: [1000, 1000] }] });
assert.ok(planar.pixel_density && planar.exact_family, 'four-corner plates give the pixel density');
call('planar_solve', { ...points, options: { transform: 'rigid', reject_threshold: null, camera: report.camera } }, 'planar_solve rigid');

// XY-table: a camera 600 mm above the stage, f = 1200 px, rotated 0.3 rad about its axis.
const project = ([x, y, z]) => {
  const [c, s] = [Math.cos(0.3), Math.sin(0.3)];
  const p = [c * x - s * y + 10, s * x + c * y - 5, z + 600];
  return [1200 * p[0] / p[2] + 640, 1200 * p[1] / p[2] + 480];
};
let xy = 'x_mm,y_mm,z_mm,u_px,v_px,role\n';
for (const z of [0, 40]) for (const x of [-100, 0, 100]) for (const y of [-80, 0, 80]) xy += `${x},${y},${z},${project([x, y, z]).join(',')},calibration\n`;
for (const [x, y] of [[-60, -50], [60, -50], [60, 50], [-60, 50]]) xy += `${x},${y},20,${project([x, y, 20]).join(',')},verify\n`;
xy += '0,0,0,640.1,480.0,still\n0,0,0,639.9,480.1,still\n0,0,0,640.0,479.9,still\n';
const xyRequest = output('workflow_csv', JSON.parse(robocal.workflow_csv('xytable', xy)), 'workflow_csv xytable');
check('workflow_csv xytable', xyRequest, propertyType(declared('WorkflowCsvKinds'), 'xytable'));
const xyReport = call('xytable_solve', xyRequest);
assert.ok(xyReport.verification && xyReport.batch.rms_px < 1e-6, 'exact projections fit exactly');
call('xytable_solve', { observations: xyRequest.observations, measurement_noise_px2: [[0.01, 0], [0, 0.01]], kalman_mode: 'linearized' }, 'xytable_solve given noise');

let motion = 'dx_mm,dy_mm,dz_mm,x_cam_mm,y_cam_mm,z_cam_mm\n';
for (const d of [[0, 0, 0], [50, 0, 0], [0, 50, 0], [0, 0, 50], [30, 30, 30]]) motion += `${d.join(',')},${100 - d[1]},${200 + d[0]},${1000 + d[2]}\n`;
const motionRequest = output('workflow_csv', JSON.parse(robocal.workflow_csv('known-motion', motion)), 'workflow_csv known-motion');
check('workflow_csv known-motion', motionRequest, propertyType(declared('WorkflowCsvKinds'), 'known-motion'));
call('known_motion_solve', motionRequest);
call('known_motion_solve', { ...motionRequest, start_reference_mm: [1, 2, 3] }, 'known_motion_solve start');

// Targets: every kind through parse_target and target_points; the text
// functions (target_svg, target_spec) read the same target JSON.
const targets = [
  meta.target,
  { kind: 'chessboard', cols: 9, rows: 6, square_m: 0.03 },
  { kind: 'circle_grid', cols: 4, rows: 11, spacing_m: 0.02, asymmetric: true, polarity: 'dark_on_light' },
  { kind: 'dot_plate', cols: 7, rows: 7, pitch_m: 0.025, dot_diameter_m: 0.0125 },
  { kind: 'single_circle', diameter_m: 0.01 },
  { kind: 'square_grid', cols: 8, rows: 8, side_m: 0.0127, pitch_m: 0.0225778 },
  { kind: 'charuco', squares_x: 8, squares_y: 6, square_m: 0.03, marker_m: 0.022, dictionary: 'DICT_5X5_100', first_id: 4, legacy: true },
  { kind: 'charuco', squares_x: 3, squares_y: 3, square_m: 0.02, marker_m: 0.015, dictionary: 'DICT_ARUCO_ORIGINAL', marker_ids: [7, 8, 9, 10] },
  { kind: 'aprilgrid', tag_cols: 6, tag_rows: 6, tag_m: 0.088, spacing_ratio: 0.3, first_id: 36 },
];
for (const t of targets) {
  const parsed = call('parse_target', t, `parse_target ${t.kind}`);
  assert.equal(parsed.kind, t.kind);
  const pts = call('target_points', t, `target_points ${t.kind}`);
  assert.ok(pts.length >= 1 && pts[0].id === 0, `${t.kind}: points in id order`);
  assert.match(robocal.target_svg(JSON.stringify(input('target_svg', t))), /^<\?xml|<svg/);
  assert.equal(robocal.parse_target(robocal.target_spec(JSON.stringify(input('target_spec', t)))), JSON.stringify(parsed), `${t.kind}: the spec reads back`);
}
// Kalibr's target YAML: an AprilGrid (its template, comments kept) and a checkerboard.
const kalibrGrid = output('read_kalibr_target', JSON.parse(robocal.read_kalibr_target("target_type: 'aprilgrid' #gridtype\ntagCols: 6\ntagRows: 6\ntagSize: 0.088 #[m]\ntagSpacing: 0.3\n")), 'read_kalibr_target aprilgrid');
assert.deepEqual(kalibrGrid, { kind: 'aprilgrid', tag_cols: 6, tag_rows: 6, tag_m: 0.088, spacing_ratio: 0.3, first_id: 0 });
const kalibrBoard = output('read_kalibr_target', JSON.parse(robocal.read_kalibr_target('target_type: checkerboard\ntargetCols: 9\ntargetRows: 6\nrowSpacingMeters: 0.03\ncolSpacingMeters: 0.03\n')), 'read_kalibr_target checkerboard');
assert.equal(kalibrBoard.kind, 'chessboard');
assert.throws(() => robocal.read_kalibr_target("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\ntagSpacing: 0.3\n"), { message: "Kalibr target: missing key 'tagSize'" });
// Stereo pairing: by number, and by order when no name has one.
const pairLeft = input('pair_images', ['cam_L_10.png', 'cam_L_2.png']);
const pairRight = input('pair_images', ['cam_R_2.png', 'cam_R_010.png']);
const byNumber = output('pair_images', JSON.parse(robocal.pair_images(JSON.stringify(pairLeft), JSON.stringify(pairRight))), 'pair_images number');
assert.deepEqual(byNumber, { paired_by: 'number', pairs: [[0, 1], [1, 0]] });
const byOrder = output('pair_images', JSON.parse(robocal.pair_images('["left.png","l.png"]', '["right.png","r.png"]')), 'pair_images order');
assert.deepEqual(byOrder, { paired_by: 'order', pairs: [[0, 0], [1, 1]] });
// Rig frames: the number in the names across cameras, or by order when no name has one.
// caliscope's timestamps.csv: rows sorted by frame_index per camera are the video's frames.
const stamps = output('video_timestamps', JSON.parse(robocal.video_timestamps('sync_index,cam_id,frame_index,frame_time\n26,1,26,123.33\n26,0,26,123.34\n27,0,27,123.5\n27,1,28,123.51\n')));
assert.deepEqual(stamps, { cameras: { 0: { sync_index: [26, 27], time_s: [123.34, 123.5] }, 1: { sync_index: [26, 27], time_s: [123.33, 123.51] } } });
assert.throws(() => robocal.video_timestamps('sync,cam\n1,2\n'), /sync_index,cam_id,frame_index,frame_time/);
// A video frame's name: the CLI's (robocal::io::video_frames), four digits at least.
assert.equal(robocal.video_frame_name('cam_0.mp4', 123), 'cam_0.mp4#frame0123');
assert.equal(robocal.video_frame_name('a.webm', 12345), 'a.webm#frame12345');
const rigNames = input('rig_frame_keys', [{ name: 'front', images: ['front07.png', 'front2.png'] }, { name: 'side', images: ['side/2.jpg'] }]);
const rigFrames = output('rig_frame_keys', JSON.parse(robocal.rig_frame_keys(JSON.stringify(rigNames), '')), 'rig_frame_keys number');
assert.deepEqual(rigFrames, { grouped_by: 'number', keys: [['7', '2'], ['2']], frames: ['2', '7'] });
assert.deepEqual(JSON.parse(robocal.rig_frame_keys('[{"name":"a","images":["x.png","y.png"]}]', '')), { grouped_by: 'order', keys: [['0', '1']], frames: ['0', '1'] });
assert.throws(() => robocal.rig_frame_keys('[{"name":"a","images":["a1.png","x.png"]}]', ''), { message: 'images: frames are grouped by the last number in the file names, but camera a has names without one: x.png (group by number or last (the last number in the name, the default), first (the first number), order (the position in each camera\'s list), or a pattern with one (\\d+) such as sync(\\d+))' });

// The checker itself: it must reject what the declarations do not allow.
const rejects = (what, value, type) => {
  const e = [];
  validate(value, type, what, e);
  assert.ok(e.length > 0, `the checker accepted ${what}`);
};
const detectionType = mapped('detect_target', 1);
const { points: _points, ...noPoints } = detections[0];
rejects('a missing key', noPoints, detectionType);
rejects('an extra key', { ...detections[0], score: 1 }, detectionType);
rejects('an extra nested key', { ...detections[0], target: { ...meta.target, spacing_m: 0.03 } }, detectionType);
rejects('a wrong kind', { ...detections[0], target: { ...meta.target, kind: 'square_grid' } }, detectionType);
rejects('a short tuple', { ...detections[0], image_size_px: [1024] }, detectionType);
rejects('null for a number', { ...report, rms_px: null }, declared('CameraCalibration'));
rejects('a string for a number', { ...meta.images[0], offset: '0' }, propertyType(mapped('render_demo', 1), 'images'));
rejects('keys of the other setup', { ...eyeInHand, base_from_camera: eyeInHand.gripper_from_camera }, mapped('solve_handeye', 1));
rejects('views and detections', { setup: 'eye-in-hand', base_from_gripper, views: viewsIn, detections }, mapped('solve_handeye', 0));

// Laser-line sensors (docs/laser.md): the plane from the rendered scans of
// laser_scene.mjs, a held-out pose's points and stripe, the plane's exports.
{
  const scene = laserScene(work);
  const plane = call('laser_plane', { ...scene.request, residual: 'image_px', stripe: { extractor: 'cog', axis: 'auto', min_contrast: 20, max_width_px: 24 } }, scene.images);
  const [off, on] = scene.pairs[scene.held];
  call('laser_points', { camera: scene.camera, plane, gripper_from_camera: { translation_m: [0, 0, 0.1], quaternion_xyzw: [0, 0, 0, 1] }, base_from_gripper: { translation_m: [0.5, 0, 0.3], quaternion_xyzw: [1, 0, 0, 0] } }, on, off);
  call('laser_points', { camera: scene.camera, plane: { laser_plane: { normal_camera: plane.laser_plane.normal_camera, distance_m: plane.laser_plane.distance_m } } }, on);
  output('laser_stripe', JSON.parse(robocal.laser_stripe(on, off, JSON.stringify(input('laser_stripe', { extractor: 'ridge' })))), 'laser_stripe ridge');
  output('laser_stripe', JSON.parse(robocal.laser_stripe(on, undefined, '')));
  input('export_report', plane);
  output('export_report_files', JSON.parse(robocal.export_report_files(JSON.stringify(input('export_report_files', plane)), 'urdf', '', '')), 'export_report_files laser plane');
}

// 4. Coverage: every function in the map is exercised both ways (where it
// has JSON), and every function of the package is in the map.
const never = (t) => (t.flags & F.Never) !== 0;
const fns = checker.getPropertiesOfType(map).map((p) => p.name);
for (const fn of fns) {
  if (!never(mapped(fn, 0))) assert.ok(checked.input.has(fn), `no input of ${fn} was checked`);
  if (!never(mapped(fn, 1))) assert.ok(checked.output.has(fn), `no output of ${fn} was checked`);
}
// `start` is the #[wasm_bindgen(start)] hook (installs the panic hook; wasm-bindgen exports it);
// the classes (ImagePreview, DemoData, LiveCapture) have no JSON map entry.
const plain = new Set(['init', 'start', 'last_panic_message', 'version', 'ImagePreview', 'DemoData', 'LiveCapture']);
const missing = Object.keys(robocal).filter((n) => !plain.has(n) && !fns.includes(n));
assert.deepEqual(missing, [], 'package functions without a RobocalJson entry');
console.log(`shapes ok: ${fns.length} functions, ${checked.input.size} inputs and ${checked.output.size} outputs match index.d.ts`);

function rotate([x, y, z, w], v) {
  // v + 2 w (q x v) + 2 q x (q x v), q = (x, y, z).
  const c = [y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]];
  const cc = [y * c[2] - z * c[1], z * c[0] - x * c[2], x * c[1] - y * c[0]];
  return [0, 1, 2].map((i) => v[i] + 2 * w * c[i] + 2 * cc[i]);
}
