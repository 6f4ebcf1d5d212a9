// The take view's first requests, started early (api.prefetchTake), are the very requests the
// view's own calls take over: one fetch per URL, the same answer, once (node --test; fetch is
// replaced by a recorder).
import assert from "node:assert/strict";
import { test } from "node:test";
import * as api from "../../frontend/js/api.js";

function recordFetches() {
  const calls = [];
  globalThis.fetch = (url, init) => {
    calls.push({ url, init });
    const body = url.includes("frames.f32") ? packed() : JSON.stringify({ url, n: calls.length });
    return Promise.resolve(new Response(body, { status: 200 }));
  };
  return calls;
}

/** An empty packed frame window (frames.js's format: uint32 n, n bytes of JSON). */
function packed() {
  const header = new TextEncoder().encode(JSON.stringify({ start: 0, step: 100, count: 0, points: 31, n_frames: 10000, arrays: [] }));
  const buffer = new Uint8Array(4 + header.length);
  new DataView(buffer.buffer).setUint32(0, header.length, true);
  buffer.set(header, 4);
  return buffer;
}

test("the take, its run's result and first frames are fetched once, by the view's own URLs", async () => {
  const calls = recordFetches();
  api.prefetchTake("t1", "r1");
  assert.deepEqual(calls.map((c) => c.url), ["/api/v1/takes/t1", "/api/v1/runs/r1/result", "/api/v1/runs/r1/frames.f32?start=0&step=1&max_frames=100"]);
  assert.ok(calls.every((c) => c.init === undefined)); // a plain GET: same-origin credentials, no headers
  const take = await api.getTake("t1");
  const result = await api.getResult("r1");
  const first = await api.getFirstFrames("r1");
  assert.equal(calls.length, 3); // nothing asked twice
  assert.deepEqual([take.n, result.n], [1, 2]);
  assert.equal(first.n_frames, 10000);
  // Taken once: a later request of the same URL asks the server again.
  assert.equal((await api.getTake("t1")).n, 4);
  assert.equal(calls.length, 4);
});

test("without a run only the take is started; dropped responses are asked for afresh", async () => {
  const calls = recordFetches();
  api.prefetchTake("t2", null);
  assert.deepEqual(calls.map((c) => c.url), ["/api/v1/takes/t2"]);
  api.dropPrefetched();
  assert.equal((await api.getTake("t2")).n, 2);
  assert.equal(calls.length, 2);
});

test("a started request that fails fails where it is taken", async () => {
  globalThis.fetch = () => Promise.reject(new TypeError("network down"));
  api.prefetchTake("t3", null);
  await assert.rejects(api.getTake("t3"), /network down/);
});
