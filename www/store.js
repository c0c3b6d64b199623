// The session: everything the user loaded and computed, kept in IndexedDB so
// that a reload or a crashed tab loses nothing. Image bytes live in their own
// object store; the rest is one JSON document.
import { checkSession } from './lib/validate.js';
const DB_NAME = 'robocal';
const DB_VERSION = 1;
/** The longest a change waits to be saved (ms). */
const SAVE_MS = 300;

export function defaultSession() {
  return {
    schema: 1,
    target: { kind: 'chessboard', cols: 9, rows: 6, square_m: 0.03 }, // the core's target JSON (views/target.js)
    images: [], // { id, name, size, included, status, info, detection, error }
    camera: { model: 'brown', method: 'zhang', options: {}, result: null, comparison: null },
    robot: { fileName: null, text: null, files: null, format: 'auto', lengthUnit: 'auto', angleUnit: 'auto', direction: 'base_from_gripper', parsed: null },
    handeye: { setup: 'eye-in-hand', method: 'all', result: null },
    workflows: { planar: null, xytable: null },
    // model, radial, tangential, options: the lens choice (views/lens.js); cameras: { name, files: [{ id, name, detection, error, spec }] }
    rig: { model: 'brown', result: null, cameras: [] },
    laser: { result: null }, // result: the laser step's `laser_plane` report (views/laser.js)
    stereo: null, // { result }: `robocal stereo`'s report, from a session saved before the rig step replaced the stereo step
    plan: null, // { inputs: { view, fields: { id: value } }, request, result }: the pose plan (views/plan.js)
    check: null, // { name, result }: the last check of a saved calibration (views/check.js)
    captureCount: 0, // the last capture_NNN.png number given (views/capture.js): names never repeat
  };
}

/**
 * A session saved before the rig step replaced the stereo step: its left
 * and right images become a rig of two cameras named left and right (when
 * the rig has no images yet), its stereo result stays for the rig step and
 * the export step until the rig is solved. Returns the ids of stereo images
 * no longer referenced (their bytes can go).
 */
export function migrateStereo(session) {
  const st = session.stereo;
  if (!st || !(st.left || st.right)) return [];
  const [left, right] = [st.left || [], st.right || []];
  let dropped = [];
  if (!(session.rig.cameras || []).some((c) => c.files.length) && (left.length || right.length)) {
    session.rig.cameras = [{ name: 'left', files: left }, { name: 'right', files: right }];
    if (st.model) session.rig.model = st.model;
  } else {
    dropped = [...left, ...right].map((f) => f.id);
  }
  session.stereo = st.result ? { result: st.result } : null;
  return dropped;
}

function openDb() {
  return new Promise((resolve, reject) => {
    if (!('indexedDB' in self)) return reject(new Error('IndexedDB is not available'));
    const req = indexedDB.open(DB_NAME, DB_VERSION);
    req.onupgradeneeded = () => {
      const db = req.result;
      if (!db.objectStoreNames.contains('session')) db.createObjectStore('session');
      if (!db.objectStoreNames.contains('blobs')) db.createObjectStore('blobs');
    };
    req.onsuccess = () => resolve(req.result);
    req.onerror = () => reject(req.error);
  });
}

function tx(db, store, mode, fn) {
  return new Promise((resolve, reject) => {
    const t = db.transaction(store, mode);
    const result = fn(t.objectStore(store));
    t.oncomplete = () => resolve(result && 'result' in result ? result.result : undefined);
    t.onerror = () => reject(t.error);
    t.onabort = () => reject(t.error || new Error('storage transaction aborted'));
  });
}

export class Store {
  constructor() {
    this.session = defaultSession();
    this.bytes = new Map(); // image id -> ArrayBuffer
    this.db = null;
    this.listeners = new Set();
    this.saveTimer = null;
    this.persistent = true;
  }

  async load() {
    try {
      this.db = await openDb();
      const saved = await tx(this.db, 'session', 'readonly', (s) => s.get('current'));
      if (saved && saved.schema === 1) {
        try {
          this.session = checkSession(saved);
        } catch (e) {
          // A damaged saved session never bricks the page: a new one starts,
          // and the damaged one stays downloadable (app.js says so).
          this.damaged = { session: saved, message: e.message };
          this.session = defaultSession();
        }
      }
      for (const img of this.session.images) {
        const buf = await tx(this.db, 'blobs', 'readonly', (s) => s.get(img.id));
        if (buf) { this.bytes.set(img.id, buf); delete img.bytesMissing; }
        // From a session file: the detection without the image (solves work; detection needs the file).
        else if (img.detection) img.bytesMissing = true;
        else { img.status = 'error'; img.error = 'the image bytes were not found in this browser\'s storage; add the file again'; }
      }
      const dropped = migrateStereo(this.session);
      if (dropped.length) await this.deleteBytes(dropped);
      for (const camera of this.session.rig.cameras) {
        const kept = [];
        for (const f of camera.files) {
          const buf = await tx(this.db, 'blobs', 'readonly', (s) => s.get(f.id));
          if (buf) { this.bytes.set(f.id, buf); kept.push(f); }
        }
        camera.files = kept;
      }
    } catch (e) {
      this.persistent = false;
      console.warn('session storage unavailable:', e);
    }
    return this.session;
  }

  onChange(fn) { this.listeners.add(fn); }

  /**
   * Tell the views, and save within SAVE_MS of the first unsaved change (a
   * stream of changes, e.g. thumbnails decoding one by one, never holds the
   * save off: a reload then finds the session as it was a moment before).
   */
  changed(what) {
    for (const fn of this.listeners) fn(what);
    if (this.saveTimer) return;
    this.saveTimer = setTimeout(() => { this.saveTimer = null; this.save(); }, SAVE_MS);
  }

  async save() {
    if (!this.db || !this.persistent) return;
    try {
      await tx(this.db, 'session', 'readwrite', (s) => s.put(this.session, 'current'));
      if (this.saveError) {
        this.saveError = null;
        for (const fn of this.listeners) fn('storage');
      }
    } catch (e) {
      // Saving never stops silently: the page says so and offers the session file.
      this.saveError = e && e.message ? e.message : String(e);
      for (const fn of this.listeners) fn('storage');
    }
  }

  /**
   * Add images (`[{ img, bytes }]`): their bytes are stored first, then
   * the session listing them is saved at once, so a reload at any moment
   * (e.g. during detection) finds every image added before it. One storage
   * transaction for all the bytes and one save: a transaction and a save
   * per image made 20 images wait 0.2-0.3 s before the first was decoded.
   */
  async addImages(list) {
    for (const { img, bytes } of list) this.bytes.set(img.id, bytes);
    if (this.db && this.persistent) {
      try { await tx(this.db, 'blobs', 'readwrite', (s) => { for (const { img, bytes } of list) s.put(bytes, img.id); }); } catch (e) { console.warn(e); }
    }
    for (const { img } of list) this.session.images.push(img);
    this.changed('images');
    await this.save();
  }

  /** Keep bytes that are not a step-2 image (the rig step's). */
  async putBytes(id, bytes) {
    this.bytes.set(id, bytes);
    if (this.db && this.persistent) {
      try { await tx(this.db, 'blobs', 'readwrite', (s) => s.put(bytes, id)); } catch (e) { console.warn(e); }
    }
  }

  async deleteBytes(ids) {
    for (const id of ids) this.bytes.delete(id);
    if (this.db && this.persistent) {
      try { await tx(this.db, 'blobs', 'readwrite', (s) => { for (const id of ids) s.delete(id); }); } catch (e) { console.warn(e); }
    }
  }

  async removeImages(ids) {
    const drop = new Set(ids);
    this.session.images = this.session.images.filter((i) => !drop.has(i.id));
    for (const id of ids) this.bytes.delete(id);
    if (this.db && this.persistent) {
      try { await tx(this.db, 'blobs', 'readwrite', (s) => { for (const id of ids) s.delete(id); }); } catch (e) { console.warn(e); }
    }
    this.changed('images');
  }

  async reset() {
    this.session = defaultSession();
    this.bytes.clear();
    if (this.db && this.persistent) {
      await tx(this.db, 'blobs', 'readwrite', (s) => s.clear());
      await tx(this.db, 'session', 'readwrite', (s) => s.clear());
    }
    this.changed('all');
  }
}
