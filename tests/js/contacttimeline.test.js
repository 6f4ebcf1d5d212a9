// Unit tests of the contact timeline's rows (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { FEET_COLORS, contactRows } from "../../frontend/js/contacttimeline.js";

const contact = (foot, start, end, confidence = 0.8) => ({ foot, start, end, confidence, id: `contact-${foot}-${start}` });
const finding = (kind, foot, start, end, value = 2.5, unit = "cm") => ({
  kind, joint: foot === "left" ? "LeftFoot" : "RightFoot", foot, start_frame: start, end_frame: end, value, unit, confidence: null,
});

test("two rows, left then right, contacts as bars by start frame", () => {
  const rows = contactRows([contact("right", 50, 99), contact("left", 60, 80), contact("left", 0, 39)], [], 100);
  assert.deepEqual(rows.map((r) => r.foot), ["left", "right"]);
  assert.deepEqual(rows[0].bars.map((b) => [b.start, b.end]), [[0, 39], [60, 80]]);
  assert.equal(rows[1].contacts, 1);
  const [bar] = rows[1].bars;
  assert.equal(bar.left, 50);
  assert.equal(bar.width, 50);
  assert.match(bar.label, /right foot · contact · frames 50–99 · confidence 0.80/);
});

test("feet findings are marked on their foot's row; other findings are not", () => {
  const findings = [finding("skate", "left", 10, 19), finding("penetration", "right", 5, 5, null), { kind: "limits", joint: "LeftFoot", start_frame: 0, end_frame: 9, value: 3 }];
  const [left, right] = contactRows([contact("left", 0, 39)], findings, 100);
  assert.deepEqual(left.marks.map((m) => [m.kind, m.start, m.end, m.color]), [["skate", 10, 19, FEET_COLORS.skate]]);
  assert.match(left.marks[0].label, /left foot · skate · frames 10–19 · 2.5 cm/);
  assert.equal(left.findings, 1);
  assert.equal(right.bars.length, 0);
  assert.deepEqual(right.marks.map((m) => [m.kind, m.left, m.width]), [["penetration", 5, 1]]);
  assert.doesNotMatch(right.marks[0].label, /null/);
});

test("no contacts and no findings: two empty rows", () => {
  assert.deepEqual(contactRows([], [], 10).map((r) => [r.foot, r.bars.length, r.marks.length]), [["left", 0, 0], ["right", 0, 0]]);
});
