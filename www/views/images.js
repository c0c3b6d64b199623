// Step 2: images. Load (files or a folder), decode and detect in the worker
// with progress and cancel, thumbnails with the detected points, an
// inspector with zoom and residuals, include/exclude, and a coverage map.
import { $, h, fill, trapFocus, droppedFiles } from '../lib/dom.js';
import { targetSpec } from './target.js';
import { MARKER_BOARDS, pointCount, otherBoard, notTheTarget, otherBoardsText, fillBoardButtons, drawOtherBoards } from './boards.js';
import { VIDEO_EXT } from '../lib/video-file.js';

const THUMB_SIDE = 320;
const IMAGE_EXT = /\.(png|jpe?g|tiff?|bmp|pgm|ppm|pnm|gif)$/i;

/** File names in natural order: im_2 before im_10 (digits compared as numbers). */
export const naturalCompare = (a, b) => a.localeCompare(b, undefined, { numeric: true, sensitivity: 'base' });

/** Run `fn` over `items` with at most `k` calls at a time (stops early when `stop()`). */
async function eachConcurrent(items, k, fn, stop = () => false) {
  let next = 0;
  const lane = async () => {
    while (!stop() && next < items.length) await fn(items[next++]);
  };
  await Promise.all(Array.from({ length: Math.max(1, Math.min(k, items.length)) }, lane));
}

export class ImagesView {
  /** `engine` answers single requests; `pool` (an EnginePool) decodes and detects several images at once. */
  constructor(store, engine, pool = engine) {
    this.store = store;
    this.engine = engine;
    this.pool = pool;
    this.lanes = pool.size || 1;
    this.previews = new Map(); // id -> { image: ImageData, scale }
    this.cards = new Map(); // id -> { li, canvas, meta, toggle }
    this.cancelled = false;
    this.busy = false;
    this.residuals = new Map(); // image name -> [{x, y, dx, dy}]
    this.wire();
    store.onChange((what) => { if (what === 'target') this.targetChanged(); });
    this.board = null; // { spec, kind, total } of the target the cards count against
    // Detections made with a card's preview (one decode for both), by image
    // id: { spec, boards, found } or { spec, boards, notFound }; detectAll
    // takes them instead of asking again while the target is the same.
    this.early = new Map();
  }

  /**
   * What the previews of new images detect: the session's target when it
   * is valid ({ spec, boards: a marker board's every board }), else null.
   */
  async detectRequest() {
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch { return null; }
    await this.boardInfo();
    return { spec, boards: !!(this.board && MARKER_BOARDS.has(this.board.kind)) };
  }

  /**
   * How many points the session's target has, from the core (a marker
   * board's card says "41 of 88 corners"); null when the target is not
   * valid. Asked once per spec.
   */
  async boardInfo() {
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch { return null; }
    if (this.board && this.board.spec === spec) return this.board;
    try {
      const reply = await this.engine.call('target', { spec });
      this.board = { spec, kind: reply.target.kind, total: reply.points.length };
    } catch { this.board = null; }
    return this.board;
  }

  /**
   * The target changed: every decoded image is detected again (after the
   * typing stops), its card saying so meanwhile; results solved from the old
   * detections are marked stale by their steps.
   */
  targetChanged() {
    const decoded = this.images.filter((i) => i.info);
    if (!decoded.length) return;
    for (const img of decoded) {
      const card = this.cards.get(img.id);
      if (card) card.meta.textContent = 'the target changed: detecting again…';
    }
    clearTimeout(this.redetectTimer);
    this.redetectTimer = setTimeout(() => this.redetect(), 700);
  }

  async redetect() {
    if (this.busy) { this.redetectAgain = true; return; }
    await this.detectAll(this.images.filter((i) => i.info));
  }

  get images() { return this.store.session.images; }

  wire() {
    $('file-input').addEventListener('change', (e) => { this.addFiles([...e.target.files]); e.target.value = ''; });
    $('folder-input').addEventListener('change', (e) => { this.addFiles([...e.target.files].filter((f) => IMAGE_EXT.test(f.name))); e.target.value = ''; });
    const zone = $('dropzone');
    zone.addEventListener('dragover', (e) => { e.preventDefault(); zone.classList.add('over'); });
    zone.addEventListener('dragleave', () => zone.classList.remove('over'));
    zone.addEventListener('drop', async (e) => {
      e.preventDefault();
      zone.classList.remove('over');
      this.addFiles(await droppedFiles(e.dataTransfer, (name) => IMAGE_EXT.test(name)));
    });
    // The file fields are hidden (no invisible tab stops): two buttons open them.
    $('choose-files').addEventListener('click', () => $('file-input').click());
    $('choose-folder').addEventListener('click', () => $('folder-input').click());
    $('detect-all').addEventListener('click', () => this.detectAll());
    $('sort-images').addEventListener('click', () => {
      this.images.sort((a, b) => naturalCompare(a.name, b.name));
      this.reorder();
    });
    $('cancel-detect').addEventListener('click', () => { this.cancelled = true; $('progress-text').textContent = 'cancelling after the current image…'; });
    $('clear-images').addEventListener('click', async () => {
      await this.store.removeImages(this.images.map((i) => i.id));
      this.previews.clear();
      this.early.clear();
      this.cards.clear();
      fill($('cards'));
      this.refresh();
    });
    $('inspector-close').addEventListener('click', () => $('inspector').close());
    trapFocus($('inspector'));
    $('inspector-zoom').addEventListener('input', () => this.drawInspector());
  }

  /**
   * Rebuild cards from the session (after a reload or a demo load). Images
   * a reload caught before their detection are detected now (not awaited:
   * the other steps need not wait for it).
   */
  async restore() {
    await this.boardInfo();
    fill($('cards'));
    this.cards.clear();
    for (const img of this.images) {
      this.makeCard(img);
      if (this.store.bytes.has(img.id)) await this.preview(img);
      this.renderCard(img);
    }
    this.refresh();
    const undetected = this.images.filter((i) => i.status === 'decoded' && !i.detection);
    if (undetected.length) this.resumed = this.detectAll(undetected);
  }

  async addFiles(files) {
    if (this.pool.warm) this.pool.warm();
    // Videos (dropped or chosen with images) are read by the video view (views/video.js).
    const videos = [...files].filter((f) => VIDEO_EXT.test(f.name));
    if (videos.length && this.videos) {
      this.videos.add(videos);
      files = [...files].filter((f) => !VIDEO_EXT.test(f.name));
    }
    const added = [];
    // A file picker may list im_28 first: the session's order (which pairs
    // images with poses) is the names' natural order, shown on the cards.
    const sorted = [...files].sort((a, b) => naturalCompare(a.name, b.name));
    // Read at once (one after another, 20 files took 0.1 s before the first decode).
    const read = await Promise.allSettled(sorted.map((file) => file.arrayBuffer()));
    const list = [];
    let unreadable = null; // a file that cannot be read: the ones before it are kept, as before
    for (const [k, file] of sorted.entries()) {
      if (read[k].status === 'rejected') { unreadable = read[k].reason; break; }
      const img = { id: `${Date.now().toString(36)}-${Math.random().toString(36).slice(2, 8)}`, name: file.name, size: file.size, included: true, status: 'pending', info: null, detection: null, error: null };
      list.push({ img, bytes: read[k].value });
    }
    // Stored (and listed in the saved session) before any is decoded: a reload meanwhile finds them.
    await this.store.addImages(list);
    for (const { img } of list) {
      this.makeCard(img);
      added.push(img);
    }
    this.refresh();
    if (unreadable) throw unreadable;
    // One image per worker at a time: memory stays bounded.
    const detect = await this.detectRequest();
    await eachConcurrent(added, this.lanes, async (img) => {
      await this.preview(img, detect);
      this.renderCard(img);
      this.refresh();
    });
    // Every decoded image (a target found with its preview too: detectAll takes that result).
    if (added.some((i) => i.info)) await this.detectAll(added);
  }

  async addBytes(list) {
    if (this.pool.warm) this.pool.warm();
    const added = [];
    // Extra fields (a camera capture's `source`) stay on the session image.
    const stored = list.map(({ name, bytes, ...extra }) => ({
      img: { ...extra, id: `${Date.now().toString(36)}-${Math.random().toString(36).slice(2, 8)}`, name, size: bytes.byteLength, included: true, status: 'pending', info: null, detection: null, error: null },
      bytes,
    }));
    await this.store.addImages(stored);
    for (const { img } of stored) {
      this.makeCard(img);
      added.push(img);
    }
    const detect = await this.detectRequest();
    await eachConcurrent(added, this.lanes, async (img) => { await this.preview(img, detect); this.renderCard(img); });
    this.refresh();
    await this.detectAll(added);
  }

  /** Decode `img` for its card; with `detect` ({ spec, boards }) its detection is made in the same decode (kept in `early`). */
  async preview(img, detect = null) {
    try {
      const bytes = this.store.bytes.get(img.id).slice(0);
      const p = await this.pool.call('preview', { bytes, maxSide: THUMB_SIDE, name: img.name, ...(detect ? { detect } : {}) }, [bytes]);
      if (detect) this.early.set(img.id, { ...detect, found: p.found, notFound: p.notFound });
      img.info = p.info;
      if (img.status === 'pending') img.status = 'decoded';
      if (detect && p.found !== undefined) this.showEarly(img, detect, p.found);
      this.previews.set(img.id, { image: p.image, scale: p.image.width / p.info.width });
    } catch (err) {
      img.status = 'error';
      img.error = err.message;
      img.included = false; // nothing to use (its pose keeps its place: pairing is by position)
    }
    this.store.changed('images');
  }

  /**
   * A target found with the preview is shown at once (a failure waits for
   * detectAll, which tries a larger grid and words the card); detectAll
   * takes the same result again from `early`.
   */
  showEarly(img, { boards }, found) {
    const detection = boards ? found.detection : found;
    if (!detection) return;
    img.detection = detection;
    img.otherBoards = boards ? found.others.map(otherBoard) : null;
    img.largerGrid = null;
    img.status = 'detected';
    img.error = null;
    img.detectError = false;
  }

  async detectAll(subset) {
    // Busy: images added meanwhile (camera captures) are detected next, never skipped.
    if (this.busy) { if (subset) this.waiting = [...(this.waiting || []), ...subset]; return; }
    const todo = (subset || this.images).filter((i) => (i.status !== 'error' || i.detectError) && !i.bytesMissing);
    if (!todo.length) return;
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch (e) { return; }
    this.busy = true;
    await this.boardInfo();
    this.cancelled = false;
    $('progress-row').hidden = false;
    $('detect-progress').max = todo.length;
    let done = 0;
    const running = new Set();
    const progress = () => {
      $('detect-progress').value = done;
      $('progress-text').textContent = `detecting ${Math.min(done + 1, todo.length)} of ${todo.length}: ${[...running].join(', ')}`;
    };
    await eachConcurrent(todo, this.lanes, async (img) => {
      running.add(img.name);
      progress();
      const card = this.cards.get(img.id);
      if (card) card.meta.textContent = 'detecting…';
      try {
        img.largerGrid = null;
        img.otherBoards = null;
        const boards = !!(this.board && MARKER_BOARDS.has(this.board.kind));
        const early = this.early.get(img.id);
        this.early.delete(img.id);
        // The preview's detection with this target, or a new one.
        const ask = async (op) => {
          if (early && early.spec === spec && early.boards === boards && (early.found !== undefined || early.notFound !== undefined)) {
            if (early.notFound !== undefined) throw new Error(early.notFound);
            return early.found;
          }
          const bytes = this.store.bytes.get(img.id).slice(0);
          return this.pool.call(op, { bytes, spec, name: img.name }, [bytes]);
        };
        if (boards) {
          // Every board of the layout: the target's own and other id blocks.
          const found = await ask('boards');
          img.otherBoards = found.others.map(otherBoard);
          if (!found.detection) throw new Error(notTheTarget(this.store.session.target, img.otherBoards));
          img.detection = found.detection;
        } else {
          try {
            img.detection = await ask('detect');
          } catch (err) {
            img.detection = await this.largerGrid(img, err);
          }
        }
        if (img.status === 'error') img.included = true; // found now (e.g. after a target change)
        img.status = 'detected';
        img.error = null;
        img.detectError = false;
      } catch (err) {
        img.detection = null;
        img.status = 'error';
        img.error = err.message;
        img.detectError = !!img.info; // decoded fine, the target was not found
        img.included = false;
      }
      done++;
      running.delete(img.name);
      if (running.size) progress();
      this.renderCard(img);
      this.refresh();
    }, () => this.cancelled);
    $('detect-progress').value = done;
    $('progress-text').textContent = this.cancelled ? `cancelled after ${done} of ${todo.length}` : `detected ${done} of ${todo.length}`;
    this.busy = false;
    setTimeout(() => { if (!this.busy) $('progress-row').hidden = true; }, 1500);
    this.store.changed('detections');
    if (this.redetectAgain) { this.redetectAgain = false; await this.redetect(); }
    if (this.waiting) { const next = this.waiting; this.waiting = null; await this.detectAll(next.filter((i) => this.images.includes(i))); }
  }

  /**
   * A chessboard grid larger than the target's (the printed board has more
   * squares than the spec): the view detected with a target of the found
   * size, noted on its card; camera calibration uses the whole grid, hand-eye
   * leaves the view out (its point 0 need not be the same board corner as in
   * the other views). Any other failure is rethrown.
   */
  async largerGrid(img, err) {
    const m = /^found a (\d+)x(\d+) chessboard grid, larger than the (\d+)x(\d+) target/.exec(err.message);
    const t = this.store.session.target;
    if (!m || !t || t.kind !== 'chessboard') throw err;
    // The core counts the grid along the image axes: turn it the way of the target.
    let [a, b] = [Number(m[1]), Number(m[2])];
    if (!(a >= Number(m[3]) && b >= Number(m[4])) && b >= Number(m[3]) && a >= Number(m[4])) [a, b] = [b, a];
    const bytes = this.store.bytes.get(img.id).slice(0);
    const spec = JSON.stringify({ ...t, cols: a, rows: b });
    let detection;
    try {
      detection = await this.pool.call('detect', { bytes, spec, name: img.name }, [bytes]);
    } catch { throw err; }
    img.largerGrid = `found ${a}x${b} inner corners, more than the ${m[3]}x${m[4]} of the target (the board has more squares than the spec): `
      + 'the whole grid is used for the camera calibration of this view; hand-eye leaves it out, because its point 0 need not be the same board corner as in the other views';
    return detection;
  }

  makeCard(img) {
    const canvas = h('canvas', { width: 4, height: 3, role: 'img', 'aria-label': `thumbnail of ${img.name}`, tabindex: 0 });
    const meta = h('p', { class: 'meta' }, 'decoding');
    const toggle = h('input', { type: 'checkbox', checked: img.included, 'aria-label': `use ${img.name} in the calibration` });
    toggle.addEventListener('change', () => { img.included = toggle.checked; this.renderCard(img); this.refresh(); this.store.changed('included'); });
    const open = () => this.inspect(img);
    canvas.addEventListener('click', open);
    canvas.addEventListener('keydown', (e) => { if (e.key === 'Enter') open(); });
    const order = h('span', { class: 'order', title: 'position: robot poses without names pair with images in this order' });
    const tool = (label, text, fn) => h('button', { type: 'button', class: 'small', 'aria-label': `${label} ${img.name}`, title: label, onclick: fn }, text);
    const tools = h('span', { class: 'card-tools' },
      tool('move earlier:', '◀', () => this.move(img, -1)), tool('move later:', '▶', () => this.move(img, 1)),
      tool('remove', 'Remove', () => this.remove(img)));
    const boards = h('div', { class: 'card-row boards', hidden: true });
    const li = h('li', { class: 'card pending', dataset: { id: img.id } }, canvas,
      h('p', { class: 'name' }, img.name), meta, boards, h('div', { class: 'card-row' }, order, h('label', { class: 'include' }, toggle, ' use'), tools));
    $('cards').append(li);
    this.cards.set(img.id, { li, canvas, meta, toggle, order, boards });
  }

  /** Move `img` one place earlier (-1) or later (+1) in the session's order. */
  move(img, step) {
    const i = this.images.indexOf(img);
    const j = i + step;
    if (i < 0 || j < 0 || j >= this.images.length) return;
    [this.images[i], this.images[j]] = [this.images[j], this.images[i]];
    this.reorder();
  }

  /** The cards in the session's order (robot poses pair with images in it). */
  reorder() {
    $('cards').append(...this.images.map((i) => this.cards.get(i.id)?.li).filter(Boolean));
    this.refresh();
    this.store.changed('images');
  }

  async remove(img) {
    await this.store.removeImages([img.id]);
    this.previews.delete(img.id);
    this.early.delete(img.id);
    this.cards.get(img.id)?.li.remove();
    this.cards.delete(img.id);
    this.refresh();
  }

  renderCard(img) {
    const card = this.cards.get(img.id);
    if (!card) return;
    const p = this.previews.get(img.id);
    card.toggle.checked = img.included;
    if (img.status === 'error' && !img.info) {
      card.canvas.hidden = true;
      card.li.className = 'card error';
      card.li.setAttribute('role', 'alert');
      card.meta.textContent = img.error;
      return;
    }
    const others = img.otherBoards || [];
    if (p) drawImage(card.canvas, p, img.detection ? img.detection.points : [], p.scale, 1, [], false, others);
    fillBoardButtons(card.boards, others, img.name, (b) => this.useBoard(b));
    card.li.className = `card ${img.status === 'error' ? 'warn' : 'ok'}${img.included ? '' : ' excluded'}`;
    const parts = [describe(img.info)];
    if (img.detection) parts.push(pointCount(img.detection.points, this.board));
    if (img.detection && img.detection.polarity === 'light_on_dark') parts.push(PRINTED_INVERTED);
    if (img.largerGrid) parts.push(img.largerGrid);
    if (img.note) parts.push(img.note); // e.g. a camera capture that repeats an earlier one
    if (img.status === 'error') parts.push(img.error);
    if (others.length) parts.push(otherBoardsText(others, (pts) => pointCount(pts, this.board)));
    if (img.bytesMissing) parts.push('from a session file: add the image to see it');
    card.meta.textContent = parts.join(' · ');
  }

  /** Make another board (one of a card's other id blocks) the target: the target step shows it, every image is detected again. */
  useBoard(board) {
    this.store.session.target = board.target;
    this.store.changed('target-loaded');
    this.store.changed('target');
  }

  refresh() {
    const imgs = this.images;
    imgs.forEach((img, i) => { const c = this.cards.get(img.id); if (c) c.order.textContent = `#${i + 1}`; });
    const count = (s) => imgs.filter((i) => i.status === s).length;
    const decoded = imgs.filter((i) => i.info).length;
    const failedDecode = imgs.filter((i) => i.status === 'error' && !i.info).length;
    const parts = [`${imgs.length} file${imgs.length === 1 ? '' : 's'}`, `${decoded} decoded`];
    if (failedDecode) parts.push(`${failedDecode} failed`);
    if (count('detected')) parts.push(`${count('detected')} with the target`);
    const notFound = imgs.filter((i) => i.status === 'error' && i.info).length;
    if (notFound) parts.push(`${notFound} without the target`);
    const excluded = imgs.filter((i) => !i.included && i.status !== 'error').length; // failed ones are counted above
    if (excluded) parts.push(`${excluded} excluded`);
    if (count('pending')) parts.push(`${count('pending')} in progress`);
    $('image-summary').textContent = parts.join(', ');
    drawCoverage($('coverage-canvas'), imgs.filter((i) => i.included && i.detection));
  }

  /** Per-point residuals from a camera solve, keyed by image name. */
  setResiduals(map) {
    this.residuals = map;
  }

  async inspect(img) {
    if (!img.info) return;
    this.inspected = img;
    $('inspector-title').textContent = img.name;
    try {
      const bytes = this.store.bytes.get(img.id).slice(0);
      const side = Math.max(img.info.width, img.info.height);
      this.full = await this.engine.call('preview', { bytes, maxSide: Math.min(side, 4096) }, [bytes]);
      this.full.scale = this.full.image.width / img.info.width;
    } catch (err) {
      $('inspector-info').textContent = err.message;
      return;
    }
    this.drawInspector();
    if (!$('inspector').open) $('inspector').showModal();
  }

  drawInspector() {
    const img = this.inspected;
    if (!img || !this.full) return;
    const zoom = Number($('inspector-zoom').value);
    const res = this.residuals.get(img.name) || [];
    drawImage($('inspector-canvas'), this.full, img.detection ? img.detection.points : [], this.full.scale, zoom, res, true, img.otherBoards || []);
    const rms = res.length ? Math.sqrt(res.reduce((s, r) => s + r.dx * r.dx + r.dy * r.dy, 0) / res.length) : null;
    $('inspector-info').textContent = `${describe(img.info)} · ${img.detection ? pointCount(img.detection.points, this.board) : img.error || 'not detected'}` +
      (img.detection && img.detection.polarity === 'light_on_dark' ? ` · ${PRINTED_INVERTED}` : '') +
      (rms !== null ? ` · reprojection RMS ${rms.toFixed(3)} px (residual vectors drawn ×${RESIDUAL_GAIN})` : '');
  }
}

const RESIDUAL_GAIN = 20;
/** Shown when the detector found the board printed light on dark (the detection's "polarity"). */
const PRINTED_INVERTED = 'printed light on dark';

function describe(info) {
  if (!info) return '';
  const channels = { 1: 'grey', 2: 'grey + alpha', 3: 'RGB', 4: 'RGBA' }[info.channels] || `${info.channels} channels`;
  return `${info.format_name} · ${info.width}×${info.height} px · ${channels}, ${info.bits_per_channel}-bit`;
}

/** Draw a preview with its points (pixel coordinates of the full image) at `zoom`. */
function drawImage(canvas, p, points, scale, zoom, residuals = [], ids = false, others = []) {
  const { width, height } = p.image; // the core's ImageData, put as it came
  canvas.width = Math.round(width * zoom);
  canvas.height = Math.round(height * zoom);
  const ctx = canvas.getContext('2d');
  const tmp = new OffscreenCanvas(width, height);
  tmp.getContext('2d').putImageData(p.image, 0, 0);
  ctx.imageSmoothingEnabled = zoom < 2;
  ctx.drawImage(tmp, 0, 0, canvas.width, canvas.height);
  const k = scale * zoom;
  // Pixel centres are at integer coordinates: +0.5 maps them to canvas space.
  const X = (x) => (x + 0.5) * k;
  const Y = (y) => (y + 0.5) * k;
  const r = Math.max(2, Math.min(6, 3 * zoom));
  drawOtherBoards(ctx, others, X, Y);
  points.forEach((pt, i) => {
    ctx.strokeStyle = i === 0 ? '#1f77b4' : '#ff7f0e';
    ctx.lineWidth = i === 0 ? 2.5 : 1.5;
    ctx.beginPath();
    ctx.arc(X(pt.x_px), Y(pt.y_px), i === 0 ? r * 1.6 : r, 0, 2 * Math.PI);
    ctx.stroke();
  });
  if (points.length > 1) {
    // Consecutive ids only: a partial view's gaps stay gaps.
    ctx.strokeStyle = 'rgba(255,127,14,0.5)';
    ctx.lineWidth = 1;
    ctx.beginPath();
    points.forEach((pt, i) => (i && pt.id === points[i - 1].id + 1 ? ctx.lineTo(X(pt.x_px), Y(pt.y_px)) : ctx.moveTo(X(pt.x_px), Y(pt.y_px))));
    ctx.stroke();
  }
  if (ids) {
    // Each point's board id beside it (dark outline so it reads on black and white).
    ctx.font = `${Math.round(Math.max(10, Math.min(16, 6 * zoom)))}px system-ui`;
    ctx.lineWidth = 3;
    ctx.strokeStyle = 'rgba(0,0,0,0.8)';
    ctx.fillStyle = '#ffd54f';
    for (const pt of points) {
      const [x, y] = [X(pt.x_px) + r + 1, Y(pt.y_px) - r - 1];
      ctx.strokeText(String(pt.id), x, y);
      ctx.fillText(String(pt.id), x, y);
    }
  }
  ctx.strokeStyle = '#d62728';
  ctx.lineWidth = 1.5;
  for (const res of residuals) {
    ctx.beginPath();
    ctx.moveTo(X(res.x), Y(res.y));
    ctx.lineTo(X(res.x + RESIDUAL_GAIN * res.dx), Y(res.y + RESIDUAL_GAIN * res.dy));
    ctx.stroke();
  }
}

/** Coverage: every detected point of every included image on one frame. */
const COVERAGE_WIDTH = 480;

function drawCoverage(canvas, imgs) {
  const ctx = canvas.getContext('2d');
  ctx.fillStyle = '#222';
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  if (!imgs.length) {
    ctx.fillStyle = '#aaa';
    ctx.font = '14px system-ui';
    ctx.fillText('No detections yet', 16, 28);
    return;
  }
  const [w, hgt] = imgs[0].detection.image_size_px;
  // The canvas takes the image's shape (a fixed 4:3 canvas left a dark band
  // beside a 5:4 or 16:9 image that read as a region without points).
  canvas.width = COVERAGE_WIDTH;
  canvas.height = Math.max(1, Math.round((COVERAGE_WIDTH * hgt) / w));
  ctx.fillStyle = '#222';
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  const s = canvas.width / w;
  // 8x6 cells: cells without any point are marked, so missing corners stand out.
  const cells = new Array(48).fill(0);
  for (const img of imgs) {
    for (const p of img.detection.points) {
      const cx = Math.min(7, Math.max(0, Math.floor((p.x_px / w) * 8)));
      const cy = Math.min(5, Math.max(0, Math.floor((p.y_px / hgt) * 6)));
      cells[cy * 8 + cx]++;
    }
  }
  for (let i = 0; i < 48; i++) {
    if (cells[i] === 0) {
      ctx.fillStyle = 'rgba(214,39,40,0.35)';
      ctx.fillRect((i % 8) * (w / 8) * s, Math.floor(i / 8) * (hgt / 6) * s, (w / 8) * s, (hgt / 6) * s);
    }
  }
  const hues = imgs.map((_, i) => `hsl(${(i * 137) % 360} 80% 60%)`);
  imgs.forEach((img, i) => {
    ctx.fillStyle = hues[i];
    for (const p of img.detection.points) ctx.fillRect(p.x_px * s - 1, p.y_px * s - 1, 2.5, 2.5);
  });
  ctx.strokeStyle = '#888';
  ctx.strokeRect(0, 0, w * s, hgt * s);
}
