// Step 10: has the camera changed since it was calibrated? A saved
// calibration file (any format robocal reads back) against the live camera
// or dropped images of step 1's target: the core's check (check_camera,
// docs/check.md) gives ok / drifted / broken, the projection shift map and
// the parameters that moved. A second calibration file gives the
// projection difference of the two (diff_cameras). Images stay here. The
// last check's report is kept in the session (session.check: shown again
// after a reload, carried by a session file and a share link, whose
// read-only page shows it without the shift map).
import { $, h, fill, table, num, message, readTextFile } from '../lib/dom.js';
import { cameraErrorText, openCamera, stopStream } from '../lib/camera.js';
import { targetSpec } from './target.js';
import { readCameraFile, cameraOfReport } from '../lib/reports.js';

/** The file names a saved calibration may have: every camera format robocal exports (HALCON's .dat and .hdev.txt, MATLAB's .m, the text matrix's .txt). */
const CAMERA_FILES = '.json,.yaml,.yml,.xml,.cameramodel,.dat,.txt,.m,text/*,application/json';
/** Distinct views of the target taken from the camera before the check runs. */
const LIVE_VIEWS = 5;
/** A live view counts as new when its first point moved this far (px) from every kept one. */
const NEW_VIEW_PX = 4;
const VERDICT_WORDS = {
  ok: 'OK: the camera agrees with its saved calibration.',
  drifted: 'DRIFTED: the camera changed beyond the saved calibration\'s uncertainty.',
  broken: 'BROKEN: the saved calibration does not describe this camera.',
};

export class CheckView {
  /** `makeEngine()` gives the live detection's own worker. */
  constructor(store, engine, makeEngine, { readonly = false } = {}) {
    this.store = store;
    this.readonly = readonly;
    this.engine = engine;
    this.makeEngine = makeEngine;
    this.calibration = null; // { text, name, camera }
    this.stream = null;
    this.live = null;
    this.views = [];
    this.build();
  }

  build() {
    const panel = $('check-panel');
    if (this.readonly) {
      fill(panel, h('div', { id: 'check-result', 'aria-live': 'polite' }));
      this.showSaved();
      return;
    }
    fill(panel,
      h('p', {}, 'Has the camera changed since it was calibrated? Load its saved calibration (any camera format robocal exports: robocal JSON report, OpenCV YAML/XML, ROS camera_info, Kalibr, mrcal, HALCON .dat or tuple, MATLAB, text matrix), then show the target of step 1 to the camera, or add a few images of it. The check poses the images with the saved camera, refits the focal lengths and principal point with the lens model held, and compares the two over the image. Images never leave this machine.'),
      h('div', { class: 'form' },
        h('label', {}, 'Saved calibration ', h('input', { type: 'file', id: 'check-file', accept: CAMERA_FILES })),
        h('p', { id: 'check-file-info', class: 'hint' }, 'No calibration loaded.'),
        h('div', {},
          h('button', { type: 'button', id: 'check-camera', disabled: true }, 'Check with the camera'), ' ',
          h('button', { type: 'button', id: 'check-stop', hidden: true }, 'Stop camera')),
        h('label', {}, 'or images of the target ', h('input', { type: 'file', id: 'check-images', multiple: true, accept: 'image/*', disabled: true })),
        h('label', {}, 'Compare with another calibration ', h('input', { type: 'file', id: 'check-other', accept: CAMERA_FILES, disabled: true }))),
      h('div', { id: 'check-live', hidden: true },
        h('div', { class: 'live-view' }, h('video', { id: 'check-video', muted: true, playsinline: true, 'aria-label': 'Live camera picture for the check' })),
        h('p', { class: 'live-status', id: 'check-live-status', role: 'status' }, 'Starting…')),
      h('div', { id: 'check-result', 'aria-live': 'polite' }));
    $('check-file').addEventListener('change', (e) => this.load(e.target.files[0]));
    $('check-camera').addEventListener('click', () => this.startCamera());
    $('check-stop').addEventListener('click', () => this.stopCamera());
    $('check-images').addEventListener('change', (e) => this.checkImages([...e.target.files]));
    $('check-other').addEventListener('change', (e) => this.diff(e.target.files[0]));
    this.showSaved();
  }

  /** The session's last check (session.check), as it was shown. */
  showSaved() {
    const saved = this.store.session.check;
    if (!saved || !saved.result) {
      if (this.readonly) this.say(message('info', 'This link holds no check.'));
      return;
    }
    try {
      this.show(saved.result, [], `The last check, of ${saved.name}:`);
    } catch (err) {
      this.say(message('error', `The saved check could not be shown (${err.message}): check again.`));
    }
  }

  say(...nodes) { fill($('check-result'), ...nodes); }

  async load(file) {
    if (!file) return;
    try {
      const read = await readTextFile(file, 'a camera calibration (any camera format robocal exports)');
      // A report is read by its kind (a rig's or a stereo pair's first camera; a check report is refused).
      const { camera, format, text } = await readCameraFile(this.engine, read);
      this.calibration = { text, name: file.name, camera };
      $('check-file-info').textContent = `${file.name} (${format}): ${camera.width} × ${camera.height}, fx ${num(camera.fx, 1)}, fy ${num(camera.fy, 1)}, cx ${num(camera.cx, 1)}, cy ${num(camera.cy, 1)}`;
      for (const id of ['check-camera', 'check-images', 'check-other']) $(id).disabled = false;
      this.say();
    } catch (err) {
      this.calibration = null;
      $('check-file-info').textContent = 'No calibration loaded.';
      this.say(message('error', `${file.name}: ${err.message}`));
    }
  }

  spec() {
    try { return targetSpec(this.store.session.target); } catch { return null; }
  }

  /** The live camera at the calibration's resolution; frames detected until enough distinct views are kept. */
  async startCamera() {
    if (!this.calibration) return;
    this.stopCamera();
    const { width, height } = this.calibration.camera;
    try {
      this.stream = await openCamera({ deviceId: '', width, height, max: false });
    } catch (err) {
      this.say(message('error', cameraErrorText(err, `${width} × ${height}`)));
      return;
    }
    const video = $('check-video');
    video.srcObject = this.stream;
    await video.play().catch(() => {});
    $('check-live').hidden = false;
    $('check-stop').hidden = false;
    if (!this.live) this.live = this.makeEngine();
    this.views = [];
    this.say();
    this.loop(this.stream);
  }

  stopCamera() {
    stopStream(this.stream);
    this.stream = null;
    $('check-video').srcObject = null;
    $('check-live').hidden = true;
    $('check-stop').hidden = true;
  }

  async loop(stream) {
    const video = $('check-video');
    const spec = this.spec();
    if (!spec) { this.say(message('error', 'Choose the target in step 1 first.')); this.stopCamera(); return; }
    while (this.stream === stream) {
      if (video.videoWidth) {
        const bitmap = await createImageBitmap(video);
        const reply = await this.live.call('frame', { bitmap, spec }, [bitmap]).catch((err) => ({ found: false, reason: err.message }));
        if (this.stream !== stream) return;
        if (reply.found && this.isNew(reply.detection)) this.views.push({ name: `camera_${this.views.length + 1}`, detection: reply.detection });
        $('check-live-status').dataset.state = reply.found ? 'found' : 'none';
        $('check-live-status').textContent = `${reply.found ? 'Board found' : 'Board not found'} · ${this.views.length} of ${LIVE_VIEWS} views kept${reply.width ? ` · ${reply.width} × ${reply.height}` : ''}: move the board (or the camera) between views, tilted in some.`;
        if (this.views.length >= LIVE_VIEWS) {
          this.stopCamera();
          await this.run(this.views);
          return;
        }
      }
      await new Promise((resolve) => setTimeout(resolve, 100));
    }
  }

  isNew(detection) {
    const [p] = detection.points;
    if (!p) return false;
    return this.views.every((v) => {
      const q = v.detection.points[0];
      return Math.hypot(p.x_px - q.x_px, p.y_px - q.y_px) > NEW_VIEW_PX;
    });
  }

  async checkImages(files) {
    const spec = this.spec();
    if (!spec) { this.say(message('error', 'Choose the target in step 1 first.')); return; }
    this.say(message('info', `Detecting the target in ${files.length} image${files.length === 1 ? '' : 's'}…`));
    const views = [];
    const missed = [];
    for (const file of files) {
      try {
        const detection = await this.engine.call('detect', { bytes: await file.arrayBuffer(), spec });
        views.push({ name: file.name, detection });
      } catch (err) {
        missed.push(`${file.name}: ${err.message}`);
      }
    }
    await this.run(views, missed);
  }

  async run(views, missed = []) {
    const request = JSON.stringify({ calibration: this.calibration.text, views });
    try {
      const report = await this.engine.call('check', { request });
      this.report = report;
      this.store.session.check = { name: this.calibration.name, result: report };
      this.store.changed('check-result');
      this.show(report, missed);
    } catch (err) {
      this.say(message('error', `The check could not run: ${err.message}`));
    }
  }

  show(report, missed, heading = null) {
    const verdict = h('p', { id: 'check-verdict', class: `verdict verdict-${report.verdict}`, dataset: { verdict: report.verdict } }, VERDICT_WORDS[report.verdict]);
    const shift = report.projection_shift_px;
    const rows = report.parameters.map((p) => [p.name, num(p.saved, 2), num(p.refit, 2), num(p.shift_px, 2), p.shift_std === null ? '—' : num(p.shift_std, 1), p.moved ? 'moved' : '']);
    const t = report.thresholds;
    this.say(heading ? h('p', { id: 'check-saved' }, heading) : null, verdict,
      report.reasons.length ? h('ul', { id: 'check-reasons' }, report.reasons.map((r) => h('li', {}, r))) : null,
      shift ? h('p', {}, `Projection shift (implied rotation compensated): worst ${num(shift.worst, 2)} px, median ${num(shift.median, 2)} px; threshold ${num(t.shift_px, 2)} px. Reprojection RMS of the saved camera on these views: ${num(report.reprojection_rms_px, 3)} px (broken above ${num(t.broken_rms_px, 2)} px).`) : null,
      shift && shift.map ? this.heatMap(shift, 'check-map') : null,
      rows.length ? table(['parameter', 'saved px', 'now px', 'shift px', 'shift in std', ''], rows, { id: 'check-params' }) : null,
      report.warnings.map((w) => message('warning', w)),
      missed.map((m) => message('warning', `${m}; skipped`)));
  }

  async diff(file) {
    if (!file || !this.calibration) return;
    try {
      const b = cameraOfReport(await readTextFile(file, 'a camera calibration (any camera format robocal exports)')).text;
      const report = await this.engine.call('diff', { request: JSON.stringify({ a: this.calibration.text, b }) });
      const d = report.projection_shift_px;
      this.say(h('p', { id: 'check-diff' }, `${this.calibration.name} against ${file.name}: projection shift worst ${num(d.worst, 2)} px at (${num(d.worst_at_px[0], 0)}, ${num(d.worst_at_px[1], 0)}), median ${num(d.median, 2)} px, RMS ${num(d.rms, 2)} px, implied rotation ${num(d.implied_rotation_deg, 3)} deg.`), this.heatMap(d, 'check-diff-map'));
    } catch (err) {
      this.say(message('error', `${file.name}: ${err.message}`));
    }
  }

  /** The shift map as a heat map (white 0 px to red at the worst), with its scale. */
  heatMap(d, id) {
    const [cols, rows] = d.grid;
    const [w, hh] = d.image_size_px;
    const scale = Math.min(480 / w, 360 / hh);
    const canvas = h('canvas', { id, width: Math.round(w * scale), height: Math.round(hh * scale) + 24, role: 'img', 'aria-label': `Projection shift over the image: worst ${num(d.worst, 2)} px, median ${num(d.median, 2)} px (the text above says the same)` });
    const ctx = canvas.getContext('2d');
    const top = Math.max(d.worst, 1e-9);
    const cw = (w * scale) / cols;
    const ch = (hh * scale) / rows;
    for (let r = 0; r < rows; r++) {
      for (let c = 0; c < cols; c++) {
        const v = d.map[r][c];
        const f = v === null ? null : Math.min(1, v / top);
        ctx.fillStyle = f === null ? '#888' : `rgb(255, ${Math.round(255 * (1 - f))}, ${Math.round(255 * (1 - f))})`;
        ctx.fillRect(c * cw, r * ch, cw + 1, ch + 1);
      }
    }
    ctx.fillStyle = '#000';
    ctx.font = '13px system-ui';
    ctx.fillText(`white 0 px … red ${num(d.worst, 2)} px`, 4, hh * scale + 17);
    return canvas;
  }
}
