import { unpackFrames } from "./frames.js";

// The only module that knows the server's URLs. Every function returns parsed JSON or throws
// an Error whose message is the API's own "detail" (with the file's line for parse errors).

const BASE = "/api/v1";
const SIGN_IN_PAGE = "/static/signin.html";

// The session's CSRF token (a cookie the page may read), repeated on every state-changing request.
export function csrfHeaders() {
  const match = document.cookie.match(/(?:^|; )mocapqa_csrf=([^;]*)/);
  return match ? { "X-CSRF-Token": decodeURIComponent(match[1]) } : {};
}

// Responses started before a view asked for them (prefetch.js, as the page starts), by URL: the
// first GET of that URL takes the started request instead of sending another. Same URL, same
// credentials (the session cookie; a GET carries no CSRF header), same answer handling.
const prefetched = new Map();

function get(url) {
  const started = prefetched.get(url);
  prefetched.delete(url);
  return started || fetch(url);
}

/** Start a GET of each path now, for the first request of the same path to take over. */
export function prefetch(paths) {
  for (const url of paths.map((path) => BASE + path)) {
    if (prefetched.has(url)) continue;
    const started = fetch(url);
    started.catch(() => {}); // a failure surfaces where the response is taken, not as unhandled
    prefetched.set(url, started);
  }
}

/** Forget the started responses not taken yet (a later view asks afresh). */
export function dropPrefetched() {
  prefetched.clear();
}

export async function request(method, path, body) {
  const init = { method, headers: method === "GET" ? {} : csrfHeaders() };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  const response = await (method === "GET" ? get(BASE + path) : fetch(BASE + path, init));
  if (response.status === 401 && !location.pathname.startsWith(SIGN_IN_PAGE)) location.assign(SIGN_IN_PAGE);
  if (!response.ok) throw await apiError(response.status, await response.text());
  if (response.status === 204) return null;
  return response.json();
}

function apiError(status, text) {
  let message = `HTTP ${status}`;
  try {
    const body = JSON.parse(text);
    if (typeof body.detail === "string") message = body.detail;
    else if (Array.isArray(body.detail)) message = body.detail.map((d) => `${d.loc.join(".")}: ${d.msg}`).join("; ");
  } catch { /* not JSON */ }
  const error = new Error(message);
  error.status = status;
  return error;
}

export const health = () => request("GET", "/health");
export const listTakes = (params = {}) => {
  const query = new URLSearchParams(Object.entries(params).filter(([, v]) => v !== "" && v != null));
  return request("GET", `/takes?${query}`);
};
const takePath = (id) => `/takes/${id}`;
const resultPath = (runId) => `/runs/${runId}/result`;
function framesPath(runId, { start = 0, stop = null, step = 1, maxFrames = 800 } = {}) {
  const query = new URLSearchParams({ start, step, max_frames: maxFrames });
  if (stop != null) query.set("stop", stop);
  return `/runs/${runId}/frames.f32?${query}`;
}
export const getTake = (id) => request("GET", takePath(id));
export const deleteTake = (id) => request("DELETE", `/takes/${id}`);
export const getRun = (id) => request("GET", `/runs/${id}`);
export const getResult = (id) => request("GET", resultPath(id));
/** Raw and corrected points (and rotations or confidence) of frames start:stop:step, the step
 * grown to hold at most maxFrames; packed float32 (a quarter of the JSON window's bytes, nothing
 * to parse): points are Float32Array views, NaN where missing (see frames.js). */
export async function getFramesPacked(id, range = {}) {
  const response = await get(BASE + framesPath(id, range));
  if (!response.ok) throw apiError(response.status, await response.text());
  return unpackFrames(await response.arrayBuffer());
}
/** Frames the take view draws first: a light overview of the whole take (its skeletons do not
 * wait for the full one). */
export const FIRST_FRAMES = 100;
export const getFirstFrames = (runId) => getFramesPacked(runId, { maxFrames: FIRST_FRAMES });
/** Start the take view's first requests: the take and, when the run is known, its result and
 * first frames (see prefetch.js). */
export function prefetchTake(takeId, runId) {
  prefetch(runId ? [takePath(takeId), resultPath(runId), framesPath(runId, { maxFrames: FIRST_FRAMES })] : [takePath(takeId)]);
}
export const startRun = (takeId, options) => request("POST", `/takes/${takeId}/runs`, options);
export const addReview = (takeId, review) => request("POST", `/takes/${takeId}/reviews`, review);
export const getDecisions = (runId) => request("GET", `/runs/${runId}/decisions`);
// `item` is "interval" (a twist interval) or "swap"; the decided take is BVH, C3D or TRC.
export const addDecision = (runId, itemId, body, item = "interval") => request("POST", `/runs/${runId}/${item === "swap" ? "swaps" : "intervals"}/${itemId}/decisions`, body);
/** Accept or reject the foot lock of a skate finding (its id, `skate-left-120`). */
export const addLockDecision = (runId, lockId, body) => request("POST", `/runs/${runId}/feet/${encodeURIComponent(lockId)}/decisions`, body);
export const decidedUrl = (runId, format = "bvh") => `${BASE}/runs/${runId}/decisions/${format}`;
export const listFilters = () => request("GET", "/filters");
export const getRunOptions = () => request("GET", "/run-options");
export const downloadUrl = (runId, kind) => `${BASE}/runs/${runId}/download/${kind}`;
export const thumbnailUrl = (takeId, runId) => `${BASE}/takes/${takeId}/thumbnail?run=${runId || ""}`;
export const takeLink = (takeId, runId) => `#/take/${takeId}${runId ? `?run=${runId}` : ""}`;

// A multipart POST with upload progress (fetch cannot report upload progress; XMLHttpRequest
// can), carrying the session's CSRF header like every other state-changing request.
function postForm(path, form, onProgress, what) {
  return new Promise((resolve, reject) => {
    const xhr = new XMLHttpRequest();
    xhr.open("POST", `${BASE}${path}`);
    for (const [name, value] of Object.entries(csrfHeaders())) xhr.setRequestHeader(name, value);
    xhr.upload.onprogress = (e) => { if (e.lengthComputable) onProgress(e.loaded, e.total); };
    xhr.onload = () => (xhr.status === 201 ? resolve(JSON.parse(xhr.responseText)) : reject(apiError(xhr.status, xhr.responseText)));
    xhr.onerror = () => reject(new Error(`network error during ${what}`));
    xhr.send(form);
  });
}

/** Upload one take; ``onProgress(bytes)`` gets the bytes of this file sent so far (the
 * request's own overhead left out). */
export function uploadTake(file, onProgress) {
  const form = new FormData();
  form.append("file", file);
  return postForm("/takes", form, (loaded, total) => onProgress(Math.min(file.size, loaded * (file.size / total))), "upload");
}

export async function waitForRun(runId, onProgress, intervalMs = 300) {
  for (;;) {
    const run = await getRun(runId);
    onProgress(run);
    if (run.status === "done" || run.status === "failed") return run;
    await new Promise((r) => setTimeout(r, intervalMs));
  }
}

// Shoots: many takes imported at once, a server-side take table, progress, review queue, export.
export const listShoots = () => request("GET", "/shoots");
export const getShoot = (id) => request("GET", `/shoots/${id}`);
export const createShoot = (name) => request("POST", "/shoots", { name });
export const renameShoot = (id, name) => request("PATCH", `/shoots/${id}`, { name });
export const deleteShoot = (id, confirm) => request("DELETE", `/shoots/${id}?confirm=${encodeURIComponent(confirm)}`);
export const shootTakes = (id, query) => request("GET", `/shoots/${id}/takes?${query}`);
export const shootProgress = (id) => request("GET", `/shoots/${id}/progress`);
export const shootHeatmap = (id, query) => request("GET", `/shoots/${id}/heatmap?${query}`);
export const limitsModels = () => request("GET", "/limits-models");
export const setShootLimitsModel = (id, name) => request("PUT", `/shoots/${id}/limits-model`, { name });
export const rerunStaleLimits = (id) => request("POST", `/shoots/${id}/limits-reruns`);
export const nextForReview = (id, after) => request("GET", `/shoots/${id}/next${after ? `?after=${after}` : ""}`);
/** The shoot summary download; `query` (exportQuery) narrows and orders it like the table. */
export const summaryUrl = (id, kind, query = "") => `${BASE}/shoots/${id}/summary.${kind}${query ? `?${query}` : ""}`;
export const shootLink = (id, query = "") => `#/shoot/${id}${query ? `?${query}` : ""}`;

/** Import files and archives into a shoot (one multipart request, field `files` repeated);
 * `onProgress(sent, total)` reports the request's bytes sent. */
export function importIntoShoot(id, files, onProgress = () => {}) {
  const form = new FormData();
  for (const file of files) form.append("files", file, file.name);
  return postForm(`/shoots/${id}/takes`, form, onProgress, "the import");
}
