// Unit tests of the one-canvas layout of the 3D views (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { canvasLayout, sameLayout } from "../../frontend/js/viewports.js";

test("two panels side by side: one box over both, viewports measured from its bottom-left", () => {
  // As at 1400 px: two 420 px high views 662 px wide, 38 px apart (padding, borders, gap).
  const raw = { left: 11, top: 33, width: 662, height: 420 };
  const corrected = { left: 711, top: 33, width: 662, height: 420 };
  const { box, viewports } = canvasLayout([raw, corrected]);
  assert.deepEqual(box, { left: 11, top: 33, width: 1362, height: 420 });
  assert.deepEqual(viewports, [
    { x: 0, y: 0, width: 662, height: 420 },
    { x: 700, y: 0, width: 662, height: 420 },
  ]);
});

test("a hidden panel (overlay mode) gets no viewport and the box shrinks to the other", () => {
  const { box, viewports } = canvasLayout([null, { left: 11, top: 33, width: 1362, height: 420 }]);
  assert.deepEqual(box, { left: 11, top: 33, width: 1362, height: 420 });
  assert.deepEqual(viewports, [null, { x: 0, y: 0, width: 1362, height: 420 }]);
  // A panel of no size (display:none inside a shown parent) counts as hidden too.
  assert.equal(canvasLayout([{ left: 0, top: 0, width: 0, height: 10 }, { left: 5, top: 5, width: 10, height: 10 }]).viewports[0], null);
});

test("no panel shown: an empty box", () => {
  assert.deepEqual(canvasLayout([null, null]), { box: { left: 0, top: 0, width: 0, height: 0 }, viewports: [null, null] });
});

test("panels at different heights: y counts from the box's bottom (WebGL's origin)", () => {
  // A longer title pushes the first view 20 px lower (compare view with a wrapped label).
  const { box, viewports } = canvasLayout([{ left: 0, top: 40, width: 100, height: 50 }, { left: 120, top: 20, width: 100, height: 50 }]);
  assert.deepEqual(box, { left: 0, top: 20, width: 220, height: 70 });
  assert.deepEqual(viewports[0], { x: 0, y: 0, width: 100, height: 50 }); // the lower one sits on the bottom
  assert.deepEqual(viewports[1], { x: 120, y: 20, width: 100, height: 50 });
  // Stacked (a window too narrow for two columns): the first on top.
  const stacked = canvasLayout([{ left: 0, top: 0, width: 300, height: 200 }, { left: 0, top: 230, width: 300, height: 200 }]);
  assert.deepEqual(stacked.viewports, [{ x: 0, y: 230, width: 300, height: 200 }, { x: 0, y: 0, width: 300, height: 200 }]);
});

test("fractional layout: whole pixels, inside the box, neighbours neither overlap nor part", () => {
  const a = { left: 10.4, top: 7.6, width: 333.3, height: 280.2 };
  const b = { left: 343.7, top: 7.6, width: 333.3, height: 280.2 }; // starts where a ends
  const { box, viewports } = canvasLayout([a, b]);
  assert.deepEqual(box, { left: 10, top: 7, width: 667, height: 281 });
  for (const v of viewports) {
    for (const value of Object.values(v)) assert.ok(Number.isInteger(value));
    assert.ok(v.x >= 0 && v.y >= 0 && v.x + v.width <= box.width && v.y + v.height <= box.height, JSON.stringify(v));
  }
  assert.equal(viewports[0].x + viewports[0].width, viewports[1].x);
  // Each viewport is within a pixel of its panel.
  assert.ok(Math.abs(viewports[0].width - a.width) <= 1 && Math.abs(viewports[1].height - b.height) <= 1);
});

test("sameLayout tells a layout to keep from one to resize", () => {
  const panels = [{ left: 0, top: 0, width: 100, height: 50 }, { left: 120, top: 0, width: 100, height: 50 }];
  const first = canvasLayout(panels);
  assert.ok(sameLayout(first, canvasLayout(panels.map((p) => ({ ...p })))));
  assert.ok(!sameLayout(null, first));
  assert.ok(!sameLayout(first, canvasLayout([panels[0], { ...panels[1], width: 101 }])));
  assert.ok(!sameLayout(first, canvasLayout([null, panels[1]])));
  assert.ok(!sameLayout(first, canvasLayout(panels.map((p) => ({ ...p, top: p.top + 3 })))));
});
