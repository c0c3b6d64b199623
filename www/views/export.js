// Step 7: export. Every format is written by the Rust core (the same bytes
// as `robocal export`); this page previews, copies and downloads them.
import { $, h, fill, download, message } from '../lib/dom.js';

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
const TRANSFORM_FORMATS = [
  ['matrix4', '4×4 matrix'],
  ['xyz-quat-xyzw', 'xyz + quaternion (x y z w)'],
  ['xyz-quat-wxyz', 'xyz + quaternion (w x y z)'],
  ['urdf', 'URDF joint'],
  ['ros2-static-tf', 'ROS 2 static_transform_publisher'],
  ['ur', 'Universal Robots p[…]'],
  ['kuka', 'KUKA frame {X…C}'],
  ['abb-tooldata', 'ABB tooldata'],
  ['abb-wobjdata', 'ABB wobjdata'],
  ['fanuc', 'FANUC UTOOL/UFRAME'],
];
const EULER_ORDERS = ['xyz', 'xzy', 'yxz', 'yzx', 'zxy', 'zyx', 'xyx', 'xzx', 'yxy', 'yzy', 'zxz', 'zyz'];

/** The report the exports read: camera keys, hand-eye transforms and the stereo right_from_left at the top level. */
export function combinedReport(session) {
  const stereo = session.stereo && session.stereo.result ? { right_from_left: session.stereo.result.right_from_left } : {};
  return { ...(session.camera.result || {}), ...(session.handeye.result || {}), ...stereo };
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
        h('div', { class: 'row', id: 'transform-formats' }, TRANSFORM_FORMATS.map(([f, label]) => h('button', { type: 'button', dataset: { format: f }, onclick: () => this.show(f, `${$('export-transform').value}.${f}.txt`) }, label))),
        euler) : null,
      h('div', { class: 'row' },
        h('button', { type: 'button', id: 'export-copy', onclick: () => this.copy() }, 'Copy to clipboard'),
        h('button', { type: 'button', id: 'export-download', onclick: () => this.save() }, 'Download'),
        h('button', { type: 'button', id: 'export-report', onclick: () => this.show('report', 'robocal-report.json') }, 'Full JSON report')),
      this.status, this.preview);
    this.show(hasCamera ? 'json' : 'matrix4', hasCamera ? 'camera.json' : 'transform.txt');
  }

  async show(format, fileName) {
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
