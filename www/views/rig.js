// Step 7, stereo pairs and camera rigs: 2 to N cameras that saw the target
// of step 1 in synchronised frames, any camera missing the board in any
// frame. Frames are grouped by the rules of `robocal rig --group-by` (the
// last number in each file name, or by order when no name has one; or the
// first number, the last, the order, or a pattern such as sync(\d+), chosen
// in the "Frames from file names" field); detection per camera in
// the worker, then one joint calibration (`calibrate_rig`, the core of
// `robocal rig`) with the lens model and held parameters of the camera step.
// Shows every camera_from_rig with its standard deviation, per-camera and
// per-frame residuals, the co-observation graph, a 3-D view of the rig and
// the rig exports; two cameras are also shown as the stereo pair
// (right_from_left, exported in step 8). Each camera's intrinsics are solved
// with the rig or held (from a camera file or its own calibration:
// rig-intrinsics.js); a solved rig can be put on a robot (rig-robot.js).
// Images, detections and the result are kept in the session.
import { h, fill, table, num, message, download } from '../lib/dom.js';
import { FrameView } from '../lib/view3d.js';
import { targetSpec } from './target.js';
import { lensFields, readLens, jsonOptions } from './lens.js';
import { stereoOfRig, stereoOfLegacy, stereoSection } from './rig-stereo.js';
import { frustum, invert, rotvecDeg, boardOutline, apply, flat } from '../lib/rig3d.js';
import { intrinsicsControl, heldCamera, driftCamera, driftHint } from './rig-intrinsics.js';
import { RigRobot } from './rig-robot.js';
import { RigVideos, rigGrouping } from './rig-video.js';

/** Frames a rig solve needs (each camera's intrinsics need 3 views: api::camera::MIN_VIEWS). */
const MIN_FRAMES = 3;
const byName = (a, b) => a.name.localeCompare(b.name, undefined, { numeric: true });
/** The rules of `robocal rig --group-by` ('' = by number unless no name has one). */
const GROUP_RULES = [
  ['', 'automatic: the last number, or order'],
  ['number', 'the last number (number)'],
  ['first', 'the first number (first)'],
  ['order', 'order (sorted names)'],
  ['pattern', 'a pattern with one (\\d+)'],
];
const groupedText = (rule) => ({
  number: 'by the number in the file names',
  last: 'by the last number in the file names',
  first: 'by the first number in the file names',
  order: 'by order (sorted names)',
  sync_index: 'by the timestamps\' sync_index (video frames)',
  'frame index': 'by frame index (video frames)',
})[rule] || `by the pattern ${rule} in the file names`;
const freeName = (cams) => { let k = 0; while (cams.some((c) => c.name === `cam${k}`)) k++; return `cam${k}`; };

export class RigView {
  constructor(store, engine, panel) {
    this.store = store;
    this.engine = engine;
    this.panel = panel;
    this.grouping = { error: null, frames: [], keys: [] };
    this.robot = new RigRobot(store, engine, () => this.rigInput());
    this.videos = new RigVideos(this);
    this.render();
  }

  get state() {
    const st = this.store.session.rig || (this.store.session.rig = { model: 'brown', result: null, cameras: [] });
    while (st.cameras.length < 2) st.cameras.push({ name: freeName(st.cameras), files: [] });
    return st;
  }

  render() {
    const st = this.state;
    const lens = lensFields(st, 'rig');
    const form = h('form', { class: 'form', id: 'rig-lens' }, lens.model, lens.brown, lens.spline, lens.options);
    form.addEventListener('change', () => { readLens(st, form); this.store.changed('rig'); });
    form.addEventListener('submit', (e) => e.preventDefault());
    this.camerasOut = h('div', { id: 'rig-cameras', class: 'form' });
    this.solveButton = h('button', { type: 'button', class: 'primary', id: 'rig-solve', disabled: true }, 'Detect and solve the rig');
    this.solveButton.addEventListener('click', () => this.solve());
    this.framesOut = h('div', { id: 'rig-frames' });
    const rule = GROUP_RULES.some(([v]) => v === (st.groupBy || '')) ? (st.groupBy || '') : 'pattern';
    const groupSelect = h('select', { id: 'rig-group-by', 'aria-label': 'Frames from file names' },
      ...GROUP_RULES.map(([v, label]) => h('option', { value: v, selected: v === rule }, label)));
    const pattern = h('input', { type: 'text', id: 'rig-group-pattern', value: rule === 'pattern' ? st.groupBy : 'sync(\\d+)', spellcheck: 'false', 'aria-label': 'Pattern with one (\\d+)', hidden: rule !== 'pattern' });
    const regroup = () => {
      const v = groupSelect.value;
      pattern.hidden = v !== 'pattern';
      st.groupBy = v === 'pattern' ? pattern.value : v;
      this.store.changed('rig');
      this.showFrames();
    };
    groupSelect.addEventListener('change', regroup);
    pattern.addEventListener('change', regroup);
    const grouping = h('div', { class: 'row', id: 'rig-grouping-rule' },
      h('label', { for: 'rig-group-by' }, 'Frames from file names'), groupSelect, pattern);
    this.progress = h('p', { id: 'rig-progress', class: 'hint', 'aria-live': 'polite' });
    this.out = h('div', { id: 'rig-results', 'aria-live': 'polite' });
    this.robotOut = h('div', { id: 'rig-robot-part' });
    fill(this.panel,
      h('p', { class: 'hint' }, 'Two or more cameras that saw the target of step 1 at the same moments: a stereo pair is a rig of two. Any camera may miss the board in any frame, but every camera must share frames with the others, directly or through other cameras. Images are grouped into frames as robocal rig groups them: by the last number in their names (left01.jpg with right1.jpg, front07.png with side7.jpg), or by order (sorted names) when no name has a number. Choose another rule when the last number is not the frame\'s: the first number (sync036_cam0.jpg), order, or a pattern: plain text with one (\\d+), such as sync(\\d+) for sync036_cam0.jpg with cam1_sync36.png. The rig frame is the first camera\'s. Each camera\'s intrinsics are solved with the rig, or held: from a camera file (robocal JSON, OpenCV YAML/XML, ROS camera_info; robocal rig --camera-file NAME=FILE) or from its own calibration (its images alone), the fix when the joint fit drags a camera\'s intrinsics away from what its own images say. Once solved, the rig can be put on a robot: a robot pose file, one pose per frame, gives gripper_from_rig or base_from_rig (robocal rig --setup … --poses FILE).'),
      this.camerasOut,
      h('div', { class: 'row' }, h('button', { type: 'button', id: 'rig-add', onclick: () => this.addCamera() }, 'Add a camera')),
      this.videos.element(),
      grouping,
      h('details', { id: 'rig-lens-details', open: st.model !== 'brown' || st.radial === '2' || st.tangential === false },
        h('summary', {}, 'Lens model and held parameters (every solved camera)'),
        h('p', { class: 'hint' }, 'As in step 3. Kalibr\'s radtan model is k1 k2 p1 p2: choose Brown-Conrady with 2 radial terms to export the rig to Kalibr.'),
        form),
      h('div', { class: 'row' }, this.solveButton, h('button', { type: 'button', id: 'rig-clear', onclick: () => this.clear() }, 'Remove the rig images')),
      this.progress, this.framesOut, this.out, this.robotOut);
    this.showCameras();
    this.showFrames();
    if (st.result) this.show(st.result);
    else this.showLegacy();
  }

  /** An earlier session's stereo result (before the rig step): shown until the rig is solved. */
  showLegacy() {
    const s = stereoOfLegacy(this.store.session.stereo && this.store.session.stereo.result);
    if (s) fill(this.out, stereoSection(s, 'Stereo pair (solved by the stereo step of an earlier version; solve the rig to replace it)'));
  }

  showCameras() {
    const cams = this.state.cameras;
    fill(this.camerasOut, cams.map((c, k) => {
      const name = h('input', { type: 'text', id: `rig-name-${k}`, value: c.name, size: 10, 'aria-label': `camera ${k + 1} name` });
      name.addEventListener('change', () => { c.name = name.value.trim(); this.store.changed('rig'); this.showFrames(); });
      const files = h('input', { type: 'file', id: `rig-input-${k}`, multiple: true, accept: 'image/*,.pgm,.ppm,.pnm,.tif,.tiff,.bmp' });
      files.addEventListener('change', () => { this.addFiles(c, [...files.files]); files.value = ''; });
      const remove = cams.length > 2 ? h('button', { type: 'button', id: `rig-remove-${k}`, onclick: () => this.removeCamera(k) }, 'Remove this camera') : null;
      const intrinsics = intrinsicsControl(c, k, this.engine, () => this.store.changed('rig'));
      return h('div', { class: 'row rig-camera' }, h('label', {}, `Camera ${k + 1} `, name), h('label', {}, 'images ', files), h('span', { class: 'hint', id: `rig-count-${k}` }, `${c.files.length} image${c.files.length === 1 ? '' : 's'}`), intrinsics, remove);
    }));
  }

  addCamera() {
    this.state.cameras.push({ name: freeName(this.state.cameras), files: [] });
    this.store.changed('rig');
    this.showCameras();
    this.showFrames();
  }

  async removeCamera(k) {
    const [gone] = this.state.cameras.splice(k, 1);
    await this.store.deleteBytes(gone.files.map((f) => f.id));
    this.store.changed('rig');
    this.showCameras();
    this.showFrames();
  }

  async addFiles(camera, files) {
    for (const f of files) {
      const id = `rig-${Date.now().toString(36)}-${Math.random().toString(36).slice(2, 8)}`;
      await this.store.putBytes(id, await f.arrayBuffer());
      camera.files.push({ id, name: f.name, detection: null, error: null, spec: null });
    }
    camera.files.sort(byName);
    this.store.changed('rig');
    this.showCameras();
    this.showFrames();
  }

  async clear() {
    await this.store.deleteBytes(this.state.cameras.flatMap((c) => c.files.map((f) => f.id)));
    for (const c of this.state.cameras) c.files = [];
    this.state.result = null;
    this.store.changed('rig');
    fill(this.out);
    fill(this.robotOut);
    this.showCameras();
    this.showFrames();
  }

  /** The cameras' names, or an error naming what to fix. */
  namesError() {
    const names = this.state.cameras.map((c) => c.name);
    if (names.some((n) => !n)) return 'every camera needs a name';
    const twice = names.find((n, i) => names.indexOf(n) !== i);
    return twice ? `two cameras are named '${twice}': give each camera its own name` : null;
  }

  async showFrames() {
    const asked = (this.asked = (this.asked || 0) + 1);
    this.solveButton.disabled = true;
    const cams = this.state.cameras;
    if (!cams.some((c) => c.files.length)) {
      this.grouping = { error: null, frames: [], keys: [] };
      fill(this.framesOut, message('info', 'Load each camera\'s images (add cameras for a rig of more than two).'));
      return;
    }
    let grouping;
    const named = this.namesError();
    try {
      if (named) throw new Error(named);
      const g = await rigGrouping(this.engine, cams, this.state.groupBy || '', this.state.videoGrouping);
      grouping = { ...g, error: null };
    } catch (err) {
      grouping = { error: err.message, frames: [], keys: [] };
    }
    if (asked !== this.asked) return;
    this.grouping = grouping;
    if (grouping.error) {
      fill(this.framesOut, h('p', { id: 'rig-grouping', class: 'msg msg-error', role: 'alert' }, `The images cannot be grouped into frames: ${grouping.error}`));
      return;
    }
    const { frames, keys } = grouping;
    const empty = cams.filter((c) => !c.files.length).map((c) => c.name);
    const short = MIN_FRAMES - frames.length;
    this.solveButton.disabled = empty.length > 0 || short > 0;
    const status = (f) => (f.error ? `not found: ${f.error}` : f.detection ? `${f.detection.points.length} points` : 'not detected yet');
    const rows = frames.map((key) => [key, ...cams.map((c, k) => {
      const i = keys[k].indexOf(key);
      return i < 0 ? '—' : `${c.files[i].name}: ${status(c.files[i])}`;
    })]);
    fill(this.framesOut,
      h('p', { id: 'rig-grouping' }, `${frames.length} frame${frames.length === 1 ? '' : 's'} over ${cams.length} cameras, grouped ${groupedText(grouping.grouped_by)}.`),
      empty.length ? h('p', { id: 'rig-missing', class: 'msg msg-info', role: 'status' }, `Add images for camera ${empty.join(', ')} to solve.`) : null,
      short > 0 ? h('p', { id: 'rig-too-few', class: 'msg msg-info', role: 'status' }, `A rig calibration needs at least ${MIN_FRAMES} frames: add ${short} more frame${short === 1 ? '' : 's'} (an image of each camera, numbered alike) to solve.`) : null,
      table(['frame', ...cams.map((c) => c.name)], rows, { id: 'rig-frame-table', class: 'scroll' }));
  }

  async detect(file, spec) {
    if (file.spec === spec && (file.detection || file.error)) return;
    file.spec = spec;
    try {
      const bytes = this.store.bytes.get(file.id);
      if (!bytes) throw new Error('the image bytes were not found in this browser\'s storage; add the file again');
      const copy = bytes.slice(0);
      file.detection = await this.engine.call('detect', { bytes: copy, spec }, [copy]);
      file.error = null;
    } catch (err) {
      file.detection = null;
      file.error = err.message;
    }
  }

  /**
   * The calibrate_rig input of the detected views (each view keyed by its
   * frame), without held intrinsics; `spec` defaults to the target of step 1.
   */
  rigInput(spec = targetSpec(this.store.session.target)) {
    const { keys, grouped_by: groupedBy, error } = this.grouping;
    if (error || keys.length !== this.state.cameras.length) throw new Error(error || 'the images are not grouped into frames yet: wait for the frame table');
    return {
      model: this.state.model,
      options: jsonOptions(this.state),
      target: spec,
      grouping: groupedBy,
      cameras: this.state.cameras.map((c, k) => ({
        name: c.name,
        views: c.files.map((f, i) => ({ f, key: keys[k][i] })).filter(({ f }) => f.detection).map(({ f, key }) => ({ key, name: f.name, detection: f.detection })),
      })),
    };
  }

  /** Camera `k`'s intrinsics held from its own calibration, then the rig solved again. */
  async holdSolo(k) {
    this.state.cameras[k].intrinsics = 'solo';
    this.store.changed('rig');
    this.showCameras();
    await this.solve();
  }

  async solve() {
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch (err) { fill(this.out, message('error', err.message)); return; }
    const cams = this.state.cameras;
    this.solveButton.disabled = true;
    try {
      const total = cams.reduce((s, c) => s + c.files.length, 0);
      let done = 0;
      for (const c of cams) {
        for (const f of c.files) {
          this.progress.textContent = `detecting ${++done} of ${total}: ${c.name} ${f.name}`;
          await this.detect(f, spec);
        }
      }
      this.store.changed('rig');
      await this.showFrames();
      const input = this.rigInput(spec);
      const blind = input.cameras.find((c) => !c.views.length);
      if (blind) throw new Error(`the target was found in no image of camera ${blind.name}`); // as robocal rig says it
      // Held intrinsics (robocal rig --camera-file NAME=FILE): a camera
      // file's camera, or the camera's own calibration made now.
      for (const [k, c] of cams.entries()) {
        if ((c.intrinsics || 'solve') === 'solo') this.progress.textContent = `calibrating camera ${c.name} alone to hold its intrinsics…`;
        const held = await heldCamera(c, input.cameras[k], input.model, input.options, this.engine);
        if (held) input.cameras[k].camera = held;
      }
      this.showCameras();
      const used = input.cameras.reduce((s, c) => s + c.views.length, 0);
      this.progress.textContent = `detected ${total} images: the target in ${used}; solving…`;
      const result = await this.engine.call('rig', { input: JSON.stringify(input) });
      this.state.result = result;
      if (this.state.robot) this.state.robot.result = null; // the rig on a robot was of the earlier rig
      this.store.session.stereo = null; // an earlier session's stereo result is replaced by the rig's
      this.store.changed('rig-result');
      this.progress.textContent = `solved with ${used} views in ${result.frames.length} frames.`;
      await this.show(result);
    } catch (err) {
      this.progress.textContent = '';
      this.state.result = null; // the error replaces an earlier result, in the session too
      this.store.changed('rig-result');
      fill(this.robotOut);
      fill(this.out, h('p', { id: 'rig-error', class: 'msg msg-error', role: 'alert' }, err.message));
    } finally {
      this.solveButton.disabled = false;
    }
  }

  async show(r) {
    const mm = (v) => num(v * 1000, 3);
    const deg = (v) => num((v * 180) / Math.PI, 4);
    const extrinsics = r.cameras.map((c) => {
      const s = c.camera_from_rig_std;
      const rv = rotvecDeg(c.camera_from_rig.quaternion_xyzw);
      return [c.name, ...c.camera_from_rig.translation_m.map(mm), ...(s ? s.translation_m.map(mm) : ['—', '—', '—']),
        ...rv.map((v) => num(v, 4)), ...(s ? s.rotation_rad.map(deg) : ['—', '—', '—'])];
    });
    const cam = (c) => { const k = c.calibration.camera_matrix; return [c.name, num(k[0][0], 3), num(k[1][1], 3), num(k[0][2], 3), num(k[1][2], 3), c.intrinsics_held ? 'given' : 'solved', String(c.frames_seen.length), num(c.rms_px, 4)]; };
    const co = r.co_observation;
    const tree = new Set(co.spanning_tree.map(([a, b]) => `${Math.min(a, b)}-${Math.max(a, b)}`));
    const coRows = co.frames.map((row, i) => [co.cameras[i], ...row.map((n, j) => (i !== j && tree.has(`${Math.min(i, j)}-${Math.max(i, j)}`) ? `${n} (tree)` : String(n)))]);
    // Drawn at the width it is shown at (a phone's too), at most 900 px.
    const width = Math.max(300, Math.min(900, this.panel.clientWidth || 900));
    this.canvas = h('canvas', { id: 'rig-3d', width, height: Math.round(width * 0.62), role: 'img', 'aria-label': 'The rig in 3-D: each camera as a frustum, each frame\'s board as an outline' });
    this.exportsOut = h('div', { id: 'rig-exports' });
    const stereo = stereoOfRig(r);
    fill(this.out,
      stereo ? stereoSection(stereo, `Stereo pair: ${r.cameras[1].name} from ${r.cameras[0].name}`) : null,
      h('h3', { id: 'rig-summary' }, `${r.cameras.length} cameras, rig frame ${r.rig_frame}: RMS ${num(r.rms_px, 4)} px over ${r.frames.length} frames`),
      h('p', { class: 'hint' }, 'camera_from_rig: p_camera = R p_rig + T; the rotation as a rotation vector (axis times angle). Standard deviations from the joint covariance; the rotation\'s as a small-angle vector.'),
      table(['camera', 'T x (mm)', 'T y (mm)', 'T z (mm)', 'std x (mm)', 'std y (mm)', 'std z (mm)', 'rot x (deg)', 'rot y (deg)', 'rot z (deg)', 'std rx (deg)', 'std ry (deg)', 'std rz (deg)'], extrinsics, { id: 'rig-extrinsics', class: 'scroll' }),
      table(['camera', 'fx', 'fy', 'cx', 'cy', 'intrinsics', 'frames seen', 'RMS (px)'], r.cameras.map(cam), { id: 'rig-camera-table' }),
      h('h3', {}, 'Co-observation graph'),
      h('p', { class: 'hint' }, 'Frames in which both cameras saw the board (the diagonal: frames each camera saw); (tree): the pairs that chained the initial poses.'),
      table(['', ...co.cameras], coRows, { id: 'rig-coobservation' }),
      h('h3', {}, 'Frames'),
      table(['frame', 'cameras', 'RMS (px)'], r.frames.map((f) => [f.key, f.cameras.join(', '), num(f.rms_px, 4)]), { id: 'rig-frame-residuals', class: 'scroll' }),
      (r.warnings || []).map((w) => message('warning', w)),
      this.driftHints(r),
      h('h3', {}, 'The rig in 3-D'),
      this.canvas,
      h('h3', {}, 'Export'),
      this.exportsOut);
    fill(this.robotOut, this.robot.render(r));
    await this.draw3d(r);
    await this.showExports(r);
  }

  /** Under a drift warning, the per-camera control that holds that camera (rig-intrinsics.js). */
  driftHints(r) {
    return (r.warnings || []).map(driftCamera).filter(Boolean).map((name) => {
      const k = this.state.cameras.findIndex((c) => c.name === name);
      return k < 0 ? null : driftHint(name, k, () => this.holdSolo(k));
    });
  }

  async draw3d(r) {
    const view = new FrameView(this.canvas);
    let outline = null;
    try { outline = boardOutline((await this.engine.call('target', { spec: r.target })).points); } catch (e) { outline = null; }
    const frames = [];
    const shapes = [];
    for (const c of r.cameras) {
      const rigFromCamera = invert(c.camera_from_rig.matrix_row_major);
      frames.push({ name: c.name, matrix_row_major: rigFromCamera });
      shapes.push(...frustum(rigFromCamera, c.calibration.camera, 0.3));
    }
    for (const f of r.frames) {
      if (!f.rig_from_target) continue;
      frames.push({ name: '', matrix_row_major: flat(f.rig_from_target.matrix_row_major), size: 0.03 });
      if (outline) shapes.push({ color: '#8c564b', points: outline.map((p) => apply(f.rig_from_target.matrix_row_major, p)), closed: true });
    }
    view.set(frames, [], shapes);
    this.view3d = view;
  }

  async showExports(r) {
    const formats = await this.engine.call('rigFormats', {});
    const report = JSON.stringify(r);
    this.exportStatus = h('div', { id: 'rig-export-status', 'aria-live': 'polite' });
    fill(this.exportsOut,
      h('p', { class: 'hint' }, 'The rig report (the file robocal rig -o rig.json writes), and every rig export of robocal export rig.json --format NAME.'),
      h('div', { class: 'row' },
        h('button', { type: 'button', id: 'rig-export-json', onclick: () => download('rig.json', `${JSON.stringify(r, null, 2)}\n`, 'application/json') }, 'rig.json'),
        formats.map((format) => {
          const b = h('button', { type: 'button', id: `rig-export-${format}` }, format);
          b.addEventListener('click', async () => {
            try {
              const files = await this.engine.call('exportFiles', { report, format });
              for (const f of files) download(f.name, f.text);
              fill(this.exportStatus, `${format}: ${files.map((f) => f.name).join(', ')}`);
            } catch (err) {
              fill(this.exportStatus, message('error', `${format}: ${err.message}`));
            }
          });
          return b;
        })),
      this.stereoExports(r),
      this.exportStatus);
  }

  /** A rig of two as a stereo pair (robocal stereo's report: left, right, right_from_left) in the stereo formats of robocal export. */
  stereoExports(r) {
    if (!stereoOfRig(r)) return null;
    const [left, right] = r.cameras;
    const report = JSON.stringify({ left: left.calibration, right: right.calibration, right_from_left: right.camera_from_rig, rms_px: r.rms_px });
    return h('div', { class: 'row', id: 'rig-stereo-exports' },
      h('span', { class: 'hint' }, `As a stereo pair (left ${left.name}, right ${right.name}; x_right = R x_left + T):`),
      [['opencv-yaml', 'OpenCV stereo YAML (K1 D1 K2 D2 R T E F, R1 R2 P1 P2 Q)'], ['ros', 'ROS left.yaml + right.yaml (rectified)'], ['kalibr', 'Kalibr camchain (cam0, cam1)']].map(([format, label]) => {
        const b = h('button', { type: 'button', id: `rig-export-stereo-${format}` }, label);
        b.addEventListener('click', async () => {
          try {
            const files = await this.engine.call('exportFiles', { report, format });
            for (const f of files) download(f.name.startsWith('stereo') ? f.name : `stereo_${f.name}`, f.text);
            fill(this.exportStatus, `stereo ${format}: ${files.map((f) => f.name).join(', ')}`);
          } catch (err) {
            fill(this.exportStatus, message('error', `stereo ${format}: ${err.message}`));
          }
        });
        return b;
      }));
  }
}
