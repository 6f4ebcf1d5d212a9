// Unit tests of the charts' linked zoom (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { zoomUpdate } from "../../frontend/js/timeline.js";

test("a zoom, a pan or a reset of one chart becomes the others' x-range", () => {
  assert.deepEqual(zoomUpdate({ "xaxis.autorange": true }), { "xaxis.autorange": true });
  assert.deepEqual(zoomUpdate({ "xaxis.range[0]": 10, "xaxis.range[1]": 90 }), { "xaxis.range": [10, 90] });
  assert.deepEqual(zoomUpdate({ "xaxis.range": [5, 6] }), { "xaxis.range": [5, 6] });
  // A zoom to a range starting at frame 0 is a zoom all the same.
  assert.deepEqual(zoomUpdate({ "xaxis.range[0]": 0, "xaxis.range[1]": 40 }), { "xaxis.range": [0, 40] });
});

test("a relayout that changes no x-range moves no other chart", () => {
  assert.equal(zoomUpdate({ "yaxis.range[0]": 1, "yaxis.range[1]": 2 }), null);
  assert.equal(zoomUpdate({ autosize: true }), null);
  assert.equal(zoomUpdate({ "xaxis.autorange": false }), null);
});
