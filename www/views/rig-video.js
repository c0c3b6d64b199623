// The rig step's recordings (issue 36): one video per camera (caliscope's
// cam_0.mp4, cam_1.mp4, ... converted to WebM when the browser cannot decode
// them) with or without its timestamps.csv, read as `robocal rig --camera
// cam0 cam_0.webm ... --timestamps timestamps.csv` reads them
// (src/cli/rig_video.rs): each video's frames chosen by the live capture's
// rules; a rig frame is a frame any camera kept, and every camera that found
// the board in it joins it; frames are matched across cameras by the
// timestamps' sync_index (the camera's cam_id is the number in its video's
// name), or without timestamps by the frame index.
import { h } from '../lib/dom.js';
import { Engine } from '../engine.js';
import { VIDEO_EXT } from '../lib/video-file.js';
import { scanVideo, scanSummary } from './video.js';
import { targetSpec } from './target.js';

/** The number in a file name (the last run of digits of its stem, robocal::io::pairing::number_in_name). */
export function numberInName(name) {
  const m = /(\d+)\D*$/.exec(name.replace(/\.[^.]*$/, ''));
  return m ? Number(m[1]) : null;
}

export class RigVideos {
  /** `rig` is the RigView: its cameras get the videos' frames. */
  constructor(rig) {
    this.rig = rig;
    this.engine = null;
    this.input = h('input', { type: 'file', id: 'rig-videos', multiple: true, accept: 'video/*,.mp4,.m4v,.mov,.webm,.mkv,.avi,.csv,text/csv' });
    this.input.addEventListener('change', () => { this.add([...this.input.files]); this.input.value = ''; });
    this.status = h('p', { id: 'rig-video-status', class: 'hint', role: 'status', 'data-state': 'idle' });
    this.message = h('p', { id: 'rig-video-message', class: 'msg msg-error', role: 'alert', hidden: true });
    this.video = h('video', { id: 'rig-video-preview', class: 'rig-video', 'aria-label': 'The video being read', hidden: true });
  }

  /** The controls for the rig panel. */
  element() {
    return h('div', { class: 'rig-videos' },
      h('div', { class: 'row' }, h('label', {}, 'Or one video per camera (with caliscope\'s timestamps.csv to match frames by sync_index) ', this.input)),
      this.video, this.status, this.message);
  }

  say(text) {
    this.message.textContent = text || '';
    this.message.hidden = !text;
  }

  show(state, text) {
    this.status.dataset.state = state;
    this.status.textContent = text;
  }

  /** Read the chosen videos (and timestamps) into the rig's cameras; returns when done. */
  async add(files) {
    this.say('');
    this.video.hidden = false;
    try {
      await this.read(files);
    } catch (err) {
      this.show('refused', 'The videos were not read.');
      this.say(err.message);
    } finally {
      this.video.hidden = true;
    }
  }

  async read(files) {
    const videos = files.filter((f) => VIDEO_EXT.test(f.name));
    const csv = files.filter((f) => !VIDEO_EXT.test(f.name));
    if (!videos.length) throw new Error('choose the cameras\' videos (cam_0.webm, cam_1.webm, ...), with their timestamps.csv if there is one');
    if (csv.length > 1) throw new Error(`one timestamps file, not ${csv.length}: ${csv.map((f) => f.name).join(', ')}`);
    const spec = targetSpec(this.rig.store.session.target);
    if (!this.engine) this.engine = new Engine();
    const stamps = csv.length ? await this.rig.engine.call('videoTimestamps', { text: await csv[0].text() }).catch((err) => { throw new Error(`${csv[0].name}: ${err.message}`); }) : null;
    // Each video's camera: cam<N> for the N of its name (its cam_id in the timestamps).
    const cams = videos.map((file) => {
      const id = numberInName(file.name);
      if (stamps && id === null) throw new Error(`${file.name}: no number in the name to find its cam_id in the timestamps (name the video cam_N.webm, as caliscope does)`);
      const rows = stamps ? stamps.cameras[String(id)] : null;
      if (stamps && !rows) throw new Error(`${file.name}: no row of ${csv[0].name} has cam_id ${id} (the file has cam_id ${Object.keys(stamps.cameras).join(', ')})`);
      const key = (index) => String(rows && index < rows.sync_index.length ? rows.sync_index[index] : index);
      return { file, name: id === null ? file.name.replace(/\.[^.]*$/, '') : `cam${id}`, key };
    });
    // 1. Each video's frames by the capture rules.
    const wanted = new Set();
    const lines = [];
    for (const cam of cams) {
      const c = await scanVideo(this.engine, this.video, cam.file, spec, {
        onKept: () => {},
        progress: (counts, index) => this.show('reading', `${cam.file.name}: frame ${index} · board in ${counts.found} of ${counts.read} · ${counts.kept} kept`),
      });
      for (const i of c.keptIndices) wanted.add(cam.key(i));
      lines.push(scanSummary(cam.file.name, c));
    }
    // 2. The rig frames: every camera's frames of the keys any camera kept, where it found the board.
    const st = this.rig.state;
    for (const cam of cams) {
      let camera = st.cameras.find((c) => c.name === cam.name);
      if (!camera) {
        camera = st.cameras.find((c) => !c.files.length && /^cam\d+$/.test(c.name) && !cams.some((o) => o.name === c.name));
        if (camera) camera.name = cam.name;
        else st.cameras.push((camera = { name: cam.name, files: [] }));
      }
      await this.rig.store.deleteBytes(camera.files.map((f) => f.id));
      camera.files = [];
      await scanVideo(this.engine, this.video, cam.file, spec, {
        keepAll: (i) => wanted.has(cam.key(i)),
        onKept: async (index, bytes, r) => {
          if (!wanted.has(cam.key(index))) return;
          const id = `rig-${Date.now().toString(36)}-${Math.random().toString(36).slice(2, 8)}`;
          await this.rig.store.putBytes(id, bytes);
          camera.files.push({ id, name: r.name, frameKey: cam.key(index), detection: null, error: null, spec: null });
        },
        progress: (counts, index) => this.show('reading', `${cam.file.name}: taking the rig frames, frame ${index}`),
      });
    }
    st.videoGrouping = stamps ? 'sync_index' : 'frame';
    this.rig.store.changed('rig');
    this.rig.showCameras();
    this.rig.showFrames();
    this.show('done', `${lines.join(' ')} ${wanted.size} rig frames from the videos (a frame any camera kept, with every camera that found the board in it)${stamps ? `, matched by the sync_index of ${csv[0].name}` : ', matched by frame index'}.`);
  }
}

const isVideoFrame = (f) => f.frameKey !== undefined;

/**
 * The rig's frame grouping (as the `rigFrames` call returns it) with the
 * video frames keyed by their sync index or frame index, the images by
 * their names' rule (`groupBy`, through `engine`).
 */
export async function rigGrouping(engine, cams, groupBy, videoGrouping) {
  const named = cams.map((c) => ({ name: c.name, images: c.files.filter((f) => !isVideoFrame(f)).map((f) => f.name) }));
  const videos = cams.some((c) => c.files.some(isVideoFrame));
  const g = !videos || named.some((c) => c.images.length)
    ? await engine.call('rigFrames', { cameras: JSON.stringify(named), groupBy })
    : { grouped_by: videoGrouping === 'sync_index' ? 'sync_index' : 'frame index', keys: named.map(() => []), frames: [] };
  if (!videos) return g;
  const keys = cams.map((c, k) => { let j = 0; return c.files.map((f) => (isVideoFrame(f) ? f.frameKey : g.keys[k][j++])); });
  const frames = [...new Set(keys.flat())].sort((a, b) => a.localeCompare(b, undefined, { numeric: true }));
  return { ...g, keys, frames };
}
