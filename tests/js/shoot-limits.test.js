import { test } from "node:test";
import assert from "node:assert/strict";
import { mayChooseModel, modelLabel, rerunNote, staleNote } from "../../frontend/js/shoot-limits.js";

test("modelLabel says what each kind of model covers", () => {
  assert.equal(modelLabel({ name: "default", kind: "default", frame: "per rig", rig_family: "", n_takes: 0 }),
    "default (the shipped choice for each rig)");
  assert.equal(modelLabel({ name: "canonical", kind: "shipped", frame: "canonical", rig_family: "canonical", n_takes: 46 }),
    "canonical (shipped; any rig with limb roles; 46 takes)");
  assert.equal(modelLabel({ name: "studio", kind: "registered", frame: "rig", rig_family: "bandai", n_takes: 31 }),
    "studio (registered; bandai rig only; 31 takes)");
});

test("only the choose_limits_model action shows the picker", () => {
  assert.equal(mayChooseModel({ can: ["read", "upload", "choose_limits_model"] }), true);
  assert.equal(mayChooseModel({ can: ["read", "upload", "delete_any"] }), false);
  assert.equal(mayChooseModel(null), false);
});

test("staleNote counts the takes checked with another model", () => {
  assert.equal(staleNote({ limits_model: "canonical", limits_stale_takes: 0 }), "");
  assert.equal(staleNote({ limits_model: "canonical" }), "");
  assert.equal(staleNote({ limits_model: "canonical", limits_stale_takes: 1 }),
    "1 take's latest run checked joint limits with another model than canonical");
  assert.equal(staleNote({ limits_model: "studio", limits_stale_takes: 3 }),
    "3 takes' latest runs checked joint limits with another model than studio");
});

test("rerunNote says what was queued and what is left", () => {
  assert.equal(rerunNote({ limits_model: "bandai", queued: [{}, {}], remaining: 0 }),
    "2 runs queued with bandai");
  assert.equal(rerunNote({ limits_model: "bandai", queued: [{}], remaining: 4 }),
    "1 run queued with bandai; 4 left (your queue is full: press again later)");
});
