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
/** The splined model's degrees and the bounds of its control points per axis (camera::splined::MAX_KNOTS). */
const SPLINE_ORDERS = [['3', 'cubic (order 3, default)'], ['2', 'quadratic (order 2)']];
const KNOTS = { min: 4, max: 40, nx: 12, ny: 8 };
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
    spline: h('div', { class: 'row', id: `${prefix}-spline-terms`, hidden: st.model !== 'splined' },
      knotInput('spline_nx', 'Control points across x', (st.spline || {}).nx ?? KNOTS.nx),
      knotInput('spline_ny', 'across y', (st.spline || {}).ny ?? KNOTS.ny),
      h('label', {}, 'Spline ', select('spline_order', SPLINE_ORDERS, String((st.spline || {}).order ?? 3))),
      h('p', { class: 'hint' }, 'Defaults 12 x 8, cubic; more control points follow finer lens structure and need more views that cover the image (40 or more).')),
    cross: h('label', { class: 'check' },
      h('input', { type: 'checkbox', name: 'cross_validate', id: `${prefix}-cross-validate`, checked: !!st.crossValidate }),
      ' Cross-validate: calibrate two halves of the views with each lens model and compare them with their predicted uncertainty (about ten times the solve time)'),
    options: h('fieldset', {}, h('legend', {}, 'Options'), opts),
  };
}

/** A number field of control points along one axis. */
function knotInput(name, label, value) {
  return h('label', {}, `${label} `, h('input', { type: 'number', name, min: KNOTS.min, max: KNOTS.max, step: 1, value, size: 3 }));
}

/** The controls of `lensFields` in `form` into `st`. */
export function readLens(st, form) {
  st.model = form.elements.model.value;
  st.radial = form.elements.radial.value;
  st.tangential = form.elements.tangential.checked;
  form.elements.radial.closest('.row').hidden = st.model !== 'brown';
  if (form.elements.spline_nx) {
    form.elements.spline_nx.closest('.row').hidden = st.model !== 'splined';
    st.spline = {
      nx: Number(form.elements.spline_nx.value) || KNOTS.nx,
      ny: Number(form.elements.spline_ny.value) || KNOTS.ny,
      order: Number(form.elements.spline_order.value) || 3,
    };
  }
  if (form.elements.cross_validate) st.crossValidate = form.elements.cross_validate.checked;
  st.options = st.options || {};
  for (const [key] of OPTIONS) st.options[key] = form.elements[key].checked;
}

/** The state's options as the core's JSON options (square pixels = aspect_ratio 1; Brown-Conrady's held coefficients). */
export function jsonOptions(st) {
  const { square_pixels: square, ...rest } = st.options || {};
  const fixed = [];
  if (st.model === 'brown' && st.radial === '2') fixed.push('k3');
  if (st.model === 'brown' && st.tangential === false) fixed.push('p1', 'p2');
  let out = square ? { ...rest, aspect_ratio: 1 } : rest;
  // The core checks the bounds and says which one a value breaks.
  if (st.model === 'splined' && st.spline) out = { ...out, spline_knots: [st.spline.nx, st.spline.ny], spline_order: st.spline.order };
  if (st.crossValidate) out = { ...out, cross_validate: true };
  return fixed.length ? { ...out, fixed_coefficients: fixed } : out;
}
