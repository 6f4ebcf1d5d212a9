// Unit tests: the largest-skate cell shows its unit, cm with the share of the body height beside it, the
// share the column sorts by (the one measure of a take in cm and of a BVH in % height).
import { test } from "node:test";
import assert from "node:assert/strict";
import { formatCell, skateSize } from "../../frontend/js/shoot-format.js";

test("a skate in cm shows its share of the body height beside it when the row has it", () => {
  assert.equal(skateSize(8.601, "cm", 5.152), "8.6 cm (5.2 % height)");
  assert.equal(skateSize(8.601, "cm", null), "8.6 cm");
  assert.equal(skateSize(8.601, "cm", Number.NaN), "8.6 cm");
  // A size in % height is the share itself: said once.
  assert.equal(skateSize(0.8, "% height", 0.8), "0.8 % height");
  assert.equal(skateSize(null, "cm", 5.1), "–");
});

test("the worst-skate cell reads the row's share", () => {
  const trc = { foot_worst_skate: 8.601, foot_skate_unit: "cm", foot_worst_skate_pct: 5.152 };
  const bvh = { foot_worst_skate: 0.8, foot_skate_unit: "% height", foot_worst_skate_pct: 0.8 };
  const older = { foot_worst_skate: 8.601, foot_skate_unit: "cm" };
  assert.equal(formatCell("foot_worst_skate", trc), "8.6 cm (5.2 % height)");
  assert.equal(formatCell("foot_worst_skate", bvh), "0.8 % height");
  assert.equal(formatCell("foot_worst_skate", older), "8.6 cm");
});
