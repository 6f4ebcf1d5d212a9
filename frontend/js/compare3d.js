// Two runs side by side in 3D for the compare view: each run's corrected take in its own view,
// both drawn with the one camera of scene3d.js, synchronised by time (B's frame is the one at
// A's instant) with an optional offset in B's frames, one player and one scrubber.
import * as api from "./api.js";
import { h } from "./dom.js";
import { flaggedAt } from "./findings.js";
import { sampleOf } from "./frames.js";
import { createPlayer } from "./player.js";

/** B's frame at A's frame `f`: the same instant, moved by `offset` of B's frames, clamped. */
export function syncedFrame(f, fpsA, fpsB, offset, nFramesB) {
  return Math.max(0, Math.min(nFramesB - 1, Math.round((f / fpsA) * fpsB) + offset));
}

/**
 * @param container  where the panel goes
 * @param a, b       {run, result} of the two runs
 * @param labels     [label of A, label of B]
 * @returns {dispose} or null when the two takes have different skeletons
 */
export async function compareViews(container, a, b, labels, onTeardown = () => {}) {
  const names = a.result.points.names;
  const same = names.length === b.result.points.names.length && names.every((n, k) => n === b.result.points.names[k]);
  if (!same) {
    container.append(h("p", { class: "muted", id: "compare-3d-note" }, "The two takes have different skeletons: no side-by-side 3D view."));
    return null;
  }
  const [framesA, framesB, { createViews }] = await Promise.all([
    api.getFramesPacked(a.run.id, { maxFrames: 800 }), api.getFramesPacked(b.run.id, { maxFrames: 800 }), import("./scene3d.js")]);
  const fpsA = a.result.summary.fps, fpsB = b.result.summary.fps;
  const nA = a.result.summary.n_frames, nB = b.result.summary.n_frames;
  const oriented = Array.isArray(framesA.corrected_rotations) && Array.isArray(framesB.corrected_rotations);
  const jointIndex = new Map(names.map((n, k) => [n, k]));
  const divA = h("div", { id: "compare-view-a", class: "view3d" }), divB = h("div", { id: "compare-view-b", class: "view3d" });
  const titleA = h("h3", { class: "view-title" }), titleB = h("h3", { class: "view-title" });
  const scrubber = h("input", { type: "range", id: "compare-scrubber", min: 0, max: nA - 1, value: 0, step: 1, "aria-label": "frame of A" });
  const offset = h("input", { type: "number", id: "compare-offset", value: 0, step: 1, size: 5, "aria-label": "offset of B (frames of B)" });
  const play = h("button", { id: "compare-play", class: "primary" }, "▶ play");
  const presets = ["front", "side", "top"].map((name) => h("button", { class: "small", "data-preset": name }, name));
  container.append(h("h2", {}, "Side by side in 3D (each run's corrected take, one camera)"),
    h("div", { class: "controls" }, "camera ", presets),
    h("div", { class: "row view-row", id: "compare-3d" }, h("div", { class: "col panel" }, titleA, divA), h("div", { class: "col panel" }, titleB, divB)),
    h("div", { class: "controls panel" }, play, scrubber, h("label", {}, "B offset ", offset, " frames of B")));
  // Both views draw "corrected" points: A's in the first view, B's in the second.
  const overview = {
    raw: framesA.corrected, corrected: framesB.corrected,
    raw_rotations: oriented ? framesA.corrected_rotations : undefined, corrected_rotations: oriented ? framesB.corrected_rotations : undefined,
  };
  const views = createViews({ raw: divA, corrected: divB }, { names, parents: a.result.points.parents, bones: a.result.points.bones, nJoints: a.result.points.n_joints, oriented }, overview);
  let frame = 0;
  const show = () => {
    const fb = syncedFrame(frame, fpsA, fpsB, Number(offset.value) || 0, nB);
    const ka = sampleOf(framesA, frame), kb = sampleOf(framesB, fb);
    views.show({
      raw: framesA.corrected[ka], corrected: framesB.corrected[kb],
      rawRotations: oriented ? framesA.corrected_rotations[ka] : null, correctedRotations: oriented ? framesB.corrected_rotations[kb] : null,
      rawFlagged: flaggedAt(a.result.findings, jointIndex, frame, () => "#1f77b4"), flagged: flaggedAt(b.result.findings, jointIndex, fb, () => "#ff7f0e"),
    });
    titleA.textContent = `A: ${labels[0]} — frame ${frame}`;
    titleB.textContent = `B: ${labels[1]} — frame ${fb}`;
    scrubber.value = frame;
  };
  const player = createPlayer({ fps: fpsA, nFrames: nA, getFrame: () => frame, onFrame: (f) => { frame = f; show(); } });
  play.addEventListener("click", () => {
    if (player.playing) player.pause(); else player.play();
    play.textContent = player.playing ? "❚❚ pause" : "▶ play";
  });
  scrubber.addEventListener("input", () => { frame = Number(scrubber.value); show(); });
  offset.addEventListener("input", show);
  presets.forEach((button) => button.addEventListener("click", () => views.setCamera(button.dataset.preset)));
  show();
  views.renderNow();
  window.mocapqaCompareViews = views; // read by the browser tests
  const dispose = () => { player.pause(); views.dispose(); };
  onTeardown(dispose);
  return { dispose, views };
}
