// A promise-based client for worker.js: call(op, args) -> Promise of the reply.
export class Engine {
  constructor(url = './worker.js') {
    this.worker = new Worker(url, { type: 'module' });
    this.nextId = 1;
    this.pending = new Map();
    this.worker.onmessage = (event) => {
      const { id, ok, value, error } = event.data;
      const entry = this.pending.get(id);
      if (!entry) return;
      this.pending.delete(id);
      ok ? entry.resolve(value) : entry.reject(new Error(error));
    };
    this.worker.onerror = (event) => {
      const message = event.message || 'the calibration engine failed to start';
      for (const entry of this.pending.values()) entry.reject(new Error(message));
      this.pending.clear();
    };
  }

  call(op, args = {}, transfer = []) {
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject });
      this.worker.postMessage({ id, op, args }, transfer);
    });
  }
}

/**
 * Several engines for independent requests (image decoding and detection):
 * `call` goes to an idle engine, starting another worker (up to `size`) when
 * all are busy. The first engine is the page's main one.
 */
export class EnginePool {
  constructor(first, size) {
    this.engines = [first];
    this.busy = [0];
    this.size = Math.max(1, size);
  }

  async call(op, args = {}, transfer = []) {
    let i = this.busy.indexOf(0);
    if (i < 0 && this.engines.length < this.size) {
      this.engines.push(new Engine());
      this.busy.push(0);
      i = this.engines.length - 1;
    }
    if (i < 0) i = this.busy.indexOf(Math.min(...this.busy));
    this.busy[i]++;
    try {
      return await this.engines[i].call(op, args, transfer);
    } finally {
      this.busy[i]--;
    }
  }
}
