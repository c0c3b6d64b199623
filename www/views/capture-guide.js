// The capture guide of live capture (LiveCapture in the live worker,
// docs/live-capture.md): auto-capture, why a frame was not kept, the
// coverage of the kept frames (image cells, tilt about both axes,
// distance), the suggested next pose drawn over the preview as the board
// outline to match, the guide's running calibration with the "good enough"
// criterion (worst projection uncertainty below 0.2 px with at least 8
// views; suggestions stop then) and, with robot poses, the hand-eye
// rotation-diversity advice.
//
// The guide's kept frames mirror the captured cards: `names[i]` is the card
// of the guide's capture i. Excluding a card excludes its capture from the
// guide (coverage, running calibration, hand-eye) and re-including it brings
// it back; removing a card removes its capture. A reload or a camera
// (re)start starts the guide afresh.
import { $, num } from '../lib/dom.js';

/** Views the guide's running calibration starts from (the core's MIN_VIEWS_TO_CALIBRATE). */
const GUIDE_FIRST_SOLVE = 4;
/**
 * Tilt bins as the user sees them. Positive tilt about the image x axis:
 * the board's top edge is farther from the camera than its bottom edge;
 * positive about the y axis: its right edge is farther (tests/node/live.mjs
 * checks the signs against the renderer's truth).
 */
const TILT_X = ['bottom edge away', 'upright', 'top edge away'];
const TILT_Y = ['left edge away', 'facing', 'right edge away'];
const DISTANCE = ['far', 'middle', 'near'];

export class CaptureGuide {
  /** `view` is the CaptureView (its live engine, capture() and the images). */
  constructor(view) {
    this.view = view;
    this.names = [];
    this.used = []; // whether the guide uses capture i (its card included)
    this.firsts = []; // the first detected point of each guide capture, for scripts
    this.report = null; // the newest frame report
    this.state = null; // the newest guide state (coverage, suggestion, good_enough, handeye)
    this.calibrated = null; // the guide's newest calibration reply
    this.history = []; // [captures, worst projection uncertainty px] of each guide solve
    this.solving = false;
    this.again = false;
  }

  get auto() { return $('capture-auto').checked; }

  /** A fresh guide (the camera opened again, perhaps at another size): the cards stay, the guide starts from none. */
  async reset() {
    Object.assign(this, { names: [], used: [], firsts: [], report: null, state: null, calibrated: null, history: [] });
    await this.call('reset');
    $('capture-guide').textContent = 'Show the board to the camera.';
    $('capture-handeye').hidden = true;
  }

  /** After each guided frame: auto-capture, the words, the coverage and the suggestion. */
  async frame(reply) {
    const r = reply.live;
    if (!r) return;
    this.report = r;
    // A frame report has no hand-eye guide: the last one stays.
    this.state = { ...r, handeye: this.state && this.state.handeye };
    if (r.keep) {
      const index = r.kept - 1;
      this.firsts[index] = r.points[0];
      this.used[index] = true;
      const name = await this.view.capture({ capture: 'auto' }, index);
      if (!name && !(await this.call('remove', { index }))?.error) { this.used.splice(index, 1); this.firsts.splice(index, 1); }
      this.solve();
    }
    this.show();
  }

  /** A guide request on the live worker; its state (if any) becomes the shown one. */
  async call(op, args = {}) {
    if (!this.view.live) return null;
    try {
      const out = await this.view.live.call('guide', { op, ...args });
      if (out && out.coverage) this.state = out;
      return out;
    } catch (err) {
      return { error: err.message };
    }
  }

  /** A manual capture named `name`: the guide keeps the frame it saw last (when it had the board). */
  async manual(name) {
    const out = await this.call('capture');
    if (!out || out.error) return null;
    this.names[out.index] = name;
    this.used[out.index] = true;
    this.firsts[out.index] = this.report && this.report.points[0];
    this.solve();
    this.show();
    return out.index;
  }

  /** The guide's capture `index` is the card `name`. */
  named(index, name) { this.names[index] = name; }

  /** Pair the guide's capture of `name` with a robot pose (`base_from_gripper` pose JSON). */
  async robotPose(name, pose) {
    const index = this.names.indexOf(name);
    if (index < 0 || !pose) return;
    await this.call('robotPose', { index, pose: JSON.stringify(pose) });
    this.show();
  }

  /**
   * The guide follows the cards: a removed card's capture leaves it (newest
   * first, so the indices hold), an excluded one is set aside and comes
   * back when its card is included again; the guide then solves again.
   */
  async sync() {
    const images = this.view.images.images;
    let changed = false;
    for (let i = this.names.length - 1; i >= 0; i--) {
      if (!this.names[i]) continue; // its card is being stored
      const img = images.find((im) => im.name === this.names[i]);
      if (!img) {
        const out = await this.call('remove', { index: i });
        if (out && !out.error) { this.names.splice(i, 1); this.used.splice(i, 1); this.firsts.splice(i, 1); changed = true; }
      } else if (Boolean(img.included) !== this.used[i]) {
        const out = await this.call('include', { index: i, included: Boolean(img.included) });
        if (out && !out.error) { this.used[i] = Boolean(img.included); changed = true; }
      }
    }
    if (changed) this.solve();
    this.show();
  }

  /** The guide's running calibration (never two at once; one more after the running one if asked). */
  async solve() {
    const used = this.state ? this.state.used : 0;
    if (used < GUIDE_FIRST_SOLVE) return;
    if (this.solving) { this.again = true; return; }
    this.solving = true;
    const out = await this.call('calibrate');
    this.solving = false;
    if (out && !out.error) { this.calibrated = out; this.history.push([out.used, out.max_std_px]); }
    this.show();
    if (this.again) { this.again = false; await this.solve(); }
  }

  /** The guide's words and data for scripts, and the coverage drawing. */
  show() {
    const g = $('capture-guide');
    const st = this.state;
    if (!st) return;
    const r = this.report;
    const words = [];
    if (st.good_enough && this.calibrated) {
      words.push(`Good enough: the worst projection uncertainty over the image is ${num(this.calibrated.max_std_px, 3)} px (below 0.2 px) with ${st.used} captures. No more poses are needed: solve in step 3 or export.`);
    } else {
      if (r) words.push(r.keep ? `Captured (${st.kept} so far).` : `Not captured: ${r.message}${r.reason === 'moving' && r.motion_px !== null ? ` (moved ${num(r.motion_px, 2)} px, at most 1.5 px)` : ''}${r.reason === 'blurred' ? ` (blur ${num(r.blur_px, 2)} px, at most 1.6 px)` : ''}.`);
      if (this.calibrated) words.push(`Guide's calibration from ${this.calibrated.used} captures: worst projection uncertainty ${num(this.calibrated.max_std_px, 3)} px (good enough below 0.2 px with at least 8 captures).`);
      if (st.suggestion) words.push(`Next: ${st.suggestion.why}`);
    }
    g.textContent = words.join(' ');
    g.dataset.kept = String(st.kept);
    g.dataset.used = String(st.used);
    g.dataset.reason = r ? r.reason : '';
    g.dataset.goodEnough = st.good_enough ? 'yes' : 'no';
    g.dataset.rule = st.suggestion ? st.suggestion.rule : '';
    g.dataset.suggestion = st.suggestion ? JSON.stringify(st.suggestion.outline_px.map((p) => p.map((v) => Math.round(v)))) : '';
    g.dataset.maxStdPx = this.calibrated ? String(this.calibrated.max_std_px) : '';
    g.dataset.history = this.history.map(([n, w]) => `${n}:${w}`).join(',');
    g.dataset.cells = String(st.coverage.cells.filter((n) => n > 0).length);
    g.dataset.names = this.names.join(',');
    g.dataset.firsts = JSON.stringify(this.firsts);
    const he = $('capture-handeye');
    he.hidden = !st.handeye || !st.handeye.poses;
    if (!he.hidden) {
      const h = st.handeye;
      he.textContent = `Hand-eye: ${h.poses} captures with robot poses, ${h.motions} motions; rotation axes spread ${h.axis_spread_deg.toFixed(1)} degrees${h.enough ? ' (enough).' : ' (at least 30 degrees and 3 motions wanted).'} ${h.advice.charAt(0).toUpperCase()}${h.advice.slice(1)}${/[.!]$/.test(h.advice) ? '' : '.'}`;
      he.dataset.enough = h.enough ? 'yes' : 'no';
    }
    drawCoverage($('capture-coverage'), st.coverage);
  }

  /** The suggested outline over the preview (after the detection's drawing). */
  drawSuggestion(ctx, width) {
    const s = this.state && this.state.suggestion;
    if (!s) return;
    const o = s.outline_px;
    ctx.save();
    ctx.lineWidth = Math.max(2, width / 320);
    ctx.setLineDash([12, 8]);
    ctx.strokeStyle = '#17becf';
    ctx.beginPath();
    o.forEach(([x, y], i) => (i ? ctx.lineTo(x, y) : ctx.moveTo(x, y)));
    ctx.closePath();
    ctx.stroke();
    // The board's origin corner, as the detected first point is marked.
    ctx.setLineDash([]);
    ctx.fillStyle = '#17becf';
    ctx.beginPath();
    ctx.arc(o[0][0], o[0][1], Math.max(4, width / 160), 0, 2 * Math.PI);
    ctx.fill();
    ctx.font = `${Math.round(Math.max(12, width / 45))}px system-ui`;
    ctx.lineWidth = 3;
    ctx.strokeStyle = 'rgba(0,0,0,0.8)';
    const label = 'next pose: match this outline';
    const [lx, ly] = [Math.min(...o.map((p) => p[0])), Math.max(12, Math.min(...o.map((p) => p[1])) - 6)];
    ctx.strokeText(label, lx, ly);
    ctx.fillText(label, lx, ly);
    ctx.restore();
  }
}

/** Image cells (points per cell), the 3 x 3 tilt bins and the 3 distance bins, frames kept in each. */
function drawCoverage(canvas, cov) {
  const ctx = canvas.getContext('2d');
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  ctx.font = '12px system-ui';
  ctx.textBaseline = 'middle';
  const shade = (n, full) => (n ? `rgba(44,160,44,${0.25 + 0.75 * Math.min(1, n / full)})` : 'rgba(214,39,40,0.15)');
  const [cols, rows] = cov.grid;
  const cw = 22, top = 22;
  ctx.fillStyle = '#222';
  ctx.fillText('image cells', 0, 9);
  for (let y = 0; y < rows; y++) {
    for (let x = 0; x < cols; x++) {
      ctx.fillStyle = shade(cov.cells[y * cols + x], 20);
      ctx.fillRect(x * cw, top + y * cw, cw - 2, cw - 2);
    }
  }
  const tx = cols * cw + 130;
  ctx.fillStyle = '#222';
  ctx.fillText('tilt (frames)', tx, 9);
  for (let i = 0; i < 3; i++) {
    // Rows: about the image x axis, top edge away first; columns: about y.
    const bx = 2 - i;
    ctx.textAlign = 'right';
    ctx.fillStyle = '#222';
    ctx.fillText(TILT_X[bx], tx - 4, top + i * 34 + 16);
    for (let by = 0; by < 3; by++) {
      const n = cov.tilt[bx][by];
      ctx.fillStyle = shade(n, 3);
      ctx.fillRect(tx + by * 34, top + i * 34, 32, 32);
      ctx.fillStyle = '#222';
      ctx.textAlign = 'center';
      ctx.fillText(String(n), tx + by * 34 + 16, top + i * 34 + 16);
    }
  }
  ctx.save();
  ctx.textAlign = 'center';
  ctx.font = '10px system-ui';
  TILT_Y.forEach((t, by) => ctx.fillText(t.split(' ')[0], tx + by * 34 + 16, top + 3 * 34 + 8));
  ctx.fillText('(edge away)', tx + 51, top + 3 * 34 + 20);
  ctx.restore();
  const dx = tx + 3 * 34 + 40;
  ctx.textAlign = 'left';
  ctx.fillStyle = '#222';
  ctx.fillText('distance (frames)', dx, 9);
  DISTANCE.forEach((d, i) => {
    ctx.fillStyle = shade(cov.distance[i], 3);
    ctx.fillRect(dx, top + i * 34, 40, 32);
    ctx.fillStyle = '#222';
    ctx.fillText(`${d}: ${cov.distance[i]}`, dx + 46, top + i * 34 + 16);
  });
  ctx.textAlign = 'start';
}
