// Unit tests of the foot lock decisions' announcements (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { announceLockDecisions, LOCK_DECISIONS_EVENT, onLockDecisions } from "../../frontend/js/lock-events.js";

test("a subscriber hears each announcement of the newest decisions until it unsubscribes", () => {
  const target = new EventTarget();
  const heard = [];
  const stop = onLockDecisions((detail) => heard.push(detail), target);
  announceLockDecisions("run-1", new Map([["skate-left-10", "accept"]]), target);
  announceLockDecisions("run-1", new Map([["skate-left-10", "reject"], ["skate-right-40", "accept"]]), target);
  stop();
  announceLockDecisions("run-1", new Map(), target);
  assert.deepEqual(heard, [
    { runId: "run-1", decisions: { "skate-left-10": "accept" } },
    { runId: "run-1", decisions: { "skate-left-10": "reject", "skate-right-40": "accept" } },
  ]);
});

test("the event has its documented name; without a document nothing is sent", () => {
  const target = new EventTarget();
  let name = null;
  target.addEventListener(LOCK_DECISIONS_EVENT, (e) => { name = e.type; });
  announceLockDecisions("r", new Map(), target);
  assert.equal(name, "mocapqa:lock-decisions");
  assert.doesNotThrow(() => announceLockDecisions("r", new Map(), null));
  assert.doesNotThrow(() => onLockDecisions(() => {}, null)());
});
