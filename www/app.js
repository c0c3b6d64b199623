// The page: bootstraps the engine (a Web Worker running the Rust core), the
// session store (IndexedDB) and the steps, and routes between steps by hash.
// A URL whose fragment is #share=... opens a read-only results page.
import { Engine, EnginePool } from './engine.js';
import { Store, defaultSession } from './store.js';
import { $ } from './lib/dom.js';
import { initTarget } from './views/target.js';
import { ImagesView } from './views/images.js';
import { CameraView } from './views/camera.js';
import { RobotView } from './views/robot.js';
import { HandEyeView } from './views/handeye.js';
import { WorkflowsView } from './views/workflows.js';
import { StereoView } from './views/stereo.js';
import { ExportView } from './views/export.js';
import { ShareView, sharedFragment, decodeShare } from './views/share.js';

const engine = new Engine();
let robotView = null;
const store = new Store();
const READONLY_STEPS = ['camera', 'handeye', 'export', 'share'];

function showStep(readonly) {
  const links = [...document.querySelectorAll('#step-list a')];
  for (const a of links) a.parentElement.hidden = readonly && !READONLY_STEPS.includes(a.dataset.step);
  const allowed = links.filter((a) => !a.parentElement.hidden).map((a) => a.dataset.step);
  const wanted = location.hash.slice(1);
  const step = allowed.includes(wanted) ? wanted : readonly ? 'camera' : 'images';
  for (const a of links) {
    if (a.dataset.step === step) a.setAttribute('aria-current', 'step');
    else a.removeAttribute('aria-current');
  }
  for (const s of document.querySelectorAll('section.step')) s.hidden = s.id !== `step-${step}`;
}

async function engineVersion() {
  try {
    const { version } = await engine.call('version');
    $('engine-status').textContent = `Calibration engine ready (robocal ${version}).`;
    $('engine-status').classList.add('ready');
    $('version').textContent = `robocal ${version}`;
    return version;
  } catch (err) {
    $('engine-status').textContent = `The calibration engine could not start: ${err.message}`;
    $('engine-status').classList.add('failed');
    return 'unknown';
  }
}

/**
 * The service worker (sw.js) that keeps the app usable offline. Its cache is
 * named after the engine's crate version, so a new build replaces it.
 */
function registerOffline(version) {
  if (!('serviceWorker' in navigator) || version === 'unknown') return;
  navigator.serviceWorker.register(`./sw.js?v=${encodeURIComponent(version)}`).catch((err) => {
    $('version').textContent += ` · offline use unavailable: ${err.message}`;
  });
}

/** A shared link: results only, in memory (never written over the user's own session). */
async function openShared(fragment) {
  const version = await engineVersion();
  registerOffline(version);
  let payload;
  try {
    payload = await decodeShare(fragment);
  } catch (err) {
    $('readonly-banner').hidden = false;
    $('readonly-banner').textContent = `${err.message}. Start your own session at ${location.pathname}.`;
    return;
  }
  store.session = defaultSession();
  store.session.target = payload.target || store.session.target;
  if (payload.camera) Object.assign(store.session.camera, payload.camera);
  if (payload.handeye) Object.assign(store.session.handeye, payload.handeye);
  store.persistent = false;
  document.body.classList.add('readonly');
  $('readonly-banner').hidden = false;
  for (const id of ['demo-button', 'new-session']) $(id).hidden = true;
  const images = { setResiduals() {} };
  const camera = new CameraView(store, engine, images, { readonly: true });
  new HandEyeView(store, engine, { pairs: () => [] }, { readonly: true });
  new ExportView(store, engine);
  new ShareView(store, version, () => camera.plots || []);
  showStep(true);
  window.addEventListener('hashchange', () => showStep(true));
}

async function main() {
  const fragment = sharedFragment();
  if (fragment) return openShared(fragment);
  const versionPromise = engineVersion();
  await store.load();
  initTarget(store, engine);
  // Decoding and detection use up to 4 workers (one per core).
  const pool = new EnginePool(engine, Math.min(4, navigator.hardwareConcurrency || 1));
  const images = new ImagesView(store, engine, pool);
  await images.restore();
  const camera = new CameraView(store, engine, images);
  const robot = new RobotView(store, engine);
  robotView = robot;
  new HandEyeView(store, engine, robot);
  new WorkflowsView(store, engine);
  const stereo = new StereoView(store, engine);
  new ExportView(store, engine);
  const version = await versionPromise;
  registerOffline(version);
  new ShareView(store, version, () => camera.plots || []);
  store.onChange((what) => { if (/detections|included|images|all/.test(what)) camera.summarise(); });
  const readyText = () => `Calibration engine ready (robocal ${version}).`;
  // A new session: nothing of the old one stays, the demo's note included.
  const newSession = async () => {
    await store.reset();
    await images.restore();
    store.changed('target-loaded');
    camera.render();
    stereo.render();
    $('engine-status').textContent = readyText();
  };
  const hasWork = () => store.session.images.length || store.session.robot.text || store.session.camera.result || store.session.stereo.left.length;
  $('new-session').addEventListener('click', async () => {
    if (store.session.images.length && !confirm('Start a new session? Images, detections and results of this session are removed from this browser.')) return;
    await newSession();
  });
  $('demo-button').addEventListener('click', async () => {
    // The demo is a session of its own: over open work, ask first.
    if (hasWork() && !confirm('Load the demo data? It starts a new session: the images, poses, detections and results of this session are removed from this browser.')) return;
    $('demo-button').disabled = true;
    try {
      if (hasWork()) await newSession();
      $('engine-status').textContent = 'Rendering the demo images…';
      const demo = await engine.call('demo', { seed: 1 });
      const t = demo.target;
      store.session.target = t; // the core's target JSON
      store.changed('target-loaded');
      await images.addBytes(demo.images);
      Object.assign(store.session.robot, { fileName: 'demo_poses.csv', text: demo.poses_csv, format: 'auto', lengthUnit: 'auto', angleUnit: 'auto', direction: 'base_from_gripper' });
      robotView.render();
      await robotView.parse();
      $('engine-status').textContent = `Demo loaded: ${demo.images.length} rendered images of a ${demo.target_spec} board and the robot poses that go with them (eye-in-hand). Solve the camera in step 3, then the hand-eye in step 5.`;
    } catch (err) {
      $('engine-status').textContent = `Demo data could not be made: ${err.message}`;
    } finally {
      $('demo-button').disabled = false;
    }
  });
  window.addEventListener('hashchange', () => showStep(false));
  showStep(false);
}

main();
