// Unit tests of the gap timeline's rows (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { gapRows } from "../../frontend/js/gaptimeline.js";

const gap = (joint, start, end, filled, value = 1.5) => ({
  kind: filled ? "gap" : "gap not filled", joint, start_frame: start, end_frame: end, value, unit: "mm", method: filled ? "pca" : null, confidence: null,
});

test("one row per marker with gaps, in the take's order, bars by start frame", () => {
  const findings = [gap("RSHO", 50, 59, true), gap("LASI", 10, 12, false), gap("RSHO", 0, 4, false), { kind: "spike", joint: "C7", start_frame: 3, end_frame: 3, value: 9 }];
  const rows = gapRows(findings, 100, ["C7", "LASI", "RSHO"]);
  assert.deepEqual(rows.map((r) => r.marker), ["LASI", "RSHO"]);
  assert.deepEqual(rows[1].bars.map((b) => [b.start, b.end, b.filled]), [[0, 4, false], [50, 59, true]]);
  assert.equal(rows[1].filled, 10);
  assert.equal(rows[1].missing, 5);
});

test("bars are placed in % of the take and say whether and how they were filled", () => {
  const [row] = gapRows([gap("A", 25, 49, true, 0.87)], 100);
  const [bar] = row.bars;
  assert.equal(bar.left, 25);
  assert.equal(bar.width, 25);
  assert.match(bar.label, /filled · frames 25–49 · expected error 0.87 mm \(pca\)/);
  const [missing] = gapRows([gap("A", 99, 99, false, null)], 100)[0].bars;
  assert.equal(missing.left + missing.width, 100);
  assert.match(missing.label, /not filled.*no method could fill it/);
});

test("no gap findings, no rows; markers missing from the order go last by name", () => {
  assert.deepEqual(gapRows([], 10), []);
  const rows = gapRows([gap("Z", 1, 1, true), gap("B", 1, 1, true), gap("K", 1, 1, true)], 10, ["K"]);
  assert.deepEqual(rows.map((r) => r.marker), ["K", "B", "Z"]);
});
