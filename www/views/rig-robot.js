// The rig on a robot, the last part of step 7 once the rig is solved:
// `robocal rig ... --setup eye-in-hand|eye-to-hand --poses FILE` in the
// page. The solved rig is held (its intrinsics and camera_from_rig, its
// covariance widening the std); a robot pose file (read as step 4 reads
// one: a table, or one file per pose) gives base_from_gripper per frame,
// paired by the frame number of its image column under the rig's grouping
// rule, else in frame order; one wasm call (`calibrate_rig_handeye`) solves
// gripper_from_rig (eye-in-hand) or base_from_rig (eye-to-hand) with its
// std, each camera's own transform and the per-frame audit. Kept in the
// session under rig.robot.
import { h, fill, table, num, message, download } from '../lib/dom.js';
import { rotvecDeg } from '../lib/rig3d.js';
import { PRESETS, loadPoseFiles, readPoseSource } from './robot.js';

const SETUPS = [
  ['eye-in-hand', 'Eye-in-hand: the rig on the gripper, the board fixed (gripper_from_rig)'],
  ['eye-to-hand', 'Eye-to-hand: the rig fixed, the board on the gripper (base_from_rig)'],
];
const rigKey = (setup) => (setup === 'eye-to-hand' ? 'base_from_rig' : 'gripper_from_rig');
const cameraKey = (setup) => (setup === 'eye-to-hand' ? 'base_from_camera' : 'gripper_from_camera');

export class RigRobot {
  /** `input()` gives the rig step's calibrate_rig input (the views the rig was solved from). */
  constructor(store, engine, input) {
    this.store = store;
    this.engine = engine;
    this.input = input;
  }

  get state() {
    const rig = this.store.session.rig;
    return rig.robot || (rig.robot = { setup: 'eye-in-hand', format: 'auto', direction: 'base_from_gripper', fileName: null, text: null, files: null, parsed: null, error: null, result: null });
  }

  options() {
    const st = this.state;
    return st.format === 'auto' ? { direction: st.direction } : { direction: st.direction, format: st.format };
  }

  /** The part, for the solved rig report `rig`. */
  render(rig) {
    this.rig = rig;
    const st = this.state;
    const setup = h('select', { id: 'rig-robot-setup', 'aria-label': 'Setup of the rig on the robot' },
      SETUPS.map(([v, t]) => h('option', { value: v, selected: v === st.setup }, t)));
    setup.addEventListener('change', () => { st.setup = setup.value; this.store.changed('rig'); });
    const format = h('select', { id: 'rig-robot-format', 'aria-label': 'Pose file format' },
      PRESETS.map(([v, t]) => h('option', { value: v, selected: v === st.format }, t)));
    const direction = h('select', { id: 'rig-robot-direction', 'aria-label': 'The pose file holds' },
      [['base_from_gripper', 'base_from_gripper (TCP pose in base: usual)'], ['gripper_from_base', 'gripper_from_base (inverted)']].map(([v, t]) => h('option', { value: v, selected: v === st.direction }, t)));
    const reread = async () => {
      st.format = format.value;
      st.direction = direction.value;
      if (st.text || (st.files && st.files.length)) Object.assign(st, await readPoseSource(this.engine, st, this.options()));
      this.store.changed('rig');
      await this.showPairing();
    };
    format.addEventListener('change', reread);
    direction.addEventListener('change', reread);
    const input = h('input', { type: 'file', id: 'rig-robot-input', 'aria-label': 'robot pose files of the rig', multiple: true, accept: '.csv,.tsv,.txt,.json,.dat,.yaml,.yml,text/*,application/json', hidden: true, tabindex: -1 });
    this.fileName = h('span', { id: 'rig-robot-file-name' }, st.fileName ? `loaded: ${st.fileName}` : 'no file loaded');
    input.addEventListener('change', async () => {
      const chosen = [...input.files];
      if (!chosen.length) return;
      input.value = '';
      Object.assign(st, await loadPoseFiles(this.engine, chosen, this.options()));
      this.fileName.textContent = `loaded: ${st.fileName}`;
      this.store.changed('rig');
      await this.showPairing();
    });
    this.solveButton = h('button', { type: 'button', class: 'primary', id: 'rig-robot-solve', disabled: true }, 'Solve the rig on the robot');
    this.solveButton.addEventListener('click', () => this.solve());
    this.pairingOut = h('div', { id: 'rig-robot-pairing' });
    this.out = h('div', { id: 'rig-robot-results', 'aria-live': 'polite' });
    const part = h('section', { id: 'rig-robot' },
      h('h3', {}, 'The rig on a robot'),
      h('p', { class: 'hint' }, 'As robocal rig … --setup eye-in-hand|eye-to-hand --poses FILE: the rig above is held (its intrinsics and camera_from_rig; its covariance widens the std), and one robot pose base_from_gripper per frame gives the rig\'s hand-eye. A pose file with an image column pairs each pose with the frame of the number in that name (the rig\'s grouping rule; any camera\'s image of the frame will do); without names the poses go with the frames in order. The pose file is read as in step 4: a table, or several files of one pose each.'),
      h('div', { class: 'form' },
        h('label', {}, 'Setup ', setup),
        h('div', { class: 'row file-row' }, h('span', {}, 'Robot poses'),
          h('button', { type: 'button', id: 'rig-robot-choose', 'aria-describedby': 'rig-robot-file-name', onclick: () => input.click() }, 'Choose pose file(s)…'), this.fileName, input),
        h('label', {}, 'Format ', format),
        h('label', {}, 'The file holds ', direction)),
      this.pairingOut,
      h('div', { class: 'row' }, this.solveButton),
      this.out);
    this.showPairing();
    if (st.result) this.show(st.result);
    return part;
  }

  /**
   * One robot pose per frame of the rig, as robocal rig pairs them: by the
   * frame key of each pose's name (the rig's grouping rule) when every pose
   * is named and the frames are not grouped by order, else in order.
   * `{poses, rows, how, error}`; `poses` is null when they cannot be paired.
   */
  async framePoses() {
    const st = this.state;
    const keys = this.rig.frames.map((f) => f.key);
    const poses = st.parsed ? st.parsed.poses : [];
    const rule = this.rig.grouping || 'number';
    const named = rule !== 'order' && poses.length > 0 && poses.every((p) => p.name);
    if (!named) {
      const rows = keys.map((k, i) => [k, poses[i] ? `pose ${i + 1} (line ${poses[i].line})` : '—']);
      const error = poses.length === keys.length ? null : `${poses.length} robot poses but ${keys.length} frames: give one robot pose per frame in frame order, or name each frame's image in an image column`;
      return { poses: error ? null : poses, rows, how: 'in frame order', error };
    }
    let poseKeys;
    try {
      const g = await this.engine.call('rigFrames', { cameras: JSON.stringify([{ name: 'of the pose file', images: poses.map((p) => p.name) }]), groupBy: rule });
      poseKeys = g.keys[0];
    } catch (err) {
      return { poses: null, rows: [], how: 'by name', error: `the pose file's image names cannot be put in frames: ${err.message}` };
    }
    const byFrame = keys.map((k) => poses.find((p, i) => poseKeys[i] === k) || null);
    const rows = keys.map((k, f) => [k, byFrame[f] ? `${byFrame[f].name} (line ${byFrame[f].line})` : '—']);
    const missing = keys.filter((k, f) => !byFrame[f]);
    const error = missing.length ? `no robot pose for frame(s) ${missing.join(', ')}: give a pose for every frame, or leave those frames' images out` : null;
    return { poses: error ? null : byFrame, rows, how: 'by the frame number of the image column', error };
  }

  async showPairing() {
    const st = this.state;
    const asked = (this.asked = (this.asked || 0) + 1);
    this.solveButton.disabled = true;
    if (st.error) { fill(this.pairingOut, message('error', st.files ? st.error : `${st.fileName}: ${st.error}`)); return; }
    if (!st.parsed) { fill(this.pairingOut, message('info', 'Load the robot\'s poses: one base_from_gripper per frame of the rig.')); return; }
    const paired = await this.framePoses();
    if (asked !== this.asked) return;
    this.paired = paired;
    const p = st.parsed;
    fill(this.pairingOut,
      h('p', { id: 'rig-robot-poses' }, `${st.fileName}: ${p.poses.length} poses read as ${p.format}, lengths in ${p.length_unit}, angles in ${p.angle_unit}; paired with the ${this.rig.frames.length} frames ${paired.how}.`),
      paired.error ? h('p', { id: 'rig-robot-pairing-error', class: 'msg msg-error', role: 'alert' }, paired.error) : null,
      table(['frame', 'robot pose'], paired.rows, { id: 'rig-robot-pairing-table', class: 'scroll' }));
    this.solveButton.disabled = !paired.poses;
  }

  async solve() {
    const st = this.state;
    const paired = this.paired;
    if (!paired || !paired.poses) return;
    this.solveButton.disabled = true;
    fill(this.out, h('p', { class: 'hint', id: 'rig-robot-progress' }, `solving the ${st.setup} hand-eye of the rig from ${paired.poses.length} robot poses…`));
    try {
      const request = {
        setup: st.setup,
        base_from_gripper: paired.poses.map((p) => ({ translation_m: p.base_from_gripper.translation_m, quaternion_xyzw: p.base_from_gripper.quaternion_xyzw })),
        calibration: this.input(),
        rig: this.rig,
      };
      st.result = await this.engine.call('rigHandeye', { input: JSON.stringify(request) });
      this.store.changed('rig-result');
      await this.show(st.result);
    } catch (err) {
      st.result = null;
      this.store.changed('rig-result');
      fill(this.out, h('p', { id: 'rig-robot-error', class: 'msg msg-error', role: 'alert' }, err.message));
    } finally {
      this.solveButton.disabled = false;
    }
  }

  async show(report) {
    const he = report.handeye;
    const key = rigKey(he.setup);
    const x = he[key];
    const std = he.pose_refinement && he.pose_refinement.camera_transform_std;
    const rv = rotvecDeg(x.quaternion_xyzw);
    const used = he.frames.filter((f) => f.used).length;
    const dash = ['—', '—', '—'];
    const camKey = cameraKey(he.setup);
    const unc = he.rig_uncertainty;
    this.exportStatus = h('div', { id: 'rig-robot-export-status', 'aria-live': 'polite' });
    const formats = await this.engine.call('rigFormats', {});
    const text = JSON.stringify(report);
    fill(this.out,
      h('h4', { id: 'rig-robot-summary' }, `${key}: T (${x.translation_m.map((v) => num(v * 1000, 3)).join(', ')}) mm, ${he.method}, ${used} of ${he.frames.length} frames used`),
      h('p', { class: 'hint' }, he.setup === 'eye-to-hand' ? 'base_from_rig: p_base = R p_rig + T (the rig fixed in the robot\'s base).' : 'gripper_from_rig: p_gripper = R p_rig + T (the rig on the gripper).'),
      table(['', 'x', 'y', 'z'], [
        ['T (mm)', ...x.translation_m.map((v) => num(v * 1000, 3))],
        ['std T (mm)', ...(std ? std.translation_mm.map((v) => num(v, 3)) : dash)],
        ['rotation vector (deg)', ...rv.map((v) => num(v, 4))],
        ['std rotation (deg)', ...(std ? std.rotation_deg.map((v) => num(v, 4)) : dash)],
      ], { id: 'rig-robot-transform' }),
      h('p', { id: 'rig-robot-uncertainty', class: 'hint' }, `${unc.note.charAt(0).toUpperCase()}${unc.note.slice(1)}${/\.$/.test(unc.note) ? '' : '.'}`),
      table(['camera', `${camKey} T x (mm)`, 'T y (mm)', 'T z (mm)'], he.cameras.map((c) => [c.name, ...c[camKey].translation_m.map((v) => num(v * 1000, 3))]), { id: 'rig-robot-cameras' }),
      table(['frame', 'cameras', 'used'], he.frames.map((f) => [f.key, f.cameras.join(', '), f.used ? 'used' : `not used${f.reason ? `: ${f.reason}` : ''}`]), { id: 'rig-robot-frames', class: 'scroll' }),
      (he.warnings || []).map((w) => message('warning', w)),
      h('div', { class: 'row' },
        h('button', { type: 'button', id: 'rig-robot-export-json', onclick: () => download('rig_robot.json', `${JSON.stringify(report, null, 2)}\n`, 'application/json') }, 'rig_robot.json'),
        formats.map((f) => {
          const b = h('button', { type: 'button', id: `rig-robot-export-${f}` }, f);
          b.addEventListener('click', async () => {
            try {
              const files = await this.engine.call('exportFiles', { report: text, format: f });
              for (const file of files) download(file.name, file.text);
              fill(this.exportStatus, `${f}: ${files.map((file) => file.name).join(', ')}`);
            } catch (err) {
              fill(this.exportStatus, message('error', `${f}: ${err.message}`));
            }
          });
          return b;
        })),
      this.exportStatus);
  }
}
