// Geometry for the rig's 3-D view: rigid transforms as row-major 4x4
// matrices (flat, 16 numbers), camera frustums and board outlines as
// polylines for FrameView.

/** A row-major 4x4 matrix, nested ([[...] x4]) or flat, as 16 numbers. */
export const flat = (m) => (Array.isArray(m[0]) ? m.flat() : [...m]);

/** The inverse of a rigid transform. */
export function invert(m) {
  const a = flat(m);
  const R = [[a[0], a[1], a[2]], [a[4], a[5], a[6]], [a[8], a[9], a[10]]];
  const t = [a[3], a[7], a[11]];
  const out = new Array(16).fill(0);
  for (let i = 0; i < 3; i++) {
    for (let j = 0; j < 3; j++) out[4 * i + j] = R[j][i];
    out[4 * i + 3] = -(R[0][i] * t[0] + R[1][i] * t[1] + R[2][i] * t[2]);
  }
  out[15] = 1;
  return out;
}

/** `m` applied to the point p. */
export function apply(m, [x, y, z]) {
  const a = flat(m);
  return [0, 1, 2].map((i) => a[4 * i] * x + a[4 * i + 1] * y + a[4 * i + 2] * z + a[4 * i + 3]);
}

/** The rotation vector (axis times angle, degrees) of a unit quaternion [x, y, z, w]. */
export function rotvecDeg([x, y, z, w]) {
  const s = Math.hypot(x, y, z);
  if (s < 1e-15) return [0, 0, 0];
  const sign = w < 0 ? -1 : 1; // the shorter way round
  const angle = 2 * Math.atan2(s, Math.abs(w));
  return [x, y, z].map((v) => ((sign * v) / s) * angle * (180 / Math.PI));
}

/**
 * A camera's viewing pyramid, `depth` metres deep: the image's corners
 * through the pinhole (no distortion), in the frame of `worldFromCamera`.
 * camera: the core's camera JSON (fx, fy, cx, cy, width, height).
 */
export function frustum(worldFromCamera, camera, depth, color = '#555') {
  const { fx, fy, cx, cy, width, height } = camera;
  const corners = [[-0.5, -0.5], [width - 0.5, -0.5], [width - 0.5, height - 0.5], [-0.5, height - 0.5]]
    .map(([u, v]) => apply(worldFromCamera, [((u - cx) / fx) * depth, ((v - cy) / fy) * depth, depth]));
  const centre = apply(worldFromCamera, [0, 0, 0]);
  return [
    { color, points: corners, closed: true },
    ...corners.map((c) => ({ color, points: [centre, c] })),
  ];
}

/** The rectangle around a target's points ([{x_m, y_m}] or [[x, y, z]]), z = 0. */
export function boardOutline(points) {
  const xy = points.map((p) => (Array.isArray(p) ? [p[0], p[1]] : [p.x_m ?? p.x, p.y_m ?? p.y]));
  const xs = xy.map((p) => p[0]);
  const ys = xy.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  if (![x0, x1, y0, y1].every(Number.isFinite)) return null;
  return [[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0]];
}
