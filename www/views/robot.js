// Step 4: robot poses. Load a pose table, or several files of one pose each
// (ROS YAML, JSON, text: read by one wasm call, paired with the images by
// file stem); see how they were read (format, units, direction: editable,
// with vendor presets), the parsed poses, and which pose goes with which
// image.
import { $, h, fill, table, num, message, readTextFile, dropTarget } from '../lib/dom.js';

export const PRESETS = [
  ['auto', 'Detect from the file'],
  ['ur', 'Universal Robots (x y z rx ry rz: m, rotation vector)'],
  ['kuka', 'KUKA (X Y Z A B C: mm, deg)'],
  ['abb', 'ABB (x y z q1 q2 q3 q4: mm, quaternion w first)'],
  ['fanuc', 'FANUC (X Y Z W P R: mm, deg)'],
  ['yaskawa', 'Yaskawa / Motoman (X Y Z Rx Ry Rz: mm, deg)'],
  ['staubli', 'Stäubli (X Y Z Rx Ry Rz: mm, deg)'],
  ['xyz_quat_xyzw', 'Generic x y z qx qy qz qw'],
  ['xyz_quat_wxyz', 'Generic x y z qw qx qy qz'],
  ['xyz_rotvec', 'Generic x y z + rotation vector'],
  ['matrix4', '4×4 matrices (16 numbers a row)'],
  ['matrix3x4', '3×4 matrices (12 numbers a row: r11 r12 r13 tx … tz)'],
  ...['extrinsic', 'intrinsic'].flatMap((kind) => ['xyz', 'xzy', 'yxz', 'yzx', 'zxy', 'zyx', 'xyx', 'xzx', 'yxy', 'yzy', 'zxz', 'zyz']
    .map((order) => [`xyz_euler_${kind}_${order}`, `Euler x y z + ${order} ${kind === 'extrinsic' ? 'about fixed axes' : 'about moving axes'}`])),
];

/** The files of a dropped folder read as poses. */
const POSE_FILE = /\.(csv|tsv|txt|json|dat|ya?ml)$/i;

/** What the page reads as one pose per file when loaded alone. */
const ONE_POSE_FILE = /\.(ya?ml)$/i;

/** The forms the step reads, for its hint. */
const FORMS_HINT = 'A pose table (CSV, TSV, text or JSON: a header such as x,y,z,qx,qy,qz,qw, X,Y,Z,A,B,C, x_mm,…,rx_deg,… or r11,…,tz, or 6, 7, 12 or 16 numbers a line), '
  + 'or several files of one pose each (choose them together: ROS YAML position/orientation, JSON, a 4×4 or 3×4 matrix as text), each paired with the image of the same file stem. '
  + 'rx ry rz in degrees are read as Euler angles about the fixed x, y, z axes (R = Rz·Ry·Rx); choose another format above for another convention.';

function rotvecDeg(q) {
  const [x, y, z, w] = q;
  const s = Math.hypot(x, y, z);
  const angle = 2 * Math.atan2(s, w);
  const k = s < 1e-12 ? 2 : angle / s;
  return [x * k, y * k, z * k].map((v) => (v * 180) / Math.PI);
}

/**
 * Read a pose source ({text} a pose table, or {files: [{name, text}]} one
 * pose each) with the worker under `options` (format, units, direction):
 * `{reading, parsed, error}`; `parsed` is the reading's poses, or its most
 * plausible candidate when the layout is ambiguous.
 */
export async function readPoseSource(engine, source, options) {
  try {
    const o = JSON.stringify(options);
    const reading = source.files && source.files.length
      ? await engine.call('poseFiles', { files: JSON.stringify(source.files), options: o })
      : await engine.call('poses', { text: source.text, options: o });
    const parsed = reading.parsed || (reading.candidates[0] ? { ...reading.candidates[0], notes: [] } : null);
    return { reading, parsed, error: null };
  } catch (err) {
    return { reading: null, parsed: null, error: err.message };
  }
}

/**
 * Chosen files as read poses: one file is a pose table (a .yaml/.yml file,
 * or a file the table reader refuses but the one-pose reader takes, is one
 * pose); several are one pose each. A file that is not text is named.
 * Returns `{fileName, text, files, reading, parsed, error}` (the robot
 * step's state; the rig step's rig on a robot reads its poses the same way).
 */
export async function loadPoseFiles(engine, chosen, options) {
  const many = chosen.length > 1 || ONE_POSE_FILE.test(chosen[0].name);
  const fileName = chosen.length > 1 ? `${chosen.length} pose files` : chosen[0].name;
  const files = [];
  try {
    for (const f of chosen) files.push({ name: f.name, text: await readTextFile(f, many ? 'one robot pose' : 'one robot pose a line, one per image').catch((err) => { throw new Error(chosen.length > 1 ? `'${f.name}': ${err.message}` : err.message); }) });
  } catch (err) {
    // Nothing of these files is used: the poses of earlier files are not
    // shown under their names.
    return { fileName, text: '', files: null, reading: null, parsed: null, error: err.message };
  }
  const source = many ? { text: null, files } : { text: files[0].text, files: null };
  const read = await readPoseSource(engine, source, options);
  // A single file the table reader refuses may be one pose: a JSON object
  // or `key: value` lines (a ROS pose as JSON, a YAML saved as .txt).
  if (!many && read.error && /^\s*\{|^\s*[A-Za-z_][\w ]*:/m.test(files[0].text)) {
    const one = await readPoseSource(engine, { files }, options);
    if (!one.error) return { fileName, text: null, files, ...one };
  }
  return { fileName, ...source, ...read };
}

export class RobotView {
  constructor(store, engine) {
    this.store = store;
    this.engine = engine;
    this.render();
    store.onChange((what) => { if (/detections|included|images|all/.test(what)) this.renderPairing(); });
    // Pose files (or a folder of them) dropped anywhere on the step: read as if chosen together.
    dropTarget($('step-robot'), (files) => this.load(files), (name) => POSE_FILE.test(name));
  }

  get state() { return this.store.session.robot; }

  render() {
    const st = this.state;
    const sel = (id, items, value, label) => h('label', {}, label, h('select', { id }, items.map(([v, t]) => h('option', { value: v, selected: v === value }, t))));
    // The native file field would say "No file chosen" once a file is read
    // (and after a reload): a button opens it, and the loaded file is named.
    const input = h('input', { type: 'file', id: 'pose-input', 'aria-label': 'pose files', multiple: true, accept: '.csv,.tsv,.txt,.json,.dat,.yaml,.yml,text/*,application/json', hidden: true, tabindex: -1 });
    const fileName = h('span', { id: 'pose-file-name' }, st.fileName ? `loaded: ${st.fileName}` : 'no file loaded');
    input.addEventListener('change', async () => {
      const chosen = [...input.files];
      if (!chosen.length) return;
      input.value = '';
      await this.load(chosen);
    });
    const form = h('div', { class: 'form', id: 'pose-form' },
      h('div', { class: 'row file-row' }, h('span', {}, 'Pose file'),
        h('button', { type: 'button', id: 'pose-choose', 'aria-describedby': 'pose-file-name', onclick: () => input.click() }, 'Choose pose file(s)…'), fileName, input,
        h('span', { class: 'hint' }, 'or drop pose files (or a folder of them) on this step')),
      h('p', { class: 'hint', id: 'pose-forms' }, FORMS_HINT),
      sel('pose-format', PRESETS, st.format, 'Format '),
      sel('pose-length', [['auto', 'from the file or preset'], ['mm', 'millimetres'], ['m', 'metres']], st.lengthUnit, 'Lengths '),
      sel('pose-angle', [['auto', 'from the file or preset'], ['deg', 'degrees'], ['rad', 'radians']], st.angleUnit, 'Angles '),
      sel('pose-direction', [['base_from_gripper', 'base_from_gripper (TCP pose in base: usual)'], ['gripper_from_base', 'gripper_from_base (inverted)']], st.direction, 'The file holds '));
    form.addEventListener('change', (e) => {
      if (e.target.id === 'pose-input') return;
      st.format = $('pose-format').value;
      st.lengthUnit = $('pose-length').value;
      st.angleUnit = $('pose-angle').value;
      st.direction = $('pose-direction').value;
      this.parse();
    });
    this.out = h('div', { id: 'pose-results', 'aria-live': 'polite' });
    this.pairing = h('div', { id: 'pose-pairing' });
    fill($('robot-panel'), form, this.out, h('h3', {}, 'Pairing of poses with images'), this.pairing);
    this.show();
  }

  /** Load chosen files (see loadPoseFiles), then show them. */
  async load(chosen) {
    Object.assign(this.state, await loadPoseFiles(this.engine, chosen, this.options()));
    this.store.changed('robot');
    $('pose-file-name').textContent = `loaded: ${this.state.fileName}`;
    this.show();
  }

  options() {
    const st = this.state;
    const o = { direction: st.direction };
    if (st.format !== 'auto') o.format = st.format;
    if (st.lengthUnit !== 'auto') o.length_unit = st.lengthUnit;
    if (st.angleUnit !== 'auto') o.angle_unit = st.angleUnit;
    return o;
  }

  async parse() {
    const st = this.state;
    if (!st.text && !(st.files && st.files.length)) return;
    Object.assign(st, await readPoseSource(this.engine, st, this.options()));
    this.store.changed('robot');
    this.show();
  }

  show() {
    const st = this.state;
    // One-pose-file errors name the file themselves.
    if (st.error) { fill(this.out, message('error', st.files ? st.error : `${st.fileName}: ${st.error}`)); this.renderPairing(); return; }
    if (!st.parsed) { fill(this.out, message('info', 'Load the robot\'s poses (one per image, in image order or with a name column, or one file per image named as the image).')); this.renderPairing(); return; }
    const p = st.parsed;
    const r = st.reading;
    const how = h('p', { id: 'pose-format-used' }, `${st.fileName}: ${p.poses.length} poses read as `, h('b', {}, p.format), `, lengths in ${p.length_unit}, angles in ${p.angle_unit}, the file holds ${st.direction}.`);
    const notes = (p.notes || []).map((n) => message('info', n));
    let candidates = null;
    if (r && !r.parsed && r.candidates.length) {
      const pick = h('select', { id: 'pose-candidate', 'aria-label': 'reading of the pose file' },
        r.candidates.map((c, i) => h('option', { value: i }, `${c.format}, ${c.length_unit}, ${c.angle_unit}${c.reasons.length ? ' — ' + c.reasons.join('; ') : ''}`)));
      pick.addEventListener('change', () => { st.parsed = { ...r.candidates[Number(pick.value)], notes: [] }; this.store.changed('robot'); this.show(); });
      const check = h('button', { type: 'button', id: 'check-conventions', onclick: () => this.checkConventions(check) }, 'Check the readings against the camera motion');
      candidates = h('div', {}, message('warning', `The file's layout is ambiguous (${r.ambiguity}). The most plausible reading is used; choose another below, or set the format.`), h('label', {}, 'Reading ', pick), h('div', { class: 'row' }, check), h('div', { id: 'convention-result', 'aria-live': 'polite' }));
    }
    const rows = p.poses.map((pose, i) => {
      const t = pose.base_from_gripper.translation_m.map((v) => num(v * 1000, 2));
      const rv = rotvecDeg(pose.base_from_gripper.quaternion_xyzw).map((v) => num(v, 3));
      return [String(i + 1), pose.name || '', String(pose.line), ...t, ...rv];
    });
    fill(this.out, how, notes, candidates,
      table(['#', 'name', 'line', 'x (mm)', 'y (mm)', 'z (mm)', 'rx (deg)', 'ry (deg)', 'rz (deg)'], rows, { id: 'pose-table', class: 'scroll' }),
      h('p', { class: 'hint' }, 'Rotations shown as rotation vectors in degrees (axis × angle) whatever the file\'s convention.'));
    this.renderPairing();
  }

  /** Score every candidate reading against the camera motion (hand-eye consistency). */
  async checkConventions(button) {
    const out = $('convention-result');
    const cam = this.store.session.camera.result;
    if (!cam) { fill(out, message('info', 'Solve the camera first (step 3): the check compares robot motion with camera motion.')); return; }
    const views = new Map((cam.views || []).map((v) => [v.name, v]));
    const r = this.state.reading;
    const pairs = this.pairs().filter((p) => p.image && p.image.included && views.has(p.image.name));
    const idx = pairs.map((p) => p.index);
    const input = {
      setup: this.store.session.handeye.setup,
      candidates: r.candidates.map((c) => ({
        name: `${c.format}, ${c.length_unit}, ${c.angle_unit}`,
        base_from_gripper: idx.map((i) => c.poses[i].base_from_gripper),
      })),
      camera_from_target: pairs.map((p) => ({ matrix_row_major: views.get(p.image.name).camera_from_target.matrix_row_major })),
    };
    button.disabled = true;
    try {
      const ranked = await this.engine.call('conventions', { input: JSON.stringify(input) });
      fill(out, ranked.recommendation ? message('info', ranked.recommendation) : null,
        table(['reading', 'rotation RMS (deg)', 'translation RMS (mm)'], ranked.scores.map((s) => [s.name,
          s.consistency ? num(s.consistency.rotation_rms_deg, 4) : 'failed', s.consistency ? num(s.consistency.translation_rms_mm, 3) : ''])));
    } catch (err) {
      fill(out, message('error', err.message));
    } finally {
      button.disabled = false;
    }
  }

  /**
   * Poses paired with images: by name when the file names images, else by
   * position in step 2's order (pose i with the i-th image). An excluded or
   * failed image keeps its pose (it is not used): excluding a view never
   * shifts the pairing of the others; removing the image does.
   *
   * A name matches an image as `robocal handeye` matches it
   * (robocal::io::pose_pairing), on the file name since the page has no
   * folders: the same file name (`images/0.png` and `C:\cell\0.png` match
   * `0.png`), else the same stem (`0` matches `0.png`). A row naming no
   * image, a name matching two images and two rows naming one image are
   * problems: `problem` says which, and the hand-eye step refuses to solve.
   */
  pairs() {
    const p = this.state.parsed;
    if (!p) return [];
    const imgs = this.store.session.images;
    const byName = p.poses.some((q) => q.name);
    if (!byName) return p.poses.map((pose, i) => ({ index: i, pose, image: imgs[i] || null, how: 'order', problem: null }));
    const base = (s) => String(s).trim().replace(/\\/g, '/').split('/').pop();
    const stem = (s) => base(s).replace(/(.)\.[^.]*$/, '$1');
    const pairs = p.poses.map((pose, i) => {
      if (!pose.name) return { index: i, pose, image: null, how: 'name', problem: 'names no image (name an image on every row, or on none to pair by order)' };
      const name = base(pose.name);
      let found = imgs.filter((im) => im.name === name);
      if (!found.length) found = imgs.filter((im) => stem(im.name) === stem(name) || stem(im.name) === name);
      if (found.length > 1) return { index: i, pose, image: null, how: 'name', problem: `'${pose.name}' matches ${found.map((im) => `'${im.name}'`).join(' and ')}` };
      return { index: i, pose, image: found[0] || null, how: 'name', problem: found.length ? null : `no image named '${pose.name}'` };
    });
    for (const q of pairs) {
      if (!q.image) continue;
      const same = pairs.filter((o) => o.image === q.image);
      if (same.length > 1) q.problem = `rows ${same.map((o) => o.pose.line).join(', ')} all name '${q.image.name}'`;
    }
    return pairs;
  }

  /**
   * The pairing's problems as one message (null when there are none), in
   * the words of `robocal handeye`.
   */
  pairingProblem() {
    const pairs = this.pairs();
    const bad = pairs.filter((q) => q.problem);
    if (!bad.length) return null;
    const missing = bad.filter((q) => !q.image && /^no image named/.test(q.problem));
    const list = (qs, f) => qs.slice(0, 5).map(f).join(', ') + (qs.length > 5 ? ` and ${qs.length - 5} more` : '');
    if (missing.length) {
      return `pairing: ${missing.length} of ${pairs.length} poses name no image that was loaded: ${list(missing, (q) => `row ${q.pose.line} '${q.pose.name}'`)}: load those images, or remove their rows from the pose file`;
    }
    const twice = bad.filter((q) => q.image);
    if (twice.length) {
      const seen = [...new Set(twice.map((q) => q.problem))];
      return `pairing: two poses name the same image: ${list(seen, (t) => t)}: each image pairs with one robot pose; fix the image column`;
    }
    return `pairing: ${list(bad, (q) => `row ${q.pose.line} ${q.problem}`)}`;
  }

  renderPairing() {
    if (!this.pairing) return;
    const pairs = this.pairs();
    if (!pairs.length) { fill(this.pairing, h('p', { class: 'hint' }, 'No poses yet.')); return; }
    const used = pairs.filter((q) => q.image && q.image.included && q.image.detection).length;
    const nImages = this.store.session.images.length;
    const rows = pairs.map((q) => [String(q.index + 1), q.pose.name || '', q.image ? q.image.name : '—',
      q.problem ? `not used: ${q.problem}` : !q.image ? 'no image' : !q.image.info ? 'dropped: the image could not be read' : !q.image.detection ? 'dropped: the target was not found in the image' : q.image.included ? 'used' : 'dropped: the image is excluded in step 2']);
    const warn = pairs.length !== nImages ? message('warning', `${pairs.length} poses but ${nImages} images: pairing ${pairs[0].how === 'name' ? 'by name' : 'by order'} leaves some unpaired. Check that the pose file matches the images.`) : null;
    const problem = this.pairingProblem();
    fill(this.pairing, problem ? message('error', problem) : null, h('p', {}, `Paired ${pairs[0].how === 'name' ? 'by the name column' : 'by order (pose i with the i-th image of step 2)'}: ${used} pairs usable.`), warn,
      table(['pose', 'name', 'image', 'status'], rows, { id: 'pairing-table' }));
  }
}
