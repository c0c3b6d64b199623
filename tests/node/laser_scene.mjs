// The laser scans of the node tier (issue 40): `robocal render
// --laser-plane` (the release CLI `make test-node` builds) draws the stripe
// of a known plane on a 9x6 chessboard at six poses of a 640x480 camera,
// a laser-off and a laser-on image per pose, the true plane and stripe
// centres in truth.json. Rendered once into WORK_DIR/laser; shapes.mjs and
// laser.mjs read it.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const LASER_TARGET = 'chessboard:9x6:30mm';
/** The plane of `robocal laser --help`'s example: n . X = d, camera frame, metres. */
export const LASER_PLANE = '0,-0.98,0.196,0.098';
const CAMERA = {
  model: 'brown', image_size_px: [640, 480],
  camera_matrix: [[800, 0, 319.5], [0, 800, 239.5], [0, 0, 1]],
  distortion: { k1: -0.05, k2: 0.02, k3: 0, p1: 0, p2: 0 },
};

/** `{camera, truth, dir, pairs: [[board, stripe] bytes], request}` of the scans in `work` (rendered on first use). */
export function laserScene(work) {
  const dir = join(work, 'laser');
  const cameraFile = join(work, 'laser-camera.json');
  if (!existsSync(join(dir, 'truth.json'))) {
    mkdirSync(dir, { recursive: true });
    writeFileSync(cameraFile, JSON.stringify(CAMERA));
    execFileSync(join(root, 'target/release/robocal'), ['render', '--out', dir, '--camera', cameraFile, '--target', LASER_TARGET, '--views', '6', '--seed', '5', '--laser-plane', LASER_PLANE], { stdio: 'ignore' });
  }
  const camera = readFileSync(cameraFile, 'utf8');
  const truth = JSON.parse(readFileSync(join(dir, 'truth.json'), 'utf8'));
  const pairs = truth.views.map((v) => [readFileSync(join(dir, v.image)), readFileSync(join(dir, v.stripe_image))]);
  // The plane from poses 2-5 (pose 1's stripe misses the board); the sixth is held out for points.
  const request = { camera, target: LASER_TARGET, pairs: true, names: truth.views.slice(1, 5).map((v) => v.image.replace(/\.png$/, '')) };
  return { camera, truth, dir, pairs, request, images: pairs.slice(1, 5).flat(), held: 5 };
}
