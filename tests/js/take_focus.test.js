// Unit tests of the take view's keys on a focused control, the link kept while playing and the
// view options kept in the link (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { elementKeepsKey, linkDue, LINK_INTERVAL_MS } from "../../frontend/js/take-controls.js";
import { reset, set, state, viewOptionParams, viewOptionsOf } from "../../frontend/js/state.js";

const input = (type) => ({ tagName: "INPUT", type, isContentEditable: false });
const element = (tagName, editable = false) => ({ tagName, isContentEditable: editable });
const COMMAND_KEYS = [" ", "n", "N", "p", "i", "o", "a", "f", "r", "l", "L", "c", "y", "x", "?"];
const SLIDER_KEYS = ["ArrowLeft", "ArrowRight", "ArrowUp", "ArrowDown", "Home", "End", "PageUp", "PageDown"];

test("a range slider keeps its arrows, Home, End and page keys; every other key is the view's", () => {
  const slider = input("range");
  for (const key of SLIDER_KEYS) assert.equal(elementKeepsKey(slider, key), true, key);
  for (const key of COMMAND_KEYS) assert.equal(elementKeepsKey(slider, key), false, key);
  assert.equal(elementKeepsKey({ tagName: "input", type: "RANGE" }, "n"), false);
});

test("text is typed in a text field, a list and an editable element; a checkbox is no field", () => {
  for (const field of [input("text"), input("search"), input("number"), element("TEXTAREA"), element("SELECT"), element("DIV", true)]) {
    for (const key of ["n", " ", "ArrowLeft"]) assert.equal(elementKeepsKey(field, key), true, `${field.tagName} ${key}`);
  }
  assert.equal(elementKeepsKey({ tagName: "INPUT" }, "n"), true); // an input with no type is a text field
  for (const box of [input("checkbox"), input("radio")]) assert.equal(elementKeepsKey(box, "n"), false);
  for (const other of [element("BUTTON"), element("TR"), element("BODY"), null, {}]) assert.equal(elementKeepsKey(other, "n"), false);
});

test("while playing, the link is written at most once per interval", () => {
  assert.equal(linkDue(undefined, 0), true);
  assert.equal(linkDue(1000, 1000 + LINK_INTERVAL_MS - 1), false);
  assert.equal(linkDue(1000, 1000 + LINK_INTERVAL_MS), true);
  // A few times a second: often enough for a reload to come back close, rarely enough for the
  // browser's limit on address changes.
  assert.ok(LINK_INTERVAL_MS >= 100 && LINK_INTERVAL_MS <= 500);
  const writes = [];
  let last;
  for (let now = 0; now < 2000; now += 1000 / 60) if (linkDue(last, now)) { writes.push(now); last = now; }
  assert.equal(writes.length, Math.ceil(2000 / LINK_INTERVAL_MS));
});

test("the view options go in the link only when changed, and come back from it", () => {
  reset();
  assert.deepEqual(viewOptionParams(state), []);
  set({ triads: true, overlay: true, floor: false });
  const params = viewOptionParams(state);
  assert.deepEqual(Object.fromEntries(params), { axes: "1", overlay: "1", floor: "0" });
  reset();
  set(viewOptionsOf(new URLSearchParams(params)));
  assert.deepEqual([state.triads, state.overlay, state.floor], [true, true, false]);
  // Absent or unreadable parameters leave the defaults.
  assert.deepEqual(viewOptionsOf(new URLSearchParams("run=r&frame=3&axes=yes")), {});
  assert.deepEqual(viewOptionsOf(new URLSearchParams("floor=1&overlay=0")), { floor: true, overlay: false });
  reset();
  assert.deepEqual([state.triads, state.overlay, state.floor], [false, false, true]);
});
