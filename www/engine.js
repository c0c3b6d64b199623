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
