// Step 5: hand-eye. Setup and method, solve with every method, the refined
// result, a Halcon-style error report, the methods side by side,
// repeatability box plots and a 3-D view of the frames.
import { $, h, fill, table, num, message } from '../lib/dom.js';
import { bars, boxplot } from '../lib/plot.js';
import { FrameView } from '../lib/view3d.js';
import { flat, mul, fromPose, IDENTITY } from '../lib/mat4.js';

// Refinement over the image points (the core's RefineMode names). 'ml' (the
// default, as the CLI's with images) sends the image points with refine
// 'none': the core's maximum likelihood over the poses, each camera pose
// weighted by its PnP covariance; 'none' sends the camera poses only, which
// the core refines the same way with a fitted noise model (refine_poses);
// 'closed' turns that off too.
const REFINE = [
  ['ml', 'Over the poses, each weighted by its image points (maximum likelihood)'],
  ['trusted', 'Over the image points, robot poses exact'],
  ['stochastic', 'Over the image points, robot pose noise estimated'],
  ['joint_intrinsics', 'Over the image points, camera intrinsics refined too'],
  ['none', 'Over the camera poses only (maximum likelihood, pose noise estimated)'],
  ['closed', 'None (closed forms on the camera poses only)'],
];

/** What each refinement minimises, in a sentence; the result is shown with it. */
const REFINE_HELP = {
  ml: 'Minimises the residuals of A X = Z B per pose, each camera pose weighted by its uncertainty from its detected points and each robot pose by the robot noise estimated from the data (maximum likelihood). Use it whenever the robot poses carry any noise (0.1 mm / 0.02 deg is enough): the most accurate, it is the default.',
  trusted: 'Minimises the reprojection error of every detected target point (px) over the hand-eye and target transforms, taking the robot poses as exact. Use it only when the robot poses are exact to well below what the camera resolves; robot noise goes straight into the result.',
  stochastic: 'Minimises the reprojection error (px) plus a small correction per robot pose, weighted by the robot pose noise it estimates from the data. Use it when the robot poses are less accurate than the camera (a cobot, a hand-measured or tracked pose).',
  joint_intrinsics: 'As "robot poses exact", with the camera intrinsics (fx, fy, cx, cy) free too. Use it only when the camera may have changed since its calibration; with inaccurate robot poses the intrinsics absorb the robot error (a warning says so).',
  none: 'Minimises the residuals of A X = Z B per pose, weighted by robot and camera pose noise estimated from the data (maximum likelihood over the poses, no pixels). Use it when only the camera poses are known, not the image points.',
  closed: 'No refinement: each closed form (Tsai-Lenz, Park-Martin, ...) solves its own algebraic form of A X = X B, rotation first, then translation. For comparison only.',
};
const WHICH = 'Which to use: the default; "robot poses exact" only for a robot far more accurate than the camera. The closure errors below (how far each pose’s robot, hand-eye and camera transforms land from one common target pose) are not what the refinements minimise, so a closed form can show a smaller closure and still be less accurate; compare the reprojection RMS, which every row shows when image points are used.';

const METHODS = [
  ['all', 'All methods (best one refined)'], ['tsai-lenz', 'Tsai-Lenz'], ['park-martin', 'Park-Martin'], ['horaud', 'Horaud'],
  ['andreff', 'Andreff'], ['daniilidis', 'Daniilidis (dual quaternion)'], ['chou-kamel', 'Chou-Kamel'], ['shah', 'Shah (AX = ZB)'], ['li', 'Li (AX = ZB)'],
];

export class HandEyeView {
  constructor(store, engine, robot, { readonly = false } = {}) {
    this.store = store;
    this.engine = engine;
    this.robot = robot;
    this.readonly = readonly;
    this.render();
  }

  get state() { return this.store.session.handeye; }

  render() {
    const st = this.state;
    const sel = (id, items, value, label) => h('label', {}, label, h('select', { id }, items.map(([v, t]) => h('option', { value: v, selected: v === value }, t))));
    const form = h('form', { class: 'form', id: 'handeye-form' },
      sel('handeye-setup', [['eye-in-hand', 'Eye-in-hand (camera on the gripper)'], ['eye-to-hand', 'Eye-to-hand (camera fixed, target on the gripper)']], st.setup, 'Setup '),
      sel('handeye-method', METHODS, st.method, 'Method '),
      sel('handeye-refine', REFINE, st.refine || 'ml', 'Refinement '),
      h('p', { class: 'hint', id: 'handeye-refine-help' }, REFINE_HELP[st.refine || 'ml']),
      h('p', { class: 'hint' }, WHICH),
      h('div', { class: 'row' }, h('button', { type: 'submit', class: 'primary', id: 'solve-handeye' }, 'Solve hand-eye')));
    form.addEventListener('change', () => {
      st.setup = $('handeye-setup').value;
      st.method = $('handeye-method').value;
      st.refine = $('handeye-refine').value;
      $('handeye-refine-help').textContent = REFINE_HELP[st.refine];
      this.store.changed('handeye-options');
    });
    form.addEventListener('submit', (e) => { e.preventDefault(); this.solve(); });
    this.out = h('div', { id: 'handeye-results', 'aria-live': 'polite' });
    this.canvas3d = h('canvas', { width: 900, height: 620, id: 'frames-3d', role: 'img', 'aria-label': '3-D view of the robot, camera and target frames' });
    this.view3d = new FrameView(this.canvas3d);
    fill($('handeye-panel'), this.readonly ? null : form, this.out);
    if (st.result) this.show(st.result);
  }

  /** Pairs of robot pose and camera_from_target from the camera solve, matched by image name. */
  input() {
    const cam = this.store.session.camera.result;
    if (!cam) throw new Error('solve the camera first (step 3): hand-eye uses the target pose of every view');
    const paired = this.robot.pairs().filter((p) => p.image && p.image.included);
    // A view detected with a larger grid than the target has another origin.
    const pairs = paired.filter((p) => !p.image.largerGrid);
    this.leftOut = paired.filter((p) => p.image.largerGrid).map((p) => p.image.name);
    const problem = this.robot.pairingProblem();
    if (problem) throw new Error(problem);
    if (!this.robot.pairs().some((p) => p.image)) throw new Error('load the robot poses first (step 4)');
    const views = new Map((cam.views || []).map((v) => [v.name, v]));
    const used = pairs.filter((p) => views.has(p.image.name));
    const refine = this.state.refine || 'ml';
    return {
      setup: this.state.setup,
      method: this.state.method,
      base_from_gripper: used.map((p) => ({ translation_m: p.pose.base_from_gripper.translation_m, quaternion_xyzw: p.pose.base_from_gripper.quaternion_xyzw })),
      camera_from_target: used.map((p) => ({ matrix_row_major: views.get(p.image.name).camera_from_target.matrix_row_major })),
      // The refinement reads the detected points through the solved camera.
      ...(refine === 'none' || refine === 'closed' ? {} : { refine: refine === 'ml' ? 'none' : refine, camera: cam.camera, camera_std: intrinsicStd(cam.std), detections: used.map((p) => p.image.detection) }),
      ...(refine === 'closed' ? { refine_poses: false } : {}),
      names: used.map((p) => p.image.name),
    };
  }

  async solve() {
    let input;
    try { input = this.input(); } catch (err) { fill(this.out, message('error', err.message)); return; }
    fill(this.out, message('info', `Solving from ${input.base_from_gripper.length} pose pairs…`));
    const names = input.names;
    delete input.names;
    try {
      const result = await this.engine.call('handeye', { input: JSON.stringify(input) });
      result.pair_names = names;
      result.left_out = this.leftOut;
      this.state.result = result;
      this.store.changed('handeye-result');
      this.show(result);
    } catch (err) {
      fill(this.out, leftOutNote(this.leftOut), message('error', err.message));
    }
  }

  show(r) {
    const eyeInHand = r.setup === 'eye-in-hand' || r.gripper_from_camera;
    const camKey = eyeInHand ? 'gripper_from_camera' : 'base_from_camera';
    const tgtKey = eyeInHand ? 'base_from_target' : 'gripper_from_target';
    const pose = (key) => {
      const p = r[key];
      if (!p) return null;
      return h('p', {}, h('b', {}, key), `: translation ${p.translation_m.map((v) => num(v * 1000, 3)).join(', ')} mm · quaternion (x y z w) ${p.quaternion_xyzw.map((v) => num(v, 6)).join(', ')}`);
    };
    const e = r.errors || {};
    const errors = table(['error (closure of A X = X B)', 'value'], [
      ['translation RMS', `${num(e.translation_rms_mm, 4)} mm`], ['translation max', `${num(e.translation_max_mm, 4)} mm`],
      ['rotation RMS', `${num(e.rotation_rms_deg, 5)} deg`], ['rotation max', `${num(e.rotation_max_deg, 5)} deg`],
      ['reprojection RMS', e.reprojection_rms_px == null ? '—' : `${num(e.reprojection_rms_px, 4)} px`]], { id: 'handeye-errors' });
    const methods = table(['method', 'minimises', 'x (mm)', 'y (mm)', 'z (mm)', 'translation RMS (mm)', 'rotation RMS (deg)', 'reprojection RMS (px)', 'vs. result (mm / deg)'],
      (r.methods || []).map((m) => {
        const p = m[camKey];
        if (!p) return [m.method, '', m.error || 'failed', '', '', '', '', '', ''];
        return [m.method, 'its algebraic A X = X B error (closed form)', ...p.translation_m.map((v) => num(v * 1000, 3)), num(m.errors && m.errors.translation_rms_mm, 4), num(m.errors && m.errors.rotation_rms_deg, 5),
          m.errors && m.errors.reprojection_rms_px != null ? num(m.errors.reprojection_rms_px, 4) : '—',
          `${num(m.disagreement_translation_mm, 3)} / ${num(m.disagreement_rotation_deg, 4)}`];
      }), { id: 'handeye-methods' });
    const poseMode = r.pose_refinement && r.pose_refinement.camera_noise_model === 'per_view' ? 'ml' : 'none';
    const mode = r.refinement ? r.refinement.mode : r.pose_refinement ? poseMode : 'closed';
    const measure = h('p', { class: 'hint', id: 'handeye-measure' }, `This result: ${REFINE_HELP[mode].split('. Use it')[0].replace(/\.$/, '')}.`);
    const ref = r.refinement;
    const refinement = ref ? h('p', { class: 'hint', id: 'handeye-refinement' },
      `Refined (${(REFINE.find(([v]) => v === ref.mode) || [, ref.mode])[1].toLowerCase()}) from ${ref.started_from}: reprojection RMS ${num(ref.reprojection_rms_px, 4)} px (closed form ${num(ref.closed_form_reprojection_rms_px, 4)} px) over ${(ref.per_view_reprojection_rms_px || []).length} views` +
      (ref.camera ? `; camera refined too: fx ${num(ref.camera.fx, 3)}, fy ${num(ref.camera.fy, 3)} px.` : '.')) : null;
    const pr = r.pose_refinement;
    const std = pr && pr.camera_transform_std;
    const poseRefinement = pr ? h('p', { class: 'hint', id: 'handeye-pose-refinement' },
      `Refined over the poses from ${pr.started_from} (maximum likelihood; estimated robot noise ${num(pr.noise.robot_rotation_deg, 4)} deg / ${num(pr.noise.robot_translation_mm, 3)} mm). ` +
      `${camKey} std: translation ${std.translation_mm.map((v) => num(v, 3)).join(', ')} mm, rotation ${std.rotation_deg.map((v) => num(v, 4)).join(', ')} deg` +
      (pr.outlier_views.length ? `; outlier views (down-weighted): ${pr.outlier_views.map((v) => v + 1).join(', ')}.` : '.') +
      (pr.reprojection_rms_px != null ? ` Reprojection RMS ${num(pr.reprojection_rms_px, 4)} px` +
        (pr.closed_form_reprojection_rms_px != null ? ` (closed form ${num(pr.closed_form_reprojection_rms_px, 4)} px)` : '') +
        ` over ${(pr.per_view_reprojection_rms_px || []).length} views, each view's points projected through the refined transforms and its robot pose.` : '')) : null;
    // The error where the robot works (report.work_point_error, tcp_error, holdout, touch_test).
    const field = [r.work_point_error, r.tcp_error].filter(Boolean).map((w, i) => h('p', { class: 'hint', id: i === 0 ? 'handeye-work-point' : 'handeye-tcp' },
      `${w.verdict}. To shrink it: ${w.shrink_by.join('; ')}.`));
    if (r.holdout) field.push(h('p', { class: 'hint', id: 'handeye-holdout' }, `Held-out poses: ${r.holdout.verdict}.`));
    if (r.touch_test) field.push(h('p', { class: 'hint', id: 'handeye-touch' }, `Touch test: ${r.touch_test.points.length} points, RMS ${num(r.touch_test.rms_mm, 3)} mm, largest ${num(r.touch_test.max_mm, 3)} mm.`));
    const motion = r.motion ? h('p', { class: 'hint' }, `${r.motion.motions} motions used (${r.motion.discarded_small_rotation} discarded for too little rotation); rotation angles ${num(r.motion.angle_min_deg, 1)}–${num(r.motion.angle_max_deg, 1)} deg (median ${num(r.motion.angle_median_deg, 1)}), axis spread ${num(r.motion.axis_spread_deg, 1)} deg.`) : null;
    // The table's quantity: closure per pose (its RMS and max are the table's).
    const names = r.pair_names || [];
    const perPose = bars(h('canvas', { width: 460, height: 300, role: 'img', 'aria-label': 'closure residual per pose', id: 'handeye-per-pose' }),
      (r.per_view || []).map((v) => ({ label: names[v.view] || `pose ${v.view + 1}`, value: v.translation_mm })),
      { ylabel: 'translation residual (mm)', title: 'Closure residual per pose (the table\'s RMS and max)', threshold: e.translation_rms_mm });
    const plots = [perPose];
    if (r.repeatability) {
      const rep = r.repeatability;
      const box = (stats, key) => stats[`${key}_samples`] || boxFromSpread(stats[key]);
      plots.push(boxplot(h('canvas', { width: 460, height: 300, role: 'img', 'aria-label': 'repeatability of the translation error' }),
        [{ label: 'leave-one-out', values: box(rep.leave_one_out, 'translation_rms_mm') }, { label: 'bootstrap', values: box(rep.bootstrap, 'translation_rms_mm') }],
        { ylabel: 'translation RMS (mm)', title: `Repeatability (${rep.method})` }));
      plots.push(boxplot(h('canvas', { width: 460, height: 300, role: 'img', 'aria-label': 'repeatability of the rotation error' }),
        [{ label: 'leave-one-out', values: box(rep.leave_one_out, 'rotation_rms_deg') }, { label: 'bootstrap', values: box(rep.bootstrap, 'rotation_rms_deg') }],
        { ylabel: 'rotation RMS (deg)', title: 'Repeatability' }));
    }
    this.plots = plots;
    const leftOut = leftOutNote(r.left_out);
    fill(this.out, h('h3', {}, `Result (${r.method})`), leftOut, (r.warnings || []).map((w) => message('warning', w)),
      measure, pose(camKey), pose(tgtKey), refinement, poseRefinement, field, errors, motion, h('h3', {}, 'Methods side by side'), methods,
      h('div', { class: 'plots' }, plots), h('h3', {}, '3-D view'), this.frames3d());
    this.draw3d(r, camKey, tgtKey, eyeInHand);
  }

  /** The 3-D view with its zoom buttons (keys on the canvas: + - 0, arrows). */
  frames3d() {
    const b = (id, label, text, f) => h('button', { type: 'button', id, 'aria-label': label, onclick: f }, text);
    return h('div', { class: 'frames-3d' },
      h('div', { class: 'row' }, b('frames-zoom-in', 'zoom in', '+', () => this.view3d.zoomBy(1.25)),
        b('frames-zoom-out', 'zoom out', '−', () => this.view3d.zoomBy(0.8)), b('frames-reset', 'reset the view', 'Reset view', () => this.view3d.reset())),
      this.canvas3d);
  }

  /** The robot poses (base_from_gripper) the 3-D view draws: the first 8 paired with an image. */
  robotPoses3d() {
    return this.robot.pairs().filter((p) => p.image).slice(0, 8).map((p) => p.pose.base_from_gripper);
  }

  draw3d(r, camKey, tgtKey, eyeInHand) {
    const robot = this.robotPoses3d().map(fromPose);
    const frames = [{ name: 'base', matrix_row_major: IDENTITY }];
    const links = [];
    robot.forEach((g, i) => {
      frames.push({ name: i === 0 ? 'gripper' : `g${i + 1}`, matrix_row_major: g });
      links.push(['base', i === 0 ? 'gripper' : `g${i + 1}`]);
    });
    if (r[camKey] && r[tgtKey]) {
      const X = flat(r[camKey]);
      const T = flat(r[tgtKey]);
      if (eyeInHand && robot.length) {
        frames.push({ name: 'camera', matrix_row_major: mul(robot[0], X) });
        frames.push({ name: 'target', matrix_row_major: T });
        links.push(['gripper', 'camera'], ['camera', 'target']);
      } else if (robot.length) {
        frames.push({ name: 'camera', matrix_row_major: X });
        frames.push({ name: 'target', matrix_row_major: mul(robot[0], T) });
        links.push(['gripper', 'target'], ['camera', 'target']);
      }
    }
    this.view3d.set(frames, links);
  }
}

/** Why views detected with a grid larger than the target are not in the hand-eye calibration. */
function leftOutNote(names) {
  if (!names || !names.length) return null;
  return message('info', `Left out of the hand-eye calibration: ${names.join(', ')}: the grid found there is larger than the target, so its point 0 (the target's origin) need not be the same board corner as in the other views, and hand-eye needs one target frame in every view. Set the target to the board's full inner-corner count to use them.`);
}

/** The camera's calibrated std of fx, fy, cx, cy (finite ones), for the joint refinement's warning. */
function intrinsicStd(std) {
  const out = {};
  for (const k of ['fx', 'fy', 'cx', 'cy']) if (std && Number.isFinite(std[k])) out[k] = std[k];
  return Object.keys(out).length ? out : null;
}

/** Without per-run samples, a box from the median and IQR (whiskers omitted). */
function boxFromSpread(s) {
  if (!s) return [];
  return [s.median - s.iqr / 2, s.median, s.median + s.iqr / 2];
}
