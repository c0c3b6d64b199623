// Step 1: the target. The page keeps no target model of its own: the form's
// fields are the core's target JSON (kinds and fields of
// docs/detection-json.md, lengths typed in millimetres), and the core (in
// the worker) checks it, spells its CLI spec, lists its points and draws
// the printable sheet (robocal::target::svg, the sheet of `robocal target
// SPEC --svg`). The drawing on the page is that sheet with the origin and
// axes over it.
import { $, download } from '../lib/dom.js';

/** Lengths between millimetres (form) and metres (core) by shifting the
 * decimal, so 33.3 mm is the double nearest 0.0333, as the core's spec
 * parser makes it (not 33.3 / 1000). */
const mToMm = (m) => shiftDecimal(m, 3);
const mmToM = (mm) => shiftDecimal(mm, -3);

/** `x` (a number or its text) times 10^k, by moving the exponent: "3e1" -> 3e-2 for k = -3. */
function shiftDecimal(x, k) {
  const m = /^([^e]*)(?:e([-+]?\d+))?$/i.exec(String(x).trim());
  return m ? Number(`${m[1]}e${Number(m[2] || 0) + k}`) : NaN;
}

/**
 * The target as the engine's detect request takes it (a CLI spec or target
 * JSON): the JSON text of the session's target. Sessions saved by earlier
 * versions of the page hold `{kind: 'chessboard'|'circles'|..., size_mm, ...}`;
 * those are read as the CLI spec they meant.
 */
export function targetSpec(t) {
  if (typeof t === 'string') return t;
  if (t && 'size_mm' in t) return legacySpec(t);
  return JSON.stringify(t);
}

/** An earlier page's target object as a CLI spec (migration only). */
function legacySpec(t) {
  const mm = (x) => `${Number(x)}mm`;
  const grid = `${t.cols}x${t.rows}`;
  switch (t.kind) {
    case 'chessboard': return `chessboard:${grid}:${mm(t.size_mm)}`;
    case 'circles': return `circles:${grid}:${mm(t.size_mm)}${t.layout === 'asymmetric' ? ':asymmetric' : ''}${t.polarity === 'light' ? ':light-on-dark' : ''}`;
    case 'dots': return `dots:${grid}:${mm(t.size_mm)}:${mm(t.diameter_mm)}`;
    case 'squares': return `squares:${grid}:${mm(t.side_mm)}:${mm(t.size_mm)}`;
    case 'circle': return `circle:${mm(t.diameter_mm)}`;
    default: return String(t.kind);
  }
}

/** The form's controls that belong to `kind` (their `data-for` names it; hints have none). */
function fieldsOf(form, kind) {
  return [...form.querySelectorAll('label[data-for]')].filter((label) => label.dataset.for.split(' ').includes(kind))
    .map((label) => label.querySelector('input, select')).filter(Boolean);
}

/** A control's key in the target JSON: `data-key` when two kinds share a
 * JSON name (the ChArUco square side is `square_m` like the chessboard's),
 * else its name with `_mm` turned into `_m`. */
const keyOf = (el) => el.dataset.key || el.name.replace(/_mm$/, '_m');

/** The label's text of a control, for messages ("Squares across"). */
const labelOf = (el) => el.closest('label').firstChild.textContent.trim();

/**
 * A number field's value, or an error naming the field: an empty field, or
 * one the browser could not read as a number (its value is then ''), would
 * otherwise reach the core as null ("invalid type: null, expected f64").
 */
function numberField(el, unit) {
  const v = el.value.trim();
  if (v !== '' && Number.isFinite(Number(v))) return v;
  throw new Error(`${labelOf(el)}: the field is empty or not a number; enter ${unit}`);
}

/** A whole-number field (counts and ids), or an error naming the field. */
function countField(el, what) {
  const v = Number(numberField(el, what));
  if (Number.isInteger(v) && v >= 0) return v;
  throw new Error(`${labelOf(el)}: ${el.value.trim()} is not a whole number; enter ${what}`);
}

/** What each whole-number field holds, for its message. */
const COUNTS = {
  cols: 'a whole number of points, at least 2',
  rows: 'a whole number of points, at least 2',
  squares_x: 'a whole number of squares, at least 2 (e.g. 12)',
  squares_y: 'a whole number of squares, at least 2 (e.g. 9)',
  tag_cols: 'a whole number of tags, at least 1 (e.g. 6)',
  tag_rows: 'a whole number of tags, at least 1 (e.g. 6)',
  markers_x: 'a whole number of markers, at least 1 (e.g. 5)',
  markers_y: 'a whole number of markers, at least 1 (e.g. 7)',
  first_id: 'the id of the board\'s first marker, 0 or more',
};

/** The form as target JSON text (names ending in _mm become _m in metres). */
function readForm(form) {
  const kind = form.elements.kind.value;
  const t = { kind };
  for (const el of fieldsOf(form, kind)) {
    const v = el.value;
    if (el.name.endsWith('_mm')) t[keyOf(el)] = mmToM(numberField(el, 'a size in millimetres, e.g. 30'));
    else if (el.name in COUNTS) t[el.name] = countField(el, COUNTS[el.name]);
    else if (el.name === 'spacing_ratio') t.spacing_ratio = Number(numberField(el, 'the gap between tags over the tag size, e.g. 0.3'));
    else if (el.type === 'checkbox') t[el.name] = el.checked;
    else if (el.name === 'asymmetric') t.asymmetric = v === 'true';
    else t[el.name] = v;
  }
  // An explicit marker id list (from a spec or a loaded session) has no
  // field: it is kept while the kind stays ChArUco, and replaces first_id.
  if (kind === 'charuco' && form.dataset.markerIds) {
    t.marker_ids = JSON.parse(form.dataset.markerIds);
    delete t.first_id;
  }
  return JSON.stringify(t);
}

/** Put a core target JSON into the form. */
function writeForm(form, t) {
  form.elements.kind.value = t.kind;
  for (const el of fieldsOf(form, t.kind)) {
    const key = keyOf(el);
    if (!(key in t)) continue;
    if (el.type === 'checkbox') el.checked = !!t[key];
    else el.value = el.name.endsWith('_mm') ? String(mToMm(t[key])) : String(t[key]);
  }
  if (t.kind === 'charuco' && Array.isArray(t.marker_ids)) form.dataset.markerIds = JSON.stringify(t.marker_ids);
  else delete form.dataset.markerIds;
}

/** What the grid fields count, per kind: a chessboard's are its inner corners, not its squares. */
const GRID_LABELS = {
  chessboard: ['Inner corners across ', 'Inner corners down '],
  square_grid: ['Squares across ', 'Squares down '],
  circle_grid: ['Circles across ', 'Circles down '],
  dot_plate: ['Dots across ', 'Dots down '],
  origin_dot_grid: ['Dots across ', 'Dots down '],
};

function showFields(form) {
  const kind = form.elements.kind.value;
  for (const el of form.querySelectorAll('[data-for]')) el.hidden = !el.dataset.for.split(' ').includes(kind);
  const [cols, rows] = GRID_LABELS[kind] || ['Columns ', 'Rows '];
  form.elements.cols.parentElement.firstChild.textContent = cols;
  form.elements.rows.parentElement.firstChild.textContent = rows;
  $('target-count-hint').hidden = kind !== 'chessboard';
}

/**
 * Draw the core's sheet scaled into the canvas, with the board axes and
 * point 0 over it. The origin sits where the sheet's `<g class="marks"
 * transform="translate(X Y)">` puts it; `points` are the core's (metres).
 */
export async function drawSheet(canvas, svg, points) {
  const doc = new DOMParser().parseFromString(svg, 'image/svg+xml');
  const [, , width, height] = doc.documentElement.getAttribute('viewBox').split(/\s+/).map(Number);
  const m = /translate\(([-\d.e]+)[ ,]+([-\d.e]+)\)/.exec(doc.querySelector('g.marks').getAttribute('transform'));
  const origin = [Number(m[1]), Number(m[2])];
  const url = URL.createObjectURL(new Blob([svg], { type: 'image/svg+xml' }));
  const image = new Image();
  try {
    image.src = url;
    await image.decode();
  } finally {
    URL.revokeObjectURL(url);
  }
  const ctx = canvas.getContext('2d');
  const scale = Math.min((canvas.width - 10) / width, (canvas.height - 10) / height);
  const ox = (canvas.width - width * scale) / 2;
  const oy = (canvas.height - height * scale) / 2;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  ctx.drawImage(image, ox, oy, width * scale, height * scale);
  const at = ([x, y]) => [ox + (origin[0] + x) * scale, oy + (origin[1] + y) * scale];
  const [px, py] = at([0, 0]);
  // Axis length: the board's extent along x and y, at least 24 px.
  const mm = points.map((p) => [mToMm(p.x_m), mToMm(p.y_m)]);
  const reach = (k) => Math.max(24, Math.max(...mm.map((p) => p[k])) * scale * 0.5);
  const arrow = (dx, dy, len, color, label) => {
    ctx.strokeStyle = color; ctx.fillStyle = color; ctx.lineWidth = 3;
    ctx.beginPath(); ctx.moveTo(px, py); ctx.lineTo(px + dx * len, py + dy * len); ctx.stroke();
    ctx.font = 'bold 14px system-ui'; ctx.fillText(label, px + dx * (len + 6) - 4, py + dy * (len + 14) + 4);
  };
  arrow(1, 0, reach(0), '#d62728', 'x');
  arrow(0, 1, reach(1), '#2ca02c', 'y');
  // Point 0 is at the origin except on marker boards (ChArUco: one square in; AprilGrid: bottom left).
  const [qx, qy] = mm.length ? at(mm[0]) : [px, py];
  ctx.fillStyle = '#1f77b4';
  ctx.beginPath(); ctx.arc(qx, qy, 5, 0, 2 * Math.PI); ctx.fill();
  return { width_mm: width, height_mm: height, origin_mm: origin };
}

export function initTarget(store, engine) {
  const form = $('target-form');
  let asked = 0; // the latest request: older replies are dropped
  let sheet = null; // { spec, svg } of the target shown
  const refuse = (text) => {
    sheet = null;
    $('target-error').textContent = text;
    $('print-target').disabled = true;
  };
  const show = async (json, fromForm) => {
    const mine = ++asked;
    let reply;
    try {
      reply = await engine.call('target', { spec: json });
    } catch (err) {
      if (mine === asked) refuse(err.message);
      return;
    }
    if (mine !== asked) return;
    sheet = reply;
    $('target-error').textContent = '';
    $('print-target').disabled = false;
    if (!fromForm) { writeForm(form, reply.target); showFields(form); }
    $('target-spec').textContent = `Target spec: ${reply.spec} (the same spelling works in the CLI: robocal detect --target ${reply.spec}; robocal target ${reply.spec} --svg board.svg prints this sheet)`;
    await drawSheet($('target-canvas'), reply.svg, reply.points);
    $('target-canvas').dataset.spec = reply.spec;
    // The session keeps the core's JSON (a session of an earlier page is
    // converted here, once).
    store.session.target = reply.target;
    if (fromForm) store.changed('target');
  };
  form.addEventListener('input', () => {
    showFields(form);
    let json;
    try {
      json = readForm(form);
    } catch (err) {
      asked++; // a reply still on its way is older than this
      refuse(err.message);
      return;
    }
    show(json, true);
  });
  form.addEventListener('submit', (e) => e.preventDefault());
  $('print-target').addEventListener('click', () => {
    if (!sheet) return;
    download(`robocal-target-${sheet.spec.replace(/[:]/g, '_')}.svg`, sheet.svg, 'image/svg+xml');
  });
  // Kalibr's target YAML (aprilgrid or checkerboard): read by the core into
  // the form, then used as if typed.
  $('kalibr-target').addEventListener('click', () => $('kalibr-input').click());
  $('kalibr-input').addEventListener('change', async (e) => {
    const [file] = e.target.files;
    e.target.value = '';
    if (!file) return;
    asked++;
    let target;
    try {
      target = await engine.call('kalibrTarget', { text: await file.text() });
    } catch (err) {
      refuse(`${file.name}: ${err.message}`);
      return;
    }
    writeForm(form, target);
    showFields(form);
    show(JSON.stringify(target), true);
  });
  const fromSession = () => show(targetSpec(store.session.target), false);
  store.onChange((what) => { if (what === 'all' || what === 'target-loaded') fromSession(); });
  return fromSession();
}
