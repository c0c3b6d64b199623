// Step 6: the industrial workflows of the seed papers. Planar eye-to-hand
// calibration at any height (seed 001) and XY-table calibration with one
// target (seed 002). Same CSV files as `robocal planar` / `robocal xytable`.
import { $, h, fill, table, num, message, readTextFile } from '../lib/dom.js';
import { lines, bars } from '../lib/plot.js';

const PARAMS = ['a11', 'a12', 'tx', 'a21', 'a22', 'ty'];

/** A CSV file input and a text area; a file that is empty or not UTF-8 goes to `onError` (and leaves the text area as it was). */
function csvInput(id, label, header, onText, onError) {
  const area = h('textarea', { id: `${id}-csv`, rows: 6, cols: 60, 'aria-label': `${label} (CSV)`, spellcheck: 'false' });
  const file = h('input', { type: 'file', id: `${id}-file`, accept: '.csv,.txt,text/csv' });
  file.addEventListener('change', async () => {
    const f = file.files[0];
    if (!f) return;
    file.value = '';
    try {
      area.value = await readTextFile(f, `a CSV file with the header ${header}`);
    } catch (err) {
      onError(`${f.name}: ${err.message}`);
      return;
    }
    onText();
  });
  return { area, node: h('div', { class: 'form' }, h('label', {}, `${label}: file `, file), h('label', {}, 'or paste CSV', area)) };
}

export class WorkflowsView {
  constructor(store, engine) {
    this.store = store;
    this.engine = engine;
    this.render();
  }

  render() {
    const planarIn = csvInput('planar', 'Point pairs (height_mm,u_px,v_px,x_mm,y_mm)', 'height_mm,u_px,v_px,x_mm,y_mm',
      () => this.solvePlanar(), (text) => fill(this.planarOut, message('error', text)));
    const transform = h('select', { id: 'planar-transform', 'aria-label': 'transform per height' },
      ['affine', 'similarity', 'rigid'].map((t) => h('option', { value: t }, t)));
    this.planarOut = h('div', { id: 'planar-results', 'aria-live': 'polite' });
    this.planarArea = planarIn.area;
    const predictH = h('input', { type: 'number', id: 'predict-height', value: 60, step: 'any', 'aria-label': 'height (mm)' });
    const predictU = h('input', { type: 'number', id: 'predict-u', value: 1000, step: 'any', 'aria-label': 'u (px)' });
    const predictV = h('input', { type: 'number', id: 'predict-v', value: 1000, step: 'any', 'aria-label': 'v (px)' });
    this.predictOut = h('p', { id: 'predict-result', 'aria-live': 'polite' });
    const xyIn = csvInput('xytable', 'Stage positions (x_mm,y_mm,z_mm,u_px,v_px[,role])', 'x_mm,y_mm,z_mm,u_px,v_px[,role]',
      () => this.solveXy(), (text) => fill(this.xyOut, message('error', text)));
    this.xyArea = xyIn.area;
    this.xyOut = h('div', { id: 'xytable-results', 'aria-live': 'polite' });
    fill($('workflows-panel'),
      h('section', { 'aria-labelledby': 'planar-title' }, h('h3', { id: 'planar-title' }, 'Planar eye-to-hand calibration at any height (seed 001)'),
        h('p', { class: 'hint' }, 'At each calibration height, image points (undistorted pixels) and their robot X, Y (mm). Every transform parameter is fitted linearly against height, so the transform at any height follows.'),
        planarIn.node, h('div', { class: 'row' }, h('label', {}, 'Transform ', transform), h('button', { type: 'button', class: 'primary', id: 'planar-solve', onclick: () => this.solvePlanar() }, 'Solve')),
        this.planarOut,
        h('div', { class: 'row' }, 'Map pixel ', predictU, predictV, ' at height (mm) ', predictH, h('button', { type: 'button', id: 'planar-predict', onclick: () => this.solvePlanar(true) }, 'Map')),
        this.predictOut),
      h('section', { 'aria-labelledby': 'xytable-title' }, h('h3', { id: 'xytable-title' }, 'XY-table calibration with one target (seed 002)'),
        h('p', { class: 'hint' }, 'The table moves one circular target to N ≥ 6 known positions; the 12-parameter projection is solved by batch least squares and by the recursive Kalman filter. Rows with role "verify" (four extra points) give the verification point; rows with role "still" estimate the image noise.'),
        xyIn.node, h('div', { class: 'row' }, h('button', { type: 'button', class: 'primary', id: 'xytable-solve', onclick: () => this.solveXy() }, 'Solve')),
        this.xyOut));
  }

  async solvePlanar(withPrediction = false) {
    try {
      const req = await this.engine.call('workflow-csv', { kind: 'planar-points', text: this.planarArea.value });
      req.options = { transform: $('planar-transform').value };
      if (withPrediction) req.predict = [{ height_mm: Number($('predict-height').value), image_px: [Number($('predict-u').value), Number($('predict-v').value)] }];
      const r = await this.engine.call('workflow', { op: 'planar_solve', input: JSON.stringify(req) });
      this.store.session.workflows.planar = r;
      this.store.changed('workflow-result');
      this.showPlanar(r);
      if (withPrediction && r.predictions[0]) {
        const p = r.predictions[0];
        this.predictOut.textContent = `At ${num(p.height_mm, 1)} mm, pixel (${num(p.image_px[0], 1)}, ${num(p.image_px[1], 1)}) maps to robot X ${num(p.robot_mm[0], 3)} mm (± ${num(p.std_mm[0], 3)}), Y ${num(p.robot_mm[1], 3)} mm (± ${num(p.std_mm[1], 3)}).`;
      }
    } catch (err) {
      fill(this.planarOut, message('error', err.message));
    }
  }

  showPlanar(r) {
    const perHeight = table(['height (mm)', ...PARAMS, 'RMS (mm)'], r.heights.map((hh) => [num(hh.height_mm, 1), ...PARAMS.map((p) => num(hh.robot_from_image[p], 6)), num(hh.rms_mm, 4)]), { id: 'planar-heights' });
    const fit = table(['parameter', 'intercept', 'slope (/mm)', 'R²', 'Pearson r', 'adj. R²', 'RSS'],
      PARAMS.map((p) => { const f = r.fit[p]; return [p, num(f.intercept, 6), num(f.slope, 6), num(f.r2, 4), num(f.pearson_r, 4), num(f.adj_r2, 4), num(f.rss, 4)]; }), { id: 'planar-fit' });
    const heights = r.heights.map((hh) => hh.height_mm);
    const plots = ['a11', 'tx'].map((p) => lines(h('canvas', { width: 420, height: 280, role: 'img', 'aria-label': `${p} against height` }), [
      { label: `${p} per height`, xs: heights, ys: r.heights.map((hh) => hh.robot_from_image[p]), markers: true },
      { label: 'linear fit', xs: heights, ys: heights.map((x) => r.fit[p].intercept + r.fit[p].slope * x), dashed: true }], { xlabel: 'height (mm)', ylabel: p, title: `${p} against height` }));
    if (r.pixel_density && r.pixel_density.length) {
      const d = r.pixel_density;
      plots.push(lines(h('canvas', { width: 420, height: 280, role: 'img', 'aria-label': 'pixel density against height' }), [
        { label: 'length (px/mm)', xs: d.map((x) => x.height_mm), ys: d.map((x) => x.length_px_per_mm), markers: true },
        { label: 'width (px/mm)', xs: d.map((x) => x.height_mm), ys: d.map((x) => x.width_px_per_mm), markers: true }], { xlabel: 'height (mm)', ylabel: 'px per mm', title: 'Pixel density' }));
    }
    const rejected = r.rejected_heights_mm && r.rejected_heights_mm.length ? message('warning', `Rejected heights (high dispersion): ${r.rejected_heights_mm.join(', ')} mm`) : null;
    fill(this.planarOut, rejected, h('h4', {}, 'Transform per height (robot mm from image px)'), perHeight, h('h4', {}, 'Linear fit against height'), fit, h('div', { class: 'plots' }, plots));
  }

  async solveXy() {
    try {
      const req = await this.engine.call('workflow-csv', { kind: 'xytable', text: this.xyArea.value });
      const r = await this.engine.call('workflow', { op: 'xytable_solve', input: JSON.stringify(req) });
      this.store.session.workflows.xytable = r;
      this.store.changed('workflow-result');
      this.showXy(r);
    } catch (err) {
      fill(this.xyOut, message('error', err.message));
    }
  }

  showXy(r) {
    const P = (m) => h('pre', {}, [0, 1, 2].map((i) => m.projection_matrix.slice(i * 4, i * 4 + 4).map((v) => num(v, 6).padStart(14)).join(' ')).join('\n'));
    const hist = r.kalman.history || [];
    const conv = lines(h('canvas', { width: 460, height: 280, role: 'img', 'aria-label': 'Kalman filter convergence' }), [
      { label: 'Kalman RMS (px)', xs: hist.map((s) => s.observation + 1), ys: hist.map((s) => s.rms_px), markers: true },
      { label: 'batch RMS (px)', xs: [1, Math.max(1, hist.length)], ys: [r.batch.rms_px, r.batch.rms_px], dashed: true }], { xlabel: 'observations processed', ylabel: 'RMS (px)', title: 'Convergence of the Kalman filter' });
    const resid = bars(h('canvas', { width: 460, height: 280, role: 'img', 'aria-label': 'residual per position' }),
      r.batch.residuals_px.map((e, i) => ({ label: String(i + 1), value: Math.hypot(e[0], e[1]) })), { ylabel: 'batch residual (px)', title: 'Residual per stage position' });
    const v = r.verification;
    fill(this.xyOut,
      h('div', { class: 'two-col' }, h('div', {}, h('h4', {}, `Batch least squares (RMS ${num(r.batch.rms_px, 4)} px)`), P(r.batch)),
        h('div', {}, h('h4', {}, `Kalman filter (RMS ${num(r.kalman.rms_px, 4)} px)`), P(r.kalman))),
      h('p', { class: 'hint' }, `Measurement noise R (px²): [${r.measurement_noise_px2.flat().map((x) => num(x, 5)).join(', ')}] from ${typeof r.noise_source === 'string' ? r.noise_source : JSON.stringify(r.noise_source)}.`),
      v ? table(['verification point', 'u (px)', 'v (px)', 'error (px)'], [
        ['measured (diagonal intersection)', num(v.measured_px[0], 3), num(v.measured_px[1], 3), ''],
        ['batch prediction', num(v.batch_predicted_px[0], 3), num(v.batch_predicted_px[1], 3), num(v.batch_error_px, 4)],
        ['Kalman prediction', num(v.kalman_predicted_px[0], 3), num(v.kalman_predicted_px[1], 3), num(v.kalman_error_px, 4)]], { id: 'xytable-verification' }) : null,
      h('div', { class: 'plots' }, conv, resid));
  }
}
