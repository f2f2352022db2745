// cutroute's service worker: the app keeps working offline after its first visit.
//
// The release build (scripts/build-release.sh → scripts/precache.py) fills in PRECACHE with
// every file of dist/ and VERSION with their content hash; the install step caches them all, so
// the first visit is enough. Requests are answered from the network when there is one (a
// redeployed app is seen at once) and from the cache when there is none. A development build
// (`trunk serve`) leaves the list empty and only caches what it fetches.
const VERSION = 'development';
const PRECACHE = [];
const CACHE = `cutroute-${VERSION}`;

self.addEventListener('install', (event) => {
  event.waitUntil(
    caches.open(CACHE)
      .then((cache) => cache.addAll(PRECACHE))
      .then(() => self.skipWaiting()),
  );
});

self.addEventListener('activate', (event) => {
  event.waitUntil(
    caches.keys()
      .then((keys) => Promise.all(keys.filter((k) => k.startsWith('cutroute-') && k !== CACHE).map((k) => caches.delete(k))))
      .then(() => self.clients.claim()),
  );
});

self.addEventListener('fetch', (event) => {
  const request = event.request;
  // Only the app's own files: hosted nests opened by ?file= from elsewhere are not kept.
  if (request.method !== 'GET' || new URL(request.url).origin !== self.location.origin) return;
  event.respondWith(
    fetch(request)
      .then((response) => {
        if (response.ok) {
          const copy = response.clone();
          caches.open(CACHE).then((cache) => cache.put(request, copy));
        }
        return response;
      })
      .catch(() => caches.open(CACHE)
        .then((cache) => cache.match(request, { ignoreSearch: true }))
        .then((cached) => cached ?? Response.error())),
  );
});
