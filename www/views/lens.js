// The lens-model choice shared by the camera step and the rig step: the
// model, Brown-Conrady's radial terms and tangential switch, and the
// options that hold parameters; read into the core's JSON `model` and
// `options` (robocal::api::camera::JsonOptions).
import { h } from '../lib/dom.js';

export const MODELS = [
  ['brown', 'Brown-Conrady (radial k1 k2 k3, tangential p1 p2: OpenCV, MATLAB, Bouguet, Kalibr radtan)'],
  ['radial_k1_k2_k5', 'Brown-Conrady radial only, Bouguet numbering (k1 k2 k5)'],
  ['rational', 'OpenCV rational (k1..k6, p1 p2, thin prism s1..s4)'],
  ['division', 'Division (Fitzgibbon, Halcon)'],
  ['kannala_brandt', 'Kannala-Brandt fisheye (OpenCV fisheye, Kalibr equidistant)'],
  ['eucm', 'Enhanced unified camera model (EUCM, wide angle)'],
  ['none', 'Pinhole, no distortion'],
];
/** Brown-Conrady as users know it: 2 or 3 radial coefficients, tangential on or off (held at 0 otherwise). */
const RADIAL = [['3', '3 radial (k1 k2 k3: OpenCV default)'], ['2', '2 radial (k1 k2, k3 held at 0: MATLAB, Bouguet, Kalibr default)']];
const OPTIONS = [
  ['fix_principal_point', 'Fix the principal point at the image centre'],
  ['fix_aspect_ratio', 'Fix the aspect ratio (fy / fx) at its closed-form value'],
  ['square_pixels', 'Square pixels: fx = fy (OpenCV CALIB_FIX_ASPECT_RATIO with aspect ratio 1)'],
  ['zero_skew', 'Zero skew', true],
  ['robust', 'Robust loss with outlier rejection'],
];

/**
 * The lens controls for the state `st` ({model, radial, tangential,
 * options}) of a form whose ids start with `prefix` (`camera-model`,
 * `rig-radial`, ...): the model select, Brown-Conrady's terms (shown for
 * brown only) and the options fieldset. The caller places them in its form
 * and calls `readLens` on the form's change.
 */
export function lensFields(st, prefix) {
  const select = (name, items, value) => h('select', { name, id: `${prefix}-${name}` },
    items.map(([v, label]) => h('option', { value: v, selected: v === value }, label)));
  const opts = OPTIONS.map(([key, label, dflt]) => h('label', { class: 'check' },
    h('input', { type: 'checkbox', name: key, checked: (st.options || {})[key] ?? !!dflt }), ' ', label));
  return {
    model: h('label', {}, 'Lens model', select('model', MODELS, st.model)),
    brown: h('div', { class: 'row', id: `${prefix}-brown-terms`, hidden: st.model !== 'brown' },
      h('label', {}, 'Radial terms ', select('radial', RADIAL, st.radial || '3')),
      h('label', { class: 'check' }, h('input', { type: 'checkbox', name: 'tangential', checked: st.tangential !== false }), ' Tangential p1 p2')),
    options: h('fieldset', {}, h('legend', {}, 'Options'), opts),
  };
}

/** The controls of `lensFields` in `form` into `st`. */
export function readLens(st, form) {
  st.model = form.elements.model.value;
  st.radial = form.elements.radial.value;
  st.tangential = form.elements.tangential.checked;
  form.elements.radial.closest('.row').hidden = st.model !== 'brown';
  st.options = st.options || {};
  for (const [key] of OPTIONS) st.options[key] = form.elements[key].checked;
}

/** The state's options as the core's JSON options (square pixels = aspect_ratio 1; Brown-Conrady's held coefficients). */
export function jsonOptions(st) {
  const { square_pixels: square, ...rest } = st.options || {};
  const fixed = [];
  if (st.model === 'brown' && st.radial === '2') fixed.push('k3');
  if (st.model === 'brown' && st.tangential === false) fixed.push('p1', 'p2');
  const out = square ? { ...rest, aspect_ratio: 1 } : rest;
  return fixed.length ? { ...out, fixed_coefficients: fixed } : out;
}
