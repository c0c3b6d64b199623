// Hand-written canvas plots (no dependency): scatter, bars, box plots, line
// series, vector fields and heat maps, with axes, ticks and labels. Each
// function draws into a canvas and returns it, so the same drawing can be
// embedded into the downloadable report with canvas.toDataURL().

const PAD = { left: 56, right: 16, top: 24, bottom: 44 };
const COLORS = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'];
export const color = (i) => COLORS[i % COLORS.length];

function niceTicks(lo, hi, n = 5) {
  if (!(hi > lo)) { hi = lo + 1; lo -= 1; }
  const raw = (hi - lo) / n;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => raw <= s) || 10 * mag;
  const ticks = [];
  for (let t = Math.ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) ticks.push(Number(t.toPrecision(12)));
  return ticks;
}

// categorical: the x axis holds labelled items (bars, boxes), so it gets no
// numeric ticks; padRight: room on the right (a colour bar).
function frame(canvas, { xmin, xmax, ymin, ymax, xlabel = '', ylabel = '', title = '', equal = false, yDown = false, categorical = false, padRight = PAD.right }) {
  const ctx = canvas.getContext('2d');
  const W = canvas.width, H = canvas.height;
  ctx.clearRect(0, 0, W, H);
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, W, H);
  let pw = W - PAD.left - padRight, ph = H - PAD.top - PAD.bottom;
  if (equal) {
    const s = Math.min(pw / (xmax - xmin || 1), ph / (ymax - ymin || 1));
    pw = s * (xmax - xmin || 1); ph = s * (ymax - ymin || 1);
  }
  const X = (x) => PAD.left + ((x - xmin) / (xmax - xmin || 1)) * pw;
  const Y = yDown ? (y) => PAD.top + ((y - ymin) / (ymax - ymin || 1)) * ph : (y) => PAD.top + ph - ((y - ymin) / (ymax - ymin || 1)) * ph;
  ctx.strokeStyle = '#999'; ctx.lineWidth = 1;
  ctx.strokeRect(PAD.left, PAD.top, pw, ph);
  ctx.fillStyle = '#333'; ctx.font = '11px system-ui'; ctx.textAlign = 'center';
  for (const t of categorical ? [] : niceTicks(xmin, xmax)) {
    if (t < xmin || t > xmax) continue;
    ctx.fillText(String(t), X(t), PAD.top + ph + 14);
    ctx.strokeStyle = '#eee'; ctx.beginPath(); ctx.moveTo(X(t), PAD.top); ctx.lineTo(X(t), PAD.top + ph); ctx.stroke();
  }
  ctx.textAlign = 'right';
  for (const t of niceTicks(ymin, ymax)) {
    if (t < ymin || t > ymax) continue;
    ctx.fillText(String(t), PAD.left - 4, Y(t) + 4);
    ctx.strokeStyle = '#eee'; ctx.beginPath(); ctx.moveTo(PAD.left, Y(t)); ctx.lineTo(PAD.left + pw, Y(t)); ctx.stroke();
  }
  ctx.textAlign = 'center'; ctx.font = '12px system-ui';
  ctx.fillText(xlabel, PAD.left + pw / 2, H - 8);
  if (title) { ctx.font = 'bold 12px system-ui'; ctx.fillText(title, PAD.left + pw / 2, 14); }
  ctx.save(); ctx.translate(14, PAD.top + ph / 2); ctx.rotate(-Math.PI / 2); ctx.font = '12px system-ui'; ctx.fillText(ylabel, 0, 0); ctx.restore();
  return { ctx, X, Y, pw, ph };
}

function extent(values, pad = 0.05) {
  const v = values.filter(Number.isFinite);
  if (!v.length) return [0, 1];
  let lo = Math.min(...v), hi = Math.max(...v);
  if (lo === hi) { lo -= 1; hi += 1; }
  const d = (hi - lo) * pad;
  return [lo - d, hi + d];
}

/** points: [{x, y, group}] ; symmetric: centre the axes on 0 with equal scale. */
export function scatter(canvas, points, { xlabel, ylabel, title, symmetric = false } = {}) {
  canvas.dataset.count = String(points.length); // what is drawn, for scripts and tests
  let [xmin, xmax] = extent(points.map((p) => p.x));
  let [ymin, ymax] = extent(points.map((p) => p.y));
  if (symmetric) {
    const m = Math.max(Math.abs(xmin), Math.abs(xmax), Math.abs(ymin), Math.abs(ymax));
    [xmin, xmax, ymin, ymax] = [-m, m, -m, m];
  }
  const { ctx, X, Y } = frame(canvas, { xmin, xmax, ymin, ymax, xlabel, ylabel, title, equal: symmetric });
  // The group of the point nearest canvas (x, y) within 8 px, for click-to-select.
  canvas.groupAt = (x, y) => {
    let best = null, bestD = 64;
    for (const p of points) {
      const d = (X(p.x) - x) ** 2 + (Y(p.y) - y) ** 2;
      if (d < bestD) { bestD = d; best = p.group || 0; }
    }
    return best;
  };
  for (const p of points) {
    ctx.fillStyle = color(p.group || 0);
    ctx.globalAlpha = 0.7;
    ctx.beginPath(); ctx.arc(X(p.x), Y(p.y), 2.2, 0, 2 * Math.PI); ctx.fill();
  }
  ctx.globalAlpha = 1;
  return canvas;
}

/** bars: [{label, value, highlight}] */
export function bars(canvas, items, { ylabel, title, threshold } = {}) {
  const ymax = Math.max(1e-9, ...items.map((b) => b.value), threshold || 0) * 1.1;
  const { ctx, X, Y, pw } = frame(canvas, { xmin: 0, xmax: items.length, ymin: 0, ymax, xlabel: '', ylabel, title, categorical: true });
  const bw = (pw / Math.max(items.length, 1)) * 0.7;
  // Every k-th label when there are more bars than slanted labels fit: two
  // 45-degree labels d px apart along the axis are d / sqrt(2) apart across,
  // and a 10 px font needs about 12 px there, so d >= 17 px.
  const every = Math.max(1, Math.ceil((17 * items.length) / pw));
  // The bar under canvas x (pixels of the canvas), for click-to-select.
  canvas.barAt = (x) => {
    const i = Math.floor((x - X(0)) / (pw / Math.max(items.length, 1)));
    return i >= 0 && i < items.length ? i : null;
  };
  items.forEach((b, i) => {
    ctx.fillStyle = b.highlight ? '#d62728' : '#1f77b4';
    ctx.fillRect(X(i + 0.5) - bw / 2, Y(b.value), bw, Y(0) - Y(b.value));
    if (i % every !== 0) return;
    ctx.save(); ctx.translate(X(i + 0.5), Y(0) + 6); ctx.rotate(Math.PI / 4);
    ctx.fillStyle = '#333'; ctx.font = '10px system-ui'; ctx.textAlign = 'left';
    ctx.fillText(String(b.label).slice(0, 14), 0, 0); ctx.restore();
  });
  if (threshold) {
    ctx.strokeStyle = '#d62728'; ctx.setLineDash([4, 4]);
    ctx.beginPath(); ctx.moveTo(X(0), Y(threshold)); ctx.lineTo(X(items.length), Y(threshold)); ctx.stroke();
    ctx.setLineDash([]);
  }
  return canvas;
}

export function quantile(sorted, q) {
  if (!sorted.length) return NaN;
  const pos = (sorted.length - 1) * q;
  const lo = Math.floor(pos), hi = Math.ceil(pos);
  return sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo);
}

/** groups: [{label, values}] -> box plots (median, IQR box, 1.5 IQR whiskers, outliers). */
export function boxplot(canvas, groups, { ylabel, title } = {}) {
  const all = groups.flatMap((g) => g.values);
  const [ymin, ymax] = extent(all, 0.1);
  const { ctx, X, Y, pw } = frame(canvas, { xmin: 0, xmax: groups.length, ymin, ymax, ylabel, title, categorical: true });
  const bw = (pw / Math.max(groups.length, 1)) * 0.4;
  groups.forEach((g, i) => {
    const s = [...g.values].sort((a, b) => a - b);
    const [q1, med, q3] = [0.25, 0.5, 0.75].map((q) => quantile(s, q));
    const iqr = q3 - q1;
    const lo = s.find((v) => v >= q1 - 1.5 * iqr), hi = [...s].reverse().find((v) => v <= q3 + 1.5 * iqr);
    const cx = X(i + 0.5);
    ctx.strokeStyle = color(i); ctx.lineWidth = 1.5;
    ctx.strokeRect(cx - bw / 2, Y(q3), bw, Y(q1) - Y(q3));
    ctx.beginPath(); ctx.moveTo(cx - bw / 2, Y(med)); ctx.lineTo(cx + bw / 2, Y(med)); ctx.lineWidth = 3; ctx.stroke(); ctx.lineWidth = 1.5;
    ctx.beginPath(); ctx.moveTo(cx, Y(q3)); ctx.lineTo(cx, Y(hi)); ctx.moveTo(cx, Y(q1)); ctx.lineTo(cx, Y(lo)); ctx.stroke();
    ctx.fillStyle = color(i);
    for (const v of s) if (v < lo || v > hi) { ctx.beginPath(); ctx.arc(cx, Y(v), 2.5, 0, 2 * Math.PI); ctx.fill(); }
    ctx.fillStyle = '#333'; ctx.font = '11px system-ui'; ctx.textAlign = 'center';
    ctx.fillText(g.label, cx, Y(ymin) + 28);
  });
  return canvas;
}

/** series: [{label, xs, ys, dashed}] */
export function lines(canvas, series, { xlabel, ylabel, title } = {}) {
  const [xmin, xmax] = extent(series.flatMap((s) => s.xs), 0.02);
  const [ymin, ymax] = extent(series.flatMap((s) => s.ys));
  const { ctx, X, Y } = frame(canvas, { xmin, xmax, ymin, ymax, xlabel, ylabel, title });
  series.forEach((s, i) => {
    ctx.strokeStyle = color(i); ctx.fillStyle = color(i); ctx.lineWidth = 2;
    ctx.setLineDash(s.dashed ? [6, 4] : []);
    ctx.beginPath();
    s.xs.forEach((x, k) => (k ? ctx.lineTo(X(x), Y(s.ys[k])) : ctx.moveTo(X(x), Y(s.ys[k]))));
    ctx.stroke();
    if (s.markers) for (let k = 0; k < s.xs.length; k++) { ctx.beginPath(); ctx.arc(X(s.xs[k]), Y(s.ys[k]), 3, 0, 2 * Math.PI); ctx.fill(); }
    ctx.setLineDash([]);
    ctx.font = '11px system-ui'; ctx.textAlign = 'left';
    ctx.fillText(s.label, PAD.left + 8, PAD.top + 14 + 14 * i);
  });
  return canvas;
}

/** vectors over an image frame of size [w, h] (y down): [{x, y, dx, dy}] scaled by gain. */
export function vectors(canvas, items, [w, h], { gain = 20, title } = {}) {
  canvas.dataset.count = String(items.length);
  const { ctx, X, Y } = frame(canvas, { xmin: 0, xmax: w, ymin: 0, ymax: h, xlabel: `x (px); vectors ×${gain}`, ylabel: 'y (px)', title, equal: true, yDown: true });
  ctx.strokeStyle = '#d62728'; ctx.lineWidth = 1;
  for (const v of items) {
    ctx.beginPath(); ctx.moveTo(X(v.x), Y(v.y)); ctx.lineTo(X(v.x + gain * v.dx), Y(v.y + gain * v.dy)); ctx.stroke();
  }
  return canvas;
}

// A perceptually ordered colour map (dark blue -> teal -> green -> yellow,
// sampled from the viridis curve), readable in grey and by most colour-blind
// viewers, unlike a blue-red ramp.
const VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
function heat(t) {
  const c = Math.max(0, Math.min(1, t)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(c)), f = c - i;
  const [r, g, b] = VIRIDIS[i].map((v, k) => Math.round(v + f * (VIRIDIS[i + 1][k] - v)));
  return `rgb(${r},${g},${b})`;
}

const BAR_W = 12;

/** grid: {cols, rows, values (row-major), width_px, height_px}; unit label. */
export function heatmap(canvas, grid, { title, unit = 'px' } = {}) {
  const padRight = 64;
  const { ctx, X, Y, ph } = frame(canvas, { xmin: 0, xmax: grid.width_px, ymin: 0, ymax: grid.height_px, xlabel: 'x (px)', ylabel: 'y (px)', title, equal: true, yDown: true, padRight });
  const finite = grid.values.filter(Number.isFinite);
  const vmax = Math.max(1e-12, ...finite);
  const vmin = finite.length ? Math.min(...finite) : 0;
  const span = vmax - vmin || vmax;
  const cw = grid.width_px / grid.cols, ch = grid.height_px / grid.rows;
  for (let r = 0; r < grid.rows; r++) {
    for (let c = 0; c < grid.cols; c++) {
      const v = grid.values[r * grid.cols + c];
      ctx.fillStyle = Number.isFinite(v) ? heat((v - vmin) / span) : '#ccc';
      ctx.fillRect(X(c * cw), Y(r * ch), X((c + 1) * cw) - X(c * cw) + 0.5, Y((r + 1) * ch) - Y(r * ch) + 0.5);
    }
  }
  // Colour bar beside the map: vmax at the top, vmin at the bottom.
  const bx = X(grid.width_px) + 10, top = Y(0), h = Math.min(ph, Y(grid.height_px) - top);
  for (let k = 0; k < h; k++) {
    ctx.fillStyle = heat(1 - k / Math.max(1, h - 1));
    ctx.fillRect(bx, top + k, BAR_W, 1.5);
  }
  ctx.strokeStyle = '#999'; ctx.strokeRect(bx, top, BAR_W, h);
  ctx.fillStyle = '#333'; ctx.font = '11px system-ui'; ctx.textAlign = 'left';
  ctx.fillText(vmax.toPrecision(3), bx + BAR_W + 3, top + 9);
  ctx.fillText(vmin.toPrecision(3), bx + BAR_W + 3, top + h);
  ctx.fillText(unit, bx + BAR_W + 3, top + h / 2 + 4);
  return canvas;
}
