// Stereo: two image sets (left and right camera) of the target from step 1,
// paired by the core's rule (robocal::io::pairing, as `robocal stereo`);
// detection in the worker, then one joint calibration of both cameras
// and right_from_left (the same core as `robocal stereo`). The images, their
// detections and the result are kept in the session (IndexedDB).
import { $, h, fill, table, num, message } from '../lib/dom.js';
import { targetSpec } from './target.js';
import { MODELS } from './camera.js';

const byName = (a, b) => a.name.localeCompare(b.name, undefined, { numeric: true });

/**
 * Pairs of left/right files by the core's rule, the one of `robocal stereo`
 * (robocal::io::pairing): the last number in each name pairs left n with
 * right n; when no name has a number, by order (here: names sorted). A
 * mismatch (a name without a number, a number twice, a file without a
 * partner) rejects with the core's message naming the files.
 */
export async function pairFiles(engine, left, right) {
  const L = [...left].sort(byName);
  const R = [...right].sort(byName);
  const { paired_by: how, pairs } = await engine.call('pair', { left: L.map((f) => f.name), right: R.map((f) => f.name) });
  return { how, pairs: pairs.map(([l, r]) => ({ left: L[l], right: R[r] })) };
}

export class StereoView {
  constructor(store, engine) {
    this.store = store;
    this.engine = engine;
    this.pairing = { how: 'order', pairs: [], error: null };
    this.render();
  }

  get state() {
    const st = this.store.session.stereo || (this.store.session.stereo = { model: 'brown', result: null });
    if (!st.left) st.left = [];
    if (!st.right) st.right = [];
    return st;
  }

  get left() { return this.state.left; }

  get right() { return this.state.right; }

  render() {
    const input = (side) => {
      const el = h('input', { type: 'file', id: `stereo-${side}-input`, multiple: true, accept: 'image/*,.pgm,.ppm,.pnm,.tif,.tiff,.bmp' });
      el.addEventListener('change', () => { this.add(side, [...el.files]); el.value = ''; });
      return h('label', {}, `${side === 'left' ? 'Left' : 'Right'} camera images `, el);
    };
    const model = h('select', { id: 'stereo-model' }, MODELS.map(([v, t]) => h('option', { value: v, selected: v === this.state.model }, t)));
    model.addEventListener('change', () => { this.state.model = model.value; this.store.changed('stereo'); });
    this.solveButton = h('button', { type: 'button', class: 'primary', id: 'stereo-solve', disabled: true }, 'Detect and solve the stereo pair');
    this.solveButton.addEventListener('click', () => this.solve());
    this.pairsOut = h('div', { id: 'stereo-pairs' });
    this.progress = h('p', { id: 'stereo-progress', class: 'hint', 'aria-live': 'polite' });
    this.out = h('div', { id: 'stereo-results', 'aria-live': 'polite' });
    fill($('stereo-panel'),
      h('p', { class: 'hint' }, 'Two cameras that saw the same target poses at the same moments. The target is the one of step 1. Images are paired as robocal stereo pairs them: by the last number in their names (left01 with right1), or by order (sorted names) when no name has a number.'),
      h('div', { class: 'form', id: 'stereo-form' }, input('left'), input('right'), h('label', {}, 'Lens model (both cameras) ', model)),
      h('div', { class: 'row' }, this.solveButton, h('button', { type: 'button', id: 'stereo-clear', onclick: () => this.clear() }, 'Remove the images')),
      this.progress, this.pairsOut, this.out);
    this.showPairs();
    if (this.state.result) this.show(this.state.result);
  }

  async add(side, files) {
    for (const f of files) {
      const id = `stereo-${side}-${Date.now().toString(36)}-${Math.random().toString(36).slice(2, 8)}`;
      await this.store.putBytes(id, await f.arrayBuffer());
      this.state[side].push({ id, name: f.name, detection: null, error: null, spec: null });
    }
    this.store.changed('stereo');
    this.showPairs();
  }

  async clear() {
    await this.store.deleteBytes([...this.left, ...this.right].map((f) => f.id));
    this.state.left = [];
    this.state.right = [];
    this.store.changed('stereo');
    this.showPairs();
  }

  async showPairs() {
    const asked = (this.asked = (this.asked || 0) + 1);
    this.solveButton.disabled = true;
    if (!this.left.length && !this.right.length) {
      this.pairing = { how: 'order', pairs: [], error: null };
      fill(this.pairsOut, message('info', 'Load the left and the right camera\'s images (at least 3 pairs).'));
      return;
    }
    let pairing;
    try {
      pairing = { ...(await pairFiles(this.engine, this.left, this.right)), error: null };
    } catch (err) {
      pairing = { how: null, pairs: [], error: err.message };
    }
    if (asked !== this.asked) return; // a newer call is showing its answer
    this.pairing = pairing;
    if (pairing.error) {
      fill(this.pairsOut, h('p', { id: 'stereo-pairing', class: 'msg msg-error', role: 'alert' }, `The images cannot be paired: ${pairing.error}`));
      return;
    }
    const { how, pairs } = pairing;
    this.solveButton.disabled = pairs.length < 3;
    const status = (f) => (f.error ? f.error : f.detection ? `${f.detection.points.length} points` : 'not detected yet');
    const rows = pairs.map((p, i) => [String(i + 1), p.left.name, status(p.left), p.right.name, status(p.right)]);
    fill(this.pairsOut,
      h('p', { id: 'stereo-pairing' }, `${pairs.length} pair${pairs.length === 1 ? '' : 's'}, paired ${how === 'number' ? 'by the number in the file names' : 'by order (sorted names)'}.`),
      pairs.length < 3 ? h('p', { id: 'stereo-too-few', class: 'msg msg-info', role: 'status' }, `A stereo calibration needs at least 3 pairs: add ${3 - pairs.length} more pair${3 - pairs.length === 1 ? '' : 's'} (a left and a right image each) to solve.`) : null,
      table(['pair', 'left', 'left detection', 'right', 'right detection'], rows, { id: 'stereo-pair-table', class: 'scroll' }));
  }

  async detect(file, spec) {
    if (file.detection || file.spec === spec) return;
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

  async solve() {
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch (err) { fill(this.out, message('error', err.message)); return; }
    const pairs = this.pairing.pairs;
    this.solveButton.disabled = true;
    try {
      let done = 0;
      for (const p of pairs) {
        for (const f of [p.left, p.right]) {
          if (f.spec !== spec) { f.detection = null; f.spec = null; }
          this.progress.textContent = `detecting ${++done} of ${2 * pairs.length}: ${f.name}`;
          await this.detect(f, spec);
        }
      }
      this.showPairs();
      this.store.changed('stereo');
      const used = pairs.filter((p) => p.left.detection && p.right.detection);
      this.progress.textContent = `detected ${2 * pairs.length} images: ${used.length} pairs with the target in both images; solving…`;
      const view = (f) => ({ name: f.name, detection: f.detection });
      const input = { model: this.state.model, left: used.map((p) => view(p.left)), right: used.map((p) => view(p.right)) };
      const result = await this.engine.call('stereo', { input: JSON.stringify(input) });
      this.state.result = result;
      this.store.changed('stereo-result');
      this.progress.textContent = `solved with ${used.length} pairs.`;
      this.show(result);
    } catch (err) {
      this.progress.textContent = '';
      fill(this.out, message('error', err.message));
    } finally {
      this.solveButton.disabled = false;
    }
  }

  show(r) {
    const m = r.right_from_left.matrix_row_major;
    const t = r.right_from_left.translation_m.map((v) => v * 1000);
    const std = r.right_from_left_std;
    const cam = (c) => { const k = c.camera_matrix; return [num(k[0][0], 4), num(k[1][1], 4), num(k[0][2], 4), num(k[1][2], 4), num((c.distortion || {}).k1, 6), num(c.rms_px, 4)]; };
    fill(this.out,
      h('p', { class: 'hint' }, 'right_from_left can be exported in every transform format in step 8.'),
      h('h3', { id: 'stereo-summary' }, `right_from_left: baseline ${num(r.baseline_m * 1000, 4)} mm, RMS ${num(r.rms_px, 4)} px over ${r.left.views.length} pairs`),
      table(['', 'x', 'y', 'z'], [
        ['T (mm)', ...t.map((v) => num(v, 4))],
        ['std T (mm)', ...(std ? std.translation_m.map((v) => num(v * 1000, 3)) : ['—', '—', '—'])],
        ['std rotation (deg)', ...(std ? std.rotation_rad.map((v) => num((v * 180) / Math.PI, 4)) : ['—', '—', '—'])],
      ], { id: 'stereo-translation' }),
      h('p', { class: 'hint' }, 'p_right = R p_left + T (the OpenCV stereoCalibrate R, T convention); R below, row by row.'),
      table(['R', 'col 1', 'col 2', 'col 3'], m.slice(0, 3).map((row, i) => [`row ${i + 1}`, ...row.slice(0, 3).map((v) => num(v, 6))]), { id: 'stereo-rotation' }),
      table(['camera', 'fx', 'fy', 'cx', 'cy', 'k1', 'RMS (px)'], [['left', ...cam(r.left)], ['right', ...cam(r.right)]], { id: 'stereo-cameras' }),
      [...(r.warnings || []).map((w) => message('warning', w)), ...(r.left.warnings || []).map((w) => message('warning', `left: ${w}`)), ...(r.right.warnings || []).map((w) => message('warning', `right: ${w}`))]);
  }
}
