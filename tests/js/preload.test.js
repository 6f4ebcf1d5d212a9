// index.html preloads every module of the dashboard's static import graph (a missing one would be
// fetched only when its importer has arrived: one more round trip before the take view's data).
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { test } from "node:test";

const js = new URL("../../frontend/js/", import.meta.url);

function staticGraph(entry, seen = new Set()) {
  if (seen.has(entry)) return seen;
  seen.add(entry);
  const text = readFileSync(new URL(entry, js), "utf8");
  for (const m of text.matchAll(/^import[^;]*?from "\.\/([\w-]+\.js)"/gms)) staticGraph(m[1], seen);
  return seen;
}

test("index.html preloads exactly the modules app.js and account-menu.js import", () => {
  const html = readFileSync(new URL("../index.html", js), "utf8");
  const preloaded = new Set([...html.matchAll(/rel="modulepreload" href="\/static\/js\/([\w-]+\.js)"/g)].map((m) => m[1]));
  const graph = new Set([...staticGraph("app.js"), ...staticGraph("account-menu.js")]);
  for (const entry of ["app.js", "account-menu.js"]) graph.delete(entry); // loaded by their <script>
  assert.deepEqual([...preloaded].sort(), [...graph].sort());
  assert.ok(graph.has("take.js") && graph.has("frames.js"));
});
