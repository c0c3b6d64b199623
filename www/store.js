// The session: everything the user loaded and computed, kept in IndexedDB so
// that a reload or a crashed tab loses nothing. Image bytes live in their own
// object store; the rest is one JSON document.
const DB_NAME = 'robocal';
const DB_VERSION = 1;

export function defaultSession() {
  return {
    schema: 1,
    target: { kind: 'chessboard', cols: 9, rows: 6, square_m: 0.03 }, // the core's target JSON (views/target.js)
    images: [], // { id, name, size, included, status, info, detection, error }
    camera: { model: 'brown', method: 'zhang', options: {}, result: null, comparison: null },
    robot: { fileName: null, text: null, format: 'auto', lengthUnit: 'auto', angleUnit: 'auto', direction: 'base_from_gripper', parsed: null },
    handeye: { setup: 'eye-in-hand', method: 'all', result: null },
    workflows: { planar: null, xytable: null },
    stereo: { model: 'brown', result: null, left: [], right: [] }, // left/right: { id, name, detection, error, spec }
    rig: { model: 'brown', result: null, cameras: [] }, // cameras: { name, files: [{ id, name, detection, error, spec }] }
  };
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
      if (saved && saved.schema === 1) this.session = { ...defaultSession(), ...saved };
      for (const img of this.session.images) {
        const buf = await tx(this.db, 'blobs', 'readonly', (s) => s.get(img.id));
        if (buf) { this.bytes.set(img.id, buf); delete img.bytesMissing; }
        // From a session file: the detection without the image (solves work; detection needs the file).
        else if (img.detection) img.bytesMissing = true;
        else { img.status = 'error'; img.error = 'the image bytes were not found in this browser\'s storage; add the file again'; }
      }
      const stereo = this.session.stereo;
      for (const side of ['left', 'right']) {
        const kept = [];
        for (const f of stereo[side] || []) {
          const buf = await tx(this.db, 'blobs', 'readonly', (s) => s.get(f.id));
          if (buf) { this.bytes.set(f.id, buf); kept.push(f); }
        }
        stereo[side] = kept;
      }
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

  changed(what) {
    for (const fn of this.listeners) fn(what);
    clearTimeout(this.saveTimer);
    this.saveTimer = setTimeout(() => this.save(), 300);
  }

  async save() {
    if (!this.db || !this.persistent) return;
    try {
      await tx(this.db, 'session', 'readwrite', (s) => s.put(this.session, 'current'));
    } catch (e) {
      console.warn('could not save the session:', e);
    }
  }

  async addImage(img, bytes) {
    this.session.images.push(img);
    this.bytes.set(img.id, bytes);
    if (this.db && this.persistent) {
      try { await tx(this.db, 'blobs', 'readwrite', (s) => s.put(bytes, img.id)); } catch (e) { console.warn(e); }
    }
    this.changed('images');
  }

  /** Keep bytes that are not a step-2 image (the stereo page's). */
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
