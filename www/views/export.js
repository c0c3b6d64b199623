// Step 7: export. Every format is written by the Rust core (the same bytes
// as `robocal export`); this page previews, copies and downloads them.
import { $, h, fill, download, message } from '../lib/dom.js';
import { sessionStereo } from './rig-stereo.js';

const CAMERA_FORMATS = [
  ['json', 'robocal JSON', 'camera.json'],
  ['opencv-yaml', 'OpenCV YAML', 'camera.yaml'],
  ['opencv-xml', 'OpenCV XML', 'camera.xml'],
  ['ros-yaml', 'ROS camera_info', 'camera_info.yaml'],
  ['kalibr', 'Kalibr camchain', 'camchain.yaml'],
  ['mrcal', 'mrcal .cameramodel', 'camera.cameramodel'],
  ['halcon', 'Halcon parameters', 'camera_halcon.txt'],
  ['matlab', 'MATLAB (1-based)', 'camera.m'],
  ['text', '3×3 matrix', 'K.txt'],
];
// [format, label, file name ending]
const TRANSFORM_FORMATS = [
  ['matrix4', '4×4 matrix', 'txt'],
  ['xyz-quat-xyzw', 'xyz + quaternion (x y z w)', 'txt'],
  ['xyz-quat-wxyz', 'xyz + quaternion (w x y z)', 'txt'],
  ['urdf', 'URDF joint', 'joint.xml'],
  ['urdf-robot', 'URDF file', 'urdf'],
  ['ros1-static-tf', 'ROS 1 static_transform_publisher', 'sh'],
  ['ros1-launch', 'ROS 1 launch file', 'launch'],
  ['ros2-static-tf', 'ROS 2 static_transform_publisher', 'sh'],
  ['ros2-launch', 'ROS 2 launch file', 'launch.py'],
  ['ur', 'Universal Robots p[…]', 'txt'],
  ['kuka', 'KUKA frame {X…C}', 'txt'],
  ['abb-tooldata', 'ABB tooldata', 'mod'],
  ['abb-wobjdata', 'ABB wobjdata', 'mod'],
  ['fanuc', 'FANUC UTOOL/UFRAME', 'txt'],
];
/**
 * Frame names written into the URDF, ROS and controller exports, by role
 * (the parts of a transform's key: gripper_from_camera). robocal's camera
 * frame is the optical frame (z forward), hence camera_optical_frame.
 */
export const DEFAULT_FRAMES = { base: 'base_link', gripper: 'tool0', camera: 'camera_optical_frame', target: 'calibration_target' };
const FRAME_ROLES = [['base', 'Robot base'], ['gripper', 'Gripper / flange'], ['camera', 'Camera (optical frame)'], ['target', 'Target']];

export function frameNames(session) {
  return { ...DEFAULT_FRAMES, ...(session.handeye.frameNames || {}) };
}
const EULER_ORDERS = ['xyz', 'xzy', 'yxz', 'yzx', 'zxy', 'zyx', 'xyx', 'xzx', 'yxy', 'yzy', 'zxz', 'zyz'];

/** The report the exports read: camera keys, hand-eye transforms and the stereo right_from_left (a 2-camera rig's) at the top level. */
export function combinedReport(session) {
  const pair = sessionStereo(session);
  const stereo = pair ? { right_from_left: pair.right_from_left } : {};
  const frames = session.handeye.result ? { frame_names: frameNames(session) } : {};
  return { ...(session.camera.result || {}), ...(session.handeye.result || {}), ...stereo, ...frames };
}

export class ExportView {
  constructor(store, engine) {
    this.store = store;
    this.engine = engine;
    this.render();
    store.onChange((what) => { if (/result|all|shared/.test(what)) this.render(); });
  }

  transformsIn(report) {
    return ['gripper_from_camera', 'base_from_camera', 'base_from_target', 'gripper_from_target', 'right_from_left']
      .filter((k) => report[k] && report[k].matrix_row_major);
  }

  render() {
    const report = combinedReport(this.store.session);
    const hasCamera = !!report.camera_matrix;
    const transforms = this.transformsIn(report);
    if (!hasCamera && !transforms.length) {
      fill($('export-panel'), message('info', 'Solve a camera (step 3) or a hand-eye calibration (step 5) first: their results are exported here.'));
      return;
    }
    this.preview = h('pre', { class: 'export', id: 'export-preview', tabindex: 0, 'aria-label': 'export preview' });
    this.status = h('p', { class: 'hint', id: 'export-status', 'aria-live': 'polite' });
    const euler = h('div', { class: 'row' },
      h('label', {}, 'Euler ', h('select', { id: 'euler-kind' }, h('option', { value: 'extrinsic' }, 'extrinsic (fixed axes)'), h('option', { value: 'intrinsic' }, 'intrinsic (rotating axes)'))),
      h('select', { id: 'euler-order', 'aria-label': 'Euler axis order' }, EULER_ORDERS.map((o) => h('option', { value: o }, o.toUpperCase()))),
      h('select', { id: 'euler-unit', 'aria-label': 'angle unit' }, h('option', { value: 'deg' }, 'degrees'), h('option', { value: 'rad' }, 'radians')),
      h('button', { type: 'button', onclick: () => this.show(`euler-${$('euler-kind').value}-${$('euler-order').value}-${$('euler-unit').value}`, 'transform-euler.txt') }, 'Show Euler'));
    const transformPick = h('select', { id: 'export-transform', 'aria-label': 'transform to export' }, transforms.map((t) => h('option', { value: t }, t)));
    fill($('export-panel'),
      hasCamera ? h('div', {}, h('h3', {}, 'Camera'), h('div', { class: 'row', id: 'camera-formats' },
        CAMERA_FORMATS.map(([f, label, file]) => h('button', { type: 'button', dataset: { format: f }, onclick: () => this.show(f, file) }, label)))) : null,
      transforms.length ? h('div', {}, h('h3', {}, 'Transforms'), h('label', {}, 'Transform ', transformPick),
        this.frameFields(),
        h('div', { class: 'row', id: 'transform-formats' }, TRANSFORM_FORMATS.map(([f, label, ext]) => h('button', { type: 'button', dataset: { format: f }, onclick: () => this.show(f, `${$('export-transform').value}.${ext === 'txt' ? `${f}.txt` : ext}`) }, label))),
        euler) : null,
      h('div', { class: 'row' },
        h('button', { type: 'button', id: 'export-copy', onclick: () => this.copy() }, 'Copy to clipboard'),
        h('button', { type: 'button', id: 'export-download', onclick: () => this.save() }, 'Download'),
        h('button', { type: 'button', id: 'export-report', onclick: () => this.show('report', 'robocal-report.json') }, 'Full JSON report')),
      this.status, this.preview);
    this.show(hasCamera ? 'json' : 'matrix4', hasCamera ? 'camera.json' : 'transform.txt');
  }

  /** Editable frame names (tool0, camera_optical_frame, ...): the core writes them into the exports. */
  frameFields() {
    const names = frameNames(this.store.session);
    const fields = FRAME_ROLES.map(([role, label]) => {
      const input = h('input', { type: 'text', id: `frame-${role}`, value: names[role], spellcheck: 'false', autocomplete: 'off', size: 18 });
      input.addEventListener('change', () => {
        this.store.session.handeye.frameNames = { ...frameNames(this.store.session), [role]: input.value.trim() || DEFAULT_FRAMES[role] };
        this.store.changed('frame-names');
        if (this.format) this.show(this.format, this.fileName);
      });
      return h('label', {}, `${label} `, input);
    });
    return h('fieldset', { id: 'frame-names', class: 'frame-names' }, h('legend', {}, 'Frame names in URDF, ROS and robot exports'), fields,
      h('p', { class: 'hint' }, 'The camera frame of every result is the optical frame (z forward, x right, y down): in ROS that is a *_optical_frame, not camera_link (x forward).'));
  }

  async show(format, fileName) {
    this.format = format;
    const report = JSON.stringify(combinedReport(this.store.session));
    const transform = $('export-transform') ? $('export-transform').value : '';
    try {
      this.text = await this.engine.call('export', { report, format, transform });
      this.fileName = fileName;
      this.preview.textContent = this.text;
      this.status.textContent = `${format}: ${this.text.length} bytes, written by the robocal core (identical to 'robocal export --format ${format}').`;
    } catch (err) {
      this.text = null;
      this.preview.textContent = '';
      this.status.textContent = err.message;
    }
  }

  async copy() {
    if (!this.text) return;
    try {
      await navigator.clipboard.writeText(this.text);
      this.status.textContent = 'Copied to the clipboard.';
    } catch (err) {
      this.status.textContent = `The browser refused the clipboard (${err.message}); use Download instead.`;
    }
  }

  save() {
    if (this.text) download(this.fileName, this.text);
  }
}
