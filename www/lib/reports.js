// Report files loaded in the page (a saved calibration in the check step, a
// camera file held by the rig or the laser step) are read by their `kind`,
// as `robocal export` reads them (docs/report-json.md): a camera or hand-eye
// report as it is, a stereo report's left or right camera, a rig report's
// camera of the same name (else its first), and a report that holds no
// camera is named as such. A report written before `kind` existed is
// recognised by its keys, as export does.

/** Every report kind robocal writes, in the order of docs/report-json.md. */
export const REPORT_KINDS = ['camera', 'stereo', 'rig', 'handeye', 'rig_handeye', 'check', 'diff', 'laser_plane', 'laser_points'];

const isObject = (v) => v !== null && typeof v === 'object' && !Array.isArray(v);

/**
 * A report's kind: its `kind` (an Error naming the valid kinds when it is
 * not one of them, in the core's words), or, without `kind`, what its keys
 * say: `cameras` with `co_observation` a rig, `left` and `right` with
 * `right_from_left` a stereo pair, anything else a camera (or hand-eye)
 * report.
 */
export function reportKind(report) {
  if (!('kind' in report)) {
    if (Array.isArray(report.cameras) && 'co_observation' in report) return isObject(report.handeye) ? 'rig_handeye' : 'rig';
    if (isObject(report.left) && isObject(report.right) && 'right_from_left' in report) return 'stereo';
    return 'camera';
  }
  const known = REPORT_KINDS.join(', ');
  if (typeof report.kind !== 'string') throw new Error(`kind: should be a string, one of ${known}, got ${JSON.stringify(report.kind)}`);
  if (!REPORT_KINDS.includes(report.kind)) throw new Error(`kind: unknown report kind '${report.kind}' (expected one of ${known})`);
  return report.kind;
}

/** Why a report of `kind` gives no camera. */
const NO_CAMERA = {
  check: 'compares a calibration with the camera and holds no camera: load the calibration itself',
  diff: 'compares two calibrations and holds no camera: load one of the calibrations itself',
  laser_plane: 'holds a laser plane, not a camera: load the camera\'s calibration',
  laser_points: 'holds laser points, not a camera: load the camera\'s calibration',
};

/**
 * The camera of a camera file's text, read by the report's kind when the
 * text is a robocal JSON report: `{ text, from }`, `text` the camera's JSON
 * (the core's camera reader takes it) and `from` what was taken ("camera
 * cam1 of a rig report") or null for the file as it is. `name` picks a
 * rig's camera or a stereo report's side (left or right; left otherwise).
 * Any other text (YAML, XML, a matrix) comes back as it is.
 */
export function cameraOfReport(text, name = null) {
  if (!/^\s*\{/.test(text)) return { text, from: null };
  let report;
  try { report = JSON.parse(text); } catch { return { text, from: null }; } // the core names the JSON error
  if (!isObject(report)) return { text, from: null };
  const kind = reportKind(report);
  switch (kind) {
    case 'camera':
    case 'handeye':
      return { text, from: null };
    case 'stereo': {
      const side = name === 'right' ? 'right' : 'left';
      if (!isObject(report[side])) throw new Error(`a 'stereo' report needs its ${side} camera (key '${side}')`);
      return { text: JSON.stringify(report[side]), from: `the ${side} camera of a stereo report` };
    }
    case 'rig':
    case 'rig_handeye': {
      const cameras = Array.isArray(report.cameras) ? report.cameras.filter((c) => isObject(c) && isObject(c.calibration)) : [];
      if (!cameras.length) throw new Error(`a '${kind}' report needs its cameras (key 'cameras', each with its 'calibration')`);
      const named = cameras.find((c) => c.name === name);
      const camera = named || cameras[0];
      const which = named ? `camera ${camera.name}` : `camera ${camera.name} (the first of ${cameras.length})`;
      return { text: JSON.stringify(camera.calibration), from: `${which} of a ${kind === 'rig' ? 'rig' : 'rig-on-a-robot'} report` };
    }
    default:
      throw new Error(`a '${kind}' report ${NO_CAMERA[kind]}`);
  }
}

/**
 * Read a camera file with the core (`cameraFile`), a report by its kind
 * first: `{ camera, format, text }`, the format saying which camera of a
 * report was taken ("json: camera cam1 of a rig report"), `text` that
 * camera's file text (what the core's check and laser requests take).
 */
export async function readCameraFile(engine, text, name = null) {
  const picked = cameraOfReport(text, name);
  const read = await engine.call('cameraFile', { text: picked.text });
  return { camera: read.camera, format: picked.from ? `${read.format}: ${picked.from}` : read.format, text: picked.text };
}
