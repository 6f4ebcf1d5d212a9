// Unit tests of the contact timeline's rows (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { FEET_COLORS, contactRows, decidedLock, lockMarks, lockStyle, overlappedMost, stopAfter } from "../../frontend/js/contacttimeline.js";

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

test("each skate finding with an id has a lock over the contact it overlaps, else its own frames", () => {
  const skate = (foot, start, end) => ({ ...finding("skate", foot, start, end), id: `skate-${foot}-${start}` });
  const findings = [skate("left", 70, 75), skate("left", 10, 19), skate("left", 200, 204), finding("skate", "left", 30, 31), skate("right", 10, 12), finding("penetration", "left", 12, 12)];
  const contacts = [contact("left", 0, 39), contact("left", 60, 99), contact("right", 50, 80)];
  const [left, right] = contactRows(contacts, findings, 400);
  // The skate without an id (none to decide) has no lock; penetrations have none.
  assert.deepEqual(left.locks.map((l) => [l.id, l.start, l.end]), [["skate-left-10", 0, 39], ["skate-left-70", 60, 99], ["skate-left-200", 200, 204]]);
  assert.deepEqual(left.locks.map((l) => l.decision), ["undecided", "undecided", "undecided"]);
  assert.equal(left.locks[1].left, 15);
  assert.equal(left.locks[1].width, 10);
  assert.match(left.locks[0].label, /left foot lock · frames 0–39 · undecided/);
  // A right contact that does not overlap the right skate: the lock holds the finding's frames.
  assert.deepEqual(right.locks.map((l) => [l.start, l.end]), [[10, 12]]);
});

test("a lock is drawn by its newest decision: accepted solid, rejected hatched and dim, undecided an outline", () => {
  const findings = [{ ...finding("skate", "left", 10, 19), id: "skate-left-10" }, { ...finding("skate", "left", 50, 55), id: "skate-left-50" }, { ...finding("skate", "left", 70, 72), id: "skate-left-70" }];
  const locks = lockMarks([contact("left", 0, 39)], findings, "left", 100, { "skate-left-10": "accept", "skate-left-50": "reject" });
  assert.deepEqual(locks.map((l) => l.decision), ["accept", "reject", "undecided"]);
  const [accepted, rejected, undecided] = locks.map((l) => l.style);
  assert.equal(accepted.background, accepted.border.split(" ").at(-1));
  assert.equal(accepted.opacity, "1");
  assert.match(rejected.background, /repeating-linear-gradient/);
  assert.ok(Number(rejected.opacity) < 1);
  assert.equal(undecided.background, "transparent");
  assert.match(undecided.border, /solid/);
  // Three looks, none alike.
  assert.equal(new Set(locks.map((l) => JSON.stringify(l.style))).size, 3);
  assert.match(locks[0].label, /accepted: the reviewed download locks it/);
  assert.match(locks[1].label, /rejected: left as recorded/);
  // Deciding again redraws the same lock: its frames kept, its look and title changed.
  const undone = decidedLock(locks[0], "reject");
  assert.deepEqual([undone.start, undone.end, undone.left, undone.width], [locks[0].start, locks[0].end, locks[0].left, locks[0].width]);
  assert.deepEqual(undone.style, lockStyle("reject"));
  assert.match(undone.label, /left foot lock · frames 0–39 · rejected/);
  assert.equal(decidedLock(locks[0], null).decision, "undecided");
  assert.match(decidedLock(locks[0], null).label, /undecided: left as recorded/);
});

test("an undecided lock the run locked is drawn striped, and says the run locked it", () => {
  const followed = decidedLock({ id: "skate-left-0", foot: "left", start: 0, end: 39, left: 0, width: 10, runLocked: true }, null);
  assert.equal(followed.decision, "undecided");
  assert.match(followed.label, /locked in the run's corrected take/);
  assert.deepEqual(followed.style, lockStyle(null, true));
  const looks = [lockStyle("accept"), lockStyle("reject"), lockStyle(null), lockStyle(null, true)];
  assert.equal(new Set(looks.map((l) => JSON.stringify(l))).size, 4);
  // lockMarks reads the run's choice from the skate finding's `applied`.
  const marks = lockMarks([contact("left", 0, 39)], [{ ...finding("skate", "left", 10, 19), id: "skate-left-10", applied: true }, { ...finding("skate", "left", 50, 55), id: "skate-left-50", applied: false }], "left", 100);
  assert.deepEqual(marks.map((l) => l.runLocked), [true, false]);
  // A decision overrides the run: rejected, it is drawn as any rejected lock.
  assert.deepEqual(decidedLock({ ...followed, decision: undefined }, "reject").style, lockStyle("reject"));
});

test("a skate over two contacts is locked over the one it overlaps most, whose confidence it carries", () => {
  const contacts = [contact("right", 144, 154), contact("right", 162, 230)];
  const marks = lockMarks(contacts, [{ ...finding("skate", "right", 141, 211), id: "skate-right-141" }], "right", 300);
  assert.deepEqual(marks.map((l) => [l.start, l.end]), [[162, 230]]);
  assert.equal(overlappedMost(contacts, "left", 141, 211), undefined);
});

test("the arrow keys walk a row's stops and move to the nearest stop of the other foot", () => {
  const rows = [[0, 10, 40, 90], [], [5, 38, 80]];
  assert.deepEqual(stopAfter(rows, [0, 1], "ArrowRight"), [0, 2]);
  assert.deepEqual(stopAfter(rows, [0, 3], "ArrowRight"), [0, 3]); // the end stays
  assert.deepEqual(stopAfter(rows, [0, 0], "ArrowLeft"), [0, 0]);
  assert.deepEqual(stopAfter(rows, [0, 2], "ArrowLeft"), [0, 1]);
  assert.deepEqual(stopAfter(rows, [0, 2], "Home"), [0, 0]);
  assert.deepEqual(stopAfter(rows, [0, 0], "End"), [0, 3]);
  // Down skips a row without stops and lands on the start nearest 40 (38).
  assert.deepEqual(stopAfter(rows, [0, 2], "ArrowDown"), [2, 1]);
  assert.deepEqual(stopAfter(rows, [2, 2], "ArrowUp"), [0, 3]);
  assert.deepEqual(stopAfter(rows, [0, 1], "ArrowUp"), [0, 1]); // no row above
  assert.equal(stopAfter(rows, [0, 1], "Enter"), null);
});
