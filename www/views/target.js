// Step 1: the target. A form, a live drawing with origin and axes, and a
// printable SVG at true scale.
import { $, download } from '../lib/dom.js';

/** Board points in millimetres, in the detector's order (row by row from
 * the origin; square grids: square by square, each square's four corners
 * clockwise from the one nearest the origin). */
export function targetPoints(t) {
  const pts = [];
  const s = Number(t.size_mm);
  if (t.kind === 'circle') return [[0, 0]];
  const side = Number(t.side_mm);
  for (let r = 0; r < t.rows; r++) {
    for (let c = 0; c < t.cols; c++) {
      if (t.kind === 'circles' && t.layout === 'asymmetric') pts.push([(2 * c + (r % 2)) * s, r * s]);
      else if (t.kind === 'squares') for (const [u, v] of [[0, 0], [1, 0], [1, 1], [0, 1]]) pts.push([c * s + u * side, r * s + v * side]);
      else pts.push([c * s, r * s]);
    }
  }
  return pts;
}

/** The CLI/engine spec string: chessboard:9x6:30mm, circles:4x11:20mm:asymmetric, dots:7x7:25mm, squares:8x8:12.7mm:22.5778mm (side, pitch), circle:10mm. */
export function targetSpec(t) {
  const mm = (x) => `${Number(x)}mm`;
  switch (t.kind) {
    case 'chessboard': return `chessboard:${t.cols}x${t.rows}:${mm(t.size_mm)}`;
    case 'circles': return `circles:${t.cols}x${t.rows}:${mm(t.size_mm)}${t.layout === 'asymmetric' ? ':asymmetric' : ''}${t.polarity === 'light' ? ':light-on-dark' : ''}`;
    case 'dots': return `dots:${t.cols}x${t.rows}:${mm(t.size_mm)}:${mm(t.diameter_mm)}`;
    case 'squares': return `squares:${t.cols}x${t.rows}:${mm(t.side_mm)}:${mm(t.size_mm)}`;
    case 'circle': return `circle:${mm(t.diameter_mm)}`;
    default: throw new Error(`unknown target kind ${t.kind}`);
  }
}

/** Checks the form values; returns an error sentence or ''. */
export function validateTarget(t) {
  if (t.kind !== 'circle') {
    if (!(Number.isInteger(t.cols) && t.cols >= 2 && t.cols <= 100)) return 'Columns must be a whole number from 2 to 100.';
    if (!(Number.isInteger(t.rows) && t.rows >= 2 && t.rows <= 100)) return 'Rows must be a whole number from 2 to 100.';
    if (!(t.size_mm > 0)) return 'The size must be a positive number of millimetres.';
  }
  if ((t.kind === 'dots' || t.kind === 'circle') && !(t.diameter_mm > 0)) return 'The diameter must be a positive number of millimetres.';
  if (t.kind === 'dots' && t.diameter_mm >= t.size_mm) return 'The dot diameter must be smaller than the pitch.';
  if (t.kind === 'squares' && !(t.side_mm > 0)) return 'The square side must be a positive number of millimetres.';
  if (t.kind === 'squares' && t.side_mm >= t.size_mm) return 'The square side must be smaller than the pitch (the squares must not touch).';
  if (t.kind === 'chessboard' && t.cols === t.rows) return '';
  return '';
}

/** Board drawing primitives in millimetres: { width, height, origin:[x,y], rects:[[x,y,w,h]], circles:[[x,y,r]], dark:'#000' } */
export function boardLayout(t) {
  const s = Number(t.size_mm);
  if (t.kind === 'chessboard') {
    const margin = s;
    const rects = [];
    for (let r = 0; r < t.rows + 1; r++) {
      for (let c = 0; c < t.cols + 1; c++) if ((r + c) % 2 === 0) rects.push([margin + c * s, margin + r * s, s, s]);
    }
    return { width: (t.cols + 3) * s, height: (t.rows + 3) * s, origin: [margin + s, margin + s], rects, circles: [], light: false };
  }
  if (t.kind === 'squares') {
    // One pitch of margin; origin at square 0's first corner.
    const side = Number(t.side_mm);
    const rects = [];
    for (let r = 0; r < t.rows; r++) for (let c = 0; c < t.cols; c++) rects.push([s + c * s, s + r * s, side, side]);
    return { width: (t.cols + 1) * s + side, height: (t.rows + 1) * s + side, origin: [s, s], rects, circles: [], light: false };
  }
  if (t.kind === 'circle') {
    const d = Number(t.diameter_mm);
    return { width: 3 * d, height: 3 * d, origin: [1.5 * d, 1.5 * d], rects: [], circles: [[0, 0, d / 2]], light: false };
  }
  const pts = targetPoints(t);
  const radius = t.kind === 'dots' ? Number(t.diameter_mm) / 2 : (t.layout === 'asymmetric' ? 0.35 : 0.25) * s;
  const maxX = Math.max(...pts.map((p) => p[0]));
  const maxY = Math.max(...pts.map((p) => p[1]));
  const margin = s;
  return {
    width: maxX + 2 * margin, height: maxY + 2 * margin, origin: [margin, margin], rects: [],
    circles: pts.map(([x, y]) => [x, y, radius]), light: t.kind === 'circles' && t.polarity === 'light',
  };
}

export function drawTarget(canvas, t) {
  const ctx = canvas.getContext('2d');
  const L = boardLayout(t);
  const scale = Math.min((canvas.width - 20) / L.width, (canvas.height - 20) / L.height);
  const ox = (canvas.width - L.width * scale) / 2;
  const oy = (canvas.height - L.height * scale) / 2;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  ctx.fillStyle = L.light ? '#111' : '#fff';
  ctx.fillRect(ox, oy, L.width * scale, L.height * scale);
  ctx.fillStyle = L.light ? '#fff' : '#111';
  for (const [x, y, w, hh] of L.rects) ctx.fillRect(ox + x * scale, oy + y * scale, w * scale, hh * scale);
  for (const [x, y, r] of L.circles) {
    ctx.beginPath();
    ctx.arc(ox + (L.origin[0] + x) * scale, oy + (L.origin[1] + y) * scale, r * scale, 0, 2 * Math.PI);
    ctx.fill();
  }
  // Origin and axes: x along the columns (red), y along the rows (green).
  const [px, py] = [ox + L.origin[0] * scale, oy + L.origin[1] * scale];
  const len = Math.max(Number(t.size_mm) * scale * 1.5, 24);
  const arrow = (dx, dy, color, label) => {
    ctx.strokeStyle = color; ctx.fillStyle = color; ctx.lineWidth = 3;
    ctx.beginPath(); ctx.moveTo(px, py); ctx.lineTo(px + dx * len, py + dy * len); ctx.stroke();
    ctx.font = 'bold 14px system-ui'; ctx.fillText(label, px + dx * (len + 6) - 4, py + dy * (len + 14) + 4);
  };
  arrow(1, 0, '#d62728', 'x');
  arrow(0, 1, '#2ca02c', 'y');
  ctx.fillStyle = '#1f77b4';
  ctx.beginPath(); ctx.arc(px, py, 5, 0, 2 * Math.PI); ctx.fill();
}

/** A printable SVG at true scale (width/height in mm). */
export function targetSvg(t) {
  const L = boardLayout(t);
  const f = (x) => Number(x.toFixed(4));
  const dark = L.light ? '#fff' : '#000';
  const parts = [
    `<?xml version="1.0" encoding="UTF-8"?>`,
    `<svg xmlns="http://www.w3.org/2000/svg" width="${f(L.width)}mm" height="${f(L.height)}mm" viewBox="0 0 ${f(L.width)} ${f(L.height)}">`,
    `<title>robocal target ${targetSpec(t)}: print at 100 % scale (no fit-to-page), then measure a square</title>`,
    `<rect x="0" y="0" width="${f(L.width)}" height="${f(L.height)}" fill="${L.light ? '#000' : '#fff'}"/>`,
    ...L.rects.map(([x, y, w, hh]) => `<rect x="${f(x)}" y="${f(y)}" width="${f(w)}" height="${f(hh)}" fill="${dark}"/>`),
    ...L.circles.map(([x, y, r]) => `<circle cx="${f(L.origin[0] + x)}" cy="${f(L.origin[1] + y)}" r="${f(r)}" fill="${dark}"/>`),
    `<text x="${f(L.width / 2)}" y="${f(L.height - Number(t.size_mm || t.diameter_mm) * 0.3)}" font-size="${f(Math.max(L.height * 0.025, 2))}" text-anchor="middle" fill="#888">${targetSpec(t)}</text>`,
    `</svg>`,
  ];
  return parts.join('\n') + '\n';
}

function readForm(form) {
  const v = (n) => form.elements[n].value;
  return {
    kind: v('kind'), cols: Number(v('cols')), rows: Number(v('rows')), size_mm: Number(v('size_mm')),
    layout: v('layout'), polarity: v('polarity'), diameter_mm: Number(v('diameter_mm')), side_mm: Number(v('side_mm')),
  };
}

function writeForm(form, t) {
  for (const [k, val] of Object.entries(t)) if (form.elements[k]) form.elements[k].value = val;
}

export function initTarget(store) {
  const form = $('target-form');
  const update = (fromForm) => {
    const t = fromForm ? readForm(form) : store.session.target;
    if (!fromForm) writeForm(form, t);
    for (const el of form.querySelectorAll('[data-for]')) {
      const kinds = el.dataset.for.split(' ');
      el.hidden = !kinds.includes(t.kind) && !(kinds.includes('grid') && t.kind !== 'circle');
    }
    $('size-label').textContent = `${{ chessboard: 'Square size', circles: 'Circle spacing', dots: 'Dot pitch', squares: 'Square pitch', circle: 'Size' }[t.kind]} (mm)`;
    form.elements.size_mm.closest('label').hidden = t.kind === 'circle';
    const err = validateTarget(t);
    $('target-error').textContent = err;
    $('print-target').disabled = !!err;
    if (err) return;
    $('target-spec').textContent = `Target spec: ${targetSpec(t)} (the same spelling works in the CLI: robocal detect --target ${targetSpec(t)})`;
    drawTarget($('target-canvas'), t);
    if (fromForm) {
      store.session.target = t;
      store.changed('target');
    }
  };
  form.addEventListener('input', () => update(true));
  form.addEventListener('submit', (e) => e.preventDefault());
  $('print-target').addEventListener('click', () => {
    const t = store.session.target;
    download(`robocal-target-${targetSpec(t).replace(/[:]/g, '_')}.svg`, targetSvg(t), 'image/svg+xml');
  });
  store.onChange((what) => { if (what === 'all' || what === 'target-loaded') update(false); });
  update(false);
}
