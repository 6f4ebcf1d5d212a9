// Unit tests of the packed frame windows' reader (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { unpackFrames } from "../../frontend/js/frames.js";

/** A packed window as the server writes it: uint32 n, n bytes of JSON (padded), float32 arrays. */
function pack(header, arrays) {
  let text = JSON.stringify(header);
  text += " ".repeat((4 - ((4 + text.length) % 4)) % 4);
  const values = arrays.flat(Infinity);
  const buffer = new ArrayBuffer(4 + text.length + 4 * values.length);
  new DataView(buffer).setUint32(0, text.length, true);
  new Uint8Array(buffer, 4, text.length).set(new TextEncoder().encode(text));
  new Float32Array(buffer, 4 + text.length).set(values);
  return buffer;
}

test("a packed window reads back as frames of points, missing points NaN", () => {
  // 2 frames (10 and 13) of 2 points: positions, then one-component confidence.
  const raw = [[[1, 2, 3], [NaN, NaN, NaN]], [[4, 5, 6], [7, 8, 9]]];
  const confidence = [[0.5, 0], [1, 0.25]];
  const header = { start: 10, step: 3, count: 2, n_frames: 20, points: 2, arrays: [["raw", 3], ["confidence", 1]] };
  const window = unpackFrames(pack(header, [raw, confidence]));
  assert.deepEqual(window.frames, [10, 13]);
  assert.equal(window.step, 3);
  assert.equal(window.n_frames, 20);
  assert.deepEqual([...window.raw[1][1]], [7, 8, 9]);
  assert.deepEqual([...window.raw[0][0]], [1, 2, 3]);
  assert.ok(window.raw[0][1].every(Number.isNaN));
  assert.deepEqual([...window.confidence[1]], [1, 0.25]);
  assert.equal(window.raw.length, 2);
});
