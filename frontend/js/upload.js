// Upload: a drop zone; progress in bytes sent (XMLHttpRequest upload events), then the analysis.
import * as api from "./api.js";
import { h } from "./dom.js";
import { fmt } from "./format.js";

export function dropZone(onFiles) {
  const input = h("input", { type: "file", id: "file-input", multiple: true, hidden: true });
  const choose = h("button", { onclick: () => input.click() }, "choose files");
  const zone = h("div", { class: "dropzone", id: "dropzone" },
    h("p", {}, "Drop takes here (BVH, TRC, CSV, OpenPose, MediaPipe, NPY/NPZ, JSON) or ", choose), input);
  input.addEventListener("change", () => input.files.length && onFiles([...input.files]));
  zone.addEventListener("dragover", (e) => { e.preventDefault(); zone.classList.add("over"); });
  zone.addEventListener("dragleave", () => zone.classList.remove("over"));
  zone.addEventListener("drop", (e) => {
    e.preventDefault(); zone.classList.remove("over");
    if (e.dataTransfer.files.length) onFiles([...e.dataTransfer.files]);
  });
  return zone;
}

const megabytes = (bytes) => `${fmt(bytes / 1e6, 2)} MB`;

/** Upload files one after the other; the bar counts bytes sent over all of them. */
export function uploader(status) {
  return async (files) => {
    const total = files.reduce((s, f) => s + f.size, 0) || 1;
    const bar = h("progress", { max: total, value: 0, id: "upload-progress" });
    const text = h("span", { id: "upload-status" });
    const analysis = h("progress", { max: 100, value: 0, id: "analysis-progress" });
    const analysisText = h("span", { id: "analysis-status" });
    const links = h("span", { id: "upload-links" });
    status.replaceChildren(h("div", {}, "upload ", bar, " ", text), h("div", {}, "analysis ", analysis, " ", analysisText), links);
    let before = 0;
    for (const file of files) {
      try {
        text.textContent = `${file.name}: ${megabytes(before)} of ${megabytes(total)}`;
        const created = await api.uploadTake(file, (loaded) => {
          bar.value = before + loaded;
          text.textContent = `${file.name}: ${megabytes(before + loaded)} of ${megabytes(total)}`;
        });
        before += file.size;
        bar.value = before;
        const run = await api.waitForRun(created.run_id, (r) => {
          analysis.value = r.progress;
          analysisText.textContent = `${file.name}: ${r.step} (${r.progress} %)`;
        });
        if (run.status === "failed") throw new Error(`analysis failed: ${run.error}`);
        analysisText.textContent = `${file.name}: done`;
        links.append(h("a", { href: api.takeLink(created.id, created.run_id), id: "open-take" }, `open ${created.name}`), " ");
      } catch (e) {
        status.append(h("p", { class: "error", id: "upload-error" }, `Rejected: ${e.message}`));
        before += file.size;
      }
    }
  };
}

export async function uploadView(main) {
  const status = h("div", { id: "upload-area" });
  main.replaceChildren(h("h1", {}, "Upload takes"), dropZone(uploader(status)), status,
    h("p", { class: "muted" }, "The analysis (twist refinement, joint limits, filtering) starts with default options."));
}
