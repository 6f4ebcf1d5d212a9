// Every multipart POST (a take upload, an import into a shoot) carries the session's CSRF
// header when signed in, as every other state-changing request does (node --test;
// XMLHttpRequest and the cookie are replaced by recorders).
import assert from "node:assert/strict";
import { test } from "node:test";
import * as api from "../../frontend/js/api.js";

function recordXhr() {
  const sent = [];
  globalThis.XMLHttpRequest = class {
    constructor() { this.headers = {}; this.upload = {}; sent.push(this); }
    open(method, url) { this.method = method; this.url = url; }
    setRequestHeader(name, value) { this.headers[name] = value; }
    send(body) {
      this.body = body;
      this.status = 201;
      this.responseText = JSON.stringify({ ok: true });
      queueMicrotask(() => this.onload());
    }
  };
  return sent;
}

test("a take upload and an import into a shoot both send the CSRF token", async () => {
  globalThis.document = { cookie: "other=1; mocapqa_csrf=tok%2Fen; x=2" };
  const sent = recordXhr();
  const file = new File(["HIERARCHY"], "walk.bvh");
  await api.uploadTake(file, () => {});
  await api.importIntoShoot("s1", [file, new File(["x"], "b.bvh")]);
  assert.deepEqual(sent.map((x) => [x.method, x.url]), [["POST", "/api/v1/takes"], ["POST", "/api/v1/shoots/s1/takes"]]);
  for (const xhr of sent) assert.equal(xhr.headers["X-CSRF-Token"], "tok/en");
  assert.deepEqual(sent[1].body.getAll("files").map((f) => f.name), ["walk.bvh", "b.bvh"]);
});

test("without a session cookie (open mode) no CSRF header is sent", async () => {
  globalThis.document = { cookie: "" };
  const sent = recordXhr();
  await api.importIntoShoot("s1", [new File(["x"], "a.bvh")]);
  assert.deepEqual(sent[0].headers, {});
});

test("upload progress is this file's bytes, without the request's overhead", async () => {
  globalThis.document = { cookie: "" };
  const sent = recordXhr();
  const seen = [];
  const done = api.uploadTake(new File(["0123456789"], "t.bvh"), (bytes) => seen.push(bytes));
  sent[0].upload.onprogress({ lengthComputable: true, loaded: 60, total: 120 });
  await done;
  assert.deepEqual(seen, [5]);
});
