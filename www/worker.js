// The calibration engine's thread: loads the wasm once and answers requests,
// so the page never freezes. Every request gets exactly one reply, success or
// error. A wasm trap (a Rust panic, out of memory) leaves the instance
// unusable: the reply says `trapped`, every later request is handed back
// unrun (`bounced`, with its buffers) and engine.js moves them to a fresh
// worker.
import init, * as robocal from './pkg/robocal.js';
import { greyFromRgba, greyFromVideoFrame, pgm } from './lib/frames.js';
import { missingWasmFeature } from './lib/wasm-features.js';

// Checked before the module is fetched: a browser without WebAssembly SIMD
// gets the reason (every request's error), not the compiler's invalid opcode.
const missing = missingWasmFeature();
const ready = missing
  ? Promise.reject(new Error(missing))
  : init().then(() => {
    robocal.init();
    return robocal.version();
  });
ready.catch(() => {}); // reported by each request that awaits it

let trapped = null; // the message of the trap that broke this instance

function trapText(err) {
  let panic = '';
  try { panic = robocal.last_panic_message(); } catch (e) { /* the instance may be too broken to ask */ }
  return panic || err.message;
}

/** `{"max_pixels": N}` for the image entries, or undefined for the defaults. */
const imageOptions = (maxPixels) => (maxPixels ? JSON.stringify({ max_pixels: maxPixels }) : undefined);

const handlers = {
  async version() {
    return { version: await ready };
  },
  /** The core's lens-model table (camera::LENS_MODELS): the page's lens list. */
  async lensModels() {
    await ready;
    return JSON.parse(robocal.lens_models());
  },
  /**
   * The file's description and a preview; with `detect` ({ spec, boards })
   * also the target detected in the same decode (`detect` or `boards`'s
   * reply as `found`, or its error as `notFound`): the images step decodes
   * each file once for its card and its detection.
   */
  async preview({ bytes, maxSide, maxPixels, detect }) {
    await ready;
    const p = robocal.decode_image_preview(new Uint8Array(bytes), maxSide, imageOptions(maxPixels), !!detect);
    try {
      // `image` is an ImageData (structured clone), ready for putImageData.
      const reply = { info: JSON.parse(p.info_json), image: p.image };
      // (A host that drops the keep_grey argument gets a preview without grey: no detection here then.)
      if (detect && p.keeps_grey) {
        try {
          reply.found = detect.boards ? splitBoards(JSON.parse(p.detect_boards(detect.spec)), detect.spec) : JSON.parse(p.detect_target(detect.spec));
        } catch (err) {
          if (err instanceof WebAssembly.RuntimeError) throw err;
          reply.notFound = err && err.message ? err.message : String(err);
        }
      }
      return reply;
    } finally {
      p.free();
    }
  },
  async detect({ bytes, spec, maxPixels }) {
    await ready;
    return JSON.parse(robocal.detect_target(new Uint8Array(bytes), spec, imageOptions(maxPixels)));
  },
  /**
   * Marker boards: every board of the target's layout in the image
   * (`detect_boards`), split into `detection` (the target's own board, null
   * when it is not in view) and `others` (boards printed with other blocks
   * of ids; each detection's target names its first id). No board at all
   * is an error, as with `detect`.
   */
  async boards({ bytes, spec, maxPixels }) {
    await ready;
    return splitBoards(JSON.parse(robocal.detect_boards(new Uint8Array(bytes), spec, imageOptions(maxPixels))), spec);
  },
  /** Everything the target step shows, from the core: the target JSON, its CLI spec, its points and its printable sheet. */
  async target({ spec }) {
    await ready;
    const target = JSON.parse(robocal.parse_target(spec));
    const json = JSON.stringify(target);
    return { target, spec: robocal.target_spec(json), points: JSON.parse(robocal.target_points(json)), svg: robocal.target_svg(json) };
  },
  /** A Kalibr target YAML as the core's target JSON (io::kalibr_target). */
  async kalibrTarget({ text }) {
    await ready;
    return JSON.parse(robocal.read_kalibr_target(text));
  },
};

/** `detect_boards`' detections as `{ detection, others }` (see `boards`). */
function splitBoards(all, spec) {
  const key = (t) => robocal.target_spec(JSON.stringify(t));
  const want = robocal.target_spec(spec);
  const own = all.find((d) => key(d.target) === want) || null;
  return { detection: own, others: all.filter((d) => d !== own) };
}

/** The laser plane from board images with the stripe (laser_plane, docs/laser.md). */
handlers.laserPlane = async ({ request, images, maxPixels }) => {
  await ready;
  return JSON.parse(robocal.laser_plane(request, images.map((b) => new Uint8Array(b)), imageOptions(maxPixels)));
};

/** One image's stripe centres, gaps and ends (laser_stripe), the laser-off image subtracted when given. */
handlers.laserStripe = async ({ bytes, off, settings, maxPixels }) => {
  await ready;
  return JSON.parse(robocal.laser_stripe(new Uint8Array(bytes), off ? new Uint8Array(off) : undefined, settings || '', imageOptions(maxPixels)));
};

handlers.export = async ({ report, format, transform }) => {
  await ready;
  return robocal.export_report(report, format, transform || '');
};

handlers.poses = async ({ text, options }) => {
  await ready;
  return JSON.parse(robocal.read_robot_poses(text, options || ''));
};

handlers.poseFiles = async ({ files, options }) => {
  await ready;
  return JSON.parse(robocal.read_robot_pose_files(files, options || ''));
};

handlers.calibrate = async ({ input }) => {
  await ready;
  return JSON.parse(robocal.calibrate_camera(input));
};

handlers.handeye = async ({ input }) => {
  await ready;
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
  return JSON.parse(robocal.rank_pose_conventions(input));
};

handlers.undistort = async ({ bytes, camera, maxSide, maxPixels }) => {
  await ready;
  return { image: robocal.undistort_preview(new Uint8Array(bytes), camera, maxSide, imageOptions(maxPixels)) };
};

/** caliscope's timestamps.csv per camera in video frame order (io::video_timestamps). */
handlers.videoTimestamps = async ({ text }) => {
  await ready;
  return JSON.parse(robocal.video_timestamps(text));
};

/** Rig frames by file name: the rule of `robocal rig` (io::pairing). */
handlers.rigFrames = async ({ cameras, groupBy }) => {
  await ready;
  return JSON.parse(robocal.rig_frame_keys(cameras, groupBy || ''));
};

handlers.rig = async ({ input }) => {
  await ready;
  return JSON.parse(robocal.calibrate_rig(input));
};

/** The rig on a robot: `robocal rig ... --setup SETUP --poses FILE`. */
handlers.rigHandeye = async ({ input }) => {
  await ready;
  return JSON.parse(robocal.calibrate_rig_handeye(input));
};

/** A camera file (robocal JSON, OpenCV YAML/XML, ROS camera_info): `{camera, format}`. */
handlers.cameraFile = async ({ text }) => {
  await ready;
  return JSON.parse(robocal.read_camera_file(text));
};

/** The check of a saved calibration against new views (check_camera, docs/check.md). */
handlers.check = async ({ request }) => {
  await ready;
  return JSON.parse(robocal.check_camera(request));
};

/** The hand-eye pose plan (plan_handeye_poses, docs/pose-plan.md); board_m from the session's target. */
handlers.plan = async ({ request, target }) => {
  await ready;
  const r = JSON.parse(request);
  r.board_m = JSON.parse(robocal.target_points(target)).map((p) => [p.x_m, p.y_m, 0]);
  return JSON.parse(robocal.plan_handeye_poses(JSON.stringify(r)));
};

/** A plan's poses as a robot program or pose table (plan_move_list): the text. */
handlers.planMoveList = async ({ report, format }) => {
  await ready;
  return robocal.plan_move_list(report, format);
};

/** The projection difference of two calibration files (diff_cameras). */
handlers.diff = async ({ request }) => {
  await ready;
  return JSON.parse(robocal.diff_cameras(request));
};

handlers.rigFormats = async () => {
  await ready;
  return JSON.parse(robocal.rig_export_formats());
};

/** A report's export as files [{name, text}] (several for a rig's ros and mrcal). */
handlers.exportFiles = async ({ report, format, transform, frames }) => {
  await ready;
  return JSON.parse(robocal.export_report_files(report, format, transform || '', frames || ''));
};

/**
 * Live detection on one video frame: a WebCodecs VideoFrame (its luma plane
 * read as it is) or an ImageBitmap (drawn, then grey from RGBA), either
 * transferred and closed here. Its grey pixels go through the same
 * detection call as an uploaded image. A frame without the target is an
 * answer, not an error: `{ found: false, reason }`. `ms` is the time spent
 * here (grey pixels and detection).
 */
handlers.frame = async ({ frame, bitmap, spec, guide, time }) => {
  await ready;
  const started = performance.now();
  let pixels = frame ? await greyFromVideoFrame(frame) : null;
  if (!pixels) pixels = greyFromBitmap(bitmap);
  const { grey, width, height } = pixels;
  if (guide) return guidedFrame(grey, width, height, spec, guide, time, started);
  let detection = null;
  let reason = null;
  try {
    detection = JSON.parse(robocal.detect_target(pgm(grey, width, height), spec));
  } catch (err) {
    if (err instanceof WebAssembly.RuntimeError) throw err;
    reason = err && err.message ? err.message : String(err);
  }
  return { found: !!detection, detection, reason, width, height, ms: performance.now() - started };
};

// The capture guide (LiveCapture, docs/live-capture.md): one session per
// target and frame size, living in this worker beside the live detection.
let guideSession = null; // { key, live, time }

function guideOf(spec, width, height) {
  const key = `${spec}|${width}x${height}`;
  if (!guideSession || guideSession.key !== key) {
    if (guideSession) guideSession.live.free();
    guideSession = { key, live: new robocal.LiveCapture(spec, width, height), time: -Infinity };
  }
  return guideSession;
}

/**
 * A frame through the guide: detection, stillness, blur and novelty in one
 * call; the reply carries the detection as `detection` (the overlay's
 * shape) and the guide's frame report as `live`. With auto-capture off a
 * frame the rule would keep is not kept (`reason: "auto_off"`).
 */
function guidedFrame(grey, width, height, spec, { auto }, time, started) {
  const g = guideOf(spec, width, height);
  // Frame times must increase: two frames read in the same millisecond are a microsecond apart.
  g.time = Math.max(time, g.time + 1e-3);
  const report = JSON.parse(g.live.push_grey(grey, width, height, g.time));
  if (report.keep && !auto) {
    Object.assign(report, JSON.parse(g.live.remove(report.kept - 1)), { keep: false, reason: 'auto_off', message: 'auto-capture is off: press Capture frame to keep this view' });
  }
  const found = report.status !== 'not_found';
  const detection = found ? { points: report.points.map(([x, y], i) => ({ id: report.ids[i], x_px: x, y_px: y })) } : null;
  return { found, detection, reason: found ? null : report.message, width, height, live: report, ms: performance.now() - started };
}

/** The guide's session calls: capture (manual), remove, include, robotPose, calibrate, state, reset. */
handlers.guide = async ({ op, index, pose, included }) => {
  await ready;
  if (op === 'reset') {
    if (guideSession) guideSession.live.free();
    guideSession = null;
    return null;
  }
  if (!guideSession) throw new Error('the capture guide has seen no frame yet');
  const { live } = guideSession;
  if (op === 'capture') return JSON.parse(live.capture());
  if (op === 'remove') return JSON.parse(live.remove(index));
  if (op === 'include') return JSON.parse(live.set_included(index, included));
  if (op === 'robotPose') return JSON.parse(live.set_robot_pose(index, pose));
  if (op === 'calibrate') return JSON.parse(live.calibrate());
  if (op === 'state') return JSON.parse(live.state());
  throw new Error(`unknown guide request '${op}'`);
};

// Video files (www/views/video.js): one LiveCapture per video, its own
// session beside the live camera's, deciding on each decoded frame by the
// same rules (found, still, sharp, adding coverage; robocal's video input
// in the CLI gives its frames to the same session).
let videoSession = null;

/**
 * `reset` starts a new video; otherwise one frame (an ImageBitmap, closed
 * here) at `time` ms of the video: the frame report of docs/live-capture.md.
 */
// One frame of a video (www/views/video.js): the capture rules' verdict,
// with the frame's name (`cam_0.mp4#frame0123`, the CLI's, from the core)
// when the page gives the video's file name and the frame's index.
handlers.videoFrame = async ({ reset, bitmap, spec, time, video, index }) => {
  await ready;
  if (reset) {
    if (videoSession) videoSession.live.free();
    videoSession = null;
    return null;
  }
  const { grey, width, height } = greyFromBitmap(bitmap);
  const key = `${spec}|${width}x${height}`;
  if (!videoSession || videoSession.key !== key) {
    if (videoSession) videoSession.live.free();
    videoSession = { key, live: new robocal.LiveCapture(spec, width, height), time: -Infinity };
  }
  videoSession.time = Math.max(time, videoSession.time + 1e-3);
  const verdict = JSON.parse(videoSession.live.push_grey(grey, width, height, videoSession.time));
  if (video !== undefined) verdict.name = robocal.video_frame_name(video, index);
  return verdict;
};

function greyFromBitmap(bitmap) {
  const { width, height } = bitmap;
  const canvas = new OffscreenCanvas(width, height);
  const ctx = canvas.getContext('2d', { willReadFrequently: true });
  ctx.drawImage(bitmap, 0, 0);
  bitmap.close();
  return { grey: greyFromRgba(ctx.getImageData(0, 0, width, height).data, width, height), width, height };
}

/** The ArrayBuffers in a request's arguments (handed back with a bounced request). */
const buffersOf = (args) => Object.values(args || {}).filter((v) => v instanceof ArrayBuffer);

self.onmessage = async (event) => {
  const { id, op, args } = event.data;
  if (trapped) {
    self.postMessage({ id, ok: false, bounced: true, args }, buffersOf(args));
    return;
  }
  try {
    const handler = handlers[op];
    if (!handler) throw new Error(`unknown request '${op}'`);
    const out = await handler(args || {});
    // Handlers that hand over buffers return { value, transfer }.
    const moves = out !== null && typeof out === 'object' && 'transfer' in out;
    self.postMessage({ id, ok: true, value: moves ? out.value : out }, moves ? out.transfer : []);
  } catch (err) {
    if (err instanceof WebAssembly.RuntimeError) {
      trapped = trapText(err);
      self.postMessage({ id, ok: false, trapped: true, error: trapped });
    } else {
      self.postMessage({ id, ok: false, error: err && err.message ? err.message : String(err) });
    }
  }
};
