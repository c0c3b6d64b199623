// Step 3: the camera. Model, method and options; solve in the worker; every
// parameter with its standard deviation, per-view errors, residual plots,
// the projection-uncertainty map, the distortion field, an undistorted
// preview and the warnings in plain words.
import { $, h, fill, table, num, message } from '../lib/dom.js';
import { bars, scatter, vectors, heatmap } from '../lib/plot.js';
import { MODELS, lensFields, readLens, jsonOptions } from './lens.js';

export const METHODS = [
  ['zhang', 'Zhang + bundle adjustment'],
  ['dlt', '12-parameter DLT'],
  ['tsai', 'Tsai (radial alignment)'],
  ['ekf', 'Extended Kalman filter'],
  ['all', 'All, side by side'],
];
const UNDISTORT_SIDE = 480;
/** The core's correlation warning (calib/report.rs), and how many are shown one by one before they fold into one. */
const CORRELATED = /^\S+ and \S+ are strongly correlated \(/;
const FOLD_PAIRS = 3;

/** One warning that says `text` and lists `items` folded (a splined lens has hundreds of correlated control points). */
function foldedPairs(id, text, items) {
  return h('div', { class: 'msg msg-warning', role: 'status', id }, text, ' ',
    h('details', {}, h('summary', {}, `The ${items.length} pairs`), h('ul', {}, items.map((x) => h('li', {}, x)))));
}

/** The names of a splined lens's control values (calib: dx0 dy0 dx1 ...). */
const SPLINE_VALUE = /^(d[xy])(\d+)$/;

/** A splined lens's control values (`rows` of the parameter table) in a collapsed box that says how many and their layout. */
function splineValues(r, rows) {
  const s = (r.camera && r.camera.distortion) || {};
  const knots = r.spline_support ? r.spline_support.knots : [s.nx, s.ny];
  const layout = knots[0] && knots[1] ? ` (${knots[0]}x${knots[1]} control points, dx and dy each${s.order ? `, order ${s.order}` : ''})` : '';
  return h('details', { id: 'camera-spline-values' },
    h('summary', {}, `${rows.length} spline control values${layout}`),
    table(['parameter', 'value', 'std'], rows, { id: 'camera-spline-table' }));
}

function putPixels(canvas, p) {
  canvas.width = p.image.width;
  canvas.height = p.image.height;
  canvas.getContext('2d').putImageData(p.image, 0, 0); // the core's ImageData
}

/** On a shared page: how many of the residuals the link carried (a sample), or that it carried none. */
function residualNote(sampled) {
  const text = sampled && sampled.kept
    ? `The residual plots show a sample of ${sampled.kept} of the ${sampled.total} points (a share link carries a sample; the session file holds them all).`
    : 'This link carries no residuals: the residual plots are empty (the session file holds them).';
  return h('p', { class: 'hint', id: 'camera-residual-sample' }, text);
}

export class CameraView {
  constructor(store, engine, images, { readonly = false } = {}) {
    this.store = store;
    this.engine = engine;
    this.images = images;
    this.readonly = readonly;
    this.render();
    // A result solved from detections of another target is stale: say so on it.
    store.onChange((what) => {
      if (what !== 'target' || !this.state.result) return;
      this.state.stale = 'The target changed after this result was solved: the images are being detected again with the new target; solve again to update the result.';
      this.show(this.state.result, this.state.comparison, this.state.comparisonNote, this.state.centre);
    });
  }

  get state() { return this.store.session.camera; }

  render() {
    const st = this.state;
    const select = (name, items, value) => h('select', { name, id: `camera-${name}` },
      items.map(([v, label]) => h('option', { value: v, selected: v === value }, label)));
    const lens = lensFields(st, 'camera');
    const form = h('form', { class: 'form', id: 'camera-form' },
      lens.model, lens.brown, lens.spline,
      h('label', {}, 'Method', select('method', METHODS, st.method)),
      lens.options, lens.cross,
      h('p', { class: 'hint', id: 'camera-input-summary' }),
      h('div', { class: 'row' }, h('button', { type: 'submit', class: 'primary', id: 'solve-camera' }, 'Solve camera')));
    form.addEventListener('change', () => this.readForm(form));
    form.addEventListener('submit', (e) => { e.preventDefault(); this.solve(); });
    this.out = h('div', { id: 'camera-results', 'aria-live': 'polite' });
    if (this.readonly) fill($('camera-panel'), this.out);
    else fill($('camera-panel'), form, this.out);
    this.summarise();
    if (st.result) this.show(st.result, st.comparison, st.comparisonNote, st.centre);
  }

  readForm(form) {
    const st = this.state;
    readLens(st, form);
    st.method = form.elements.method.value;
    this.store.changed('camera-options');
  }

  usable() {
    return this.store.session.images.filter((i) => i.included && i.detection && i.detection.points.length >= 4);
  }

  summarise() {
    const n = this.usable().length;
    const el = $('camera-input-summary');
    if (el) el.textContent = `${n} view${n === 1 ? '' : 's'} with a detected target will be used (exclude views in step 2).`;
  }

  async solve() {
    const views = this.usable();
    const st = this.state;
    fill(this.out, message('info', `Solving with ${views.length} views…`));
    const input = {
      model: st.model,
      method: st.method,
      options: jsonOptions(st),
      views: views.map((i) => ({ name: i.name, detection: i.detection })),
    };
    try {
      const result = await this.engine.call('calibrate', { input: JSON.stringify(input) });
      st.result = result.report || result;
      st.comparison = result.comparison || null;
      st.comparisonNote = result.comparison_note || null; // e.g. why the DLT was left out
      st.stale = null;
      // Circle grids and dot plates: the views' circle-centre model ('mixed' with the views of each).
      st.centre = result.centre_model ? { model: result.centre_model, groups: result.centre_models || [] } : null;
      this.store.changed('camera-result');
      this.show(st.result, st.comparison, st.comparisonNote, st.centre);
    } catch (err) {
      fill(this.out, message('error', err.message));
    }
  }

  show(r, comparison, comparisonNote, centre) {
    const names = ['fx', 'fy', 'cx', 'cy', 'skew', ...Object.keys(r.distortion || {})];
    const k = r.camera_matrix.flat();
    const value = { fx: k[0], skew: k[1], cx: k[2], fy: k[4], cy: k[5], ...(r.distortion || {}) };
    const std = r.std || {};
    const row = (n) => [n, num(value[n], 6), stdText(std[n])];
    // A splined lens's control values (2 per control point, 140 at 10x7):
    // folded under a count, the intrinsics and named parameters in view.
    // The report's distortion keys come sorted as text (dx0 dx1 dx10 ...):
    // listed in the camera's own order, control point by control point.
    const controlOrder = (n) => { const [, axis, i] = SPLINE_VALUE.exec(n); return 2 * Number(i) + (axis === 'dy' ? 1 : 0); };
    const control = r.model === 'splined'
      ? names.filter((n) => SPLINE_VALUE.test(n)).sort((a, b) => controlOrder(a) - controlOrder(b)) : [];
    const params = h('div', { class: 'camera-params-box' },
      table(['parameter', 'value', 'std'], names.filter((n) => !control.includes(n)).map(row), { id: 'camera-params' }),
      control.length ? splineValues(r, control.map(row)) : null);
    const texts = (r.warnings || []).map((w) => (typeof w === 'string' ? w : w.message));
    // Many "X and Y are strongly correlated" (a splined lens's neighbouring
    // control points): one warning with the pairs folded, not a box each.
    const pairs = texts.filter((t) => CORRELATED.test(t));
    const folded = pairs.length > FOLD_PAIRS;
    const warnings = [...texts.filter((t) => !folded || !CORRELATED.test(t)).map((t) => this.warning(t, r.model)),
      folded ? foldedPairs('camera-correlated-warnings', `${pairs.length} pairs of parameters are strongly correlated: the views do not separate them.`, pairs) : null];
    const perView = (r.views || []).map((v) => ({ label: v.name, value: v.rms_px, highlight: v.rms_px > 2 * r.rms_px }));
    const residualPoints = [];
    const residualVectors = [];
    const byImage = new Map();
    (r.views || []).forEach((v, vi) => {
      const list = [];
      for (const p of v.residuals_px || []) {
        residualPoints.push({ x: p.dx, y: p.dy, group: vi });
        residualVectors.push({ x: p.x, y: p.y, dx: p.dx, dy: p.dy });
        list.push(p);
      }
      byImage.set(v.name, list);
    });
    this.images.setResiduals(byImage);
    const [w, hgt] = r.image_size_px;
    const canvases = [];
    const canvas = (id, label) => { const c = h('canvas', { id, width: 460, height: 340, role: 'img', 'aria-label': label }); canvases.push(c); return c; };
    const viewBars = bars(canvas('plot-view-rms', 'reprojection RMS per view'), perView, { ylabel: 'RMS (px)', title: 'Reprojection error per view', threshold: r.rms_px });
    const scat = scatter(canvas('plot-residuals', 'residual scatter'), residualPoints, { xlabel: 'du (px)', ylabel: 'dv (px)', title: 'Residuals', symmetric: true });
    const vec = vectors(canvas('plot-vectors', 'residual vectors over the image'), residualVectors, [w, hgt], { title: 'Residual vectors', gain: 50 });
    const pu = r.projection_uncertainty;
    const unc = pu && pu.std_px && pu.std_px.length ? heatmap(canvas('plot-uncertainty', 'projection uncertainty map'), {
      cols: pu.x_px.length, rows: pu.y_px.length, width_px: w, height_px: hgt,
      values: pu.std_px.flat().map((v) => (v === null ? NaN : v)),
    }, { title: `Projection uncertainty (1 sigma, points at ${num(pu.reference_depth_m, 2)} m)` }) : null;
    const dist = r.distortion_field ? vectors(canvas('plot-distortion', 'distortion field'), r.distortion_field.vectors, [w, hgt], { title: 'Distortion field', gain: 1 }) : null;
    this.plots = canvases;
    const picked = h('div', { id: 'camera-view-picked', 'aria-live': 'polite' },
      this.readonly ? null : h('p', { class: 'hint' }, 'Click a bar (or a point of the residual scatter) to select that view, then exclude it and solve again.'));
    if (!this.readonly) {
      viewBars.addEventListener('click', (e) => this.pickView(r, viewBars.barAt?.(e.offsetX * viewBars.width / viewBars.clientWidth), picked));
      scat.addEventListener('click', (e) => {
        const g = scat.groupAt?.(e.offsetX * scat.width / scat.clientWidth, e.offsetY * scat.height / scat.clientHeight);
        this.pickView(r, g, picked);
      });
    }
    fill(this.out,
      this.state.stale && !this.readonly ? message('warning', this.state.stale) : null,
      h('h3', {}, `Result: RMS ${num(r.rms_px, 4)} px over ${(r.views || []).length} views`),
      centre ? h('p', { class: 'hint', id: 'centre-model' }, centre.model === 'mixed'
        ? `Circle centres: mixed models (${centre.groups.map((g) => `${g.centre_model}: ${g.views.length} views`).join(', ')}): detect every image with the same centre model.`
        : `Circle centres: ${centre.model}.`) : null,
      warnings,
      r.rejected ? this.rejectedNote(r) : null,
      h('div', { class: 'two-col' }, params, h('div', { class: 'plots' }, viewBars, scat, picked)),
      this.readonly ? residualNote(this.state.residualsSampled) : null,
      r.spline_support ? h('p', { class: 'hint', id: 'camera-valid-region' },
        `Splined lens: ${r.spline_support.supported} of ${r.spline_support.knots[0] * r.spline_support.knots[1]} control points have data; `
        + `the valid region (image cells holding points) is ${num(100 * r.spline_support.image_coverage, 0)} % of the image, and outside it the model is extrapolated: trust it where the uncertainty map is low.`) : null,
      h('div', { class: 'plots' }, vec, unc, dist),
      r.cross_validation ? this.crossValidationSection(r.cross_validation, [w, hgt]) : null,
      this.undistortSection(r),
      comparison ? this.comparisonTable(comparison, comparisonNote) : null,
      r.correlation && r.correlation.matrix ? this.correlationNote(r.correlation) : null);
  }

  /**
   * A warning of the report; the core's lens-model advice ("... (CLI: --model
   * NAME)") comes with a button that switches the model and solves again.
   */
  warning(text, chosen) {
    const m = /\(CLI: --model (\w+)\)/.exec(text);
    const model = m && MODELS.find(([v]) => v === m[1]);
    if (this.readonly || !model || m[1] === chosen) return message('warning', text);
    const button = h('button', { type: 'button', class: 'switch-model', dataset: { model: m[1] } }, `Switch to ${model[1].replace(/ \(.*$/, '')} and solve again`);
    button.addEventListener('click', () => {
      this.state.model = m[1];
      this.store.changed('camera-options');
      this.render();
      this.solve();
    });
    return h('div', { class: 'msg msg-warning', role: 'status' }, text, ' ', button);
  }

  /** View `i` of the result selected: its numbers, and a button that excludes it and solves again. */
  pickView(r, i, out) {
    const v = r.views && r.views[i];
    if (!v) return;
    const img = this.store.session.images.find((x) => x.name === v.name);
    const exclude = h('button', { type: 'button', id: 'camera-exclude-view' }, `Exclude ${v.name} and solve again`);
    exclude.addEventListener('click', () => {
      if (img) {
        img.included = false;
        this.images.renderCard(img);
        this.images.refresh();
        this.store.changed('included');
      }
      this.solve();
    });
    const open = h('button', { type: 'button' }, 'Show the image');
    open.addEventListener('click', () => img && this.images.inspect(img));
    fill(out, h('p', { id: 'camera-view-selected' }, `View ${i + 1}: ${v.name}, reprojection RMS ${num(v.rms_px, 4)} px (overall ${num(r.rms_px, 4)} px).`),
      h('div', { class: 'row' }, exclude, img ? open : null));
  }

  /** Pick an image and see it as taken and undistorted (the core resamples it in the worker). */
  undistortSection(r) {
    if (this.readonly || !r.camera) return null;
    const imgs = this.store.session.images.filter((i) => i.info && this.store.bytes.has(i.id));
    if (!imgs.length) return null;
    const pick = h('select', { id: 'undistort-image' }, imgs.map((i) => h('option', { value: i.id }, i.name)));
    const status = h('p', { class: 'hint', id: 'undistort-status', 'aria-live': 'polite' });
    const before = h('canvas', { id: 'undistort-before', width: 4, height: 3, role: 'img', 'aria-label': 'the chosen image as taken' });
    const after = h('canvas', { id: 'undistort-after', width: 4, height: 3, role: 'img', 'aria-label': 'the chosen image undistorted' });
    const button = h('button', { type: 'button', id: 'undistort-show' }, 'Show undistorted');
    button.addEventListener('click', () => this.undistort(r, pick.value, { before, after, status, button }));
    return h('section', { class: 'undistort', 'aria-labelledby': 'undistort-title' },
      h('h3', { id: 'undistort-title' }, 'Undistorted preview'),
      h('div', { class: 'row' }, h('label', {}, 'Image ', pick), button),
      status,
      h('div', { class: 'plots' },
        h('figure', {}, before, h('figcaption', {}, 'As taken')),
        h('figure', {}, after, h('figcaption', {}, 'Undistorted: the same camera matrix without lens distortion (straight lines look straight)'))));
  }

  async undistort(r, id, { before, after, status, button }) {
    const img = this.store.session.images.find((i) => i.id === id);
    const bytes = img && this.store.bytes.get(id);
    if (!bytes) return;
    button.disabled = true;
    status.textContent = `Undistorting ${img.name}…`;
    try {
      const a = bytes.slice(0);
      const b = bytes.slice(0);
      const [orig, und] = await Promise.all([
        this.engine.call('preview', { bytes: a, maxSide: UNDISTORT_SIDE }, [a]),
        this.engine.call('undistort', { bytes: b, camera: JSON.stringify(r.camera), maxSide: UNDISTORT_SIDE }, [b]),
      ]);
      putPixels(before, orig);
      putPixels(after, und);
      status.textContent = `${img.name}: undistorted at ${und.image.width}×${und.image.height} px (preview).`;
    } catch (err) {
      status.textContent = `${img.name}: ${err.message}`;
    } finally {
      button.disabled = false;
    }
  }

  /**
   * The cross-validation (report key cross_validation): each model's two
   * halves, their median difference against its predicted uncertainty, and
   * the chosen model's difference map (grey where the halves have no data).
   */
  crossValidationSection(cv, [w, hgt]) {
    const chosen = cv.models[0];
    const canvas = h('canvas', { id: 'plot-cross-validation', width: 460, height: 340, role: 'img', 'aria-label': 'cross-validation difference map' });
    const map = chosen && chosen.diff_map_px && chosen.diff_map_px.length ? heatmap(canvas, {
      cols: cv.x_px.length, rows: cv.y_px.length, width_px: w, height_px: hgt,
      values: chosen.diff_map_px.flat().map((v) => (v === null ? NaN : v)),
    }, { title: `Two halves of the views with ${chosen.model}: projection difference` }) : null;
    const rows = cv.models.map((m) => [m.model + (m.chosen ? ' (chosen)' : ''),
      m.error ? '-' : num(m.diff_median_px, 3), m.error ? '-' : num(m.predicted_median_px, 3),
      m.error ? '-' : num(m.ratio_median, 1), m.error ? `not fitted: ${m.error}` : (m.agree ? 'agree' : 'disagree')]);
    return h('section', { id: 'camera-cross-validation', 'aria-labelledby': 'cross-validation-title' },
      h('h3', { id: 'cross-validation-title' }, `Cross-validation: ${cv.views[0]} and ${cv.views[1]} views`),
      h('p', { class: 'hint' }, 'Each half of the views is calibrated alone; halves that differ by about their predicted uncertainty mean the model fits the lens, many times more mean it does not.'),
      table(['model', 'median difference (px)', 'predicted (px)', 'ratio', 'halves'], rows, { id: 'camera-cross-validation-table' }),
      h('p', { id: 'camera-cross-validation-summary' }, cv.summary),
      map ? h('div', { class: 'plots' }, map) : null);
  }

  /** The `method: "all"` rows, and the core's note on methods it left out (said once). */
  comparisonTable(methods, note) {
    return h('div', {}, h('h3', {}, 'Methods side by side'),
      table(['method', 'fx', 'fy', 'cx', 'cy', 'k1', 'std u (px)', 'std v (px)', 'RMS (px)'],
        methods.map((m) => [m.method, num(m.fx, 3), num(m.fy, 3), num(m.cx, 3), num(m.cy, 3), num(m.k1, 5),
          num(m.std_u_px, 4), num(m.std_v_px, 4), m.error ? m.error : num(m.rms_px, 4)]), { id: 'camera-methods' }),
      note ? h('p', { id: 'camera-methods-note', class: 'note' }, note) : null);
  }

  /** The robust option's rejections: the core's sentence, and every rejected point with its place in the image. */
  rejectedNote(r) {
    const rows = (r.views || []).flatMap((v) => (v.outliers || []).map((o) => [v.name, o.index, `${num(o.x_px, 1)}, ${num(o.y_px, 1)}`, num(o.residual_px, 3)]));
    return h('div', { id: 'camera-rejected' }, message(rows.length ? 'warning' : 'info', r.rejected.summary),
      rows.length ? h('details', {}, h('summary', {}, `Where: the ${rows.length} rejected point${rows.length === 1 ? '' : 's'}`),
        h('div', { class: 'table-scroll' }, table(['view', 'point', 'at x, y (px)', 'residual (px)'], rows, { id: 'camera-rejected-points' }))) : null);
  }

  correlationNote({ names, matrix }) {
    const strong = [];
    for (let i = 0; i < matrix.length; i++) for (let j = i + 1; j < matrix.length; j++) if (Math.abs(matrix[i][j]) > 0.95) strong.push(`${names[i]}–${names[j]}: ${num(matrix[i][j], 3)}`);
    const advice = 'Add views with more tilt and coverage to separate them.';
    if (strong.length > FOLD_PAIRS) return foldedPairs('camera-correlation-note', `${strong.length} pairs of parameters are strongly correlated (|r| > 0.95). ${advice}`, strong);
    return strong.length ? message('warning', `Strongly correlated parameters (|r| > 0.95): ${strong.join(', ')}. ${advice}`) : null;
  }
}

/**
 * A standard deviation as shown: 3 decimals from 0.01 up, 3 significant
 * digits in exponent form below (so a small std does not read "0.000"),
 * "held" for a parameter the solve did not move (std exactly 0).
 */
function stdText(x) {
  if (x === 0) return 'held';
  if (typeof x === 'number' && Number.isFinite(x) && Math.abs(x) < 0.01) return x.toExponential(2);
  return num(x, 3);
}

