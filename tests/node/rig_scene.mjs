// A noise-free camera rig for the node tier, built here from known cameras
// and poses so the package's answer can be checked against the truth:
// three pinhole cameras in a row (the middle one turned 20 degrees, the
// right one 40 degrees about y), a 9x6 board of 30 mm squares at ten poses,
// and each camera seeing only some frames (left: 0-6, middle: all,
// right: 3-9). Views are explicit correspondences (`object_m`, `image_px`).

const deg = Math.PI / 180;

// Rotation matrix (rows) from a rotation vector (Rodrigues).
export function rotation(rx, ry, rz) {
  const t = Math.hypot(rx, ry, rz);
  if (t === 0) return [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  const [x, y, z] = [rx / t, ry / t, rz / t];
  const c = Math.cos(t), s = Math.sin(t), v = 1 - c;
  return [
    [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
    [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
    [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
  ];
}

const apply = (R, t, p) => R.map((row, i) => row[0] * p[0] + row[1] * p[1] + row[2] * p[2] + t[i]);

export const truth = [
  { name: 'left', f: 1000, R: rotation(0, 0, 0), t: [0, 0, 0] },
  { name: 'middle', f: 950, R: rotation(0, 20 * deg, 0), t: [-0.12, 0.0, 0.02] },
  { name: 'right', f: 1050, R: rotation(0.02, 40 * deg, 0), t: [-0.25, 0.01, 0.08] },
];
const seen = { left: [0, 1, 2, 3, 4, 5, 6], middle: [0, 1, 2, 3, 4, 5, 6, 7, 8, 9], right: [3, 4, 5, 6, 7, 8, 9] };

/** rig_from_target per frame: the board about 0.8 m ahead, tilted, drifting to the right. */
export function rigFromTarget() {
  return Array.from({ length: 10 }, (_, k) => ({
    R: rotation(0.35 * Math.sin(k), 0.25 * Math.cos(1.3 * k) + 0.05 * k, 0.1 * k),
    t: [-0.2 + 0.06 * k, -0.08, 0.75 + 0.02 * (k % 3)],
  }));
}

export function rigInput() {
  const board = [];
  for (let r = 0; r < 6; r++) for (let c = 0; c < 9; c++) board.push([c * 0.03, r * 0.03, 0]);
  const frames = rigFromTarget();
  const cameras = truth.map((cam) => ({
    name: cam.name,
    image_size_px: [1280, 960],
    views: seen[cam.name].map((k) => {
      const image_px = board.map((p) => {
        const q = apply(cam.R, cam.t, apply(frames[k].R, frames[k].t, p));
        return [cam.f * q[0] / q[2] + 639.5, cam.f * q[1] / q[2] + 479.5];
      });
      return { key: String(k + 1), name: `${cam.name}${k + 1}.png`, object_m: board, image_px };
    }),
  }));
  // k3 held at 0: Kalibr's radtan has no k3 (the kalibr export needs it).
  return { model: 'brown', options: { fixed_coefficients: ['k3'] }, target: 'chessboard:9x6:30mm', cameras };
}

const mul = (A, B) => A.map((row) => B[0].map((_, j) => row.reduce((acc, v, k) => acc + v * B[k][j], 0)));
const hom = (R, t) => [[...R[0], t[0]], [...R[1], t[1]], [...R[2], t[2]], [0, 0, 0, 1]];
const inv = (M) => {
  const Rt = [0, 1, 2].map((i) => [0, 1, 2].map((j) => M[j][i]));
  const t = [0, 1, 2].map((i) => -(Rt[i][0] * M[0][3] + Rt[i][1] * M[1][3] + Rt[i][2] * M[2][3]));
  return hom(Rt, t);
};

/**
 * The rig on a robot, eye-in-hand: a known gripper_from_rig and
 * base_from_target, and the robot pose of every frame that closes the chain
 * (base_from_gripper = base_from_target * target_from_rig * rig_from_gripper).
 */
export function rigOnRobot() {
  const gripperFromRig = hom(rotation(0.1, -0.05, 0.3), [0.03, -0.02, 0.11]);
  const baseFromTarget = hom(rotation(3.0, 0.1, -0.2), [0.7, 0.1, -0.1]);
  const robot = rigFromTarget().map((f) => mul(mul(baseFromTarget, inv(hom(f.R, f.t))), inv(gripperFromRig)));
  return {
    gripperFromRig,
    input: { setup: 'eye-in-hand', base_from_gripper: robot.map((m) => ({ matrix_row_major: m })), calibration: rigInput() },
  };
}
