// Step 8: share. A link whose URL fragment holds the results (never the
// images), compressed; the fragment is not sent to any server. And a
// self-contained HTML report for download (no scripts, plots as images).
import { $, h, fill, download, message, table, num } from '../lib/dom.js';
import { combinedReport } from './export.js';

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
  return payload;
}

export function sharedFragment() {
  return location.hash.startsWith(PREFIX) ? location.hash.slice(PREFIX.length) : null;
}

export function sharePayload(session, version) {
  return {
    kind: 'robocal-share', schema: 1, robocal_version: version,
    target: session.target,
    camera: session.camera.result ? { result: session.camera.result, comparison: session.camera.comparison, model: session.camera.model, method: session.camera.method } : null,
    handeye: session.handeye.result ? { result: session.handeye.result, setup: session.handeye.setup } : null,
    workflows: session.workflows,
  };
}

export class ShareView {
  constructor(store, version, plotsProvider) {
    this.store = store;
    this.version = version;
    this.plotsProvider = plotsProvider;
    this.render();
    store.onChange((what) => { if (/result|all|shared/.test(what)) this.render(); });
  }

  render() {
    const s = this.store.session;
    if (!s.camera.result && !s.handeye.result) {
      fill($('share-panel'), message('info', 'Solve a camera or a hand-eye calibration first: the link and the report hold their results.'));
      return;
    }
    this.link = h('input', { type: 'text', readonly: true, id: 'share-link', 'aria-label': 'share link', class: 'wide' });
    this.status = h('p', { class: 'hint', 'aria-live': 'polite', id: 'share-status' });
    fill($('share-panel'),
      h('p', {}, 'The link holds the results (not the images) compressed in its fragment (after #), which browsers never send to a server. Whoever opens it sees a read-only results page.'),
      h('div', { class: 'row' },
        h('button', { type: 'button', class: 'primary', id: 'make-share', onclick: () => this.makeLink() }, 'Create share link'),
        h('button', { type: 'button', id: 'copy-share', onclick: () => this.copy() }, 'Copy link'),
        h('button', { type: 'button', id: 'download-report', onclick: () => this.downloadReport() }, 'Download HTML report')),
      this.link, this.status);
  }

  async makeLink() {
    const data = await encodeShare(sharePayload(this.store.session, this.version));
    this.link.value = `${location.origin}${location.pathname}${PREFIX}${data}`;
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
    download('robocal-report.html', await reportHtml(this.store.session, this.version, this.plotsProvider()), 'text/html');
  }
}

/** The report's style sheet: allowed by its hash in the report's CSP. */
const REPORT_STYLE = `body{font-family:system-ui,sans-serif;max-width:960px;margin:2rem auto;padding:0 1rem;color:#1b1d21}
table{border-collapse:collapse}td,th{border-bottom:1px solid #ccc;padding:.2rem .6rem;text-align:right}
td:first-child,th:first-child{text-align:left}.warn{background:#fff3cd;padding:.4rem}img{max-width:100%}pre{white-space:pre-wrap}`;

async function sha256Base64(text) {
  const digest = new Uint8Array(await crypto.subtle.digest('SHA-256', new TextEncoder().encode(text)));
  return btoa(String.fromCharCode(...digest));
}

/**
 * A self-contained HTML report: tables, warnings and plots as PNG images; no
 * scripts. Built as a DOM (every value a text node or an attribute set by
 * setAttribute, so a crafted share link's strings stay text) and serialised.
 * Its own CSP: nothing loads, nothing runs; only its style (by hash) and
 * its embedded data: images.
 */
export async function reportHtml(session, version, canvases) {
  const doc = document.implementation.createHTMLDocument('robocal calibration report');
  const el = (tag, attrs = {}, ...children) => {
    const e = doc.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
    for (const c of children.flat()) if (c !== null && c !== undefined) e.append(typeof c === 'object' && 'nodeType' in c ? c : doc.createTextNode(String(c)));
    return e;
  };
  const adopt = (node) => doc.importNode(node, true);
  const text = (w) => (typeof w === 'string' ? w : w && typeof w.message === 'string' ? w.message : JSON.stringify(w));
  const csp = `default-src 'none'; style-src 'sha256-${await sha256Base64(REPORT_STYLE)}'; img-src data:; base-uri 'none'; form-action 'none'`;
  doc.documentElement.setAttribute('lang', 'en');
  doc.head.prepend(el('meta', { charset: 'utf-8' }), el('meta', { 'http-equiv': 'Content-Security-Policy', content: csp }));
  doc.head.append(el('style', {}, REPORT_STYLE));
  const body = doc.body;
  body.append(el('h1', {}, 'robocal calibration report'),
    el('p', {}, `robocal ${version} · generated in the browser; no data left the machine.`));
  const cam = session.camera.result;
  if (cam) {
    const k = (cam.camera_matrix || []).flat();
    const rows = [['fx', k[0]], ['fy', k[4]], ['cx', k[2]], ['cy', k[5]], ['skew', k[1]], ...Object.entries(cam.distortion || {})]
      .map(([n, v]) => [n, num(v, 6), num((cam.std || {})[n], 3)]);
    body.append(el('h2', {}, `Camera (${cam.model})`),
      el('p', {}, `RMS reprojection error ${num(cam.rms_px, 4)} px over ${Array.isArray(cam.views) ? cam.views.length : 0} views.`),
      adopt(table(['parameter', 'value', 'std'], rows)));
    for (const w of Array.isArray(cam.warnings) ? cam.warnings : []) body.append(el('p', { class: 'warn' }, text(w)));
  }
  const he = session.handeye.result;
  if (he) {
    body.append(el('h2', {}, `Hand-eye (${session.handeye.setup})`));
    for (const key of ['gripper_from_camera', 'base_from_camera', 'base_from_target', 'gripper_from_target']) {
      if (!he[key]) continue;
      const list = (a, f) => (Array.isArray(a) ? a.map(f).join(', ') : '—');
      const t = list(he[key].translation_m, (v) => num(v * 1000, 3));
      const q = list(he[key].quaternion_xyzw, (v) => num(v, 6));
      body.append(el('p', {}, el('b', {}, key), `: translation (mm) [${t}], quaternion xyzw [${q}]`));
    }
    if (he.errors && typeof he.errors === 'object') body.append(adopt(table(['error', 'value'], Object.entries(he.errors).map(([n, v]) => [n, num(v, 4)]))));
    for (const w of Array.isArray(he.warnings) ? he.warnings : []) body.append(el('p', { class: 'warn' }, text(w)));
  }
  for (const c of canvases || []) {
    let src;
    try { src = c.toDataURL('image/png'); } catch (e) { continue; } // a tainted canvas is skipped
    body.append(el('figure', {}, el('img', { alt: c.getAttribute('aria-label') || 'plot', src })));
  }
  body.append(el('h2', {}, 'Full results (JSON)'), el('pre', {}, JSON.stringify(combinedReport(session), null, 2)));
  return `<!doctype html>\n${doc.documentElement.outerHTML}\n`;
}
