// Video files in the page (issue 36, recordings): which codec a file holds
// (read from its container, for the message when the browser cannot decode
// it), its frame duration when the container states it, and its frames one
// by one through the browser's own decoder (<video>, paused on each frame
// by requestVideoFrameCallback, so no frame is skipped however slow the
// detection of the one before).

/** File names taken as videos (the CLI's list, src/cli/video.rs). */
export const VIDEO_EXT = /\.(mp4|m4v|mov|avi|mkv|webm)$/i;

/** Container codec ids and what they are. */
const CODECS = {
  avc1: 'H.264', avc3: 'H.264', hvc1: 'H.265/HEVC', hev1: 'H.265/HEVC', vp08: 'VP8', vp09: 'VP9', av01: 'AV1',
  mp4v: 'MPEG-4 Part 2', xvid: 'MPEG-4 Part 2', divx: 'MPEG-4 Part 2', fmp4: 'MPEG-4 Part 2', dx50: 'MPEG-4 Part 2',
  mjpg: 'Motion JPEG', jpeg: 'Motion JPEG', mjpa: 'Motion JPEG', s263: 'H.263', h263: 'H.263',
  'V_VP8': 'VP8', 'V_VP9': 'VP9', 'V_AV1': 'AV1', 'V_MPEG4/ISO/AVC': 'H.264', 'V_MPEGH/ISO/HEVC': 'H.265/HEVC',
  'V_MPEG4/ISO/ASP': 'MPEG-4 Part 2', 'V_MPEG4/ISO/SP': 'MPEG-4 Part 2', 'V_THEORA': 'Theora', 'V_MJPEG': 'Motion JPEG',
};

/** Bytes as text, one character per byte (latin1: any byte reads). */
const ascii = (bytes, at, n) => new TextDecoder('latin1').decode(bytes.subarray(at, at + n));

/** `file`'s bytes `[from, to)`. */
async function slice(file, from, to) {
  return new Uint8Array(await file.slice(from, Math.min(to, file.size)).arrayBuffer());
}

/** The boxes of an MP4/MOV byte range: `{ type, start (of the payload), end }`. */
function boxes(bytes, from = 0, to = bytes.length) {
  const out = [];
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let at = from;
  while (at + 8 <= to) {
    let size = view.getUint32(at);
    let head = 8;
    if (size === 1 && at + 16 <= to) { size = Number(view.getBigUint64(at + 8)); head = 16; }
    if (size === 0) size = to - at;
    if (size < head || at + size > to) break;
    out.push({ type: ascii(bytes, at + 4, 4), start: at + head, end: at + size });
    at += size;
  }
  return out;
}

/** The moov box's bytes of an MP4/MOV file (top-level boxes walked by their headers, wherever moov is). */
async function moovOf(file) {
  let at = 0;
  while (at + 8 <= file.size) {
    const head = await slice(file, at, at + 16);
    const view = new DataView(head.buffer);
    let size = view.getUint32(0);
    if (size === 1 && head.length >= 16) size = Number(view.getBigUint64(8));
    if (size === 0) size = file.size - at;
    if (size < 8) return null;
    if (ascii(head, 4, 4) === 'moov') return slice(file, at, at + size);
    at += size;
  }
  return null;
}

/** The video track of an MP4/MOV file: `{ codec, frameS, frames }` (frameS the most common frame duration). */
async function mp4Video(file) {
  const moov = await moovOf(file);
  if (!moov) return null;
  const view = new DataView(moov.buffer);
  const child = (box, type) => boxes(moov, box.start, box.end).find((b) => b.type === type);
  const [top] = boxes(moov);
  for (const trak of boxes(moov, top.start, top.end).filter((b) => b.type === 'trak')) {
    const mdia = child(trak, 'mdia');
    const hdlr = mdia && child(mdia, 'hdlr');
    if (!hdlr || ascii(moov, hdlr.start + 8, 4) !== 'vide') continue;
    const mdhd = child(mdia, 'mdhd');
    const timescale = mdhd ? view.getUint32(mdhd.start + (moov[mdhd.start] === 1 ? 20 : 12)) : 0;
    const minf = child(mdia, 'minf');
    const stbl = minf && child(minf, 'stbl');
    const stsd = stbl && child(stbl, 'stsd');
    const stts = stbl && child(stbl, 'stts');
    const codec = stsd ? ascii(moov, stsd.start + 12, 4) : '';
    let frameS = null;
    let frames = 0;
    if (stts && timescale) {
      let most = 0;
      const n = view.getUint32(stts.start + 4);
      for (let k = 0; k < n; k++) {
        const count = view.getUint32(stts.start + 8 + 8 * k);
        const delta = view.getUint32(stts.start + 12 + 8 * k);
        frames += count;
        if (count > most && delta > 0) { most = count; frameS = delta / timescale; }
      }
    }
    return { codec, frameS, frames };
  }
  return null;
}

/**
 * A Matroska/WebM track's DefaultDuration (element 0x23E383, nanoseconds
 * per frame) near its CodecID at `near`, in seconds, or null.
 */
function defaultDuration(bytes, near) {
  for (let i = Math.max(0, near - 400); i + 4 < Math.min(bytes.length, near + 400); i++) {
    if (bytes[i] !== 0x23 || bytes[i + 1] !== 0xe3 || bytes[i + 2] !== 0x83) continue;
    const first = bytes[i + 3];
    const len = Math.clz32(first) - 23; // the size's own length (1 for 0x8N)
    if (len < 1 || len > 8) return null;
    let size = first & (0xff >> len);
    for (let k = 1; k < len; k++) size = size * 256 + bytes[i + 3 + k];
    let ns = 0;
    for (let k = 0; k < size; k++) ns = ns * 256 + bytes[i + 3 + len + k];
    return size >= 1 && size <= 8 && ns > 0 ? ns / 1e9 : null;
  }
  return null;
}

/**
 * The codec of a video file as its container names it (`mp4v`, `avc1`,
 * `V_VP9`, an AVI's fourcc, ...) with what it is, and the frame duration
 * in seconds when the container says (MP4/MOV), else null.
 */
export async function videoCodec(file) {
  const head = await slice(file, 0, 1 << 20);
  let codec = '';
  let frameS = null;
  if (ascii(head, 4, 4) === 'ftyp' || ['moov', 'mdat', 'wide', 'free'].includes(ascii(head, 4, 4))) {
    const v = await mp4Video(file).catch(() => null);
    if (v) ({ codec, frameS } = v);
  } else if (head[0] === 0x1a && head[1] === 0x45 && head[2] === 0xdf && head[3] === 0xa3) {
    const text = ascii(head, 0, head.length);
    const m = /V_[A-Z0-9/]+/.exec(text);
    if (m) {
      codec = Object.keys(CODECS).filter((k) => m[0].startsWith(k)).sort((a, b) => b.length - a.length)[0] || m[0];
      frameS = defaultDuration(head, m.index);
    }
  } else if (ascii(head, 0, 4) === 'RIFF' && ascii(head, 8, 3) === 'AVI') {
    const at = ascii(head, 0, head.length).indexOf('vids');
    if (at >= 0) codec = ascii(head, at + 4, 4);
  }
  return { codec, what: CODECS[codec] || CODECS[codec.toLowerCase()] || '', frameS };
}

/** A file name as one shell word. */
const shellWord = (name) => (/^[\w.,+@%=:/-]+$/.test(name) ? name : `'${name.replace(/'/g, "'\\''")}'`);

/**
 * The message for a video the browser cannot decode: the file, its codec
 * and the ffmpeg line that makes a VP9 WebM of it (which every browser
 * with the page decodes).
 */
export function undecodableText(name, { codec, what }) {
  const stem = name.replace(/\.[^.]*$/, '');
  const out = /\.webm$/i.test(name) ? `${stem}-vp9.webm` : `${stem}.webm`;
  const codecText = codec ? `codec ${codec.trim()}${what ? `, ${what}` : ''}` : 'codec not recognised';
  return `This browser cannot decode the video of ${name} (${codecText}). Convert it to VP9 in WebM with ffmpeg, then add the .webm file: ffmpeg -i ${shellWord(name)} -c:v libvpx-vp9 ${shellWord(out)}`;
}

/**
 * Open `file` in `video` (a <video> element in the page): resolves with
 * `{ width, height, duration }` once its first frame can be shown, or
 * rejects with the undecodable message (the codec named from the
 * container) when the browser cannot decode its video.
 */
export async function openVideo(video, file, codec) {
  const refuse = () => new Error(undecodableText(file.name, codec));
  video.muted = true;
  video.playsInline = true;
  video.preload = 'auto';
  video.src = URL.createObjectURL(file);
  await new Promise((resolve, reject) => {
    const done = (fn) => { clearTimeout(timer); video.onloadeddata = null; video.onerror = null; fn(); };
    const timer = setTimeout(() => done(() => reject(refuse())), 30000);
    video.onloadeddata = () => done(resolve);
    video.onerror = () => done(() => reject(refuse()));
  });
  // A file whose only decodable stream is sound has no picture.
  if (!video.videoWidth || !video.videoHeight) throw refuse();
  return { width: video.videoWidth, height: video.videoHeight, duration: video.duration };
}

/** Release what `openVideo` took. */
export function closeVideo(video) {
  const url = video.src;
  video.pause();
  video.removeAttribute('src');
  video.load();
  if (url.startsWith('blob:')) URL.revokeObjectURL(url);
}

/** Seek the paused `video` to `t` s and wait until the frame there is shown. */
function seekTo(video, t) {
  return new Promise((resolve) => {
    video.addEventListener('seeked', resolve, { once: true });
    video.currentTime = t;
  });
}

/**
 * Every frame of the opened `video` in order, as `onFrame(index, timeMs)`
 * (awaited, the video paused on the frame: draw it from `video`). The
 * video plays and pauses on each new frame (requestVideoFrameCallback); a
 * frame the player went past meanwhile (a busy page) is fetched by seeking
 * to its middle, so every frame is given once, in order. `index` is the
 * frame's number from the container's frame duration (`frameS`) or, when
 * it states none, from the step between the first two frames. `onFrame`
 * returning `false` stops the reading. Resolves with the number of frames
 * read.
 */
export function eachFrame(video, frameS, onFrame) {
  if (!video.requestVideoFrameCallback) return eachFrameBySeeking(video, frameS || 1 / 30, onFrame);
  return new Promise((resolve, reject) => {
    let step = frameS;
    let firstTime = null; // the first frame waits for the step when the container gave none
    let next = 0; // the index of the next frame to give
    let read = 0;
    let stopped = false;
    let busy = false;
    let ending = false;
    let pending = 0; // the requestVideoFrameCallback handle
    const finish = () => { stopped = true; video.pause(); video.onended = null; resolve(read); };
    const give = async (index, t) => {
      read++;
      next = index + 1;
      return (await onFrame(index, t * 1000)) !== false;
    };
    /** The frames from `next` to the one at `t` (those skipped fetched by seeking). */
    const upTo = async (t) => {
      const index = Math.round(t / step);
      if (index < next) return true; // shown again (after a seek): given already
      const missed = index - next;
      for (let m = next; m < index; m++) {
        await seekTo(video, t + (m - index + 0.5) * step);
        if (!(await give(m, t + (m - index) * step))) return false;
      }
      if (missed) await seekTo(video, t + step / 2);
      return give(index, t);
    };
    const turn = async (_now, meta) => {
      if (stopped || ending) return;
      video.pause();
      busy = true;
      try {
        const t = meta.mediaTime;
        let go = true;
        if (!step && firstTime === null) {
          firstTime = t;
        } else {
          if (!step) step = t - firstTime > 1e-6 ? t - firstTime : null;
          if (firstTime !== null && step) {
            // The first frame, now that its index is known: shown again, then back here.
            await seekTo(video, firstTime + step / 2);
            go = await give(Math.round(firstTime / step), firstTime);
            firstTime = null;
            if (go) await seekTo(video, t + step / 2);
          }
          if (go && step) go = await upTo(t);
        }
        busy = false;
        if (!go) return finish();
        if (video.ended) return end();
        pending = video.requestVideoFrameCallback(turn);
        await video.play();
      } catch (err) {
        stopped = true;
        video.pause();
        reject(err);
      }
    };
    const end = async () => {
      if (stopped || busy) return;
      // The seeks below show frames: the callback waiting for the next one must not run.
      ending = true;
      video.cancelVideoFrameCallback(pending);
      try {
        // A one-frame video: its frame is frame 0.
        if (firstTime !== null) { await give(0, firstTime); firstTime = null; }
        // The last frames, when the player ran past them to the end.
        for (let m = next; step && (m + 0.5) * step < video.duration; m++) {
          await seekTo(video, (m + 0.5) * step);
          if (!(await give(m, m * step))) break;
        }
      } catch (err) {
        stopped = true;
        reject(err);
        return;
      }
      finish();
    };
    video.onended = () => end();
    video.currentTime = 0;
    pending = video.requestVideoFrameCallback(turn);
    video.play().catch(reject);
  });
}

/** Browsers without requestVideoFrameCallback: seek to the middle of each frame in turn. */
async function eachFrameBySeeking(video, frameS, onFrame) {
  const total = Math.max(1, Math.floor(video.duration / frameS + 1e-6));
  let read = 0;
  for (let k = 0; k < total; k++) {
    await new Promise((resolve) => { video.onseeked = resolve; video.currentTime = (k + 0.5) * frameS; });
    read++;
    if ((await onFrame(k, k * frameS * 1000)) === false) break;
  }
  video.onseeked = null;
  return read;
}
