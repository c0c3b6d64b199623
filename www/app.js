// The page: bootstraps the engine (a Web Worker running the Rust core), the
// session store (IndexedDB) and the steps, and routes between steps by hash.
// A URL whose fragment is #share=... opens a read-only results page.
import { Engine, EnginePool } from './engine.js';
import { Store, defaultSession } from './store.js';
import { $, h, fill, download } from './lib/dom.js';
import { initTarget } from './views/target.js';
import { ImagesView } from './views/images.js';
import { CaptureView } from './views/capture.js';
import { VideoView } from './views/video.js';
import { CameraView } from './views/camera.js';
import { loadLensModels } from './views/lens.js';
import { RobotView } from './views/robot.js';
import { HandEyeView } from './views/handeye.js';
import { PlanView } from './views/plan.js';
import { WorkflowsView } from './views/workflows.js';
import { RigView } from './views/rig.js';
import { ExportView } from './views/export.js';
import { CheckView } from './views/check.js';
import { LaserView } from './views/laser.js';
import { ShareView, sharedFragment, decodeShare, sessionFile, restoreResiduals } from './views/share.js';

const engine = new Engine();
let robotView = null;
const store = new Store();
const READONLY_STEPS = ['camera', 'handeye', 'export', 'share'];

/** The steps of a shared page: the check too when the link holds one. */
const readonlySteps = () => [...READONLY_STEPS, ...(store.session.check && store.session.check.result ? ['check'] : [])];

function showStep(readonly) {
  const links = [...document.querySelectorAll('#step-list a')];
  const shown = readonlySteps();
  for (const a of links) a.parentElement.hidden = readonly && !shown.includes(a.dataset.step);
  const allowed = links.filter((a) => !a.parentElement.hidden).map((a) => a.dataset.step);
  const wanted = location.hash.slice(1);
  // A new session opens on step 1 (the target); a session with images on step 2.
  const step = allowed.includes(wanted) ? wanted : readonly ? 'camera' : store.session.images.length ? 'images' : 'target';
  for (const a of links) {
    if (a.dataset.step === step) a.setAttribute('aria-current', 'step');
    else a.removeAttribute('aria-current');
  }
  for (const s of document.querySelectorAll('section.step')) s.hidden = s.id !== `step-${step}`;
}

/** Left/right arrow keys (and Home/End) on the step list move between the steps. */
function stepKeys() {
  $('step-list').addEventListener('keydown', (e) => {
    const links = [...document.querySelectorAll('#step-list a')].filter((a) => !a.parentElement.hidden);
    const i = links.indexOf(document.activeElement);
    if (i < 0) return;
    const next = { ArrowRight: i + 1, ArrowDown: i + 1, ArrowLeft: i - 1, ArrowUp: i - 1, Home: 0, End: links.length - 1 }[e.key];
    if (next === undefined) return;
    e.preventDefault();
    const a = links[(next + links.length) % links.length];
    a.focus();
    location.hash = a.dataset.step;
  });
}

/** A share link pasted into this tab (only the fragment changes): open it. */
function onHashChange(readonly, openedFragment) {
  window.addEventListener('hashchange', () => {
    const fragment = sharedFragment();
    if (fragment && fragment !== openedFragment) location.reload();
    else showStep(readonly);
  });
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
  if (payload.camera) {
    const { residualSample, ...camera } = payload.camera;
    Object.assign(store.session.camera, camera);
    // The link's sample of the residuals: drawn by the camera step's residual plots.
    // A damaged sample is left out (the page says the link carries no residuals).
    try {
      if (residualSample && camera.result) store.session.camera.residualsSampled = restoreResiduals(camera.result, residualSample);
    } catch (err) {
      console.warn(err);
    }
  }
  if (payload.handeye) Object.assign(store.session.handeye, payload.handeye);
  if (payload.plan) store.session.plan = { inputs: { view: null, fields: {} }, request: { setup: payload.plan.setup }, result: payload.plan.result };
  if (payload.check) store.session.check = payload.check;
  store.persistent = false;
  document.body.classList.add('readonly');
  $('readonly-banner').hidden = false;
  for (const id of ['demo-button', 'new-session']) $(id).hidden = true;
  const images = { setResiduals() {} };
  await loadLensModels(engine);
  const camera = new CameraView(store, engine, images, { readonly: true });
  // The robot poses the link carries: the hand-eye step's 3-D view draws them.
  const robotPoses = (payload.handeye && payload.handeye.robotPoses) || [];
  new HandEyeView(store, engine, { pairs: () => robotPoses.map((pose) => ({ image: true, pose: { base_from_gripper: pose } })) }, { readonly: true });
  new PlanView(store, engine, { pairs: () => [] }, { readonly: true });
  new CheckView(store, engine, () => new Engine(), { readonly: true });
  new ExportView(store, engine);
  new ShareView(store, version, () => camera.plots || [], null, () => robotPoses);
  showStep(true);
  stepKeys();
  onHashChange(true, fragment);
}

/**
 * What the page says about this browser's storage: a saved session that
 * could not be restored (kept downloadable), or saving that failed (the
 * session file offered). Empty and hidden when all is well.
 */
function showStorage(store) {
  const box = $('storage-status');
  const parts = [];
  if (store.damaged) {
    parts.push(h('p', {}, `The session saved in this browser could not be restored (${store.damaged.message}); a new session was started.`),
      h('button', { type: 'button', id: 'download-damaged-session', onclick: () => download('robocal-damaged-session.json', sessionFile(store.damaged.session, 'unknown'), 'application/json') }, 'Download the damaged session'));
  }
  if (store.saveError) {
    parts.push(h('p', {}, `Your work is no longer being saved in this browser (${store.saveError}): download the session file to keep it.`),
      h('button', { type: 'button', id: 'download-unsaved-session', onclick: () => download('robocal-session.json', sessionFile(store.session, 'unknown'), 'application/json') }, 'Download session file'));
  }
  fill(box, ...parts);
  box.hidden = !parts.length;
}

async function main() {
  const fragment = sharedFragment();
  if (fragment) return openShared(fragment);
  const versionPromise = engineVersion();
  stepKeys();
  await store.load();
  showStorage(store);
  store.onChange((what) => { if (what === 'storage') showStorage(store); });
  // Whatever fails while the steps are built, New session still starts anew.
  let started = false;
  $('new-session').addEventListener('click', async () => {
    if (started) return;
    await store.reset();
    location.hash = '';
    location.reload();
  });
  try {
    await startSteps(versionPromise);
    started = true;
  } catch (err) {
    $('restoring').hidden = true;
    $('engine-status').textContent = `The page could not restore this session: ${err.message}. Press New session to start anew.`;
    console.error(err);
  }
}

async function startSteps(versionPromise) {
  // Decoding the thumbnails of a saved session takes seconds: say so on the
  // step that will open instead of showing a blank panel.
  showStep(false);
  const restoring = $('restoring');
  const saved = store.session.images.length;
  if (saved || store.session.camera.result) {
    restoring.textContent = `Restoring your session${saved ? ` (${saved} image${saved === 1 ? '' : 's'})` : ''}…`;
    restoring.hidden = false;
  }
  initTarget(store, engine);
  const lensModels = loadLensModels(engine);
  // Decoding and detection use up to 4 workers (one per core).
  const pool = new EnginePool(engine, Math.min(4, navigator.hardwareConcurrency || 1));
  const images = new ImagesView(store, engine, pool);
  await images.restore();
  // The live camera detects in a worker of its own: solves never hold up the preview.
  new CaptureView(store, images, engine, () => new Engine(), () => robotView);
  // Video files: decoded by the browser, frames chosen in a worker of their own.
  new VideoView(store, images, () => new Engine());
  await lensModels;
  const camera = new CameraView(store, engine, images);
  const robot = new RobotView(store, engine);
  robotView = robot;
  const handeye = new HandEyeView(store, engine, robot);
  const plan = new PlanView(store, engine, robot);
  const workflows = new WorkflowsView(store, engine);
  const rig = new RigView(store, engine, $('rig-panel'));
  new ExportView(store, engine);
  // The check detects live frames in a worker of its own, as the capture does.
  new CheckView(store, engine, () => new Engine());
  const laser = new LaserView(store, engine);
  const version = await versionPromise;
  registerOffline(version);
  new ShareView(store, version, () => [...(camera.plots || []), ...(handeye.plots || [])], async (session) => {
    // A session file: written to this browser's storage, then the page restarts on it.
    await store.reset();
    store.session = { ...defaultSession(), ...session, images: session.images.map((i) => ({ ...i, bytesMissing: true })) };
    await store.save();
    location.hash = session.camera && session.camera.result ? 'camera' : 'images';
    location.reload();
  }, () => handeye.robotPoses3d());
  restoring.hidden = true;
  store.onChange((what) => { if (/detections|included|images|all/.test(what)) camera.summarise(); });
  const readyText = () => `Calibration engine ready (robocal ${version}).`;
  // A new session: nothing of the old one stays, the demo's note included.
  const newSession = async () => {
    await store.reset();
    location.hash = 'target';
    await images.restore();
    store.changed('target-loaded');
    // Every view that holds the session's objects in its closures is drawn
    // anew on the new session (the robot and hand-eye steps kept the old
    // session's poses and setup otherwise).
    camera.render();
    robot.render();
    handeye.render();
    plan.render();
    workflows.render();
    rig.render();
    laser.render();
    $('engine-status').textContent = readyText();
  };
  const hasWork = () => store.session.images.length || store.session.robot.text || store.session.robot.files || store.session.camera.result || store.session.rig.cameras.some((c) => c.files.length);
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
      Object.assign(store.session.robot, { fileName: 'demo_poses.csv', text: demo.poses_csv, files: null, format: 'auto', lengthUnit: 'auto', angleUnit: 'auto', direction: 'base_from_gripper' });
      robotView.render();
      await robotView.parse();
      if (!location.hash || location.hash === '#target') location.hash = 'images';
      $('engine-status').textContent = `Demo loaded: ${demo.images.length} rendered images of a ${demo.target_spec} board and the robot poses that go with them (eye-in-hand). Solve the camera in step 3, then the hand-eye in step 5.`;
    } catch (err) {
      $('engine-status').textContent = `Demo data could not be made: ${err.message}`;
    } finally {
      $('demo-button').disabled = false;
    }
  });
  onHashChange(false, null);
  showStep(false);
}

main();
