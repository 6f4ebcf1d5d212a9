// Unit tests of the foot-lock decisions' pure helpers (node --test).
import { test } from "node:test";
import assert from "node:assert/strict";
import { acceptedCount, decidableLocks, downloadText, lockKeyTarget, lockLabel, mergedHistory, reviewedFormat } from "../../frontend/js/lock-decisions.js";

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

test("the download link says how many foot locks it applies: accepted ones only", () => {
  const latest = new Map([["skate-left-32", "accept"], ["skate-right-9", "reject"], ["skate-left-80", "accept"]]);
  assert.equal(acceptedCount(latest), 2);
  assert.equal(acceptedCount(new Map()), 0);
  assert.equal(downloadText(0, 0), "Download reviewed take");
  assert.equal(downloadText(3, 0), "Download reviewed take (no foot lock applied of 3)");
  assert.equal(downloadText(3, 1), "Download reviewed take (1 foot lock applied of 3)");
  assert.equal(downloadText(3, 2), "Download reviewed take (2 foot locks applied of 3)");
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
