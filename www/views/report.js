// The HTML report: one self-contained page to read and to archive. The
// parameters with their standard deviations (significant digits, so a small
// std never reads 0.000), the plots as images, the per-view table, the
// hand-eye transforms and errors, and the results JSON attached as a
// download link (not printed inline). No scripts; its own CSP.

/** The report's style sheet: allowed by its hash in the report's CSP. */
const REPORT_STYLE = `body{font-family:system-ui,sans-serif;max-width:960px;margin:2rem auto;padding:0 1rem;color:#1b1d21;line-height:1.4}
table{border-collapse:collapse;margin:.5rem 0}td,th{border-bottom:1px solid #ccc;padding:.2rem .6rem;text-align:right;font-variant-numeric:tabular-nums}
td:first-child,th:first-child{text-align:left}.warn{background:#fff3cd;padding:.4rem}
.plots{display:grid;grid-template-columns:repeat(auto-fill,minmax(300px,1fr));gap:.6rem}
figure{margin:0}img{width:100%;height:auto;border:1px solid #ddd}figcaption{font-size:.85rem;color:#555}
.hint{color:#555;font-size:.9rem}`;

async function sha256Base64(text) {
  const digest = new Uint8Array(await crypto.subtle.digest('SHA-256', new TextEncoder().encode(text)));
  return btoa(String.fromCharCode(...digest));
}

/** `x` with `n` significant digits; exponent form outside [1e-4, 1e6). */
export function sig(x, n = 2) {
  if (typeof x !== 'number') return x === null || x === undefined ? '—' : String(x);
  if (!Number.isFinite(x)) return String(x);
  if (x === 0) return '0';
  const a = Math.abs(x);
  if (a < 1e-4 || a >= 1e6) return x.toExponential(n - 1);
  return String(Number(x.toPrecision(n)));
}

/**
 * A value and its standard deviation as printed: the std to 2 significant
 * digits, the value to the same last decimal place (900.12 ± 0.35,
 * -0.28153 ± 0.00012); a held parameter (std 0) says "held".
 */
export function valueWithStd(value, std) {
  if (typeof value !== 'number' || !Number.isFinite(value)) return [sig(value), sig(std)];
  if (std === 0) return [String(Number(value.toPrecision(7))), 'held'];
  if (typeof std !== 'number' || !Number.isFinite(std) || std < 0) return [String(Number(value.toPrecision(7))), '—'];
  const decimals = Math.min(12, Math.max(0, 1 - Math.floor(Math.log10(std))));
  const a = Math.abs(value);
  const v = a !== 0 && (a < 1e-4 || a >= 1e6) ? value.toExponential(Math.max(1, decimals + Math.floor(Math.log10(a)))) : value.toFixed(decimals);
  return [v, sig(std, 2)];
}

function base64Utf8(text) {
  const bytes = new TextEncoder().encode(text);
  let s = '';
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

/**
 * Built as a DOM (every value a text node or an attribute set by
 * setAttribute, so a crafted share link's strings stay text) and serialised.
 * Its own CSP: nothing loads, nothing runs; only its style (by hash) and its
 * embedded data: images. `resultsJson` is attached as a data: download link.
 */
export async function reportHtml(session, version, canvases, resultsJson) {
  const doc = document.implementation.createHTMLDocument('robocal calibration report');
  const el = (tag, attrs = {}, ...children) => {
    const e = doc.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
    for (const c of children.flat()) if (c !== null && c !== undefined) e.append(typeof c === 'object' && 'nodeType' in c ? c : doc.createTextNode(String(c)));
    return e;
  };
  const tbl = (id, headers, rows) => el('table', { id },
    el('thead', {}, el('tr', {}, headers.map((t) => el('th', { scope: 'col' }, t)))),
    el('tbody', {}, rows.map((r) => el('tr', {}, r.map((c) => el('td', {}, c))))));
  const text = (w) => (typeof w === 'string' ? w : w && typeof w.message === 'string' ? w.message : JSON.stringify(w));
  const list = (a, f) => (Array.isArray(a) ? a.map(f).join(', ') : '—');
  const csp = `default-src 'none'; style-src 'sha256-${await sha256Base64(REPORT_STYLE)}'; img-src data:; base-uri 'none'; form-action 'none'`;
  doc.documentElement.setAttribute('lang', 'en');
  doc.head.prepend(el('meta', { charset: 'utf-8' }), el('meta', { 'http-equiv': 'Content-Security-Policy', content: csp }),
    el('meta', { name: 'viewport', content: 'width=device-width, initial-scale=1' }));
  doc.head.append(el('style', {}, REPORT_STYLE));
  const body = doc.body;
  body.append(el('h1', {}, 'robocal calibration report'),
    el('p', {}, `robocal ${version} · generated in the browser; no data left the machine.`));
  if (resultsJson) {
    body.append(el('p', {}, el('a', { id: 'results-json', download: 'robocal-results.json', href: `data:application/json;base64,${base64Utf8(resultsJson)}` }, 'Download the results as JSON'),
      ' (camera, transforms, errors; the detected points are in the session file, saved from the page\'s Share step).'));
  }
  const cam = session.camera.result;
  if (cam) {
    const k = (Array.isArray(cam.camera_matrix) ? cam.camera_matrix : []).flat();
    const std = cam.std && typeof cam.std === 'object' ? cam.std : {};
    const rows = [['fx', k[0]], ['fy', k[4]], ['cx', k[2]], ['cy', k[5]], ['skew', k[1]], ...Object.entries(cam.distortion || {})]
      .map(([n, v]) => [n, ...valueWithStd(v, std[n])]);
    const views = Array.isArray(cam.views) ? cam.views : [];
    body.append(el('h2', {}, `Camera (${cam.model})`),
      el('p', {}, `RMS reprojection error ${sig(cam.rms_px, 3)} px over ${views.length} views` + (Array.isArray(cam.image_size_px) ? `, images ${cam.image_size_px.join(' × ')} px.` : '.')),
      tbl('report-params', ['parameter', 'value', 'std (1 sigma)'], rows));
    for (const w of Array.isArray(cam.warnings) ? cam.warnings : []) body.append(el('p', { class: 'warn' }, text(w)));
    if (views.length) {
      body.append(el('h3', {}, 'Per view'), tbl('report-views', ['view', 'RMS (px)', 'points used', 'points rejected'],
        views.map((v) => [v.name, sig(v.rms_px, 3), v.n_points, Array.isArray(v.outliers) ? v.outliers.length : '—'])));
    }
  }
  const he = session.handeye.result;
  if (he) {
    body.append(el('h2', {}, `Hand-eye (${session.handeye.setup})`));
    for (const key of ['gripper_from_camera', 'base_from_camera', 'base_from_target', 'gripper_from_target']) {
      if (!he[key]) continue;
      const t = list(he[key].translation_m, (v) => sig(v * 1000, 6));
      const q = list(he[key].quaternion_xyzw, (v) => sig(v, 6));
      body.append(el('p', {}, el('b', {}, key), `: translation (mm) [${t}], quaternion xyzw [${q}]`));
    }
    const pstd = he.pose_refinement && he.pose_refinement.camera_transform_std;
    if (pstd && Array.isArray(pstd.translation_mm)) {
      body.append(el('p', { class: 'hint' }, `std (1 sigma): translation ${list(pstd.translation_mm, (v) => sig(v, 2))} mm, rotation ${list(pstd.rotation_deg, (v) => sig(v, 2))} deg`));
    }
    if (he.errors && typeof he.errors === 'object') body.append(tbl('report-handeye-errors', ['error', 'value'], Object.entries(he.errors).map(([n, v]) => [n, sig(v, 4)])));
    for (const w of Array.isArray(he.warnings) ? he.warnings : []) body.append(el('p', { class: 'warn' }, text(w)));
  }
  const figures = [];
  for (const c of canvases || []) {
    let src;
    try { src = c.toDataURL('image/png'); } catch (e) { continue; } // a tainted canvas is skipped
    const label = c.getAttribute('aria-label') || 'plot';
    figures.push(el('figure', {}, el('img', { alt: label, src }), el('figcaption', {}, label)));
  }
  if (figures.length) body.append(el('h2', {}, 'Plots'), el('div', { class: 'plots' }, figures));
  return `<!doctype html>\n${doc.documentElement.outerHTML}\n`;
}
