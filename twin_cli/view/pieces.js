// twin: the page takes each model from twin's worker (pieces_worker.js), which fetches only the
// pieces keyed by content that the page lacks (a second robot of the same description: no mesh
// bytes) off the main thread. Loaded after MuJoCo's page script, it puts each bundle the
// worker posts into that script's model cache (a cache hit loads at once when the state stream
// names the model), replaces its downloadModel (a global function) to ask the worker, and
// wraps loadModelBytes to record when each model showed. While the worker fetches a new model
// the page draws no frames. If the worker fails, MuJoCo's own download runs.
(() => {
  const WORKER_WAIT_MS = 30000; // then MuJoCo's whole download
  // What the page received and when models showed; read by tests and in the console.
  const record = { bytes: 0, assetBytes: 0, received: [], loads: [] };
  window.twinPieces = record;
  const waiting = new Map(); // crc32 (0: the current model) -> [resolve]
  const worker = new Worker("twin/pieces_worker.js");

  // The server sends a software-rendered page the fast look (no shadows, no multisampling:
  // frames 2-3 times quicker), so it is told which renderer this page's WebGL uses. A canvas of
  // its own: MuJoCo's is not created yet.
  function reportRenderer() {
    const gl = document.createElement("canvas").getContext("webgl2");
    if (!gl) return;
    const info = gl.getExtension("WEBGL_debug_renderer_info");
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    record.renderer = name;
    gl.getExtension("WEBGL_lose_context")?.loseContext();
    fetch("twin/renderer?name=" + encodeURIComponent(name), { cache: "no-store" }).catch((e) =>
      console.warn("[twin] renderer not reported:", e),
    );
  }
  reportRenderer();

  function settle(crc, bytes) {
    for (const key of [crc, 0]) {
      for (const resolve of waiting.get(key) || []) resolve(bytes);
      waiting.delete(key);
    }
  }

  // While the worker fetches a new model the page draws no frames. In SwiftShader a frame of a
  // large robot costs about a CPU-second, and the page takes the new model only between two
  // frames: a frame begun during the fetch delays the new robot by up to that long and takes
  // the CPU the fetch needs. MuJoCo's render loop (Emscripten's MainLoop, a global of its page
  // script) is paused when the worker sees a new model and resumed once it is loaded, after
  // HOLD_MAX_MS at the latest.
  const HOLD_MAX_MS = 3000;
  let held = null; // the timer that resumes the render loop, while it is paused
  function hold() {
    const loop = typeof MainLoop === "undefined" ? null : MainLoop;
    if (held || !loop || !loop.func || !currentModelCrc || !Module.pauseMainLoop) return;
    Module.pauseMainLoop();
    held = setTimeout(release, HOLD_MAX_MS);
  }
  function release() {
    if (!held) return;
    clearTimeout(held);
    held = null;
    Module.resumeMainLoop();
  }

  worker.onmessage = (event) => {
    const { crc, model, error, published, coming } = event.data;
    if (coming) {
      if (coming !== currentModelCrc) hold();
      return;
    }
    if (error) {
      console.warn("[twin] pieces failed:", error);
      settle(crc, null);
      recoverSkipped(crc);
      release();
      return;
    }
    const s = model.stats;
    record.bytes += s.bytes;
    record.assetBytes += s.assetBytes;
    record.received.push({ crc: model.crc, at: Date.now(), ...s });
    console.log(
      "[twin] model " + model.crc + ": " + s.pieces + " of " + s.of + " pieces, " + s.bytes +
        " bytes (" + s.assetBytes + " of meshes and textures) in " + s.ms.toFixed(0) + " ms",
    );
    cacheModel(model.crc, model.bytes);
    settle(model.crc, model.bytes);
    if (published) showPublished(model.crc);
    release();
  };

  // The server's newest model shows as soon as the worker has it, not when the state stream
  // names it: the page reads that stream once a frame, and a frame in SwiftShader can take a
  // second. State payloads still in flight for the model before then name a superseded model:
  // MuJoCo's page would load it again (the robot would vanish for a moment), so those reloads
  // are skipped; its payloads, sized for the other model, are dropped by the page meanwhile.
  // A skipped reload leaves the page's client waiting for a model: it applies no state until
  // one is parsed. The payload after the stale ones names the model already shown, and that
  // reload runs (a cache hit: parsed at once, no download), or the page would show the world
  // frozen at the new model's spawn poses under "Downloading model".
  let newest = 0;
  const superseded = new Set();
  let skipped = 0; // the last reload skipped, until another runs
  const mujocoReload = reloadModel;
  function showPublished(crc) {
    if (newest && newest !== crc) superseded.add(newest);
    superseded.delete(crc);
    newest = crc;
    if (currentModelCrc && currentModelCrc !== crc) {
      skipped = 0;
      mujocoReload(crc);
    }
  }
  // A model the world went back to after it was superseded (a spawn, then a delete) that the
  // worker fails to fetch: the state stream's reload of it must run (MuJoCo's download), and
  // if it came before the failure and was skipped, the page waits for it: it runs now.
  function recoverSkipped(crc) {
    superseded.delete(crc);
    if (skipped !== crc) return;
    skipped = 0;
    mujocoReload(crc);
  }
  // eslint-disable-next-line no-global-assign
  reloadModel = function (crc) {
    const asked = (crc || 0) >>> 0;
    if (superseded.has(asked)) {
      skipped = asked;
      return Promise.resolve();
    }
    skipped = 0;
    return mujocoReload(crc);
  };

  const mujocoDownload = downloadModel;
  // eslint-disable-next-line no-global-assign
  downloadModel = function (crc, report) {
    // A twin world never returns to an earlier model by its crc32: no background prefetch.
    if (!report) return Promise.resolve(null);
    const asked = new Promise((resolve) => {
      waiting.set(crc, [...(waiting.get(crc) || []), resolve]);
      worker.postMessage({ want: crc });
      setTimeout(() => resolve(null), WORKER_WAIT_MS);
    });
    return asked.then((bytes) => bytes || mujocoDownload(crc, report));
  };

  const mujocoLoad = loadModelBytes;
  // eslint-disable-next-line no-global-assign
  loadModelBytes = function (bytes) {
    const started = Date.now();
    const crc = mujocoLoad(bytes);
    // shown: the next animation frame began; presented: the one after it began, by which the
    // page's render loop has drawn the new model (its frame with new meshes runs in between).
    const load = { crc: crc, started: started, parsed: Date.now(), shown: null, presented: null };
    record.loads.push(load);
    requestAnimationFrame(() => {
      load.shown = Date.now();
      requestAnimationFrame(() => (load.presented = Date.now()));
    });
    return crc;
  };
})();
