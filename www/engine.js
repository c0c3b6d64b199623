// A promise-based client for worker.js: call(op, args) -> Promise of the reply.
//
// The worker survives nothing that breaks its wasm instance, so the Engine
// replaces it: after a trap (worker.js replies `trapped`) or a worker error,
// the Engine terminates that worker, starts a fresh one, fails the request
// that was running with a message naming the step (and the file, from
// `args.name`), and re-sends the requests that had not run yet (the old
// worker hands them back with their buffers). Everything the page keeps
// (images, results) lives outside the worker and is untouched.

/** What a request does, for messages: "detecting the target in board.png". */
const STEPS = {
  preview: 'decoding', detect: 'detecting the target in', boards: 'detecting the boards in', undistort: 'undistorting', calibrate: 'solving the camera',
  handeye: 'solving the hand-eye calibration', rig: 'solving the rig', rigFrames: 'grouping the rig images into frames', export: 'exporting', poses: 'reading the robot poses',
  demo: 'rendering the demo', target: 'checking the target', kalibrTarget: 'reading the Kalibr target file', conventions: 'ranking the pose conventions',
  workflow: 'solving the workflow', lensModels: 'listing the lens models', 'workflow-csv': 'reading the workflow file', frame: 'detecting the target in the live video', guide: 'updating the capture guide',
  laserPlane: 'finding the laser plane', laserStripe: 'finding the laser stripe in',
};

export function stepText(op, args = {}) {
  const step = STEPS[op] || `the '${op}' request`;
  return args.name ? `${step} ${args.name}` : /\b(in|decoding|undistorting)$/.test(step) ? `${step} an image` : step;
}

export class Engine {
  constructor(url = './worker.js') {
    this.url = url;
    this.nextId = 1;
    this.pending = new Map(); // id -> { resolve, reject, op, args, worker }
    this.restarts = 0;
    this.start();
  }

  start() {
    const worker = new Worker(this.url, { type: 'module' });
    this.worker = worker;
    worker.onmessage = (event) => this.reply(worker, event.data);
    worker.onerror = (event) => {
      event.preventDefault();
      const why = event.message || 'the calibration engine failed';
      // A worker that never answered anything failed to start: there is
      // nothing to recover, say so instead of restarting forever.
      this.fail(worker, (entry) => `the calibration engine stopped while ${stepText(entry.op, entry.args)} (${why})`);
      if (worker === this.worker && this.answered) this.restart(worker);
    };
  }

  reply(worker, { id, ok, value, error, trapped, bounced, args }) {
    const entry = this.pending.get(id);
    if (!entry) return;
    this.answered = true;
    if (bounced) {
      // Not run by a broken worker: run it on the current one.
      entry.args = args;
      this.send(id, entry, Object.values(args || {}).filter((v) => v instanceof ArrayBuffer));
      this.retireIfDone(worker);
      return;
    }
    this.pending.delete(id);
    if (ok) entry.resolve(value);
    else if (trapped) {
      entry.reject(new Error(`the calibration engine crashed while ${stepText(entry.op, entry.args)} (${error}); it was restarted and your images and results are kept. Please report this with the file or data of that step.`));
      this.restart(worker);
    } else entry.reject(new Error(error));
    this.retireIfDone(worker);
  }

  /** Reject every request on `worker` with `message(entry)`. */
  fail(worker, message) {
    for (const [id, entry] of this.pending) {
      if (entry.worker !== worker) continue;
      this.pending.delete(id);
      entry.reject(new Error(message(entry)));
    }
  }

  /** A fresh worker for new requests; the old one is ended once it has handed back what it holds. */
  restart(old) {
    if (old !== this.worker) return;
    this.restarts++;
    this.retiring = old;
    this.start();
    this.retireIfDone(old);
  }

  retireIfDone(worker) {
    if (worker === this.worker) return;
    for (const entry of this.pending.values()) if (entry.worker === worker) return;
    worker.terminate();
  }

  send(id, entry, transfer) {
    entry.worker = this.worker;
    this.worker.postMessage({ id, op: entry.op, args: entry.args }, transfer);
  }

  call(op, args = {}, transfer = []) {
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      const entry = { resolve, reject, op, args, worker: null };
      this.pending.set(id, entry);
      this.send(id, entry, transfer);
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

  /**
   * Start every worker of the pool now (each loads the wasm when it starts):
   * called when images arrive, so the workers are ready by the time the
   * images are stored and the first decodes are sent.
   */
  warm() {
    while (this.engines.length < this.size) {
      this.engines.push(new Engine());
      this.busy.push(0);
    }
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
