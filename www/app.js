// The page: wires the drop zone and file picker to the engine (a Web Worker
// running the Rust core) and shows one card per file.
import { Engine } from './engine.js';

const THUMB_SIDE = 320;
const engine = new Engine();
const $ = (id) => document.getElementById(id);
const images = []; // { name, size, status: 'pending'|'ok'|'error', info?, error? }

engine.call('version').then(
  ({ version }) => {
    $('engine-status').textContent = `Calibration engine ready (robocal ${version}).`;
    $('engine-status').classList.add('ready');
    $('version').textContent = `robocal ${version}`;
  },
  (err) => {
    $('engine-status').textContent = `The calibration engine could not start: ${err.message}`;
    $('engine-status').classList.add('failed');
  },
);

function updateSummary() {
  const ok = images.filter((i) => i.status === 'ok').length;
  const bad = images.filter((i) => i.status === 'error').length;
  const pending = images.length - ok - bad;
  const parts = [`${images.length} file${images.length === 1 ? '' : 's'}`, `${ok} decoded`];
  if (bad) parts.push(`${bad} failed`);
  if (pending) parts.push(`${pending} in progress`);
  $('image-summary').textContent = parts.join(', ');
}

function makeCard(name) {
  const li = document.createElement('li');
  li.className = 'card pending';
  li.dataset.name = name;
  const canvas = document.createElement('canvas');
  canvas.width = 4;
  canvas.height = 3;
  canvas.setAttribute('role', 'img');
  canvas.setAttribute('aria-label', `thumbnail of ${name}`);
  const title = document.createElement('p');
  title.className = 'name';
  title.textContent = name;
  const meta = document.createElement('p');
  meta.className = 'meta';
  meta.textContent = 'decoding';
  li.append(canvas, title, meta);
  $('cards').append(li);
  return { li, canvas, meta };
}

function drawThumbnail(canvas, { width, height, rgba }) {
  canvas.width = width;
  canvas.height = height;
  const ctx = canvas.getContext('2d');
  ctx.putImageData(new ImageData(new Uint8ClampedArray(rgba), width, height), 0, 0);
}

function describe(info) {
  const channels = { 1: 'grey', 2: 'grey + alpha', 3: 'RGB', 4: 'RGBA' }[info.channels] || `${info.channels} channels`;
  return `${info.format_name} · ${info.width}×${info.height} px · ${channels}, ${info.bits_per_channel}-bit`;
}

async function addFile(file) {
  const entry = { name: file.name, size: file.size, status: 'pending' };
  images.push(entry);
  updateSummary();
  const card = makeCard(file.name);
  try {
    const bytes = await file.arrayBuffer();
    const preview = await engine.call('preview', { bytes, maxSide: THUMB_SIDE }, [bytes]);
    entry.status = 'ok';
    entry.info = preview.info;
    drawThumbnail(card.canvas, preview);
    card.li.className = 'card ok';
    card.meta.textContent = describe(preview.info);
  } catch (err) {
    entry.status = 'error';
    entry.error = err.message;
    card.canvas.remove();
    card.li.className = 'card error';
    card.li.setAttribute('role', 'alert');
    card.meta.textContent = err.message;
  }
  updateSummary();
}

function addFiles(fileList) {
  // Sequential on purpose: the worker is single-threaded and memory stays bounded.
  return [...fileList].reduce((chain, f) => chain.then(() => addFile(f)), Promise.resolve());
}

$('file-input').addEventListener('change', (e) => {
  addFiles(e.target.files);
  e.target.value = '';
});
const zone = $('dropzone');
zone.addEventListener('dragover', (e) => {
  e.preventDefault();
  zone.classList.add('over');
});
zone.addEventListener('dragleave', () => zone.classList.remove('over'));
zone.addEventListener('drop', (e) => {
  e.preventDefault();
  zone.classList.remove('over');
  addFiles(e.dataTransfer.files);
});
zone.addEventListener('keydown', (e) => {
  if (e.key === 'Enter' || e.key === ' ') {
    e.preventDefault();
    $('file-input').click();
  }
});
