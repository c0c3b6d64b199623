// Step 9: share. A link whose URL fragment holds the results (never the
// images or the detections), compressed; the fragment is not sent to any
// server. A session file (detections, poses, options, results) to save and
// load. And a self-contained HTML report (views/report.js).
import { $, h, fill, download, message } from '../lib/dom.js';
import { reportHtml } from './report.js';
import { checkSession, checkSharePayload } from '../lib/validate.js';
import { REPORT_KINDS } from '../lib/reports.js';

const PREFIX = '#share=';

function toBase64Url(bytes) {
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
}

function fromBase64Url(text) {
  const b64 = text.replace(/-/g, '+').replace(/_/g, '/');
  const bin = atob(b64 + '='.repeat((4 - (b64.length % 4)) % 4));
  return Uint8Array.from(bin, (c) => c.charCodeAt(0));
}

async function pipe(bytes, stream) {
  return new Uint8Array(await new Response(new Blob([bytes]).stream().pipeThrough(stream)).arrayBuffer());
}

/** Results -> URL-safe compressed text. */
export async function encodeShare(payload) {
  const json = new TextEncoder().encode(JSON.stringify(payload));
  return toBase64Url(await pipe(json, new CompressionStream('deflate-raw')));
}

/** The inverse of encodeShare; throws an Error that says what is wrong. */
export async function decodeShare(text) {
  let bytes;
  try {
    bytes = await pipe(fromBase64Url(text), new DecompressionStream('deflate-raw'));
  } catch (e) {
    throw new Error('this share link is damaged (it may have been cut off when it was copied)');
  }
  let payload;
  try {
    payload = JSON.parse(new TextDecoder().decode(bytes));
  } catch (e) {
    // It decompresses, but to no JSON (JSON.parse's own words name a token, not the link).
    throw new Error('this link does not hold robocal results (its content is not JSON)');
  }
  if (!payload || payload.kind !== 'robocal-share' || payload.schema !== 1) throw new Error('this link does not hold robocal results');
  try {
    return checkSharePayload(payload);
  } catch (e) {
    throw new Error(`this link's results are damaged: ${e.message}`);
  }
}

export function sharedFragment() {
  return location.hash.startsWith(PREFIX) ? location.hash.slice(PREFIX.length) : null;
}

/**
 * Keys of a result that grow with the number of views or points, and the
 * pose refinement's 12 x 12 covariance (the per-axis std stay): left out of
 * a link. The per-view reprojection RMS of the hand-eye refinements stay (a
 * number a view: the shared page says over how many views); the residuals
 * come as a sample (residualSample).
 */
const BULKY = new Set(['residuals_px', 'per_motion', 'distortion_field', 'camera_from_target', 'detections', 'covariance']);

/** Keys of a result kept with every digit. */
const EXACT = new Set(['camera', 'camera_matrix', 'distortion', 'rms_px', 'std']);

/** Significant digits of the other numbers in a link (0.1 µm on a metre, 1e-4 px on 1000 px). */
const LINK_DIGITS = 7;

/**
 * Keys drawn, never read as numbers, on the shared page, and their
 * significant digits: the projection uncertainty map (colours) and the
 * correlation matrix (|r| > 0.95 named to 3 decimals).
 */
const COARSE = new Map([['projection_uncertainty', 3], ['correlation', 5]]);

/**
 * A result without its per-point and per-motion data (a few KB): what a
 * link carries. Arrays of per-run samples (repeatability) go too, and the
 * matrix of a transform nested below the top level (the methods' rows keep
 * translation and quaternion); the per-view rows keep their name, RMS and
 * point counts. Numbers keep LINK_DIGITS significant digits (COARSE's keys fewer).
 */
export function compactResult(value, depth = 0, digits = LINK_DIGITS) {
  if (typeof value === 'number') return Number.isFinite(value) ? Number(value.toPrecision(digits)) : value;
  if (Array.isArray(value)) return value.map((v) => compactResult(v, depth + 1, digits));
  if (!value || typeof value !== 'object') return value;
  const out = {};
  const pose = 'translation_m' in value && 'quaternion_xyzw' in value;
  for (const [k, v] of Object.entries(value)) {
    if (BULKY.has(k) || k.endsWith('_samples') || (pose && depth > 1 && k === 'matrix_row_major')) continue;
    // The results themselves (camera, its matrix and coefficients, the
    // transforms) keep every digit: the shared page shows and exports them.
    const exact = depth === 0 && (EXACT.has(k) || (v && typeof v === 'object' && 'translation_m' in v));
    out[k] = exact ? v : compactResult(v, depth + 1, Math.min(digits, COARSE.get(k) || digits));
  }
  return out;
}

/**
 * At most `budget` of the camera's residuals, spread over every view (every
 * k-th point): the shared page's residual plots. Packed as 4 bytes a point,
 * base64: x and y in 256ths of the image's width and height, dx and dy
 * signed in steps of `step_px` (1/127 of the largest residual kept):
 * `{ total, image_size_px, step_px, counts, data }`, `counts[i]` the
 * points of the result's view i; null when none are kept.
 */
function residualSample(cam, budget) {
  const views = Array.isArray(cam.views) ? cam.views : [];
  const total = views.reduce((n, v) => n + (Array.isArray(v.residuals_px) ? v.residuals_px.length : 0), 0);
  const size = cam.image_size_px;
  if (!budget || !total || !Array.isArray(size)) return null;
  const every = Math.ceil(total / budget);
  let i = 0;
  const kept = views.map((v) => (Array.isArray(v.residuals_px) ? v.residuals_px : []).filter(() => i++ % every === 0));
  const points = kept.flat();
  const largest = Math.max(...points.map((r) => Math.max(Math.abs(r.dx), Math.abs(r.dy))), 1e-9);
  const step = Number((largest / 127).toPrecision(4));
  const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, Math.round(v)));
  let text = '';
  for (const r of points) {
    const q = [clamp((r.x / size[0]) * 256 - 0.5, 0, 255), clamp((r.y / size[1]) * 256 - 0.5, 0, 255), clamp(r.dx / step, -127, 127) & 255, clamp(r.dy / step, -127, 127) & 255];
    text += String.fromCharCode(...q);
  }
  return { total, image_size_px: size, step_px: step, counts: kept.map((k) => k.length), data: btoa(text) };
}

/**
 * A link's residual sample put back on the camera result's views (as
 * `residuals_px`, what the residual plots draw); `{ kept, total }`. Throws
 * when the sample does not hold its counts' points.
 */
export function restoreResiduals(result, sample) {
  const bytes = Uint8Array.from(atob(sample.data), (c) => c.charCodeAt(0));
  const kept = sample.counts.reduce((a, b) => a + b, 0);
  if (bytes.length !== 4 * kept) throw new Error(`the residual sample holds ${bytes.length} bytes, not the ${4 * kept} of its ${kept} points`);
  const [w, hgt] = sample.image_size_px;
  const signed = (b) => (b > 127 ? b - 256 : b);
  let k = 0;
  sample.counts.forEach((n, vi) => {
    const points = [];
    for (let j = 0; j < n; j++, k += 4) {
      points.push({ x: ((bytes[k] + 0.5) * w) / 256, y: ((bytes[k + 1] + 0.5) * hgt) / 256, dx: signed(bytes[k + 2]) * sample.step_px, dy: signed(bytes[k + 3]) * sample.step_px });
    }
    if (result.views && result.views[vi]) result.views[vi].residuals_px = points;
  });
  return { kept, total: sample.total };
}

/**
 * The hand-eye methods' rows as the shared page's table shows them: each
 * camera transform's translation (no rotation, no target transform).
 */
function compactMethods(rows) {
  const shown = ['gripper_from_camera', 'base_from_camera'];
  const hidden = ['base_from_target', 'gripper_from_target'];
  return rows.map((row) => {
    if (!row || typeof row !== 'object') return row;
    const out = {};
    for (const [k, v] of Object.entries(row)) {
      if (hidden.includes(k)) continue;
      out[k] = shown.includes(k) && v && Array.isArray(v.translation_m) ? { translation_m: v.translation_m } : v;
    }
    return out;
  });
}

/** Significant digits of the robot poses a link carries for the 3-D view. */
const POSE_DIGITS = 4;

/**
 * What a link (and the HTML report's JSON) holds. `residuals`: how many of
 * the camera's residuals to carry (a sample; 0: none); `robotPoses`: the
 * base_from_gripper poses of the hand-eye step's 3-D view; `link`: the
 * hand-eye methods' rows as the shared page shows them.
 */
export function sharePayload(session, version, { residuals = 0, robotPoses = [], link = false } = {}) {
  const cam = session.camera.result;
  const he0 = session.handeye.result;
  // A link's methods rows as its table shows them (the HTML report's JSON keeps them whole).
  const he = he0 && link && Array.isArray(he0.methods) ? { ...he0, methods: compactMethods(he0.methods) } : he0;
  let camera = null;
  if (cam) {
    const sample = residualSample(cam, residuals);
    camera = { result: compactResult(cam), comparison: session.camera.comparison, model: session.camera.model, method: session.camera.method, ...(sample ? { residualSample: sample } : {}) };
  }
  const round = (v) => Number(v.toPrecision(POSE_DIGITS));
  const poses = (robotPoses || []).map((p) => ({ translation_m: p.translation_m.map(round), quaternion_xyzw: p.quaternion_xyzw.map(round) }));
  return {
    kind: 'robocal-share', schema: 1, robocal_version: version,
    target: session.target,
    camera,
    handeye: he ? { result: compactResult(he), setup: session.handeye.setup, frameNames: session.handeye.frameNames, ...(poses.length ? { robotPoses: poses } : {}) } : null,
    workflows: compactResult(session.workflows),
    // The pose plan without its camera poses (no 3-D view on the shared
    // page) and the last check without its shift map: a few hundred bytes each.
    plan: session.plan && session.plan.result ? { result: compactPlan(session.plan.result), setup: session.plan.request && session.plan.request.setup } : null,
    check: session.check && session.check.result ? { name: session.check.name, result: compactCheck(session.check.result) } : null,
  };
}

/** Significant digits of a shared plan's poses (10 µm on a metre; the table shows 0.01 mm) and of its angles and distances. */
const PLAN_DIGITS = 5;
const PLAN_TABLE_DIGITS = 4;

/** A plan for a link: the predicted error, each pose's flange pose, tilt, distance and roll, the travel; not the camera poses, the motion statistics or the notes. */
function compactPlan(plan) {
  const round = (v, digits = PLAN_DIGITS) => Number(v.toPrecision(digits));
  const p = plan.predicted;
  return {
    predicted: { bound95_mm: p.bound95_mm, rms_mm: p.rms_mm, verdict: p.verdict },
    poses: plan.poses.map((x) => ({
      base_from_gripper: { translation_m: x.base_from_gripper.translation_m.map((v) => round(v)), quaternion_xyzw: x.base_from_gripper.quaternion_xyzw.map((v) => round(v)) },
      tilt_deg: round(x.tilt_deg, PLAN_TABLE_DIGITS), distance_m: round(x.distance_m, PLAN_TABLE_DIGITS), roll_deg: round(x.roll_deg, PLAN_TABLE_DIGITS),
    })),
    travel_m: round(plan.travel_m),
    candidates: plan.candidates,
  };
}

/** A check report for a link: the verdict, reasons, parameters and shift statistics, not the map. */
function compactCheck(report) {
  const { map, ...shift } = report.projection_shift_px || {};
  return compactResult({ ...report, projection_shift_px: report.projection_shift_px ? shift : null, refit: undefined });
}

/** The session file: everything but the image bytes (target, detections, poses, options, results). */
export function sessionFile(session, version) {
  return JSON.stringify({ kind: 'robocal-session', schema: 1, robocal_version: version, session }, null, 1);
}

/** The session a session file holds; throws an Error that says what is wrong. */
export function readSessionFile(text) {
  let doc;
  try { doc = JSON.parse(text); } catch (e) { throw new Error('this file is not a robocal session file (it is not JSON)'); }
  // A calibration report (its kind, docs/report-json.md) is no session: say where it loads.
  if (doc && typeof doc.kind === 'string' && REPORT_KINDS.includes(doc.kind)) {
    throw new Error(`this file is a robocal '${doc.kind}' report, not a session file: a report loads where the page takes a camera file (the check step, a rig camera's intrinsics, the laser step)`);
  }
  if (!doc || doc.kind !== 'robocal-session' || doc.schema !== 1 || !doc.session || typeof doc.session !== 'object') {
    throw new Error('this file is not a robocal session file (save one with "Download session file")');
  }
  if (!Array.isArray(doc.session.images)) throw new Error('this session file has no image list');
  try {
    return checkSession(doc.session, 'session');
  } catch (e) {
    throw new Error(`this session file is damaged: ${e.message}; nothing was loaded, the current session is kept`);
  }
}

/** Residual samples tried, largest first, until the link fits in LINK_CHARS. */
const RESIDUAL_BUDGETS = [240, 180, 120, 90, 60, 40, 0];
/** The longest link made with a residual sample (characters; browsers and servers take 8 KB request lines). */
const LINK_CHARS = 6400;

export class ShareView {
  /**
   * `loadSession(session)` replaces this tab's session (absent on a shared,
   * read-only page); `robotPoses()` the robot poses of the hand-eye step's
   * 3-D view, carried by the link.
   */
  constructor(store, version, plotsProvider, loadSession = null, robotPoses = () => []) {
    this.store = store;
    this.version = version;
    this.plotsProvider = plotsProvider;
    this.loadSession = loadSession;
    this.robotPoses = robotPoses;
    this.render();
    store.onChange((what) => { if (/result|all|shared/.test(what)) this.render(); });
  }

  render() {
    const s = this.store.session;
    const sessionTools = this.loadSession ? this.sessionSection() : null;
    if (!s.camera.result && !s.handeye.result && !(s.plan && s.plan.result) && !(s.check && s.check.result)) {
      fill($('share-panel'), message('info', 'Solve a camera or a hand-eye calibration, plan robot poses or check a saved calibration first: the link and the report hold their results.'), sessionTools);
      return;
    }
    this.link = h('input', { type: 'text', readonly: true, id: 'share-link', 'aria-label': 'share link', class: 'wide' });
    this.status = h('p', { class: 'hint', 'aria-live': 'polite', id: 'share-status' });
    fill($('share-panel'),
      h('p', {}, 'The link holds the results (camera, transforms, errors, a sample of the residuals, the robot poses of the 3-D view, the pose plan, the last check; not the images or the detections) compressed in its fragment (after #), which browsers never send to a server. Whoever opens it sees a read-only results page.'),
      h('div', { class: 'row' },
        h('button', { type: 'button', class: 'primary', id: 'make-share', onclick: () => this.makeLink() }, 'Create share link'),
        h('button', { type: 'button', id: 'copy-share', onclick: () => this.copy() }, 'Copy link'),
        h('button', { type: 'button', id: 'download-report', onclick: () => this.downloadReport() }, 'Download HTML report')),
      this.link, this.status, sessionTools);
  }

  /** Save the whole session (detections, poses, options, results; no image bytes) to a file, or load one. */
  sessionSection() {
    const input = h('input', { type: 'file', id: 'session-input', 'aria-label': 'session file', accept: '.json,application/json', hidden: true, tabindex: -1 });
    const status = h('p', { class: 'hint', id: 'session-status', 'aria-live': 'polite' });
    input.addEventListener('change', async () => {
      const file = input.files[0];
      input.value = '';
      if (!file) return;
      try {
        const session = readSessionFile(await file.text());
        if (this.store.session.images.length && !confirm('Replace this session with the one in the file? Images, detections and results of this session are removed from this browser.')) return;
        status.textContent = `Loading ${file.name}…`;
        await this.loadSession(session);
      } catch (err) {
        status.textContent = `${file.name}: ${err.message}`;
      }
    });
    return h('section', { 'aria-labelledby': 'session-title' },
      h('h3', { id: 'session-title' }, 'Session file'),
      h('p', { class: 'hint' }, 'A session file holds the target, the detected points of every image, the robot poses, the options and the results (not the images): load it here, in any browser, to carry on.'),
      h('div', { class: 'row' },
        h('button', { type: 'button', id: 'download-session', onclick: () => download('robocal-session.json', sessionFile(this.store.session, this.version), 'application/json') }, 'Download session file'),
        h('button', { type: 'button', id: 'load-session', onclick: () => input.click() }, 'Load session file…'), input),
      status);
  }

  async makeLink() {
    const base = `${location.origin}${location.pathname}${PREFIX}`;
    const robotPoses = this.store.session.handeye.result ? this.robotPoses() : [];
    let data = '';
    for (const residuals of RESIDUAL_BUDGETS) {
      data = await encodeShare(sharePayload(this.store.session, this.version, { residuals, robotPoses, link: true }));
      if (base.length + data.length <= LINK_CHARS) break;
    }
    this.link.value = `${base}${data}`;
    this.status.textContent = `Link ready: ${this.link.value.length} characters.`;
    return this.link.value;
  }

  async copy() {
    if (!this.link.value) await this.makeLink();
    try {
      await navigator.clipboard.writeText(this.link.value);
      this.status.textContent = 'Link copied.';
    } catch (err) {
      this.link.select();
      this.status.textContent = 'Select the link and copy it (the browser refused the clipboard).';
    }
  }

  async downloadReport() {
    const results = JSON.stringify(sharePayload(this.store.session, this.version), null, 1);
    download('robocal-report.html', await reportHtml(this.store.session, this.version, this.plotsProvider(), results), 'text/html');
  }
}
