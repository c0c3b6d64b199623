// Small DOM helpers: element creation without innerHTML (strict CSP, no
// injection of file names or error text).

/** h('p', { class: 'x', onclick: f }, 'text', child) -> element */
export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith('on') && typeof v === 'function') el.addEventListener(k.slice(2), v);
    else if (k === 'class') el.className = v;
    else if (k === 'dataset') Object.assign(el.dataset, v);
    else if (v === true) el.setAttribute(k, '');
    else el.setAttribute(k, String(v));
  }
  for (const c of children.flat()) {
    if (c === undefined || c === null || c === false) continue;
    el.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
  return el;
}

export const $ = (id) => document.getElementById(id);

/** Replace the children of `el`. */
export function fill(el, ...children) {
  el.replaceChildren(...children.flat().filter((c) => c !== null && c !== undefined && c !== false));
  return el;
}

/** A table from a header row and data rows (cells are text or nodes). */
export function table(headers, rows, attrs = {}) {
  return h('table', attrs,
    h('thead', {}, h('tr', {}, headers.map((t) => h('th', { scope: 'col' }, t)))),
    h('tbody', {}, rows.map((r) => h('tr', {}, r.map((c) => h('td', {}, c))))));
}

/** Format a number with `digits` significant decimals, '—' for null. */
export function num(x, digits = 4) {
  if (x === null || x === undefined || Number.isNaN(x)) return '—';
  if (typeof x !== 'number') return String(x);
  if (x !== 0 && (Math.abs(x) >= 1e6 || Math.abs(x) < 1e-4)) return x.toExponential(digits - 1);
  return x.toFixed(digits);
}

/** Format a number with exactly `digits` decimals (never exponential: a
 * unit vector's component near 0 reads 0.00003, not 3.0000e-5), '—' for null. */
export function fixed(x, digits = 4) {
  if (x === null || x === undefined || Number.isNaN(x)) return '—';
  if (typeof x !== 'number') return String(x);
  return x.toFixed(digits);
}

/** Offer `text` as a download named `name`. */
export function download(name, text, type = 'text/plain') {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = h('a', { href: url, download: name });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

/** A plain-words message box: kind is 'error', 'warning' or 'info'. */
export function message(kind, text) {
  return h('p', { class: `msg msg-${kind}`, role: kind === 'error' ? 'alert' : 'status' }, text);
}

/**
 * The text of a user's file, strictly as UTF-8 (File.text() would turn bytes
 * that are not UTF-8 into U+FFFD, and the reader would then blame the wrong
 * thing). Rejects an empty file and one that is not UTF-8 with a message
 * that says what to do; `what` names the content, e.g. "one robot pose a line".
 */
export async function readTextFile(file, what) {
  const bytes = new Uint8Array(await file.arrayBuffer());
  let text;
  try {
    text = new TextDecoder('utf-8', { fatal: true }).decode(bytes);
  } catch (e) {
    throw new Error('the file is not UTF-8 text: save it as UTF-8 (or plain ASCII) and load it again');
  }
  if (!text.trim()) throw new Error(`the file is empty${bytes.length ? ' (only white space)' : ''}: expected ${what}`);
  return text;
}

/**
 * Keep Tab and Shift+Tab inside a modal dialog while it is open (the last
 * control wraps to the first and back), close it with Escape (the
 * dialog's own cancel), and give focus back to what opened it.
 */
export function trapFocus(dialog) {
  let opener = null;
  const focusable = () => [...dialog.querySelectorAll('button, input, select, textarea, a[href], [tabindex]:not([tabindex="-1"])')]
    .filter((e) => !e.disabled && !e.hidden && e.getClientRects().length);
  dialog.addEventListener('keydown', (e) => {
    if (e.key !== 'Tab') return;
    const items = focusable();
    if (!items.length) return;
    const i = items.indexOf(document.activeElement);
    const next = e.shiftKey ? (i <= 0 ? items.length - 1 : i - 1) : (i === items.length - 1 || i < 0 ? 0 : i + 1);
    e.preventDefault();
    items[next].focus();
  });
  new MutationObserver(() => {
    if (dialog.open) opener = opener || document.activeElement;
    else if (opener) { const o = opener; opener = null; if (o.isConnected) o.focus(); }
  }).observe(dialog, { attributes: true, attributeFilter: ['open'] });
}

/**
 * The files of a drop (files, and the files inside dropped folders, walked
 * to any depth), in natural name order. A file inside a folder is kept when
 * `keep(name)`; a file dropped itself always is (its reader says what is
 * wrong with it).
 */
export async function droppedFiles(dt, keep = () => true) {
  const entries = [...dt.items].map((i) => (i.webkitGetAsEntry ? i.webkitGetAsEntry() : null)).filter(Boolean);
  if (!entries.length) return [...dt.files];
  const out = [];
  const walk = async (entry) => {
    if (entry.isFile) {
      const file = await new Promise((res, rej) => entry.file(res, rej));
      if (keep(file.name) || !entry.fullPath.includes('/', 1)) out.push(file);
    } else if (entry.isDirectory) {
      const reader = entry.createReader();
      let batch;
      do {
        batch = await new Promise((res, rej) => reader.readEntries(res, rej));
        for (const e of batch) await walk(e);
      } while (batch.length);
    }
  };
  for (const e of entries) await walk(e);
  return out.sort((a, b) => a.name.localeCompare(b.name, undefined, { numeric: true }));
}

/**
 * Files dropped on `zone` go to `take(files)`: the zone is outlined while
 * files are dragged over it. `keep(name)` chooses the files inside folders.
 */
export function dropTarget(zone, take, keep) {
  const files = (e) => e.dataTransfer && [...e.dataTransfer.types].includes('Files');
  zone.addEventListener('dragover', (e) => { if (!files(e)) return; e.preventDefault(); zone.classList.add('over'); });
  zone.addEventListener('dragleave', (e) => { if (!zone.contains(e.relatedTarget)) zone.classList.remove('over'); });
  zone.addEventListener('drop', async (e) => {
    if (!files(e)) return;
    e.preventDefault();
    zone.classList.remove('over');
    const dropped = await droppedFiles(e.dataTransfer, keep);
    if (dropped.length) take(dropped);
  });
}
