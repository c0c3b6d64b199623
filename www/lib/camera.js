// The browser's camera, without any page: the devices, opening one at a
// chosen resolution (up to what it can do), the messages for the ways it
// fails, and the frame rate of what it delivers.

/** Resolutions offered (width, height), smallest first; the camera's own maximum is added. */
export const RESOLUTIONS = [[640, 480], [1280, 720], [1920, 1080], [2560, 1440], [3840, 2160]];

/**
 * The plain-words message for a getUserMedia failure (a DOMException by
 * name), saying what to do; `what` is the resolution asked for, if any.
 */
export function cameraErrorText(err, what = '') {
  switch (err && err.name) {
    case 'NotAllowedError':
    case 'SecurityError':
      return 'Camera access was refused. Allow the camera for this page (the camera icon in the address bar, or the site settings), then press Start camera again. Image files can still be added above.';
    case 'NotFoundError':
    case 'DevicesNotFoundError':
      return 'No camera was found. Connect a camera and press Start camera again, or add image files above.';
    case 'NotReadableError':
    case 'TrackStartError':
      return 'The camera could not be started: another program may be using it. Close that program and press Start camera again.';
    case 'OverconstrainedError':
      return `The camera cannot deliver ${what || 'the resolution asked for'}: choose a smaller resolution.`;
    case 'AbortError':
      return 'The camera stopped while starting. Press Start camera again.';
    default:
      return `The camera could not be opened: ${err && err.message ? err.message : String(err)}.`;
  }
}

/** The video inputs (after permission their labels are known; before it, generic names). */
export async function videoInputs() {
  if (!navigator.mediaDevices || !navigator.mediaDevices.enumerateDevices) return [];
  const all = await navigator.mediaDevices.enumerateDevices();
  return all.filter((d) => d.kind === 'videoinput').map((d, i) => ({ id: d.deviceId, label: d.label || `camera ${i + 1}` }));
}

/**
 * Open a camera: `deviceId` (or the default one when empty), at
 * `width`x`height` when given (the camera's nearest otherwise), or at its
 * maximum when `max` is set. Throws the getUserMedia DOMException; a page
 * that is not a secure context has no navigator.mediaDevices at all.
 */
export async function openCamera({ deviceId, width, height, max }) {
  if (!navigator.mediaDevices || !navigator.mediaDevices.getUserMedia) {
    const err = new Error('this page is not a secure context (https or localhost), so the browser offers no camera');
    err.name = 'InsecureContext';
    throw err;
  }
  const video = {};
  if (deviceId) video.deviceId = { exact: deviceId };
  if (width && height) Object.assign(video, { width: { ideal: width }, height: { ideal: height } });
  let stream = await navigator.mediaDevices.getUserMedia({ audio: false, video });
  if (max) {
    const caps = capabilities(stream);
    if (caps.width && caps.height) {
      const [track] = stream.getVideoTracks();
      try {
        await track.applyConstraints({ width: { ideal: caps.width }, height: { ideal: caps.height } });
      } catch (e) {
        // Keep the stream as it opened: the maximum is a wish, not a need.
      }
    }
  }
  return stream;
}

/** The largest width and height the stream's camera reports (null when it does not say). */
export function capabilities(stream) {
  const [track] = stream.getVideoTracks();
  const caps = track && track.getCapabilities ? track.getCapabilities() : {};
  return { width: caps.width ? caps.width.max : null, height: caps.height ? caps.height.max : null };
}

/** The resolutions to offer for a camera whose maximum is `max` (every listed one up to it, then the maximum). */
export function resolutionChoices(max) {
  const fits = RESOLUTIONS.filter(([w, hh]) => !max.width || (w <= max.width && hh <= max.height));
  if (max.width && !fits.some(([w, hh]) => w === max.width && hh === max.height)) fits.push([max.width, max.height]);
  return fits;
}

/** Stop every track of a stream. */
export function stopStream(stream) {
  if (stream) for (const t of stream.getTracks()) t.stop();
}

/**
 * Frames per second over a sliding window of `windowMs`: `tick(t, n)` when
 * `n` events (default 1) happened by time t (ms), `rate(now)` the events
 * after the window's start divided by the window's length. The window starts
 * at the first tick until `windowMs` has passed, so a burst of close ticks
 * never reads as a high rate.
 */
export class RateMeter {
  constructor(windowMs = 2000) {
    this.windowMs = windowMs;
    this.start = null;
    this.ticks = [];
  }

  tick(t, n = 1) {
    if (this.start === null) this.start = t;
    this.ticks.push([t, n]);
    while (this.ticks.length && this.ticks[0][0] < t - this.windowMs) this.ticks.shift();
  }

  rate(now) {
    if (this.start === null) return 0;
    const from = Math.max(this.start, now - this.windowMs);
    const span = now - from;
    if (span <= 0) return 0;
    const count = this.ticks.reduce((sum, [t, n]) => (t > from && t <= now ? sum + n : sum), 0);
    return (count * 1000) / span;
  }
}
