// Per-camera intrinsics of step 7's rig (`robocal rig --camera-file
// NAME=FILE` in the page): each camera's intrinsics are solved with the
// rig, or held from a camera file (robocal JSON or report, OpenCV YAML/XML,
// ROS camera_info, read by the core), or held from the camera's own
// calibration (its views alone, the lens model and options of the rig; the
// calibration the joint fit's drift warning compares with). A held camera
// goes into the rig input as `cameras[i].camera`: the joint fit keeps it
// exactly.
import { h, message, num, readTextFile, download } from '../lib/dom.js';
import { readCameraFile } from '../lib/reports.js';

export const CHOICES = [
  ['solve', 'solve with the rig'],
  ['file', 'hold from a camera file'],
  ['solo', 'hold from its own calibration'],
];

/** The words of a choice, as the select shows it. */
export const choiceLabel = (v) => (CHOICES.find(([k]) => k === v) || CHOICES[0])[1];

/** fx, fy, cx, cy of a camera object, for a status line. */
const summary = (camera) => {
  const k = camera.camera_matrix || [[camera.fx, 0, camera.cx], [0, camera.fy, camera.cy]];
  return `fx ${num(k[0][0], 2)}, fy ${num(k[1][1], 2)}, cx ${num(k[0][2], 2)}, cy ${num(k[1][2], 2)}`;
};

/**
 * The control of camera `c` (index `k`): the choice, a camera file field
 * when holding from a file, and what is held. `changed()` after any change.
 */
export function intrinsicsControl(c, k, engine, changed) {
  const choice = c.intrinsics || 'solve';
  const select = h('select', { id: `rig-intrinsics-${k}`, 'aria-label': `camera ${k + 1} intrinsics` },
    CHOICES.map(([v, t]) => h('option', { value: v, selected: v === choice }, t)));
  const file = h('input', { type: 'file', id: `rig-camera-file-${k}`, 'aria-label': `camera ${k + 1} camera file`, accept: '.json,.yaml,.yml,.xml,.cameramodel,.dat,.m,.txt,text/*,application/json', hidden: choice !== 'file' });
  const status = h('span', { class: 'hint', id: `rig-held-${k}` }, statusText(c));
  select.addEventListener('change', () => {
    c.intrinsics = select.value;
    file.hidden = select.value !== 'file';
    status.textContent = statusText(c);
    changed();
  });
  file.addEventListener('change', async () => {
    const f = file.files[0];
    file.value = '';
    if (!f) return;
    try {
      const text = await readTextFile(f, 'a camera: robocal JSON, OpenCV YAML/XML or ROS camera_info');
      // A rig report gives the camera of this name (a stereo report its left or right).
      const read = await readCameraFile(engine, text, c.name);
      c.cameraFile = { name: f.name, format: read.format, camera: read.camera };
      status.textContent = statusText(c);
      status.classList.remove('msg-error');
    } catch (err) {
      c.cameraFile = null;
      status.textContent = `${f.name}: ${err.message}`;
      status.classList.add('msg-error');
    }
    changed();
  });
  // Its own calibration as a file: what `robocal rig --camera-file NAME=FILE` takes.
  const save = c.solo ? h('button', { type: 'button', id: `rig-solo-save-${k}`, onclick: () => download(`${c.name}_calibration.json`, `${JSON.stringify(c.solo, null, 2)}\n`, 'application/json') }, 'Save its own calibration') : null;
  return h('span', { class: 'rig-intrinsics' }, h('label', {}, 'intrinsics ', select), file, status, save);
}

function statusText(c) {
  switch (c.intrinsics || 'solve') {
    case 'file': return c.cameraFile ? `held from ${c.cameraFile.name} (${c.cameraFile.format}): ${summary(c.cameraFile.camera)}` : 'choose a camera file';
    case 'solo': return c.solo ? `held from its own calibration: ${summary(c.solo.camera)}` : 'its own calibration is made when the rig is solved';
    default: return '';
  }
}

/**
 * The camera to hold for camera `c` of the rig input `cam` (its views),
 * or null to solve it: a camera file's camera, or the camera calibrated
 * from its own views alone (`calibrate_camera` with the rig's `model` and
 * `options`; its report is kept in `c.solo`). Errors name the camera.
 */
export async function heldCamera(c, cam, model, options, engine) {
  switch (c.intrinsics || 'solve') {
    case 'file':
      if (!c.cameraFile) throw new Error(`camera ${c.name}: choose a camera file to hold its intrinsics, or solve them with the rig`);
      return c.cameraFile.camera;
    case 'solo': {
      const input = { model, options, views: cam.views.map((v) => ({ name: v.name, detection: v.detection })) };
      let out;
      try {
        out = await engine.call('calibrate', { input: JSON.stringify(input) });
      } catch (err) {
        throw new Error(`camera ${c.name}: its own calibration: ${err.message}`);
      }
      c.solo = out.report || out;
      return c.solo.camera;
    }
    default:
      return null;
  }
}

/** The rig warning that names a camera's intrinsics drift, as [camera name] or null. */
export function driftCamera(warning) {
  const m = /^camera (.+?): the joint rig fit moved its intrinsics beyond their own uncertainty/.exec(warning);
  return m ? m[1] : null;
}

/**
 * The page's words under a drift warning: the per-camera control that holds
 * the camera's intrinsics, and a button doing so (then solving again).
 */
export function driftHint(name, k, hold) {
  return h('div', { class: 'row', id: `rig-drift-hint-${k}` },
    message('info', `In the page: set camera ${k + 1} (${name})'s intrinsics to "${choiceLabel('solo')}" (or "${choiceLabel('file')}") above and solve again.`),
    h('button', { type: 'button', id: `rig-hold-solo-${k}`, onclick: hold }, `Hold ${name}'s intrinsics from its own calibration and solve again`));
}
