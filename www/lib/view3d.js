// A 3-D view of coordinate frames (robot base, gripper, camera, target) on a
// canvas: drag or arrow keys to rotate, wheel, + / - keys or the buttons
// (zoomBy) to zoom, 0 to reset. Labels are placed so they do not overlap. Frames are 4x4 row-major
// matrices in one world frame (metres); each is drawn as an x/y/z triad
// (red/green/blue) with its name, so a wrong direction is visible at once.

function mat(m) { return { R: [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]], t: [m[3], m[7], m[11]] }; }

export class FrameView {
  constructor(canvas) {
    this.canvas = canvas;
    this.yaw = -0.7;
    this.pitch = 0.5;
    this.zoom = 1;
    this.frames = [];
    this.links = [];
    this.centre = [0, 0, 0];
    this.scale = 1;
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      this.yaw += (e.clientX - drag[0]) * 0.01;
      this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch + (e.clientY - drag[1]) * 0.01));
      drag = [e.clientX, e.clientY];
      this.draw();
    });
    canvas.addEventListener('wheel', (e) => { e.preventDefault(); this.zoom *= e.deltaY < 0 ? 1.1 : 1 / 1.1; this.draw(); }, { passive: false });
    canvas.tabIndex = 0;
    canvas.addEventListener('keydown', (e) => {
      const zoom = { '+': 1.25, '=': 1.25, '-': 0.8, _: 0.8 }[e.key];
      if (zoom) { e.preventDefault(); this.zoomBy(zoom); return; }
      if (e.key === '0') { e.preventDefault(); this.reset(); return; }
      const k = { ArrowLeft: [-0.1, 0], ArrowRight: [0.1, 0], ArrowUp: [0, -0.1], ArrowDown: [0, 0.1] }[e.key];
      if (!k) return;
      e.preventDefault();
      this.yaw += k[0]; this.pitch = Math.max(-1.5, Math.min(1.5, this.pitch + k[1]));
      this.draw();
    });
  }

  /** Zoom in (f > 1) or out, within 0.2x to 20x. */
  zoomBy(f) {
    this.zoom = Math.max(0.2, Math.min(20, this.zoom * f));
    this.draw();
  }

  /** The initial view direction and zoom. */
  reset() {
    [this.yaw, this.pitch, this.zoom] = [-0.7, 0.5, 1];
    this.draw();
  }

  /**
   * frames: [{name, matrix_row_major, size?}] (an empty name: no label),
   * links: [[nameA, nameB]] drawn as dashed lines, shapes: [{points:
   * [[x, y, z], ...], closed?, color?}] drawn as thin polylines (a rig's
   * camera frustums, board outlines).
   */
  set(frames, links = [], shapes = []) {
    this.canvas.dataset.frames = String(frames.length); // what is drawn, for scripts and tests
    this.shapes = shapes;
    this.frames = frames.map((f) => ({ name: f.name, ...mat(f.matrix_row_major), size: f.size }));
    this.links = links;
    // Look at the middle of the frames' bounding box, scaled to its size,
    // so the scene fills the canvas wherever the frames are in the world.
    const lo = [0, 1, 2].map((k) => Math.min(...this.frames.map((f) => f.t[k])));
    const hi = [0, 1, 2].map((k) => Math.max(...this.frames.map((f) => f.t[k])));
    this.centre = this.frames.length ? lo.map((v, k) => (v + hi[k]) / 2) : [0, 0, 0];
    this.scale = Math.max(0.05, 0.5 * Math.hypot(...hi.map((v, k) => v - lo[k])));
    this.draw();
  }

  project([px, py, pz]) {
    const [x, y, z] = [px - this.centre[0], py - this.centre[1], pz - this.centre[2]];
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw), cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    // World z up on screen: rotate about z (yaw), then tilt about the screen x axis (pitch).
    const x1 = cy * x - sy * y, y1 = sy * x + cy * y;
    const depth = cp * y1 + sp * z, up = -sp * y1 + cp * z;
    const f = (Math.min(this.canvas.width, this.canvas.height) * 0.5 * this.zoom) / this.scale;
    const persp = 1 / (1 + depth / (6 * this.scale));
    return [this.canvas.width / 2 + x1 * f * persp, this.canvas.height / 2 - up * f * persp, depth];
  }

  draw() {
    const ctx = this.canvas.getContext('2d');
    ctx.fillStyle = '#fafafa';
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    const byName = new Map(this.frames.map((f) => [f.name, f]));
    ctx.setLineDash([5, 4]); ctx.strokeStyle = '#999'; ctx.lineWidth = 1;
    for (const [a, b] of this.links) {
      const fa = byName.get(a), fb = byName.get(b);
      if (!fa || !fb) continue;
      const [x0, y0] = this.project(fa.t), [x1, y1] = this.project(fb.t);
      ctx.beginPath(); ctx.moveTo(x0, y0); ctx.lineTo(x1, y1); ctx.stroke();
    }
    ctx.setLineDash([]);
    for (const s of this.shapes || []) {
      const pts = s.points.map((p) => this.project(p));
      ctx.strokeStyle = s.color || '#555'; ctx.lineWidth = 1;
      ctx.beginPath();
      pts.forEach(([x, y], i) => (i ? ctx.lineTo(x, y) : ctx.moveTo(x, y)));
      if (s.closed) ctx.closePath();
      ctx.stroke();
    }
    const axisLen = this.scale * 0.18;
    const labels = [];
    for (const f of this.frames) {
      const o = this.project(f.t);
      const L = f.size || axisLen;
      ['#d62728', '#2ca02c', '#1f77b4'].forEach((c, k) => {
        const tip = this.project([f.t[0] + f.R[0][k] * L, f.t[1] + f.R[1][k] * L, f.t[2] + f.R[2][k] * L]);
        ctx.strokeStyle = c; ctx.lineWidth = 2.5;
        ctx.beginPath(); ctx.moveTo(o[0], o[1]); ctx.lineTo(tip[0], tip[1]); ctx.stroke();
      });
      if (f.name) labels.push({ name: f.name, at: o });
    }
    this.labels = placeLabels(ctx, labels, this.canvas.width, this.canvas.height - 20);
    for (const l of this.labels) {
      if (l.leader) {
        ctx.strokeStyle = '#999'; ctx.lineWidth = 1;
        ctx.beginPath(); ctx.moveTo(l.at[0], l.at[1]); ctx.lineTo(l.x + (l.x < l.at[0] ? l.w : 0), l.y - 4); ctx.stroke();
      }
      ctx.fillStyle = 'rgba(250,250,250,0.85)';
      ctx.fillRect(l.box.x0, l.box.y0, l.box.x1 - l.box.x0, l.box.y1 - l.box.y0);
      ctx.fillStyle = '#222';
      ctx.fillText(l.name, l.x, l.y);
    }
    ctx.fillStyle = '#666'; ctx.font = '12px system-ui';
    // On a narrow canvas (a phone) the help goes on as many lines as it needs, bottom up.
    const lines = [];
    for (const part of HELP.split(' · ')) {
      const last = lines.length - 1;
      if (last >= 0 && ctx.measureText(`${lines[last]} · ${part}`).width <= this.canvas.width - 16) lines[last] += ` · ${part}`;
      else lines.push(part);
    }
    lines.reverse().forEach((line, i) => ctx.fillText(line, 8, this.canvas.height - 8 - 15 * i));
  }
}

const LABEL_FONT = '13px system-ui';
const HELP = 'drag or arrow keys: rotate · wheel, + / − keys or buttons: zoom · 0: reset · x red, y green, z blue';

/**
 * Puts each frame's name next to its origin where it overlaps no name
 * placed before it: the named frames (base, gripper, camera, target) first,
 * the numbered robot poses after; each tries offsets around its point, then
 * further out with a leader line. Returns [{name, at, x, y, w, leader}]
 * (x, y: the text's baseline start).
 */
export function placeLabels(ctx, labels, width, height) {
  ctx.font = LABEL_FONT;
  const numbered = (l) => /^g\d+$/.test(l.name);
  const order = [...labels].sort((a, b) => numbered(a) - numbered(b));
  const placed = [];
  const box = (x, y, w) => ({ x0: x - 2, y0: y - 12, x1: x + w + 2, y1: y + 3 });
  const overlap = (a, b) => Math.max(0, Math.min(a.x1, b.x1) - Math.max(a.x0, b.x0)) * Math.max(0, Math.min(a.y1, b.y1) - Math.max(a.y0, b.y0));
  for (const l of order) {
    const w = ctx.measureText(l.name).width;
    const [px, py] = l.at;
    let best = null;
    for (const r of [8, 22, 40]) {
      for (const [dx, dy] of [[1, -1], [1, 1], [-1, -1], [-1, 1], [0, -1.4], [0, 1.6]]) {
        const x = dx > 0 ? px + r * 0.8 : dx < 0 ? px - r * 0.8 - w : px - w / 2;
        const y = py + dy * r * 0.8 + (dy > 0 ? 10 : 0);
        const b = box(x, y, w);
        const outside = (b.x0 < 0 || b.x1 > width || b.y0 < 0 || b.y1 > height) ? 1e6 : 0;
        const cost = outside + placed.reduce((s, p) => s + overlap(b, p.box), 0);
        if (!best || cost < best.cost) best = { x, y, cost, r };
        if (cost === 0) break;
      }
      if (best.cost === 0) break;
    }
    placed.push({ name: l.name, at: l.at, x: best.x, y: best.y, w, leader: best.r > 8, box: box(best.x, best.y, w) });
  }
  return placed;
}
