// Step 5, second part: plan robot poses for a hand-eye calibration from one
// view of the target (docs/pose-plan.md, the page's `robocal plan`). The
// camera is the session's solved one, the current view one of the paired
// images (its camera_from_target from the camera solve), the current robot
// pose a line the user can edit (prefilled with that image's robot pose);
// the rough hand-eye transform is the solved one when there is one. Shows
// the predicted error at the work point, the poses, a 3-D view of the
// flange frames and camera frustums, and the program or pose table for the
// robot in the chosen format. The inputs, the request and the plan are
// kept in the session (session.plan): a reload or a session file shows the
// plan again. The limits of `robocal plan` (tilt, roll, distance, the
// flange box, the image margin) go to the core as given: its words, the
// CLI's, come back for values it refuses. A shared page shows the plan
// read-only.
import { $, h, fill, table, num, message, download } from '../lib/dom.js';
import { FrameView } from '../lib/view3d.js';
import { mul, fromPose, IDENTITY } from '../lib/mat4.js';
import { invert, apply, frustum, boardOutline } from '../lib/rig3d.js';
import { PRESETS } from './robot.js';

/** The move-list formats: `robocal plan --format` names, label, file name. */
export const MOVE_FORMATS = [
  ['ur-script', 'UR script (movel program)', 'robocal_plan.script'],
  ['kuka-krl', 'KUKA KRL (LIN program)', 'robocal_plan.src'],
  ['abb-rapid', 'ABB RAPID (MoveL program)', 'robocal_plan.mod'],
  ['ur', 'Pose table: UR (m, rotation vector)', 'robocal_plan_ur.csv'],
  ['kuka', 'Pose table: KUKA (mm, A B C deg)', 'robocal_plan_kuka.csv'],
  ['abb', 'Pose table: ABB (mm, quaternion w first)', 'robocal_plan_abb.csv'],
  ['fanuc', 'Pose table: FANUC (mm, W P R deg)', 'robocal_plan_fanuc.csv'],
  ['yaskawa', 'Pose table: Yaskawa (mm, deg)', 'robocal_plan_yaskawa.csv'],
  ['staubli', 'Pose table: Stäubli (mm, deg)', 'robocal_plan_staubli.csv'],
  ['xyz_quat_xyzw', 'Pose table: x y z qx qy qz qw (m)', 'robocal_plan_xyzw.csv'],
];

/** The inputs kept in session.plan.inputs.fields: every field of the form but the view. */
const FIELD_IDS = ['plan-robot-pose', 'plan-pose-format', 'plan-count', 'plan-max-tilt', 'plan-max-roll', 'plan-distance-min', 'plan-distance-max', 'plan-margin',
  'plan-box-x0', 'plan-box-y0', 'plan-box-z0', 'plan-box-x1', 'plan-box-y1', 'plan-box-z1'];
const BOX_IDS = FIELD_IDS.filter((id) => id.startsWith('plan-box-'));

const poseLine = (p) => [...p.translation_m, ...p.quaternion_xyzw].map((v) => String(Number(v.toFixed(9)))).join(',');

export class PlanView {
  constructor(store, engine, robot, { readonly = false } = {}) {
    this.store = store;
    this.engine = engine;
    this.robot = robot;
    this.readonly = readonly;
    this.report = null;
    this.render();
    if (!readonly) store.onChange((what) => { if (/camera-result|handeye-result|robot|detections|included|all/.test(what)) this.renderViews(); });
  }

  /** Paired images with a camera pose from the camera solve: the possible current views. */
  views() {
    const cam = this.store.session.camera.result;
    if (!cam) return [];
    const byName = new Map((cam.views || []).map((v) => [v.name, v]));
    return this.robot.pairs().filter((p) => p.image && p.image.included && byName.has(p.image.name))
      .map((p) => ({ name: p.image.name, pose: p.pose.base_from_gripper, camera_from_target: byName.get(p.image.name).camera_from_target }));
  }

  render() {
    this.out = h('div', { id: 'plan-results', 'aria-live': 'polite' });
    this.canvas3d = h('canvas', { width: 900, height: 620, id: 'plan-3d', role: 'img', 'aria-label': '3-D view of the planned flange frames and camera frustums' });
    this.view3d = new FrameView(this.canvas3d);
    this.report = null;
    if (this.readonly) {
      const saved = this.store.session.plan;
      fill($('plan-panel'), saved && saved.result ? [h('h3', {}, 'Planned robot poses'), this.out] : null);
      if (saved && saved.result) this.restoreResult(saved);
      return;
    }
    const field = (id, label, value, attrs = {}) => h('label', {}, label, h('input', { id, value, ...attrs }));
    this.viewSelect = h('select', { id: 'plan-view' });
    this.viewSelect.addEventListener('change', () => this.prefill());
    const form = h('form', { class: 'form', id: 'plan-form' },
      h('label', {}, 'Current view (image) ', this.viewSelect),
      h('label', {}, 'Current robot pose (base_from_gripper) ', h('input', { id: 'plan-robot-pose', spellcheck: false })),
      h('label', {}, 'Read as ', h('select', { id: 'plan-pose-format' }, PRESETS.map(([v, t]) => h('option', { value: v, selected: v === 'xyz_quat_xyzw' }, v === 'xyz_quat_xyzw' ? `${t} (m)` : t)))),
      h('div', { class: 'row' },
        field('plan-count', 'Poses ', '12', { type: 'number', min: 3, max: 60, step: 1 }),
        field('plan-max-tilt', 'Max tilt (deg) ', '40', { type: 'number', min: 5, max: 80, step: 1 }),
        field('plan-distance-min', 'Distance from (mm) ', '', { type: 'number', min: 1, step: 1 }),
        field('plan-distance-max', 'to (mm) ', '', { type: 'number', min: 1, step: 1 })),
      h('p', { class: 'hint' }, 'The distance range starts at the chosen view\'s camera-to-target distance, 20 % either way.'),
      h('div', { class: 'row' },
        field('plan-max-roll', 'Max roll about the optical axis (deg) ', '60', { type: 'number', step: 'any' }),
        field('plan-margin', 'Image margin (px) ', '20', { type: 'number', step: 'any' })),
      h('fieldset', { id: 'plan-box' }, h('legend', {}, 'Flange box (base frame, mm, two opposite corners; empty: no box)'),
        h('div', { class: 'row' }, ['x0', 'y0', 'z0', 'x1', 'y1', 'z1'].map((k) => field(`plan-box-${k}`, `${k} `, '', { type: 'number', step: 'any', size: 7 })))),
      h('p', { class: 'hint' }, 'The camera is the solved one (step 3), the target the session\'s; the rough hand-eye transform is the solved one (above) when there is one, identity otherwise. Joint limits, reachability and collisions are not modelled: check the poses in simulation before running them.'),
      h('div', { class: 'row' }, h('button', { type: 'submit', class: 'primary', id: 'plan-run' }, 'Plan poses')));
    form.addEventListener('submit', (e) => { e.preventDefault(); this.plan(); });
    fill($('plan-panel'), h('h3', {}, 'Plan robot poses'), h('p', { class: 'hint' }, 'Poses for the robot to visit for a hand-eye calibration, from one view of the target and the robot pose there (as robocal plan).'), form, this.out);
    this.renderViews();
    this.restore();
  }

  /** The inputs and the plan of session.plan, back in the form and the results. */
  restore() {
    const saved = this.store.session.plan;
    if (!saved) return;
    try {
      for (const [id, value] of Object.entries(saved.inputs.fields)) if (FIELD_IDS.includes(id)) $(id).value = value;
      this.savedView = saved.inputs.view;
      if (this.savedView) this.renderViews();
      if (saved.result) this.restoreResult(saved);
    } catch (err) {
      fill(this.out, message('error', `The saved plan could not be shown (${err.message}): plan again.`));
    }
  }

  restoreResult(saved) {
    try {
      this.report = saved.result;
      this.show(saved.result, saved.request);
    } catch (err) {
      this.report = null;
      fill(this.out, message('error', `The saved plan could not be shown (${err.message}): plan again.`));
    }
  }

  /** The form's values, as session.plan.inputs keeps them. */
  inputs() {
    return { view: this.viewSelect.value || null, fields: Object.fromEntries(FIELD_IDS.map((id) => [id, $(id).value])) };
  }

  renderViews() {
    const views = this.views();
    // A restored plan's view, once the paired images are there: chosen, its restored fields kept.
    const restored = this.savedView && views.some((v) => v.name === this.savedView) ? this.savedView : null;
    const old = restored || this.viewSelect.value;
    fill(this.viewSelect, views.map((v) => h('option', { value: v.name, selected: v.name === old }, v.name)));
    if (restored) { this.savedView = null; return; }
    if (views.length && (!old || !views.some((v) => v.name === old))) this.prefill();
  }

  prefill() {
    const v = this.views().find((x) => x.name === this.viewSelect.value);
    if (!v) return;
    $('plan-robot-pose').value = poseLine(v.pose);
    // The working distance range: the chosen view's camera-to-target
    // distance (to the target origin), 20 % either way; robocal plan without
    // --distance measures to the board centre.
    const t = v.camera_from_target && v.camera_from_target.translation_m;
    if (t) {
      const mm = Math.hypot(...t) * 1000;
      $('plan-distance-min').value = String(Math.round(mm * 0.8));
      $('plan-distance-max').value = String(Math.round(mm * 1.2));
    }
  }

  /** The request of plan_handeye_poses (without board_m: the worker adds the target's points). */
  async request() {
    if (!this.viewSelect.value) this.renderViews();
    const cam = this.store.session.camera.result;
    if (!cam) throw new Error('solve the camera first (step 3): the plan uses its intrinsics and its view of the target');
    const view = this.views().find((x) => x.name === this.viewSelect.value);
    if (!view) throw new Error('load the robot poses first (step 4): the current view is a paired image');
    const text = $('plan-robot-pose').value.trim();
    if (!text) throw new Error('give the current robot pose');
    const format = $('plan-pose-format').value;
    const options = format === 'auto' ? {} : { format, ...(format === 'xyz_quat_xyzw' ? { length_unit: 'm' } : {}) };
    const reading = await this.engine.call('poses', { text, options: JSON.stringify(options) });
    const parsed = reading.parsed || null;
    if (!parsed || !parsed.poses.length) throw new Error(`the current robot pose: ${reading.ambiguity || 'no pose read'}; choose its format`);
    const b = parsed.poses[0].base_from_gripper;
    const setup = this.store.session.handeye.setup;
    const he = this.store.session.handeye.result;
    const guessKey = setup === 'eye-in-hand' ? 'gripper_from_camera' : 'gripper_from_target';
    const guess = he && he[guessKey] ? { translation_m: he[guessKey].translation_m, quaternion_xyzw: he[guessKey].quaternion_xyzw } : undefined;
    const poses = Number($('plan-count').value);
    const maxTilt = Number($('plan-max-tilt').value);
    if (!Number.isInteger(poses) || poses < 3) throw new Error('Poses: a whole number, at least 3');
    if (!(maxTilt > 0)) throw new Error('Max tilt: a positive number of degrees');
    // Roll, margin and the flange box go to the core as given: it says what it refuses.
    const optional = (id) => ($(id).value.trim() === '' ? undefined : Number($(id).value));
    const maxRoll = optional('plan-max-roll');
    const margin = optional('plan-margin');
    const box = BOX_IDS.map(optional);
    const given = box.filter((v) => v !== undefined).length;
    if (given && given < 6) throw new Error('Flange box: give all six corner coordinates (mm), or none');
    const [d0, d1] = ['plan-distance-min', 'plan-distance-max'].map((id) => $(id).value.trim());
    let distance;
    if (d0 || d1) {
      const d = [Number(d0), Number(d1)];
      if (!d0 || !d1 || !d.every((x) => x > 0) || d[0] >= d[1]) throw new Error('Distance: both ends in mm, the first smaller');
      distance = d.map((x) => x / 1000);
    }
    return {
      setup,
      base_from_gripper: { translation_m: b.translation_m, quaternion_xyzw: b.quaternion_xyzw },
      camera_from_target: { matrix_row_major: view.camera_from_target.matrix_row_major },
      camera: cam.camera,
      ...(guess ? { guess } : {}),
      poses,
      max_tilt_deg: maxTilt,
      ...(distance ? { distance_m: distance } : {}),
      ...(maxRoll !== undefined ? { max_roll_deg: maxRoll } : {}),
      ...(margin !== undefined ? { margin_px: margin } : {}),
      ...(given ? { flange_box_m: [box.slice(0, 3).map((v) => v / 1000), box.slice(3).map((v) => v / 1000)] } : {}),
    };
  }

  async plan() {
    let request;
    try { request = await this.request(); } catch (err) { fill(this.out, message('error', err.message)); return; }
    fill(this.out, message('info', `Planning ${request.poses} poses…`));
    const inputs = this.inputs();
    try {
      this.report = await this.engine.call('plan', { request: JSON.stringify(request), target: JSON.stringify(this.store.session.target) });
      this.store.session.plan = { inputs, request, result: this.report };
      this.store.changed('plan-result');
      this.show(this.report, request);
    } catch (err) {
      this.report = null;
      this.store.session.plan = { inputs, request: null, result: null };
      this.store.changed('plan-result');
      fill(this.out, message('error', err.message));
    }
  }

  show(r, request) {
    const w = r.predicted;
    const predicted = h('p', { id: 'plan-predicted' }, h('b', {}, 'Predicted error at the work point: '),
      `${num(w.bound95_mm, 3)} mm (95 %), RMS ${num(w.rms_mm, 3)} mm. ${w.verdict}`);
    const rows = r.poses.map((p, i) => [String(i + 1), ...p.base_from_gripper.translation_m.map((v) => num(v * 1000, 2)),
      p.base_from_gripper.quaternion_xyzw.map((v) => num(v, 5)).join(', '), num(p.tilt_deg, 1), num(p.distance_m * 1000, 1), num(p.roll_deg, 1)]);
    const poses = table(['#', 'x (mm)', 'y (mm)', 'z (mm)', 'quaternion (x y z w)', 'tilt (deg)', 'distance (mm)', 'roll (deg)'], rows, { id: 'plan-poses' });
    const motion = h('p', { class: 'hint' }, `Travel ${num(r.travel_m * 1000, 0)} mm from the current pose, ${r.candidates} candidates considered.`);
    this.formatSelect = h('select', { id: 'plan-format' }, MOVE_FORMATS.map(([v, t]) => h('option', { value: v }, t)));
    this.formatSelect.addEventListener('change', () => this.preview());
    this.listOut = h('pre', { id: 'plan-move-list', class: 'export', tabindex: 0, 'aria-label': 'move list preview' });
    this.listStatus = h('p', { id: 'plan-move-status', class: 'hint' });
    const b = (id, label, text, f) => h('button', { type: 'button', id, 'aria-label': label, onclick: f }, text);
    // A shared link's plan holds no camera poses: no 3-D view then.
    const in3d = request && r.poses.every((p) => p.camera_from_target);
    fill(this.out, predicted, (r.notes || []).map((n) => message('info', n)), poses, motion,
      in3d ? h('h3', {}, '3-D view') : null,
      !in3d ? null : h('div', { class: 'frames-3d' },
        h('div', { class: 'row' }, b('plan-zoom-in', 'zoom in', '+', () => this.view3d.zoomBy(1.25)),
          b('plan-zoom-out', 'zoom out', '−', () => this.view3d.zoomBy(0.8)), b('plan-reset', 'reset the view', 'Reset view', () => this.view3d.reset())),
        this.canvas3d),
      h('h3', {}, 'For the robot'),
      h('div', { class: 'row' }, h('label', {}, 'Format ', this.formatSelect),
        h('button', { type: 'button', id: 'plan-download', onclick: () => this.save() }, 'Download')),
      this.listStatus, this.listOut);
    if (in3d) this.draw3d(r, request);
    this.preview();
  }

  /** The flange frames, camera frustums and board outlines, base frame. */
  async draw3d(r, request) {
    const eyeInHand = request.setup === 'eye-in-hand';
    const guess = request.guess ? fromPose(request.guess) : IDENTITY;
    const b0 = fromPose(request.base_from_gripper);
    const c0 = request.camera_from_target.matrix_row_major.flat();
    const frames = [{ name: 'base', matrix_row_major: IDENTITY }, { name: 'now', matrix_row_major: b0 }];
    const links = [['base', 'now']];
    const shapes = [];
    let board = null;
    try {
      const t = await this.engine.call('target', { spec: JSON.stringify(this.store.session.target) });
      board = boardOutline(t.points);
    } catch (err) { /* no outline: the frames and frustums still show */ }
    const outline = (worldFromTarget) => board && shapes.push({ color: '#8c564b', closed: true, points: board.map((p) => apply(worldFromTarget, p)) });
    const depth = Math.max(0.02, 0.3 * (r.poses[0] ? r.poses[0].distance_m : 0.3));
    const camera = request.camera;
    if (eyeInHand) {
      // The target stays where the current view puts it; each pose's camera is where its view puts it.
      const target = mul(mul(b0, guess), c0);
      frames.push({ name: 'target', matrix_row_major: target });
      outline(target);
      r.poses.forEach((p) => shapes.push(...frustum(mul(target, invert(p.camera_from_target.matrix_row_major)), camera, depth, '#1f77b4')));
    } else {
      // The camera stays; the target on the flange moves with each pose.
      const cam = mul(mul(b0, guess), invert(c0));
      frames.push({ name: 'camera', matrix_row_major: cam });
      shapes.push(...frustum(cam, camera, depth, '#1f77b4'));
      r.poses.forEach((p) => outline(mul(cam, p.camera_from_target.matrix_row_major.flat())));
    }
    r.poses.forEach((p, i) => {
      frames.push({ name: `p${i + 1}`, matrix_row_major: fromPose(p.base_from_gripper), size: 0.04 });
      links.push([i === 0 ? 'now' : `p${i}`, `p${i + 1}`]);
    });
    this.view3d.set(frames, links, shapes);
  }

  async preview() {
    const format = this.formatSelect.value;
    try {
      this.listText = await this.engine.call('planMoveList', { report: JSON.stringify(this.report), format });
      this.listOut.textContent = this.listText;
      this.listStatus.textContent = `${format}: ${this.listText.length} bytes, ${this.report.poses.length} poses.`;
    } catch (err) {
      this.listText = null;
      this.listOut.textContent = '';
      this.listStatus.textContent = `${format}: ${err.message}`;
    }
  }

  save() {
    const entry = MOVE_FORMATS.find(([v]) => v === this.formatSelect.value);
    if (this.listText && entry) download(entry[2], this.listText);
  }
}
