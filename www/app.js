// The page: bootstraps the engine (a Web Worker running the Rust core), the
// session store (IndexedDB) and the steps, and routes between steps by hash.
import { Engine } from './engine.js';
import { Store } from './store.js';
import { $ } from './lib/dom.js';
import { initTarget } from './views/target.js';
import { ImagesView } from './views/images.js';

const engine = new Engine();
const store = new Store();

function showStep() {
  const links = [...document.querySelectorAll('#step-list a')];
  const wanted = (location.hash || '#images').slice(1);
  const step = links.some((a) => a.dataset.step === wanted) ? wanted : 'images';
  for (const a of links) {
    if (a.dataset.step === step) a.setAttribute('aria-current', 'step');
    else a.removeAttribute('aria-current');
  }
  for (const s of document.querySelectorAll('section.step')) s.hidden = s.id !== `step-${step}`;
}

async function main() {
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
  await store.load();
  initTarget(store);
  const images = new ImagesView(store, engine);
  await images.restore();
  $('new-session').addEventListener('click', async () => {
    if (store.session.images.length && !confirm('Start a new session? Images, detections and results of this session are removed from this browser.')) return;
    await store.reset();
    await images.restore();
    store.changed('target-loaded');
  });
  $('demo-button').addEventListener('click', async () => {
    $('demo-button').disabled = true;
    try {
      const demo = await engine.call('demo', {});
      store.session.target = demo.target;
      store.changed('target-loaded');
      await images.addBytes(demo.images);
    } catch (err) {
      $('engine-status').textContent = `Demo data could not be made: ${err.message}`;
    } finally {
      $('demo-button').disabled = false;
    }
  });
  window.addEventListener('hashchange', showStep);
  showStep();
}

main();
