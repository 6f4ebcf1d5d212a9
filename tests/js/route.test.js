// Unit tests of the dashboard's address parsing (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { parseRoute } from "../../frontend/js/route.js";

test("a take's address gives its id and the run, frame and joint", () => {
  const { parts, params } = parseRoute("#/take/abc123?run=r9&frame=42&joint=LeftUpLeg");
  assert.deepEqual(parts, ["take", "abc123"]);
  assert.equal(params.get("run"), "r9");
  assert.equal(params.get("frame"), "42");
  assert.equal(params.get("joint"), "LeftUpLeg");
});

test("an empty address and the list's address have no parts", () => {
  for (const hash of ["", "#", "#/", "#/?q=walk"]) assert.deepEqual(parseRoute(hash).parts, [], hash);
  assert.equal(parseRoute("#/?q=walk").params.get("q"), "walk");
  assert.equal(parseRoute("").params.get("run"), null);
});

test("a shoot's review queue keeps its three parts", () => {
  assert.deepEqual(parseRoute("#/shoot/s1/review").parts, ["shoot", "s1", "review"]);
  assert.deepEqual(parseRoute("#/take/abc/").parts, ["take", "abc"]);
});
