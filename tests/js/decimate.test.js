// Unit tests of the charts' min–max decimation (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { buckets, decimateFigure, decimateHeatmap, decimateLine, keptIndices } from "../../frontend/js/decimate.js";

const range = (n) => Array.from({ length: n }, (_, i) => i);
const extremes = (y) => {
  const v = y.filter((e) => e != null && !Number.isNaN(e));
  return [Math.min(...v), Math.max(...v)];
};

test("each bucket keeps its first, lowest, highest and last sample, in time order", () => {
  const y = [5, 9, 1, 4, /* next bucket */ 7, 2, 8, 3];
  assert.deepEqual(keptIndices(y, Int32Array.from([0, 0, 0, 0, 1, 1, 1, 1])), [0, 1, 2, 3, 4, 5, 6, 7]);
  const z = [5, 1, 0, 9, 2, 6];
  // first 0, min 2, max 3, last 5 — sample 1 and 4 dropped.
  assert.deepEqual(keptIndices(z, new Int32Array(6)), [0, 2, 3, 5]);
});

test("a long line keeps at most four samples per pixel column, its extremes and ends", () => {
  const x = range(10_000);
  const y = x.map((i) => Math.sin(i / 37) * 100 + (i === 6_543 ? 400 : 0) + (i === 2_000 ? -300 : 0));
  const out = decimateLine(x, y, 300);
  assert.ok(out.x.length <= 4 * 300, `${out.x.length} points`);
  assert.deepEqual(extremes(out.y), extremes(y));
  assert.equal(out.x[0], 0);
  assert.equal(out.x.at(-1), 9_999);
  assert.ok(out.x.every((v, i) => i === 0 || v > out.x[i - 1]), "time order");
  assert.ok(out.x.every((v, i) => out.y[i] === y[v]), "real samples only");
});

test("a gap stays a gap: every run of missing samples keeps one of them", () => {
  const x = range(10_000);
  const y = x.map((i) => ((i >= 4_000 && i < 4_003) || i === 7_777 ? null : i % 50));
  const nan = x.map((i) => (i >= 100 && i < 5_000 ? NaN : 1));
  const out = decimateLine(x, y, 200);
  const gaps = out.x.filter((_, i) => out.y[i] === null);
  assert.ok(gaps.some((f) => f >= 4_000 && f < 4_003));
  assert.ok(gaps.includes(7_777));
  // The samples either side of a gap are kept apart by it: no line is drawn across.
  const outNan = decimateLine(x, nan, 200);
  const at = (f) => outNan.x.indexOf(f);
  assert.ok(outNan.x.includes(99) && outNan.x.includes(5_000));
  assert.ok(outNan.y.slice(at(99) + 1, at(5_000)).every(Number.isNaN));
  assert.ok(at(5_000) - at(99) > 1);
});

test("a zoomed range is drawn from the full data, the rest stays coarse", () => {
  const x = range(10_000);
  const y = x.map((i) => (i * 7919) % 101);
  const whole = decimateLine(x, y, 100);
  const zoomed = decimateLine(x, y, 100, [5_000, 5_100]);
  // All 101 samples inside the range are kept (one column per sample or less).
  for (let f = 5_000; f <= 5_100; f++) assert.ok(zoomed.x.includes(f), `frame ${f}`);
  // Outside it, about the whole-take decimation: extremes and ends kept.
  assert.ok(zoomed.x.length < whole.x.length + 110);
  assert.deepEqual(extremes(zoomed.y), extremes(y));
  assert.equal(zoomed.x[0], 0);
  assert.equal(zoomed.x.at(-1), 9_999);
  // The range's buckets are its own: the bucket numbers never go down.
  const b = buckets(x, 100, [5_100, 5_000]);
  assert.ok(b.every((v, i) => i === 0 || v >= b[i - 1]));
});

test("a short line is handed over as it is", () => {
  const x = range(100), y = x.map((i) => i * i);
  const out = decimateLine(x, y, 300);
  assert.equal(out.x, x);
  assert.equal(out.y, y);
});

test("a heat map keeps each bucket's largest value, its cells spanning the same frames", () => {
  const x = range(10_000);
  const z = [x.map((i) => (i === 1_234 ? 50 : 0)), x.map((i) => (i % 1_000 === 999 ? 3 : null))];
  const out = decimateHeatmap(x, z, 250);
  assert.equal(out.x.length, out.z[0].length + 1);
  assert.ok(out.z[0].length <= 250);
  assert.equal(out.x[0], -0.5);
  assert.equal(out.x.at(-1), 9_999.5);
  assert.equal(Math.max(...out.z[0]), 50);
  const cell = out.z[0].indexOf(50);
  assert.ok(out.x[cell] <= 1_234 && 1_234 <= out.x[cell + 1]);
  assert.equal(out.z[1].filter((v) => v === 3).length, 10);
  assert.ok(out.z[1].includes(null));
});

test("a figure's bands, stacked areas and layout are left as they are", () => {
  const x = range(5_000);
  const line = { type: "scatter", x, y: x.map((i) => i % 7) };
  const band = { type: "bar", x: [10, 20], y: [1, 1], base: [0, 0] };
  const stacked = { type: "scatter", stackgroup: "w", x, y: x.map(() => 0.5) };
  const layout = { margin: { l: 1, r: 1 } };
  const out = decimateFigure({ data: [line, band, stacked], layout }, 100);
  assert.ok(out.data[0].x.length <= 400);
  assert.equal(out.data[1], band);
  assert.equal(out.data[2], stacked);
  assert.equal(out.layout, layout);
  assert.equal(line.x, x, "the full figure is not changed");
});
