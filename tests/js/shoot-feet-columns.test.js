import { test } from "node:test";
import assert from "node:assert/strict";
import { formatCell, isFiltered, skateSize, TABLE_DEFAULTS, TAKE_COLUMNS, tableState, takesQuery } from "../../frontend/js/shoot-format.js";

test("skateSize gives every size with its unit (the header names none: a shoot mixes units)", () => {
  assert.equal(skateSize(9.15, "cm"), "9.2 cm");
  assert.equal(skateSize(2.4, "% height"), "2.4 % height");
  assert.equal(skateSize(0, "cm"), "0.0 cm");
  assert.equal(skateSize(3, null), "3.0 cm");
});

test("skateSize shows no figure as a dash, never 0", () => {
  for (const value of [null, undefined, Number.NaN, "n/a"]) assert.equal(skateSize(value, "cm"), "–");
});

test("the feet columns are sortable, the worst skate's header names no unit its cells may not show, and no figure is a dash", () => {
  const keys = TAKE_COLUMNS.map((c) => c.key);
  for (const key of ["foot_skates", "foot_worst_skate", "foot_penetrations", "foot_floating"]) assert.ok(keys.includes(key), key);
  const worst = TAKE_COLUMNS.find((c) => c.key === "foot_worst_skate");
  assert.equal(worst.label, "worst skate");
  assert.doesNotMatch(worst.label, /cm|height/);
  const measured = { foot_skates: 2, foot_worst_skate: 4.04, foot_skate_unit: "% height", foot_penetrations: 0, foot_floating: 1 };
  assert.equal(formatCell("foot_skates", measured), "2");
  assert.equal(formatCell("foot_worst_skate", measured), "4.0 % height");
  assert.equal(formatCell("foot_penetrations", measured), "0");
  assert.equal(formatCell("foot_floating", measured), "1");
  // Checked and clean: 0 skates and no largest; analysed before the feet figures: all dashes.
  const clean = { foot_skates: 0, foot_worst_skate: null, foot_skate_unit: null, foot_penetrations: 0, foot_floating: 0 };
  assert.equal(formatCell("foot_skates", clean), "0");
  assert.equal(formatCell("foot_worst_skate", clean), "–");
  const before = { status: "done", score: 80 };
  for (const key of ["foot_skates", "foot_worst_skate", "foot_penetrations", "foot_floating"]) assert.equal(formatCell(key, before), "–", key);
});

test("the skates filter reaches the query, the view's URL state and the filtered flag", () => {
  assert.equal(TABLE_DEFAULTS.has_skates, "");
  const state = tableState(new URLSearchParams("has_skates=true&sort=foot_worst_skate&order=desc"));
  const query = new URLSearchParams(takesQuery(state));
  assert.equal(query.get("has_skates"), "true");
  assert.equal(query.get("sort"), "foot_worst_skate");
  assert.equal(isFiltered(state), true);
  assert.equal(isFiltered({ ...TABLE_DEFAULTS }), false);
});
