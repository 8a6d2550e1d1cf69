// Opens an MCAP file with Foxglove Studio's own data source (the open-source
// @foxglove/studio-base, the code Lichtblick forked) and prints, as JSON, what the app
// would show: its problems, its topics with their schema, and per topic how many messages
// its deserializer decoded and the first one.
//
// The app's MCAP source lives in a webpack chunk meant for a Web Worker; this file loads
// that chunk's modules with a minimal webpack runtime instead of a worker. No parsing rule
// is written here: channels, schemas and messages go through the app's code unchanged.
//
// usage: node foxglove_source.cjs ASSETS_DIR FILE.mcap
"use strict";
const fs = require("node:fs");
const path = require("node:path");
const vm = require("node:vm");

const [assets, mcapPath] = process.argv.slice(2);
const CHUNK_GLOBAL = "webpackChunk_foxglove_studio_base";
const WORKER_ENTRY_MARK = "McapIterableSourceWorker.worker.ts";

// module id -> chunk file, from each chunk's "/***/ 12345:" headers
const where = new Map();
for (const name of fs.readdirSync(assets)) {
  if (!name.endsWith(".js") || name === "index.js" || name.startsWith("ts.worker")) continue;
  const text = fs.readFileSync(path.join(assets, name), "latin1");
  for (const m of text.matchAll(/^\/\*\*\*\/ (\d+):$/gm)) where.set(m[1], name);
}

const factories = {};
const loaded = new Set();
globalThis.self = globalThis;
globalThis[CHUNK_GLOBAL] = { push: ([, modules]) => Object.assign(factories, modules) };
function load(id) {
  const file = where.get(String(id));
  if (file === undefined) throw new Error(`webpack module ${id} is in no chunk`);
  if (!loaded.has(file)) {
    loaded.add(file);
    vm.runInThisContext(fs.readFileSync(path.join(assets, file), "utf8"), { filename: file });
  }
}

const cache = {};
let exposed;
function req(id) {
  if (cache[id]) return cache[id].exports;
  if (!factories[id]) load(id);
  const module = (cache[id] = { id, loaded: false, exports: {} });
  factories[id].call(module.exports, module, module.exports, req);
  module.loaded = true;
  return module.exports;
}
// the webpack 5 runtime helpers these modules use
req.o = (obj, key) => Object.prototype.hasOwnProperty.call(obj, key);
req.d = (exports, getters) => {
  for (const key in getters) {
    if (req.o(getters, key) && !req.o(exports, key)) {
      Object.defineProperty(exports, key, { enumerable: true, get: getters[key] });
    }
  }
};
req.r = (exports) => {
  Object.defineProperty(exports, Symbol.toStringTag, { value: "Module" });
  Object.defineProperty(exports, "__esModule", { value: true });
};
req.n = (module) => {
  const getter = module && module.__esModule ? () => module.default : () => module;
  req.d(getter, { a: getter });
  return getter;
};
req.t = function (value, mode) {
  if (mode & 1) value = this(value);
  if (mode & 8) return value;
  if (typeof value === "object" && value) {
    if (mode & 4 && value.__esModule) return value;
  }
  const ns = Object.create(null);
  req.r(ns);
  const def = {};
  for (const key in value) def[key] = () => value[key];
  def.default = () => value;
  req.d(ns, def);
  return ns;
};
req.g = globalThis;
req.nmd = (module) => {
  module.paths = [];
  if (!module.children) module.children = [];
  return module;
};
req.hmd = req.nmd;
req.p = "";
req.e = () => Promise.resolve();
// the decompressors fetch their .wasm next to the chunks
const realFetch = globalThis.fetch;
globalThis.fetch = async (url, init) => {
  const local = path.join(assets, String(url));
  if (!/^[a-z]+:/.test(String(url)) && fs.existsSync(local)) {
    return new Response(fs.readFileSync(local), { headers: { "content-type": "application/wasm" } });
  }
  return realFetch(url, init);
};

// The worker entry hands its `initialize` to Comlink.expose and wraps results in
// Comlink.proxy; without a worker both are plain calls: expose keeps the function, proxy
// returns its argument (comlink's other exports stay the real ones).
async function main() {
  const entryFile = fs
    .readdirSync(assets)
    .find((f) => f.endsWith(".js") && fs.readFileSync(path.join(assets, f), "utf8").includes(`MODULE: ./src/players/IterablePlayer/Mcap/${WORKER_ENTRY_MARK}`));
  if (!entryFile) throw new Error("the app's MCAP worker chunk was not found");
  const entryText = fs.readFileSync(path.join(assets, entryFile), "utf8");
  const entryId = entryText.match(/^\/\*\*\*\/ (\d+):$/m)[1];
  const comlinkId = entryText.match(/var comlink = __webpack_require__\((\d+)\);/)[1];
  const proxyName = entryText.match(/comlink\/\* proxy \*\/\.(\w+)\(/)[1];
  const exposeName = entryText.match(/comlink\/\* expose \*\/\.(\w+)\(/)[1];
  const real = req(comlinkId);
  cache[comlinkId] = {
    exports: new Proxy(real, {
      get(target, key) {
        if (key === exposeName) return (fn) => void (exposed = fn);
        if (key === proxyName) return (value) => value;
        return target[key];
      },
    }),
  };
  req(entryId);
  if (typeof exposed !== "function") throw new Error("the worker exposed no initialize()");

  const bytes = fs.readFileSync(mcapPath);
  const file = new File([bytes], path.basename(mcapPath));
  const source = exposed({ file });
  const init = await source.initialize();
  const topics = init.topics.map((t) => ({ name: t.name, schemaName: t.schemaName }));
  const problems = init.problems.map((p) => ({ severity: p.severity, message: p.message, error: p.error ? String(p.error.message ?? p.error) : undefined }));
  const perTopic = {};
  for (const t of topics) perTopic[t.name] = { decoded: 0, first: undefined };
  const iterator = source.messageIterator({ topics: topics.map((t) => t.name), start: init.start, end: init.end, consumptionType: "full" });
  for await (const result of iterator) {
    if (result.type === "message-event") {
      const entry = perTopic[result.msgEvent.topic];
      entry.decoded += 1;
      if (entry.first === undefined) entry.first = result.msgEvent.message;
    } else if (result.type === "problem") {
      problems.push({ severity: result.problem.severity, message: result.problem.message, error: result.problem.error ? String(result.problem.error.message ?? result.problem.error) : undefined });
    }
  }
  const replacer = (_k, v) => (typeof v === "bigint" ? Number(v) : v instanceof Uint8Array ? { bytes: v.length } : v);
  process.stdout.write(JSON.stringify({ topics, problems, perTopic, datatypes: [...init.datatypes.keys()] }, replacer));
}

main().catch((err) => {
  process.stderr.write(`${err.stack ?? err}\n`);
  process.exit(1);
});
