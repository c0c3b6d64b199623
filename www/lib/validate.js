// Sessions and share links checked field by field before the page uses them
// (issue 37): a damaged or crafted one is refused with a message naming the
// field, never half-used (a null step used to leave "Restoring your
// session..." forever, an image without an id silently stopped saving).
import { defaultSession } from '../store.js';

/** Most images, rig files, views or poses a session or link may hold. */
export const MAX_ITEMS = 10000;

const isObject = (v) => v !== null && typeof v === 'object' && !Array.isArray(v);

function describe(v) {
  if (v === null) return 'null';
  if (Array.isArray(v)) return 'a list';
  if (v === undefined) return 'nothing';
  if (typeof v === 'string') return `the text '${v.length > 20 ? `${v.slice(0, 20)}…` : v}'`;
  return typeof v === 'object' ? 'an object' : `a ${typeof v}`;
}

function fail(path, want, got) {
  throw new Error(`${path} must be ${want}, got ${describe(got)}`);
}

const check = {
  object(v, path) { if (!isObject(v)) fail(path, 'an object', v); return v; },
  objectOrNull(v, path) { if (v !== null && v !== undefined && !isObject(v)) fail(path, 'an object or null', v); return v ?? null; },
  string(v, path) { if (typeof v !== 'string') fail(path, 'a text', v); return v; },
  stringOrNull(v, path) { if (v !== null && v !== undefined && typeof v !== 'string') fail(path, 'a text or null', v); return v ?? null; },
  number(v, path) { if (typeof v !== 'number' || !Number.isFinite(v)) fail(path, 'a finite number', v); return v; },
  list(v, path) {
    if (!Array.isArray(v)) fail(path, 'a list', v);
    if (v.length > MAX_ITEMS) throw new Error(`${path} holds ${v.length} entries, more than the ${MAX_ITEMS} the page takes`);
    return v;
  },
  oneOf(v, path, values) {
    if (!values.includes(v)) throw new Error(`${path} must be one of ${values.join(', ')}, got ${describe(v)}`);
    return v;
  },
};

/** A 3 x 3 matrix of finite numbers. */
function matrix3(v, path) {
  check.list(v, path);
  if (v.length !== 3) throw new Error(`${path} must have 3 rows, got ${v.length}`);
  v.forEach((row, i) => {
    check.list(row, `${path}[${i}]`);
    if (row.length !== 3) throw new Error(`${path}[${i}] must have 3 numbers, got ${row.length}`);
    row.forEach((x, j) => check.number(x, `${path}[${i}][${j}]`));
  });
}

/** The camera step's result as the views read it: a camera report. */
export function checkCameraResult(r, path) {
  if (r === null || r === undefined) return null;
  check.object(r, path);
  matrix3(r.camera_matrix, `${path}.camera_matrix`);
  if (r.distortion !== undefined) check.object(r.distortion, `${path}.distortion`);
  if (r.rms_px !== undefined) check.number(r.rms_px, `${path}.rms_px`);
  if (r.std !== undefined) check.object(r.std, `${path}.std`);
  if (r.views !== undefined) {
    check.list(r.views, `${path}.views`).forEach((view, i) => {
      check.object(view, `${path}.views[${i}]`);
      if (view.name !== undefined) check.string(view.name, `${path}.views[${i}].name`);
    });
  }
  if (r.warnings !== undefined) check.list(r.warnings, `${path}.warnings`);
  return r;
}

/** The hand-eye step's result: a hand-eye report. */
export function checkHandeyeResult(r, path) {
  if (r === null || r === undefined) return null;
  check.object(r, path);
  if (r.setup !== undefined) check.oneOf(r.setup, `${path}.setup`, ['eye-in-hand', 'eye-to-hand']);
  for (const key of ['gripper_from_camera', 'base_from_camera', 'base_from_target', 'gripper_from_target']) {
    if (r[key] !== undefined && r[key] !== null) {
      check.object(r[key], `${path}.${key}`);
      const m = r[key].matrix_row_major;
      if (m !== undefined) {
        check.list(m, `${path}.${key}.matrix_row_major`);
        m.forEach((row, i) => check.list(row, `${path}.${key}.matrix_row_major[${i}]`).forEach((x, j) => check.number(x, `${path}.${key}.matrix_row_major[${i}][${j}]`)));
      }
    }
  }
  for (const key of ['errors', 'motion', 'pose_refinement', 'repeatability']) check.objectOrNull(r[key], `${path}.${key}`);
  for (const key of ['warnings', 'methods', 'per_view', 'per_motion', 'pairs', 'pair_names']) if (r[key] !== undefined) check.list(r[key], `${path}.${key}`);
  return r;
}

/** A list of `n` finite numbers. */
function numbers(v, path, n) {
  check.list(v, path);
  if (v.length !== n) throw new Error(`${path} must have ${n} numbers, got ${v.length}`);
  v.forEach((x, i) => check.number(x, `${path}[${i}]`));
}

/** A pose as the plan holds it: translation_m and quaternion_xyzw, or a 4 x 4 matrix_row_major. */
function checkPose(p, path) {
  check.object(p, path);
  if (p.matrix_row_major !== undefined) {
    check.list(p.matrix_row_major, `${path}.matrix_row_major`);
    const flat = p.matrix_row_major.flat();
    if (flat.length !== 16) throw new Error(`${path}.matrix_row_major must hold 16 numbers, got ${flat.length}`);
    flat.forEach((x, i) => check.number(x, `${path}.matrix_row_major[${i}]`));
  }
  if (p.translation_m !== undefined || p.matrix_row_major === undefined) {
    numbers(p.translation_m, `${path}.translation_m`, 3);
    numbers(p.quaternion_xyzw, `${path}.quaternion_xyzw`, 4);
  }
  return p;
}

/** The pose plan's report (views/plan.js shows it): its poses and the predicted error. */
export function checkPlanResult(r, path) {
  if (r === null || r === undefined) return null;
  check.object(r, path);
  check.object(r.predicted, `${path}.predicted`);
  for (const key of ['bound95_mm', 'rms_mm']) check.number(r.predicted[key], `${path}.predicted.${key}`);
  check.string(r.predicted.verdict, `${path}.predicted.verdict`);
  check.list(r.poses, `${path}.poses`).forEach((pose, i) => {
    const p = `${path}.poses[${i}]`;
    check.object(pose, p);
    checkPose(pose.base_from_gripper, `${p}.base_from_gripper`);
    if (pose.camera_from_target !== undefined) checkPose(pose.camera_from_target, `${p}.camera_from_target`);
    for (const key of ['tilt_deg', 'distance_m', 'roll_deg']) check.number(pose[key], `${p}.${key}`);
  });
  for (const key of ['travel_m', 'candidates']) check.number(r[key], `${path}.${key}`);
  if (r.notes !== undefined) check.list(r.notes, `${path}.notes`).forEach((n, i) => check.string(n, `${path}.notes[${i}]`));
  return r;
}

/** The plan step's saved part: its inputs (field values), the request it sent and its report. */
function checkPlan(plan, path) {
  if (plan === null || plan === undefined) return null;
  check.object(plan, path);
  check.object(plan.inputs, `${path}.inputs`);
  plan.inputs.view = check.stringOrNull(plan.inputs.view, `${path}.inputs.view`);
  check.object(plan.inputs.fields, `${path}.inputs.fields`);
  for (const [k, v] of Object.entries(plan.inputs.fields)) check.string(v, `${path}.inputs.fields.${k}`);
  plan.request = check.objectOrNull(plan.request, `${path}.request`);
  if (plan.request) {
    check.oneOf(plan.request.setup, `${path}.request.setup`, ['eye-in-hand', 'eye-to-hand']);
    checkPose(plan.request.base_from_gripper, `${path}.request.base_from_gripper`);
    checkPose(plan.request.camera_from_target, `${path}.request.camera_from_target`);
    check.object(plan.request.camera, `${path}.request.camera`);
    if (plan.request.guess !== undefined) checkPose(plan.request.guess, `${path}.request.guess`);
  }
  plan.result = checkPlanResult(plan.result, `${path}.result`);
  if (plan.result && !plan.request) throw new Error(`${path}.request must be an object when ${path}.result is, got null`);
  return plan;
}

/** The check step's report (views/check.js shows it). */
export function checkCheckResult(r, path) {
  if (r === null || r === undefined) return null;
  check.object(r, path);
  check.oneOf(r.verdict, `${path}.verdict`, ['ok', 'drifted', 'broken']);
  check.list(r.reasons, `${path}.reasons`).forEach((x, i) => check.string(x, `${path}.reasons[${i}]`));
  check.list(r.parameters, `${path}.parameters`).forEach((p, i) => {
    check.object(p, `${path}.parameters[${i}]`);
    check.string(p.name, `${path}.parameters[${i}].name`);
  });
  check.list(r.warnings, `${path}.warnings`);
  r.projection_shift_px = check.objectOrNull(r.projection_shift_px, `${path}.projection_shift_px`);
  if (r.projection_shift_px) {
    for (const key of ['worst', 'median']) check.number(r.projection_shift_px[key], `${path}.projection_shift_px.${key}`);
    if (r.projection_shift_px.map !== undefined) {
      check.list(r.projection_shift_px.map, `${path}.projection_shift_px.map`);
      numbers(r.projection_shift_px.grid, `${path}.projection_shift_px.grid`, 2);
      numbers(r.projection_shift_px.image_size_px, `${path}.projection_shift_px.image_size_px`, 2);
    }
  }
  check.object(r.thresholds, `${path}.thresholds`);
  return r;
}

/** The check step's saved part: the calibration file's name and the report. */
function checkCheck(c, path) {
  if (c === null || c === undefined) return null;
  check.object(c, path);
  check.string(c.name, `${path}.name`);
  c.result = checkCheckResult(c.result, `${path}.result`);
  return c;
}

/** One image of the session's list. */
function checkImage(img, path) {
  check.object(img, path);
  if (!(typeof img.id === 'string' && img.id) && !Number.isFinite(img.id)) fail(`${path}.id`, 'a text or number', img.id);
  check.string(img.name, `${path}.name`);
  if (img.included === undefined) img.included = true;
  else if (typeof img.included !== 'boolean') fail(`${path}.included`, 'true or false', img.included);
  for (const key of ['detection', 'info']) check.objectOrNull(img[key], `${path}.${key}`);
  for (const key of ['status', 'error']) check.stringOrNull(img[key], `${path}.${key}`);
  return img;
}

/**
 * A session (IndexedDB or a session file) made whole and checked: missing
 * steps and fields take their defaults, a field of the wrong type is an
 * Error naming it (`session.camera must be an object, got null`).
 */
export function checkSession(raw, path = 'session') {
  check.object(raw, path);
  const d = defaultSession();
  const step = (key) => {
    if (raw[key] === undefined) return d[key];
    check.object(raw[key], `${path}.${key}`);
    return { ...d[key], ...raw[key] };
  };
  const s = { ...d, ...raw, schema: 1 };
  s.target = raw.target === undefined ? d.target : check.object(raw.target, `${path}.target`);
  s.images = raw.images === undefined ? [] : check.list(raw.images, `${path}.images`);
  s.images.forEach((img, i) => checkImage(img, `${path}.images[${i}]`));
  const ids = new Set();
  s.images.forEach((img, i) => {
    if (ids.has(img.id)) throw new Error(`${path}.images[${i}].id '${img.id}' is used twice`);
    ids.add(img.id);
  });

  if (!Number.isInteger(s.captureCount) || s.captureCount < 0) fail(`${path}.captureCount`, 'a whole number >= 0', s.captureCount);

  s.camera = step('camera');
  check.string(s.camera.model, `${path}.camera.model`);
  check.string(s.camera.method, `${path}.camera.method`);
  check.object(s.camera.options, `${path}.camera.options`);
  s.camera.result = checkCameraResult(s.camera.result, `${path}.camera.result`);
  if (s.camera.comparison !== null && s.camera.comparison !== undefined && typeof s.camera.comparison !== 'object') fail(`${path}.camera.comparison`, 'an object, a list or null', s.camera.comparison);

  s.robot = step('robot');
  for (const key of ['fileName', 'text']) s.robot[key] = check.stringOrNull(s.robot[key], `${path}.robot.${key}`);
  s.robot.files = s.robot.files === undefined || s.robot.files === null ? null : check.list(s.robot.files, `${path}.robot.files`);
  (s.robot.files || []).forEach((f, i) => { check.object(f, `${path}.robot.files[${i}]`); check.string(f.name, `${path}.robot.files[${i}].name`); check.string(f.text, `${path}.robot.files[${i}].text`); });
  for (const key of ['format', 'lengthUnit', 'angleUnit', 'direction']) check.string(s.robot[key], `${path}.robot.${key}`);
  s.robot.parsed = check.objectOrNull(s.robot.parsed, `${path}.robot.parsed`);
  if (s.robot.parsed && s.robot.parsed.poses !== undefined) check.list(s.robot.parsed.poses, `${path}.robot.parsed.poses`);

  s.handeye = step('handeye');
  check.oneOf(s.handeye.setup, `${path}.handeye.setup`, ['eye-in-hand', 'eye-to-hand']);
  check.string(s.handeye.method, `${path}.handeye.method`);
  s.handeye.result = checkHandeyeResult(s.handeye.result, `${path}.handeye.result`);

  s.workflows = step('workflows');
  for (const key of ['planar', 'xytable']) s.workflows[key] = check.objectOrNull(s.workflows[key], `${path}.workflows.${key}`);

  s.rig = step('rig');
  check.string(s.rig.model, `${path}.rig.model`);
  s.rig.result = check.objectOrNull(s.rig.result, `${path}.rig.result`);
  if (s.rig.videoGrouping !== undefined) check.oneOf(s.rig.videoGrouping, `${path}.rig.videoGrouping`, ['sync_index', 'frame']);
  check.list(s.rig.cameras, `${path}.rig.cameras`).forEach((cam, i) => {
    const p = `${path}.rig.cameras[${i}]`;
    check.object(cam, p);
    check.string(cam.name, `${p}.name`);
    check.list(cam.files, `${p}.files`).forEach((f, j) => {
      check.object(f, `${p}.files[${j}]`);
      if (!(typeof f.id === 'string' && f.id) && !Number.isFinite(f.id)) fail(`${p}.files[${j}].id`, 'a text or number', f.id);
      check.string(f.name, `${p}.files[${j}].name`);
      // A video frame's rig frame key (rig-video.js: its sync index or frame index).
      if (f.frameKey !== undefined) check.string(f.frameKey, `${p}.files[${j}].frameKey`);
    });
    // Held intrinsics (rig-intrinsics.js); absent in sessions saved before them.
    if (cam.intrinsics !== undefined) check.oneOf(cam.intrinsics, `${p}.intrinsics`, ['solve', 'file', 'solo']);
    for (const key of ['cameraFile', 'solo']) if (cam[key] !== undefined) cam[key] = check.objectOrNull(cam[key], `${p}.${key}`);
  });
  // The rig on a robot (rig-robot.js).
  if (s.rig.robot !== undefined && s.rig.robot !== null) {
    check.object(s.rig.robot, `${path}.rig.robot`);
    check.oneOf(s.rig.robot.setup, `${path}.rig.robot.setup`, ['eye-in-hand', 'eye-to-hand']);
    s.rig.robot.result = check.objectOrNull(s.rig.robot.result, `${path}.rig.robot.result`);
    s.rig.robot.parsed = check.objectOrNull(s.rig.robot.parsed, `${path}.rig.robot.parsed`);
  }
  // The laser step (views/laser.js); absent in sessions saved before it.
  s.laser = step('laser');
  s.laser.result = check.objectOrNull(s.laser.result, `${path}.laser.result`);
  if (s.laser.result) check.oneOf(s.laser.result.kind, `${path}.laser.result.kind`, ['laser_plane']);
  s.stereo = check.objectOrNull(raw.stereo, `${path}.stereo`);
  // The pose plan (views/plan.js) and the check (views/check.js); absent in sessions saved before them.
  s.plan = checkPlan(raw.plan, `${path}.plan`);
  s.check = checkCheck(raw.check, `${path}.check`);
  return s;
}

/** A share link's payload (`{kind, schema, target, camera, handeye, ...}`) checked as the read-only page reads it. */
export function checkSharePayload(p) {
  if (p.target !== undefined && p.target !== null) check.object(p.target, 'target');
  if (p.camera !== undefined && p.camera !== null) {
    check.object(p.camera, 'camera');
    checkCameraResult(p.camera.result, 'camera.result');
    // The residuals' sample (share.js): packed points, drawn by the residual plots.
    if (p.camera.residualSample !== undefined) {
      const sample = check.object(p.camera.residualSample, 'camera.residualSample');
      for (const key of ['total', 'step_px']) check.number(sample[key], `camera.residualSample.${key}`);
      numbers(sample.image_size_px, 'camera.residualSample.image_size_px', 2);
      check.list(sample.counts, 'camera.residualSample.counts').forEach((n, i) => {
        if (!Number.isInteger(n) || n < 0) fail(`camera.residualSample.counts[${i}]`, 'a whole number >= 0', n);
      });
      check.string(sample.data, 'camera.residualSample.data');
      if (!/^[A-Za-z0-9+/]*={0,2}$/.test(sample.data)) fail('camera.residualSample.data', 'base64 text', sample.data);
    }
  }
  if (p.handeye !== undefined && p.handeye !== null) {
    check.object(p.handeye, 'handeye');
    if (p.handeye.setup !== undefined) check.oneOf(p.handeye.setup, 'handeye.setup', ['eye-in-hand', 'eye-to-hand']);
    checkHandeyeResult(p.handeye.result, 'handeye.result');
    // The robot poses of the 3-D view (share.js).
    if (p.handeye.robotPoses !== undefined) check.list(p.handeye.robotPoses, 'handeye.robotPoses').forEach((pose, i) => checkPose(pose, `handeye.robotPoses[${i}]`));
  }
  if (p.plan !== undefined && p.plan !== null) {
    check.object(p.plan, 'plan');
    if (p.plan.setup !== undefined) check.oneOf(p.plan.setup, 'plan.setup', ['eye-in-hand', 'eye-to-hand']);
    checkPlanResult(p.plan.result, 'plan.result');
  }
  if (p.check !== undefined && p.check !== null) checkCheck(p.check, 'check');
  return p;
}
