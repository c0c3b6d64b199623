// The calibration engine's thread: loads the wasm once and answers requests,
// so the page never freezes. Every request gets exactly one reply, success or
// error; a Rust panic becomes an error reply, never a dead worker.
import init, * as robocal from './pkg/robocal.js';

const ready = init().then(() => {
  robocal.init();
  return robocal.version();
});

function errorText(err) {
  if (err instanceof WebAssembly.RuntimeError) {
    const panic = robocal.last_panic_message();
    return `internal error (${panic || err.message}); please report it with the file that caused it`;
  }
  return err && err.message ? err.message : String(err);
}

const handlers = {
  async version() {
    return { version: await ready };
  },
  async preview({ bytes, maxSide }) {
    await ready;
    const p = robocal.decode_image_preview(new Uint8Array(bytes), maxSide);
    const reply = { info: JSON.parse(p.info_json), width: p.width, height: p.height, rgba: p.rgba.buffer };
    p.free();
    return { value: reply, transfer: [reply.rgba] };
  },
  async detect({ bytes, spec }) {
    await ready;
    requireFn('detect_target');
    return JSON.parse(robocal.detect_target(new Uint8Array(bytes), spec));
  },
};

handlers.export = async ({ report, format, transform }) => {
  await ready;
  return robocal.export_report(report, format, transform || '');
};

handlers.poses = async ({ text, options }) => {
  await ready;
  return JSON.parse(robocal.read_robot_poses(text, options || ''));
};

handlers.calibrate = async ({ input }) => {
  await ready;
  requireFn('calibrate_camera');
  return JSON.parse(robocal.calibrate_camera(input));
};

handlers.handeye = async ({ input }) => {
  await ready;
  requireFn('solve_handeye');
  return JSON.parse(robocal.solve_handeye(input));
};

handlers['workflow-csv'] = async ({ kind, text }) => {
  await ready;
  return JSON.parse(robocal.workflow_csv(kind, text));
};

const WORKFLOW_OPS = new Set(['planar_fit', 'planar_solve', 'xytable_solve', 'known_motion_solve']);
handlers.workflow = async ({ op, input }) => {
  await ready;
  if (!WORKFLOW_OPS.has(op)) throw new Error(`unknown workflow '${op}'`);
  return JSON.parse(robocal[op](input));
};

handlers.demo = async ({ seed }) => {
  await ready;
  const demo = robocal.render_demo(seed || 1);
  const meta = JSON.parse(demo.json);
  const all = demo.bytes;
  demo.free();
  const images = meta.images.map((im) => ({ name: im.name, bytes: all.slice(im.offset, im.offset + im.length).buffer }));
  return { value: { ...meta, images }, transfer: images.map((i) => i.bytes) };
};

handlers.conventions = async ({ input }) => {
  await ready;
  requireFn('rank_pose_conventions');
  return JSON.parse(robocal.rank_pose_conventions(input));
};

handlers.undistort = async ({ bytes, camera, maxSide }) => {
  await ready;
  requireFn('undistort_preview');
  const p = robocal.undistort_preview(new Uint8Array(bytes), camera, maxSide);
  const reply = { width: p.width, height: p.height, rgba: p.rgba.buffer };
  p.free();
  return { value: reply, transfer: [reply.rgba] };
};

handlers.stereo = async ({ input }) => {
  await ready;
  requireFn('calibrate_stereo');
  return JSON.parse(robocal.calibrate_stereo(input));
};

function requireFn(name) {
  if (typeof robocal[name] !== 'function') throw new Error(`this build of the engine has no ${name}`);
}

self.onmessage = async (event) => {
  const { id, op, args } = event.data;
  try {
    const handler = handlers[op];
    if (!handler) throw new Error(`unknown request '${op}'`);
    const out = await handler(args || {});
    // Handlers that hand over buffers return { value, transfer }.
    const moves = out !== null && typeof out === 'object' && 'transfer' in out;
    self.postMessage({ id, ok: true, value: moves ? out.value : out }, moves ? out.transfer : []);
  } catch (err) {
    self.postMessage({ id, ok: false, error: errorText(err) });
  }
};
