// Unit tests of the foot-lock decisions' pure helpers (node --test).
import { test } from "node:test";
import assert from "node:assert/strict";
import { decidableLocks, downloadText, keptCount, lockKept, lockKeyTarget, lockLabel, mergedHistory, reviewedFormat, runLockText } from "../../frontend/js/lock-decisions.js";

const skate = { kind: "skate", id: "skate-left-32", foot: "left", start_frame: 32, end_frame: 47, joint: "CC_Base_L_Foot" };

test("the foot locks are the skate findings with an id, in findings order", () => {
  const findings = [{ kind: "penetration", id: "penetration-left-3", foot: "left" }, skate, { kind: "skate", foot: "right" }, { kind: "twist", id: 0 }];
  assert.deepEqual(decidableLocks({ findings }), [skate]);
  assert.deepEqual(decidableLocks({}), []);
  assert.equal(lockLabel(skate), "left foot lock frames 32–47");
});

test("the reviewed download is BVH for a motion take, C3D for a take the run wrote a corrected C3D of, else none", () => {
  assert.equal(reviewedFormat({ kind: "motion" }), "bvh");
  assert.equal(reviewedFormat({ kind: "keypoints", downloads: ["csv", "c3d"] }), "c3d");
  assert.equal(reviewedFormat({ kind: "keypoints", downloads: ["trc"] }), null);
  assert.equal(reviewedFormat({ kind: "keypoints" }), null);
});

test("the download link says how many foot locks it applies: accepted ones, and undecided ones the run locked", () => {
  const latest = new Map([["skate-left-32", "accept"], ["skate-right-9", "reject"], ["skate-left-80", "accept"]]);
  const cleanupOff = new Map(["skate-left-32", "skate-right-9", "skate-left-80", "skate-right-99"].map((id) => [id, { id, applied: false }]));
  assert.equal(keptCount(cleanupOff, latest), 2);
  assert.equal(keptCount(cleanupOff, new Map()), 0);
  const runLocked = new Map([...cleanupOff].map(([id, lock]) => [id, { ...lock, applied: true }]));
  // The run locked all four: the rejected one is undone, the undecided one follows the run.
  assert.equal(keptCount(runLocked, latest), 3);
  assert.equal(keptCount(runLocked, new Map()), 4);
  assert.equal(lockKept({ applied: true }, "reject"), false);
  assert.equal(lockKept({ applied: false }, "accept"), true);
  assert.equal(lockKept({ applied: true }, undefined), true);
  assert.equal(lockKept({}, undefined), false); // a run recorded before the flag locked none
  assert.equal(downloadText(0, 0), "Download reviewed take");
  assert.equal(downloadText(3, 0), "Download reviewed take (0 of 3 foot locks applied)");
  assert.equal(downloadText(3, 1), "Download reviewed take (1 of 3 foot locks applied)");
  assert.equal(downloadText(3, 2), "Download reviewed take (2 of 3 foot locks applied)");
  assert.equal(downloadText(1, 1), "Download reviewed take (1 of 1 foot lock applied)");
  assert.equal(downloadText(5, 0), "Download reviewed take (0 of 5 foot locks applied)");
});

test("a lock's cell says what the run chose: cleanup off by default, else locked or not", () => {
  assert.equal(runLockText(undefined).notLocked, "run: cleanup off");
  assert.equal(runLockText("none").notLocked, "run: cleanup off");
  const confident = runLockText("confident");
  assert.equal(confident.locked, "run: locked");
  assert.equal(confident.notLocked, "run: not locked");
  assert.match(confident.title, /confident/);
});

test("both histories merge newest first", () => {
  const history = [{ id: 7, interval_id: 1 }, { id: 2, interval_id: 0 }];
  const locks = [{ id: 5, lock_id: "skate-left-32" }];
  assert.deepEqual(mergedHistory(history, locks).map((r) => r.id), [7, 5, 2]);
  assert.deepEqual(mergedHistory(history, undefined).map((r) => r.id), [7, 2]);
});

test("Y / X act on the focused or last opened foot lock, and leave other kinds to their own rule", () => {
  const ids = new Map([["skate-left-32", skate]]);
  assert.deepEqual(lockKeyTarget({ kind: "skate", lock: "skate-left-32" }, null, "twist", ids), { lock: "skate-left-32" });
  assert.deepEqual(lockKeyTarget(null, "skate-left-32", "skate", ids), { lock: "skate-left-32" });
  // A focused row of another kind, or another kind opened last: not a lock.
  assert.equal(lockKeyTarget({ kind: "twist", interval: "0" }, "skate-left-32", "skate", ids), null);
  assert.equal(lockKeyTarget(null, "skate-left-32", "penetration", ids), null);
  assert.equal(lockKeyTarget(null, null, null, ids), null);
  // A skate row without a lock to decide says so.
  assert.match(lockKeyTarget({ kind: "skate", lock: undefined }, null, null, ids).message, /no foot lock/);
  assert.match(lockKeyTarget(null, "skate-right-9", "skate", new Map()).message, /no foot lock/);
});
