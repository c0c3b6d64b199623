// The service worker: keeps the app (shell, modules and the wasm engine) in
// a cache so the page starts and works offline once it has been loaded.
// The cache is named after the crate version (app.js registers
// `sw.js?v=<version>`), so a new build installs a new worker whose cache
// replaces the old one. Requests go to the network first (a reachable server
// always serves the current files, which also refresh the cache) and fall
// back to the cache when the network fails. Same-origin GETs only: the app
// sends nothing anywhere.
const VERSION = new URL(self.location.href).searchParams.get('v') || 'dev';
const CACHE = `robocal-${VERSION}`;

// Every file the app loads (tests/e2e/offline.mjs checks this list against www/).
const SHELL = [
  './',
  'index.html',
  'style.css',
  'app.js',
  'engine.js',
  'worker.js',
  'store.js',
  'lib/camera.js',
  'lib/dom.js',
  'lib/frames.js',
  'lib/mat4.js',
  'lib/plot.js',
  'lib/reports.js',
  'lib/rig3d.js',
  'lib/validate.js',
  'lib/video-file.js',
  'lib/view3d.js',
  'lib/wasm-features.js',
  'views/boards.js',
  'views/camera.js',
  'views/capture.js',
  'views/capture-guide.js',
  'views/capture-poses.js',
  'views/capture-solve.js',
  'views/check.js',
  'views/export.js',
  'views/handeye.js',
  'views/images.js',
  'views/laser.js',
  'views/robot.js',
  'views/report.js',
  'views/share.js',
  'views/rig.js',
  'views/rig-stereo.js',
  'views/rig-robot.js',
  'views/rig-intrinsics.js',
  'views/rig-video.js',
  'views/lens.js',
  'views/plan.js',
  'views/target.js',
  'views/video.js',
  'views/workflows.js',
  'pkg/robocal.js',
  'pkg/robocal_bg.wasm',
];

self.addEventListener('install', (event) => {
  event.waitUntil((async () => {
    const cache = await caches.open(CACHE);
    // `reload`: bypass the HTTP cache so the precache holds this build's files.
    await cache.addAll(SHELL.map((path) => new Request(path, { cache: 'reload' })));
    await self.skipWaiting();
  })());
});

self.addEventListener('activate', (event) => {
  event.waitUntil((async () => {
    for (const name of await caches.keys()) {
      if (name.startsWith('robocal-') && name !== CACHE) await caches.delete(name);
    }
    await self.clients.claim();
  })());
});

self.addEventListener('fetch', (event) => {
  const request = event.request;
  const url = new URL(request.url);
  if (request.method !== 'GET' || url.origin !== self.location.origin) return;
  event.respondWith((async () => {
    const cache = await caches.open(CACHE);
    try {
      const response = await fetch(request);
      if (response.ok && response.type === 'basic') await cache.put(request, response.clone());
      return response;
    } catch (err) {
      // Offline: the cached copy; a navigation to any page of the app gets the shell.
      const cached = await cache.match(request, { ignoreSearch: true })
        || (request.mode === 'navigate' ? await cache.match('index.html') : undefined);
      if (cached) return cached;
      throw err;
    }
  })());
});
