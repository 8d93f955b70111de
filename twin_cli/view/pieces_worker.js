// twin: fetches models as pieces keyed by content, off the page's main thread (which renders
// in SwiftShader and may get a turn only every few hundred ms). It watches the server's
// current model (a few bytes every POLL_MS), fetches the pieces it lacks as soon as a model is
// published, and posts the whole bundle to the page, so the bundle is usually there before
// the page learns of the new model from the state stream. The page can also ask for a model.
const BATCH_BYTES = 4 * 1024 * 1024; // per request
const BATCH_KEYS = 256; // the server's limit
const PARALLEL = 4;
const POLL_MS = 50;
let pieces = new Map(); // key -> Uint8Array: the pieces of the last model assembled
const inflight = new Map(); // crc32 (0: the current one) -> Promise of the bundle
let lastCrc = -1;

function batches(missing) {
  const out = [];
  let batch = [];
  let bytes = 0;
  for (const piece of missing) {
    if (batch.length && (bytes + piece[1] > BATCH_BYTES || batch.length >= BATCH_KEYS)) {
      out.push(batch);
      batch = [];
      bytes = 0;
    }
    batch.push(piece);
    bytes += piece[1];
  }
  if (batch.length) out.push(batch);
  return out;
}

async function fetchBatch(batch, got, stats) {
  const resp = await fetch("pieces?keys=" + batch.map((p) => p[0]).join(","), { cache: "no-store" });
  if (!resp.ok) throw new Error("pieces: HTTP " + resp.status);
  const body = new Uint8Array(await resp.arrayBuffer());
  let offset = 0;
  for (const [key, size, asset] of batch) {
    got.set(key, body.subarray(offset, offset + size));
    offset += size;
    stats.bytes += size;
    if (asset) stats.assetBytes += size;
  }
  if (offset !== body.length) throw new Error("pieces: " + body.length + " bytes, not " + offset);
}

async function assemble(crc, seenAt) {
  const started = performance.now();
  const resp = await fetch("manifest" + (crc ? "?crc32=" + crc : ""), { cache: "no-store" });
  if (!resp.ok) throw new Error("manifest: HTTP " + resp.status);
  const manifest = await resp.json();
  const seen = new Set();
  const missing = manifest.pieces.filter((p) => {
    if (pieces.has(p[0]) || seen.has(p[0])) return false;
    seen.add(p[0]);
    return true;
  });
  const stats = { bytes: 0, assetBytes: 0, pieces: missing.length, of: manifest.pieces.length };
  stats.seen = seenAt || Date.now();
  stats.manifestMs = performance.now() - started;
  const got = new Map();
  const queue = batches(missing);
  await Promise.all(
    Array.from({ length: PARALLEL }, async () => {
      while (queue.length) await fetchBatch(queue.shift(), got, stats);
    }),
  );
  const bytes = new Uint8Array(manifest.size);
  const kept = new Map();
  let offset = 0;
  for (const [key, size] of manifest.pieces) {
    bytes.set(pieces.get(key) || got.get(key), offset);
    kept.set(key, bytes.subarray(offset, offset + size));
    offset += size;
  }
  pieces = kept; // only this model's pieces, as views of its bytes
  stats.ms = performance.now() - started;
  return { crc: manifest.crc32, bytes: bytes, stats: stats };
}

function deliver(crc, published, seenAt) {
  let job = inflight.get(crc);
  if (!job) {
    job = assemble(crc, seenAt).then(
      (model) => {
        // A copy: the worker keeps its pieces as views of its own bytes.
        model.stats.posted = Date.now();
        postMessage({ crc: crc, model: model, published: published });
        return model;
      },
      (error) => postMessage({ crc: crc, error: String(error) }),
    );
    inflight.set(crc, job);
    job.finally(() => inflight.delete(crc));
  }
  return job;
}

async function watch() {
  for (;;) {
    try {
      const resp = await fetch("current", { cache: "no-store" });
      if (resp.ok) {
        const crc = Number(await resp.text()) >>> 0;
        if (crc && crc !== lastCrc) {
          lastCrc = crc;
          postMessage({ coming: crc }); // the page may hold its frames until the model is here
          await deliver(crc, true, Date.now());
        }
      }
    } catch (e) {
      // The server went away or restarts: keep watching.
    }
    await new Promise((r) => setTimeout(r, POLL_MS));
  }
}

onmessage = (event) => deliver(event.data.want >>> 0, false);
watch();
