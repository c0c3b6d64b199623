// The lens-model choice shared by the camera step and the rig step: the
// model, Brown-Conrady's radial terms and tangential switch, and the
// options that hold parameters; read into the core's JSON `model` and
// `options` (robocal::api::camera::JsonOptions).
import { h } from '../lib/dom.js';

/**
 * The lens models as `[name, description]`, in menu order: the core's table
 * (camera::LENS_MODELS through the wasm call `lens_models()`), filled by
 * `loadLensModels` before the steps render. No list is kept here.
 */
export const MODELS = [];

/** Fill `MODELS` from the engine (worker.js `lensModels`); an engine that cannot start leaves it empty. */
export async function loadLensModels(engine) {
  try {
    const rows = await engine.call('lensModels');
    MODELS.splice(0, MODELS.length, ...rows.map((m) => [m.name, m.description]));
  } catch (err) {
    // The engine's own status line says why it could not start.
    console.error(err);
  }
}
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
