// A rig of two cameras is a stereo pair: right_from_left is the second
// camera's camera_from_rig (the rig frame is the first camera's), with the
// tables the stereo step showed (OpenCV stereoCalibrate's R, T), and the
// transform every export of step 8 writes. Sessions saved before the rig
// step replaced the stereo step keep their stereo result (`robocal stereo`'s
// report) until the rig is solved: it is shown and exported the same way.
import { h, table, num, message } from '../lib/dom.js';

/**
 * The stereo pair of a 2-camera rig report, or null:
 * {right_from_left, std, baseline_m, rms_px, pairs, cameras: [{name, camera_matrix, distortion, rms_px}] x2}.
 */
export function stereoOfRig(r) {
  if (!r || !r.cameras || r.cameras.length !== 2 || r.rig_frame !== r.cameras[0].name) return null;
  const [left, right] = r.cameras;
  const t = right.camera_from_rig.translation_m;
  return {
    right_from_left: right.camera_from_rig,
    std: right.camera_from_rig_std,
    baseline_m: Math.hypot(...t),
    rms_px: r.rms_px,
    pairs: r.co_observation.frames[0][1],
    cameras: [left, right].map((c) => ({ name: c.name, camera_matrix: c.calibration.camera_matrix, distortion: c.calibration.distortion, rms_px: c.rms_px })),
    warnings: [],
  };
}

/** The same shape from an earlier session's stereo result (`robocal stereo`'s report). */
export function stereoOfLegacy(s) {
  if (!s || !s.right_from_left) return null;
  const cam = (c, name) => ({ name, camera_matrix: c.camera_matrix, distortion: c.distortion, rms_px: c.rms_px });
  return {
    right_from_left: s.right_from_left,
    std: s.right_from_left_std,
    baseline_m: s.baseline_m,
    rms_px: s.rms_px,
    pairs: s.left.views.length,
    cameras: [cam(s.left, 'left'), cam(s.right, 'right')],
    warnings: [...(s.warnings || []), ...(s.left.warnings || []).map((w) => `left: ${w}`), ...(s.right.warnings || []).map((w) => `right: ${w}`)],
  };
}

/** The session's stereo pair: the solved 2-camera rig, else an earlier session's stereo result. */
export function sessionStereo(session) {
  return stereoOfRig(session.rig && session.rig.result) || stereoOfLegacy(session.stereo && session.stereo.result);
}

/** The stereo tables of a pair (ids as the stereo step had them). */
export function stereoSection(s, heading) {
  const m = s.right_from_left.matrix_row_major;
  const t = s.right_from_left.translation_m.map((v) => v * 1000);
  const cam = (c) => { const k = c.camera_matrix; return [c.name, num(k[0][0], 4), num(k[1][1], 4), num(k[0][2], 4), num(k[1][2], 4), num((c.distortion || {}).k1, 6), num(c.rms_px, 4)]; };
  const [left, right] = s.cameras;
  return h('div', { id: 'stereo-results' },
    h('h3', {}, heading),
    h('p', { id: 'stereo-summary', class: 'summary' }, `right_from_left: baseline ${num(s.baseline_m * 1000, 4)} mm, RMS ${num(s.rms_px, 4)} px over ${s.pairs} pairs`),
    h('p', { class: 'hint' }, `${left.name === 'left' && right.name === 'right' ? '' : `right = camera ${right.name}, left = camera ${left.name}: `}p_right = R p_left + T (the OpenCV stereoCalibrate R, T convention); right_from_left can be exported in every transform format in step 8.`),
    table(['', 'x', 'y', 'z'], [
      ['T (mm)', ...t.map((v) => num(v, 4))],
      ['std T (mm)', ...(s.std ? s.std.translation_m.map((v) => num(v * 1000, 3)) : ['—', '—', '—'])],
      ['std rotation (deg)', ...(s.std ? s.std.rotation_rad.map((v) => num((v * 180) / Math.PI, 4)) : ['—', '—', '—'])],
    ], { id: 'stereo-translation' }),
    table(['R', 'col 1', 'col 2', 'col 3'], m.slice(0, 3).map((row, i) => [`row ${i + 1}`, ...row.slice(0, 3).map((v) => num(v, 6))]), { id: 'stereo-rotation' }),
    table(['camera', 'fx', 'fy', 'cx', 'cy', 'k1', 'RMS (px)'], [cam(left), cam(right)], { id: 'stereo-cameras' }),
    s.warnings.map((w) => message('warning', w)));
}
