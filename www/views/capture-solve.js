// The running calibration of live capture: after each captured frame with
// the board, the camera is solved again from the captured views (the same
// 'calibrate' request as step 3, on the page's main worker, so the live
// detection never waits for it). Shown: the parameters with their standard
// deviations, the projection-uncertainty map of the newest solve, and the
// worst and median uncertainty over the image, solve after solve.
import { $, fill, table, num } from '../lib/dom.js';
import { heatmap, lines } from '../lib/plot.js';

/** Views needed before the first solve (Zhang's method needs 3; one more gives it a check). */
export const FIRST_SOLVE_VIEWS = 4;

/** Worst and median of a projection-uncertainty grid (null cells left out). */
export function uncertaintySummary(pu) {
  const values = (pu && pu.std_px ? pu.std_px.flat() : []).filter((v) => v !== null && Number.isFinite(v)).sort((a, b) => a - b);
  if (!values.length) return null;
  return { worst_px: values[values.length - 1], median_px: values[Math.floor(values.length / 2)] };
}

export class RunningSolve {
  /** `views()` lists the session images to solve from (captured, included, detected). */
  constructor(store, engine, views) {
    this.store = store;
    this.engine = engine;
    this.views = views;
    this.running = false;
    this.again = false;
    this.history = []; // { views, worst_px, median_px, report }
    this.listeners = new Set();
  }

  /** Call `fn(entry)` after each solve (the guide uses its uncertainty). */
  onSolved(fn) { this.listeners.add(fn); }

  get latest() { return this.history[this.history.length - 1] || null; }

  /** Solve now, or right after the solve that is running (never two at once, never a queue). */
  async update() {
    if (this.running) { this.again = true; return; }
    // A frame captured twice (the board and camera both still: the same
    // points) adds nothing and the solver refuses it: the first one is used.
    const seen = new Set();
    const all = this.views();
    const views = all.filter((i) => { const key = JSON.stringify(i.detection.points); return !seen.has(key) && seen.add(key); });
    this.duplicates = all.length - views.length;
    if (views.length < FIRST_SOLVE_VIEWS) {
      $('capture-solve-summary').textContent = `The running calibration starts at ${FIRST_SOLVE_VIEWS} captured views with the board (${views.length} so far).`;
      return;
    }
    this.running = true;
    $('capture-solve-summary').dataset.busy = 'yes';
    const st = this.store.session.camera;
    const input = { model: st.model, method: 'zhang', options: {}, views: views.map((i) => ({ name: i.name, detection: i.detection })) };
    try {
      const result = await this.engine.call('calibrate', { input: JSON.stringify(input) });
      const report = result.report || result;
      const entry = { views: views.length, report, ...uncertaintySummary(report.projection_uncertainty) };
      this.history.push(entry);
      this.show(entry);
      for (const fn of this.listeners) fn(entry);
    } catch (err) {
      $('capture-solve-summary').textContent = `The running calibration failed with ${views.length} views: ${err.message}`;
    } finally {
      this.running = false;
    }
    if (this.again) { this.again = false; await this.update(); }
    if (!this.running) $('capture-solve-summary').dataset.busy = 'no';
  }

  show(entry) {
    const r = entry.report;
    const k = r.camera_matrix.flat();
    const value = { fx: k[0], fy: k[4], cx: k[2], cy: k[5], ...(r.distortion || {}) };
    const std = r.std || {};
    const summary = $('capture-solve-summary');
    summary.textContent = `Solved from ${entry.views} captured views: RMS ${num(r.rms_px, 3)} px; projection uncertainty (1 sigma) worst ${num(entry.worst_px, 3)} px, median ${num(entry.median_px, 3)} px over the image.${this.duplicates ? ` ${this.duplicates} capture${this.duplicates === 1 ? '' : 's'} with the same points as an earlier one left out.` : ''}`;
    summary.dataset.views = String(entry.views);
    summary.dataset.worstPx = String(entry.worst_px);
    // Every solve's view count and worst uncertainty, for scripts: "4:0.31,5:0.27".
    summary.dataset.history = this.history.map((e) => `${e.views}:${e.worst_px}`).join(',');
    fill($('capture-solve-params'), table(['parameter', 'value', 'std'], Object.keys(value).map((n) => [n, num(value[n], 5), std[n] === undefined ? '—' : num(std[n], 3)]), { id: 'capture-params' }));
    const pu = r.projection_uncertainty;
    const [w, hh] = r.image_size_px;
    if (pu && pu.std_px && pu.std_px.length) {
      heatmap($('capture-uncertainty'), {
        cols: pu.x_px.length, rows: pu.y_px.length, width_px: w, height_px: hh, values: pu.std_px.flat().map((v) => (v === null ? NaN : v)),
      }, { title: `Projection uncertainty, ${entry.views} views (1 sigma)` });
    }
    const solved = this.history.filter((e) => Number.isFinite(e.worst_px));
    if (solved.length) {
      lines($('capture-uncertainty-history'), [
        { label: 'worst over the image', xs: solved.map((e) => e.views), ys: solved.map((e) => e.worst_px), markers: true },
        { label: 'median', xs: solved.map((e) => e.views), ys: solved.map((e) => e.median_px), markers: true, dashed: true },
      ], { xlabel: 'captured views', ylabel: 'uncertainty (px)', title: 'Projection uncertainty as views are added' });
    }
  }
}
