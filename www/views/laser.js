// Step 11: a laser-line (sheet-of-light) sensor. Images of step 1's board
// with the laser stripe on it, at two or more poses, and the calibrated
// camera (step 3's, or a camera file) give the laser plane in the camera
// frame (laser_plane, docs/laser.md): its normal, distance and their std
// from the covariance, the residuals per image and the warnings when the
// poses do not constrain it. Every image is shown with the stripe's centres
// drawn on it; the plane exports as robocal JSON, HALCON sheet-of-light
// parameters and a URDF / ROS static TF frame (export_report, the bytes of
// `robocal export`). Images stay in this tab; the plane report is kept in
// the session.
import { $, h, fill, table, num, fixed, message, download, readTextFile } from '../lib/dom.js';
import { targetSpec } from './target.js';
import { readCameraFile } from '../lib/reports.js';

/** [format, label, file name]: the formats a laser plane report is written in. */
const EXPORTS = [
  ['report', 'robocal JSON', 'laser_plane.json'],
  ['halcon', 'HALCON sheet-of-light', 'laser_plane_halcon.txt'],
  ['urdf', 'URDF joint', 'laser_plane_joint.xml'],
  ['urdf-robot', 'URDF file', 'laser_plane.urdf'],
  ['ros2-static-tf', 'ROS 2 static TF', 'laser_plane_ros2_static_tf.sh'],
  ['ros1-static-tf', 'ROS 1 static TF', 'laser_plane_ros1_static_tf.sh'],
];
/** The longer side of an image as drawn with its stripe, px. */
const PREVIEW_SIDE = 480;
/** The stripe's centres are drawn in this colour (pure red: the images are grey). */
const CENTRE_COLOUR = 'rgb(255, 0, 0)';
const CAMERA_FILES = 'a camera calibration (robocal JSON, OpenCV YAML/XML or ROS camera_info)';

/** File names in code-point order: `view_000.png` before `view_000_laser.png`. */
const byName = (a, b) => (a.name < b.name ? -1 : a.name > b.name ? 1 : 0);
const stem = (name) => name.replace(/\.[^.]+$/, '');

export class LaserView {
  constructor(store, engine) {
    this.store = store;
    this.engine = engine;
    this.cameraFile = null; // { text, name }
    this.files = [];
    this.build();
    this.render();
  }

  build() {
    fill($('laser-panel'),
      h('p', {}, 'A laser-line sensor: a camera and a laser that projects a plane of light. Show the board of step 1 with the laser stripe across it at two or more poses (tilted differently: the stripes must not be parallel), either one image per pose or two (the board with the laser off, then the same pose with it on). The calibrated camera gives each board\'s pose; the stripe\'s centre in every column (or row) on the board, met with the board, gives points on the laser plane. Images never leave this machine.'),
      h('div', { class: 'form' },
        h('p', { id: 'laser-camera-info', class: 'hint' }),
        h('label', {}, 'Camera file (instead of step 3\'s camera) ', h('input', { type: 'file', id: 'laser-camera-file', accept: '.json,.yaml,.yml,.xml,.txt' })),
        h('label', {}, 'Images ', h('input', { type: 'file', id: 'laser-images', multiple: true, accept: 'image/*' })),
        h('label', {}, h('input', { type: 'checkbox', id: 'laser-pairs', checked: true }), ' In pairs, by file name: the board with the laser off, then the same pose with it on (view_000.png, view_000_laser.png, ...)'),
        h('label', {}, 'Stripe centre ', h('select', { id: 'laser-extractor' },
          h('option', { value: 'cog' }, 'centre of gravity'), h('option', { value: 'ridge' }, 'ridge (Steger)'))),
        h('label', {}, 'Residual ', h('select', { id: 'laser-residual' },
          h('option', { value: 'image_px' }, 'pixels along the scan (maximum likelihood)'), h('option', { value: 'point_to_plane' }, 'point to plane, metres'))),
        h('div', {}, h('button', { type: 'button', id: 'laser-solve', class: 'primary', disabled: true }, 'Find the laser plane'))),
      h('div', { id: 'laser-status', 'aria-live': 'polite' }),
      h('div', { id: 'laser-result' }),
      h('div', { id: 'laser-overlays', class: 'laser-overlays' }));
    $('laser-camera-file').addEventListener('change', (e) => this.loadCamera(e.target.files[0]));
    $('laser-images').addEventListener('change', (e) => {
      this.files = [...e.target.files].sort(byName);
      this.enable();
    });
    $('laser-solve').addEventListener('click', () => this.solve());
    this.store.onChange((what) => { if (/result|all/.test(what)) this.describeCamera(); });
  }

  /** The session's laser result drawn anew (a restored or new session). */
  render() {
    this.describeCamera();
    fill($('laser-status'));
    fill($('laser-overlays'));
    const report = this.store.session.laser.result;
    if (report) {
      this.show(report);
      fill($('laser-status'), message('info', 'The laser plane of this session. Add the images again to see their stripes.'));
    } else {
      fill($('laser-result'));
    }
  }

  /** The camera's file text: a loaded file, else step 3's report. */
  cameraText() {
    if (this.cameraFile) return this.cameraFile.text;
    const result = this.store.session.camera.result;
    return result ? JSON.stringify(result) : null;
  }

  describeCamera() {
    const info = $('laser-camera-info');
    const result = this.store.session.camera.result;
    if (this.cameraFile) info.textContent = `Camera: ${this.cameraFile.name}.`;
    else if (result) info.textContent = 'Camera: the calibration of step 3.';
    else info.textContent = 'No camera yet: solve one in step 3, or load its calibration file.';
    this.enable();
  }

  enable() {
    $('laser-solve').disabled = !(this.files.length && this.cameraText());
  }

  async loadCamera(file) {
    if (!file) return;
    try {
      // A report is read by its kind (a rig's or a stereo pair's first camera).
      const { camera, format, text } = await readCameraFile(this.engine, await readTextFile(file, CAMERA_FILES));
      this.cameraFile = { text, name: `${file.name} (${format}, ${camera.width} × ${camera.height})` };
      fill($('laser-status'));
    } catch (err) {
      this.cameraFile = null;
      fill($('laser-status'), message('error', `${file.name}: ${err.message}`));
    }
    this.describeCamera();
  }

  /** The poses of the chosen files: `[{name, board, stripe}]` (board null for one image per pose). */
  poses() {
    if (!$('laser-pairs').checked) return this.files.map((f) => ({ name: f.name, board: null, stripe: f }));
    const poses = [];
    for (let i = 0; i + 1 < this.files.length; i += 2) poses.push({ name: stem(this.files[i + 1].name), board: this.files[i], stripe: this.files[i + 1] });
    return poses;
  }

  async solve() {
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch { fill($('laser-status'), message('error', 'Choose the target in step 1 first.')); return; }
    const pairs = $('laser-pairs').checked;
    const extractor = $('laser-extractor').value;
    const poses = this.poses();
    const request = {
      camera: this.cameraText(), target: spec, pairs,
      residual: $('laser-residual').value, stripe: { extractor },
    };
    // With pairs the core refuses an odd count by its own words; names only when they match.
    if (!pairs || this.files.length % 2 === 0) request.names = poses.map((p) => p.name);
    fill($('laser-status'), message('info', `Finding the board and the stripe in ${this.files.length} image${this.files.length === 1 ? '' : 's'}…`));
    $('laser-solve').disabled = true;
    try {
      const images = await Promise.all(this.files.map((f) => f.arrayBuffer()));
      const report = await this.engine.call('laserPlane', { request: JSON.stringify(request), images });
      this.store.session.laser.result = report;
      this.store.changed('laser');
      this.show(report);
      fill($('laser-status'));
      await this.overlays(poses, report, extractor);
    } catch (err) {
      fill($('laser-status'), message('error', `The laser plane could not be found: ${err.message}`));
    } finally {
      this.enable();
    }
  }

  show(report) {
    const p = report.laser_plane;
    const n = p.normal_camera;
    const plane = h('p', { id: 'laser-plane', dataset: { normal: JSON.stringify(n), distanceM: String(p.distance_m), normalStdDeg: String(p.normal_std_deg), distanceStdMm: String(p.distance_std_mm) } },
      `Laser plane in the camera frame (n · X = d): normal (${fixed(n[0], 5)}, ${fixed(n[1], 5)}, ${fixed(n[2], 5)}) ± ${num(p.normal_std_deg, 4)}°, distance ${num(p.distance_m * 1e3, 3)} ± ${num(p.distance_std_mm, 3)} mm (1 std from the covariance; ${report.residual} residual, ${report.extractor} centres, variance factor ${num(report.variance_factor, 2)}).`);
    const rows = report.images.map((i) => [i.name, num(i.board_rms_px, 3), String(i.stripe_points), String(i.n_points), num(i.rms_px, 3), num(i.rms_mm, 4), i.gaps.length ? i.gaps.map(([a, b]) => `${a}–${b}`).join(', ') : '—']);
    this.exportText = null;
    fill($('laser-result'),
      plane,
      table(['image', 'board RMS px', 'centres found', 'on the board', 'RMS px', 'RMS mm', 'gaps (lines)'], rows, { id: 'laser-residuals' }),
      h('div', { id: 'laser-warnings' }, report.warnings.map((w) => message('warning', w))),
      h('h3', {}, 'Export the plane'),
      h('div', { class: 'row', id: 'laser-exports' }, EXPORTS.map(([format, label, name]) =>
        h('button', { type: 'button', dataset: { format }, onclick: () => this.export(report, format, name) }, label))),
      h('div', { class: 'row' },
        h('button', { type: 'button', id: 'laser-download', onclick: () => { if (this.exportText) download(this.exportName, this.exportText); } }, 'Download')),
      h('p', { class: 'hint', id: 'laser-export-status', 'aria-live': 'polite' }),
      h('pre', { class: 'export', id: 'laser-export-preview', tabindex: 0, 'aria-label': 'laser plane export preview' }));
  }

  async export(report, format, name) {
    try {
      this.exportText = await this.engine.call('export', { report: JSON.stringify(report), format, transform: '' });
      this.exportName = name;
      $('laser-export-preview').textContent = this.exportText;
      $('laser-export-status').textContent = `${format}: ${this.exportText.length} bytes (identical to 'robocal export --format ${format}').`;
    } catch (err) {
      this.exportText = null;
      $('laser-export-preview').textContent = '';
      $('laser-export-status').textContent = err.message;
    }
  }

  /** Every pose's stripe image with the extracted centres drawn on it. */
  async overlays(poses, report, extractor) {
    const box = $('laser-overlays');
    fill(box, h('h3', {}, 'The stripes found'));
    for (const [k, pose] of poses.entries()) {
      try {
        const bytes = await pose.stripe.arrayBuffer();
        const off = pose.board ? await pose.board.arrayBuffer() : null;
        const stripe = await this.engine.call('laserStripe', { bytes, off, settings: JSON.stringify({ extractor }) });
        const preview = await this.engine.call('preview', { bytes, maxSide: PREVIEW_SIDE });
        box.append(this.figure(k, pose.name, stripe, preview, report.images[k]));
      } catch (err) {
        box.append(message('warning', `${pose.name}: ${err.message}`));
      }
    }
  }

  figure(k, name, stripe, preview, fit) {
    const { image, info } = preview;
    const canvas = h('canvas', { id: `laser-overlay-${k}`, width: image.width, height: image.height, role: 'img', dataset: { points: String(stripe.points.length) }, 'aria-label': `${name}: ${stripe.points.length} stripe centres drawn in red on the image` });
    const ctx = canvas.getContext('2d');
    ctx.putImageData(image, 0, 0);
    const s = image.width / info.width;
    ctx.fillStyle = CENTRE_COLOUR;
    // One dot per centre, at least a pixel; pixel (0, 0) is the centre of the top-left pixel.
    const r = Math.max(1, s * 1.5);
    for (const p of stripe.points) ctx.fillRect(Math.round((p.x_px + 0.5) * s - r / 2), Math.round((p.y_px + 0.5) * s - r / 2), Math.ceil(r), Math.ceil(r));
    ctx.strokeStyle = CENTRE_COLOUR;
    for (const [x, y] of stripe.ends) {
      ctx.beginPath();
      ctx.arc((x + 0.5) * s, (y + 0.5) * s, 5, 0, 2 * Math.PI);
      ctx.stroke();
    }
    const used = fit ? `, ${fit.n_points} on the board, residual ${num(fit.rms_px, 3)} px` : '';
    return h('figure', { class: 'laser-figure' }, canvas,
      h('figcaption', {}, `${name}: ${stripe.points.length} centres along the ${stripe.axis}${used}; ${stripe.gaps.length} gap${stripe.gaps.length === 1 ? '' : 's'}, ends circled.`));
  }
}
