// Step 2's camera source: a live picture from getUserMedia with the target
// detected on it in a worker of its own, and frames captured into the
// session like uploaded images.
//
// Live detection takes the newest video frame only: while one frame is
// being detected, the frames that arrive are dropped (counted, never
// queued), so the overlay lags the picture by at most one detection.
import { $, download } from '../lib/dom.js';
import { cameraErrorText, videoInputs, openCamera, capabilities, resolutionChoices, stopStream, RateMeter } from '../lib/camera.js';
import { targetSpec } from './target.js';
import { CapturePoses } from './capture-poses.js';
import { RunningSolve } from './capture-solve.js';
import { CaptureGuide } from './capture-guide.js';

/** Marker boards report any subset of their corners: fewer than all is "partly found". */
const MARKER_BOARDS = new Set(['charuco', 'aprilgrid', 'aruco_grid']);
/** Captured frames are named capture_001.png, capture_002.png, ... (natural order = capture order). */
const CAPTURE_NAME = /^capture_(\d+)\.png$/;
/** Point ids are written on the overlay up to this many points (more would cover the board). */
const MOST_IDS = 120;

export class CaptureView {
  /**
   * `images` is the ImagesView (captures join its session); `engine` reads
   * typed robot poses; `makeEngine()` gives the live detection's own worker;
   * `robot()` the RobotView once it exists.
   */
  constructor(store, images, engine, makeEngine, robot) {
    this.store = store;
    this.images = images;
    this.makeEngine = makeEngine;
    this.poses = new CapturePoses(store, engine, robot);
    // Solves run on the page's main worker: the live worker keeps detecting.
    this.solve = new RunningSolve(store, engine, () => this.captured().filter((i) => i.included && i.detection));
    this.solvedKey = '';
    this.live = null; // the Engine that detects live frames
    this.stream = null;
    this.inFlight = false;
    this.last = null; // the newest detection reply
    this.cameraRate = new RateMeter();
    this.detectRate = new RateMeter();
    this.dropped = 0;
    this.listeners = new Set(); // fn(reply, bitmapless frame info) after each live detection
    this.guide = new CaptureGuide(this);
    this.wire();
  }

  /** Call `fn(reply)` after every live detection (the guide uses it). */
  onDetection(fn) { this.listeners.add(fn); }

  wire() {
    $('camera-start').addEventListener('click', () => this.start());
    // Disabled in the page until here: a click before the view exists would do nothing.
    $('camera-start').disabled = false;
    $('camera-stop').addEventListener('click', () => this.stop());
    $('camera-device').addEventListener('change', () => { if (this.stream) this.start(); });
    $('camera-resolution').addEventListener('change', () => { if (this.stream) this.start(); });
    $('capture-frame').addEventListener('click', () => this.capture());
    $('capture-pose').addEventListener('keydown', (e) => { if (e.key === 'Enter') { e.preventDefault(); this.capture(); } });
    $('download-captures').addEventListener('click', () => this.downloadCaptures());
    document.addEventListener('keydown', (e) => {
      if (e.key !== ' ' || !this.stream || $('step-images').hidden) return;
      // Space keeps its meaning on controls and in text fields.
      if (e.target.closest && e.target.closest('input, select, textarea, button, a, [contenteditable], dialog')) return;
      e.preventDefault();
      this.capture();
    });
    if (navigator.mediaDevices && navigator.mediaDevices.addEventListener) {
      navigator.mediaDevices.addEventListener('devicechange', () => this.listDevices());
    }
    this.store.onChange((what) => {
      // Another target while the camera runs: "partly found" counts against its points.
      if (/^target/.test(what) && this.stream) this.images.boardInfo().then((b) => { this.board = b; });
      if (/detections|included|images|all/.test(what)) this.solveIfChanged();
      if (/included|images|all/.test(what)) this.guide.sync();
      if (!/images|all/.test(what)) return;
      this.countCaptures();
      // A removed or moved capture takes its typed pose along.
      if (what === 'images' && this.images.images.some((i) => i.robotPose)) this.poses.sync();
    });
    this.countCaptures();
  }

  say(text) {
    const m = $('camera-message');
    m.textContent = text || '';
    m.hidden = !text;
  }

  async listDevices() {
    const select = $('camera-device');
    const current = select.value;
    let cams = [];
    try { cams = await videoInputs(); } catch { return []; }
    select.replaceChildren(new Option('default camera', ''), ...cams.map((c) => new Option(c.label, c.id)));
    if (cams.some((c) => c.id === current)) select.value = current;
    return cams;
  }

  /** Open the chosen camera at the chosen resolution (again, after a change) and start the live loop. */
  async start() {
    this.stopStream();
    this.say('');
    const choice = $('camera-resolution').value;
    const [width, height] = choice === 'max' ? [null, null] : choice.split('x').map(Number);
    $('camera-start').disabled = true;
    try {
      // No video input at all: say so without asking for a permission that cannot help.
      const cams = await this.listDevices();
      const known = cams.some((c) => c.id);
      if (!cams.length && navigator.mediaDevices) throw Object.assign(new Error('no video input'), { name: 'NotFoundError' });
      const deviceId = known ? $('camera-device').value : '';
      this.stream = await openCamera({ deviceId, width, height, max: choice === 'max' });
    } catch (err) {
      this.stream = null;
      $('camera-start').disabled = false;
      $('camera-live').hidden = true;
      this.say(err.name === 'InsecureContext' ? `Camera access is not possible: ${err.message}.` : cameraErrorText(err, choice === 'max' ? '' : choice.replace('x', ' × ')));
      return;
    }
    await this.listDevices(); // labels are known once permission is given
    const [track] = this.stream.getVideoTracks();
    const settings = track.getSettings();
    if (settings.deviceId) $('camera-device').value = settings.deviceId;
    this.offerResolutions(capabilities(this.stream), choice);
    track.addEventListener('ended', () => {
      if (this.stream) { this.stop(); this.say('The camera stopped (unplugged or taken by another program). Press Start camera to open it again.'); }
    });
    const video = $('camera-video');
    video.srcObject = this.stream;
    await video.play().catch(() => {});
    $('camera-live').hidden = false;
    $('camera-stop').hidden = false;
    $('camera-start').disabled = false;
    $('camera-start').textContent = 'Restart camera';
    if (!this.live) this.live = this.makeEngine();
    await this.guide.reset();
    this.board = await this.images.boardInfo();
    this.cameraRate = new RateMeter();
    this.detectRate = new RateMeter();
    this.dropped = 0;
    this.last = null;
    this.loop(this.stream);
  }

  /** The resolution list of this camera: the usual ones up to its maximum, and the maximum itself. */
  offerResolutions(max, choice) {
    const select = $('camera-resolution');
    const options = resolutionChoices(max).map(([w, hh]) => new Option(`${w} × ${hh}`, `${w}x${hh}`));
    options.push(new Option(max.width ? `the camera's maximum (${max.width} × ${max.height})` : "the camera's maximum", 'max'));
    select.replaceChildren(...options);
    select.value = options.some((o) => o.value === choice) ? choice : 'max';
  }

  stopStream() {
    stopStream(this.stream);
    this.stream = null;
  }

  stop() {
    this.stopStream();
    $('camera-video').srcObject = null;
    $('camera-live').hidden = true;
    $('camera-stop').hidden = true;
    $('camera-start').disabled = false;
    $('camera-start').textContent = 'Start camera';
  }

  /** One turn per video frame while `stream` is the open one. */
  loop(stream) {
    const video = $('camera-video');
    const next = (fn) => (video.requestVideoFrameCallback ? video.requestVideoFrameCallback(fn) : requestAnimationFrame(fn));
    let lastTime = -1;
    let presented = null;
    const turn = (now, meta) => {
      if (this.stream !== stream) return;
      if (video.currentTime !== lastTime && video.videoWidth) {
        lastTime = video.currentTime;
        // The camera's rate counts the frames the video presented: a busy
        // page runs fewer callbacks than there were frames, and a detection
        // may take a frame no callback saw.
        const count = meta && Number.isFinite(meta.presentedFrames) ? meta.presentedFrames : null;
        this.cameraRate.tick(performance.now(), count === null ? 1 : presented === null ? 0 : Math.max(0, count - presented));
        if (count !== null) presented = count;
        // The step is out of sight: the camera keeps running, detection rests.
        if (!$('step-images').hidden) this.detectNewest(video, stream);
      }
      next(turn);
    };
    next(turn);
  }

  /** Detect on this frame unless a detection is running (then the frame is dropped). */
  async detectNewest(video, stream) {
    // Busy: this frame is dropped, but the one showing when the detection
    // ends is taken at once (not a frame later).
    if (this.inFlight) { this.dropped++; this.missed = true; return; }
    this.missed = false;
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch { return; }
    this.inFlight = true;
    try {
      const started = performance.now();
      // A VideoFrame wraps the decoded frame without a copy; browsers
      // without WebCodecs hand over an ImageBitmap.
      const args = typeof VideoFrame === 'function' ? { frame: new VideoFrame(video) } : { bitmap: await createImageBitmap(video) };
      // The frame just detected, still showing: not again.
      if (args.frame && args.frame.timestamp === this.lastTimestamp) { args.frame.close(); return; }
      if (args.frame) this.lastTimestamp = args.frame.timestamp;
      // The guide (auto-capture, coverage, suggestion) decides on the same frame in the worker.
      const reply = await this.live.call('frame', { ...args, spec, guide: { auto: this.guide.auto }, time: performance.now() }, [args.frame || args.bitmap]);
      if (this.stream !== stream) return;
      reply.cycleMs = performance.now() - started;
      this.detectRate.tick(performance.now());
      this.last = reply;
      this.draw(reply);
      for (const fn of this.listeners) fn(reply);
      this.guide.frame(reply);
    } catch (err) {
      if (this.stream === stream) this.showStatus('none', `Live detection failed: ${err.message}`);
    } finally {
      this.inFlight = false;
    }
    if (this.missed && this.stream === stream && !$('step-images').hidden) this.detectNewest(video, stream);
  }

  /** found (every point), partial (a marker board's subset) or none. */
  state(reply) {
    if (!reply.found) return 'none';
    const b = this.board;
    return b && MARKER_BOARDS.has(b.kind) && reply.detection.points.length < b.total ? 'partial' : 'found';
  }

  draw(reply) {
    const canvas = $('camera-overlay');
    if (canvas.width !== reply.width || canvas.height !== reply.height) {
      canvas.width = reply.width;
      canvas.height = reply.height;
    }
    const ctx = canvas.getContext('2d');
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    const state = this.state(reply);
    const points = reply.found ? reply.detection.points : [];
    const r = Math.max(3, reply.width / 200);
    const colour = { found: '#2ca02c', partial: '#ff9f0e', none: '#d62728' }[state];
    ctx.lineWidth = Math.max(1.5, r / 2);
    ctx.strokeStyle = colour;
    for (const p of points) {
      ctx.beginPath();
      ctx.arc(p.x_px + 0.5, p.y_px + 0.5, r, 0, 2 * Math.PI);
      ctx.stroke();
    }
    if (points.length) {
      ctx.fillStyle = '#1f77b4';
      ctx.beginPath();
      ctx.arc(points[0].x_px + 0.5, points[0].y_px + 0.5, r * 1.4, 0, 2 * Math.PI);
      ctx.fill();
    }
    if (points.length <= MOST_IDS) {
      ctx.font = `${Math.round(r * 3)}px system-ui`;
      ctx.lineWidth = 3;
      ctx.strokeStyle = 'rgba(0,0,0,0.8)';
      ctx.fillStyle = '#ffd54f';
      for (const p of points) {
        ctx.strokeText(String(p.id), p.x_px + r + 2, p.y_px - r);
        ctx.fillText(String(p.id), p.x_px + r + 2, p.y_px - r);
      }
    }
    this.guide.drawSuggestion(ctx, reply.width);
    // A frame around the picture in the state's colour, readable at a glance.
    ctx.lineWidth = Math.max(4, reply.width / 160);
    ctx.strokeStyle = colour;
    ctx.strokeRect(0, 0, canvas.width, canvas.height);
    const words = {
      found: `Board found: ${points.length} points`,
      partial: `Board partly found: ${points.length} of ${this.board ? this.board.total : '?'} corners`,
      none: 'Board not found',
    }[state];
    const now = performance.now();
    // The first point's position, for tests and scripts that wait for a new view.
    $('camera-status').dataset.first = points.length ? `${points[0].x_px.toFixed(1)},${points[0].y_px.toFixed(1)}` : '';
    this.showStatus(state, `${words} · ${reply.width} × ${reply.height} · camera ${this.cameraRate.rate(now).toFixed(1)} fps · detection ${this.detectRate.rate(now).toFixed(1)} fps (${reply.ms.toFixed(0)} ms a frame in the worker, ${reply.cycleMs.toFixed(0)} ms in all; frames dropped while busy: ${this.dropped})`);
  }

  showStatus(state, text) {
    const s = $('camera-status');
    s.dataset.state = state;
    const now = performance.now();
    s.dataset.fps = this.cameraRate.rate(now).toFixed(2);
    s.dataset.detectFps = this.detectRate.rate(now).toFixed(2);
    s.textContent = text;
    // Screen readers hear the state when it changes, not every frame.
    const found = $('camera-found');
    const words = { found: 'Board found', partial: 'Board partly found', none: 'Board not found' }[state];
    if (found.textContent !== words) found.textContent = words;
  }

  /** The current frame at the camera's full resolution, as PNG bytes. */
  async grabPng() {
    const video = $('camera-video');
    const canvas = document.createElement('canvas');
    canvas.width = video.videoWidth;
    canvas.height = video.videoHeight;
    canvas.getContext('2d').drawImage(video, 0, 0);
    const blob = await new Promise((resolve) => canvas.toBlob(resolve, 'image/png'));
    if (!blob) throw new Error('the frame could not be encoded as PNG');
    return blob.arrayBuffer();
  }

  /**
   * The next capture's name, taken at once (before any await): two captures
   * in flight never share a number. The session counts every number given
   * (kept in IndexedDB), so a name never comes back after a reload or after
   * its frame was removed.
   */
  nextCaptureName() {
    const s = this.store.session;
    const used = this.images.images.map((i) => CAPTURE_NAME.exec(i.name)).filter(Boolean).map((m) => Number(m[1]));
    const n = Math.max(s.captureCount || 0, ...used) + 1;
    s.captureCount = n;
    return `capture_${String(n).padStart(3, '0')}.png`;
  }

  /**
   * Capture the current frame into the session (a card, kept in IndexedDB,
   * detected like an upload). `extra` fields go on the session image (the
   * guide adds why it kept the frame). `guideIndex` is the guide's capture
   * of an auto-capture; a manual capture asks the guide to keep its last
   * frame. Returns the image's name.
   */
  async capture(extra = {}, guideIndex = null) {
    if (!this.stream || !$('camera-video').videoWidth) return null;
    // A typed robot pose must read before the frame is taken: a capture
    // without its pose would shift the pairing of every later one.
    const line = this.poses.line;
    let reading = null;
    if (line) {
      try {
        reading = await this.poses.check(line);
      } catch (err) {
        this.poses.note(`Nothing captured: the robot pose could not be read (${err.message}). Correct the line, or empty it to capture without a pose.`);
        return null;
      }
    }
    this.say('');
    // Named once the pose reads (a refused line takes no number).
    const name = this.nextCaptureName();
    if (guideIndex !== null) this.guide.named(guideIndex, name);
    try {
      const bytes = await this.grabPng();
      // The frame's card appears at once; detection of the PNG follows.
      const done = this.images.addBytes([{ name, bytes, source: 'camera', ...(line ? { robotPose: line } : {}), ...extra }]);
      if (guideIndex === null) await this.guide.manual(name);
      if (line) {
        await this.poses.captured(name, line, reading);
        await this.guide.robotPose(name, reading.poses[0] && reading.poses[0].base_from_gripper);
      }
      await done;
      this.leaveOutRepeat(name);
    } catch (err) {
      this.say(`The frame could not be captured: ${err.message}`);
      return null;
    }
    return name;
  }

  /**
   * A capture whose points are exactly those of an earlier one (camera and
   * board both still) adds nothing, and the solvers refuse a view given
   * twice: it is kept but left out, with a note on its card.
   */
  leaveOutRepeat(name) {
    const img = this.images.images.find((i) => i.name === name);
    if (!img || !img.detection) return;
    const key = JSON.stringify(img.detection.points);
    const earlier = this.captured().find((i) => i !== img && i.detection && JSON.stringify(i.detection.points) === key);
    if (!earlier) return;
    img.included = false;
    img.note = `the same points as ${earlier.name}: left out`;
    this.images.renderCard(img);
    this.images.refresh();
    this.store.changed('included');
  }

  /** A new solve when the captured views with the board are not the ones solved last. */
  solveIfChanged() {
    const key = this.captured().filter((i) => i.included && i.detection).map((i) => i.id).join(',');
    if (key === this.solvedKey) return;
    this.solvedKey = key;
    this.solve.update();
  }

  captured() { return this.images.images.filter((i) => i.source === 'camera' && this.store.bytes.has(i.id)); }

  countCaptures() {
    const n = this.captured().length;
    $('capture-count').textContent = n ? `${n} frame${n === 1 ? '' : 's'} captured` : '';
    $('download-captures').disabled = !n;
  }

  /** Every captured frame as its PNG file (one download each). */
  async downloadCaptures() {
    for (const img of this.captured()) {
      download(img.name, this.store.bytes.get(img.id), 'image/png');
      // Browsers let a page start several downloads when they do not come at once.
      await new Promise((resolve) => setTimeout(resolve, 150));
    }
  }
}
