// Step 2's video source (issue 36, recordings): an MP4 or WebM file decoded
// by the browser, each frame given to a live-capture session in a worker of
// its own, and the frames it keeps (board found, still, sharp, adding
// coverage: the live camera's rules, docs/live-capture.md) added to the
// session as PNG cards named `cam_0.mp4#frame0123`, as `robocal` names the
// frames it takes from a video. A video the browser cannot decode gets the
// ffmpeg line that converts it.
import { $ } from '../lib/dom.js';
import { VIDEO_EXT, videoCodec, openVideo, closeVideo, eachFrame } from '../lib/video-file.js';
import { targetSpec } from './target.js';

/** Frames kept per video at most (`robocal --max-frames`'s default, src/cli/video_frames.rs). */
export const MAX_FRAMES = 60;

export const isVideo = (file) => VIDEO_EXT.test(file.name);

/** The frame shown by `video` as PNG bytes. */
export async function framePng(video) {
  const canvas = document.createElement('canvas');
  canvas.width = video.videoWidth;
  canvas.height = video.videoHeight;
  canvas.getContext('2d').drawImage(video, 0, 0);
  const blob = await new Promise((resolve) => canvas.toBlob(resolve, 'image/png'));
  if (!blob) throw new Error('the frame could not be encoded as PNG');
  return blob.arrayBuffer();
}

/**
 * Read `file`'s frames through `engine`'s `videoFrame` session (the
 * capture rules) in the <video> `video`: `onKept(index, pngBytes, verdict)`
 * for each frame kept (`verdict.name`: the frame's name `cam_0.mp4#frame0123`,
 * the CLI's, from the core's `video_frame_name` in the worker),
 * `progress(counts)` after each frame, `stop()` true to stop.
 * Returns `{ read, looked, found, kept, reasons, width, height, codec }`;
 * throws the undecodable-codec message for a video the browser cannot decode.
 */
export async function scanVideo(engine, video, file, spec, { onKept, progress = () => {}, stop = () => false, maxFrames = MAX_FRAMES, keepAll = null }) {
  const codec = await videoCodec(file);
  const { width, height } = await openVideo(video, file, codec);
  const counts = { read: 0, found: 0, kept: 0, reasons: {}, width, height, codec: codec.codec, keptIndices: [], foundIndices: [] };
  try {
    await engine.call('videoFrame', { reset: true });
    await eachFrame(video, codec.frameS, async (index, timeMs) => {
      if (stop()) return false;
      counts.read++;
      const bitmap = await createImageBitmap(video);
      const r = await engine.call('videoFrame', { bitmap, spec, time: timeMs, video: file.name, index }, [bitmap]);
      if (r.status !== 'not_found') { counts.found++; counts.foundIndices.push(index); }
      // `keepAll(index)`: a frame another camera kept (a rig), taken whenever the board is in it.
      const wanted = r.keep || (keepAll && keepAll(index) && r.status !== 'not_found');
      if (wanted) {
        if (r.keep) { counts.kept++; counts.keptIndices.push(index); }
        await onKept(index, await framePng(video), r);
      } else {
        counts.reasons[r.message] = (counts.reasons[r.message] || 0) + 1;
      }
      progress(counts, index);
      return counts.kept < maxFrames;
    });
  } finally {
    closeVideo(video);
  }
  return counts;
}

/** One line like the CLI's: frames read, with the board, kept and why the others were left out. */
export function scanSummary(name, c) {
  const left = Object.entries(c.reasons).sort(([a], [b]) => (a < b ? -1 : 1)).map(([m, n]) => `${n} ${m}`).join(', ');
  return `${name}: ${c.read} frames read (${c.width} × ${c.height}${c.codec ? `, ${c.codec.trim()}` : ''}), board in ${c.found}, ${c.kept} kept by the capture rules${left ? ` (left out: ${left})` : ''}.`;
}

export class VideoView {
  /** `images` is the ImagesView (the kept frames join its session); `makeEngine()` gives the video's own worker. */
  constructor(store, images, makeEngine) {
    this.store = store;
    this.images = images;
    this.makeEngine = makeEngine;
    this.engine = null;
    this.queue = Promise.resolve();
    this.cancelled = false;
    $('choose-video').addEventListener('click', () => $('video-input').click());
    $('video-input').addEventListener('change', (e) => { this.add([...e.target.files]); e.target.value = ''; });
    $('video-stop').addEventListener('click', () => { this.cancelled = true; });
    // Videos dropped or chosen with the images come here.
    images.videos = this;
  }

  say(text) {
    const m = $('video-message');
    m.textContent = text || '';
    m.hidden = !text;
  }

  /** Read each video in turn (one at a time). */
  add(files) {
    this.queue = this.queue.then(async () => {
      this.say('');
      const messages = [];
      for (const file of files) {
        const text = await this.scan(file);
        if (text) messages.push(text);
      }
      this.say(messages.join('\n'));
    });
    return this.queue;
  }

  status(state, text, counts = null) {
    const s = $('video-status');
    s.dataset.state = state;
    if (counts) Object.assign(s.dataset, { read: counts.read, found: counts.found, kept: counts.kept });
    s.textContent = text;
  }

  /** Read one video; returns an error message or ''. */
  async scan(file) {
    let spec;
    try { spec = targetSpec(this.store.session.target); } catch (err) { return `${file.name}: choose the target in step 1 first (${err.message}).`; }
    if (!this.engine) this.engine = this.makeEngine();
    this.cancelled = false;
    $('video-scan').hidden = false;
    $('video-stop').hidden = false;
    this.status('reading', `${file.name}: opening…`);
    const detections = [];
    try {
      const counts = await scanVideo(this.engine, $('video-preview'), file, spec, {
        stop: () => this.cancelled,
        onKept: (index, bytes, r) => { detections.push(this.images.addBytes([{ name: r.name, bytes, source: 'video' }])); },
        progress: (c, index) => this.status('reading', `${file.name}: frame ${index} · board in ${c.found} of ${c.read} · ${c.kept} kept`, c),
      });
      await Promise.all(detections);
      this.status('done', scanSummary(file.name, counts), counts);
      return '';
    } catch (err) {
      this.status('refused', `${file.name}: not read.`);
      return err.message;
    } finally {
      $('video-stop').hidden = true;
    }
  }
}
