// The take view's page parts: the heading, the 3D views' row with the camera and view options,
// the player's controls, the keys' help line, and the run picker, steps and downloads panels.
// Elements only: take.js wires their behaviour.
import * as api from "./api.js";
import { badge, h } from "./dom.js";
import { fmt, runOptionsLabel } from "./format.js";
import { takeLine, uncheckedSteps, viewLegend } from "./take-format.js";

export const KEYS_HELP = "Keys: space play/pause · ←/→ one frame (shift: 10) · N/P next/previous finding · I/O in/out point · L loop in/out · shift+L loop the finding · C close-in · A/F/R approve, needs fix, reject the take (saves) · Y/X accept, reject the focused or last opened twist interval, swap or foot lock (saves) · Enter on a row opens it · ? shows or hides this line";

/** The take's name with its run's state, and what the take is. */
export function takeHeader(take, run) {
  return h("div", {}, h("h1", {}, take.name, " ", badge(run ? run.status : "none")), h("p", { class: "muted" }, takeLine(take)));
}

/** The run's progress while it is queued or running; when it ends, the view opens again (the
 * failure said instead). */
export async function waitForRun(main, run) {
  const bar = h("progress", { max: 100, value: run.progress }), text = h("span", {}, run.step);
  main.append(h("p", {}, bar, " ", text));
  const final = await api.waitForRun(run.id, (r) => { bar.value = r.progress; text.textContent = `${r.step} (${r.progress} %)`; });
  if (final.status === "failed") { main.append(h("p", { class: "error" }, final.error)); return; }
  window.dispatchEvent(new HashChangeEvent("hashchange"));
}

/** The player's controls: play, speed, the frame and joint lines, the scrubber and the loop's. */
function playerControls(nFrames) {
  return {
    frameLabel: h("span", { id: "frame-label" }),
    jointLabel: h("span", { id: "joint-label", class: "muted" }),
    scrubber: h("input", { type: "range", id: "scrubber", min: 0, max: nFrames - 1, value: 0, step: 1, "aria-label": "frame" }),
    playButton: h("button", { id: "play", class: "primary", "aria-keyshortcuts": "Space" }, "▶ play"),
    speed: h("select", { id: "speed", "aria-label": "speed" }, [0.25, 0.5, 1, 2].map((s) => h("option", { value: s, selected: s === 1 }, `${s}×`))),
    loopButton: h("button", { id: "loop", "aria-pressed": "false", "aria-keyshortcuts": "L", title: "loop playback over the in/out range (L)" }, "⟲ loop"),
    loopFindingButton: h("button", { id: "loop-finding", class: "small", "aria-keyshortcuts": "Shift+L", title: "loop the current finding with a margin (shift+L)" }, "loop finding"),
    clearLoopButton: h("button", { id: "loop-clear", class: "small", title: "clear the in/out range" }, "clear in/out"),
    loopLabel: h("span", { id: "loop-label", class: "muted" }, "in/out: none (I / O or drag on the bar)"),
  };
}

/** The camera's buttons and the view options. */
function viewControls(oriented) {
  return {
    presets: ["front", "side", "top"].map((name) => h("button", { id: `camera-${name}`, class: "small" }, name)),
    closeButton: h("button", { id: "camera-close", class: "small", "aria-pressed": "false", title: "frame the selected joint (or the current finding's joint) close (C)" }, "close-in"),
    followButton: h("button", { id: "camera-follow", class: "small", "aria-pressed": "false", title: "keep the root in the centre while playing" }, "follow"),
    triadsBox: h("input", { type: "checkbox", id: "show-axes", disabled: !oriented }),
    overlayBox: h("input", { type: "checkbox", id: "overlay" }),
    ...floorToggle(),
  };
}

/** The floor plane's checkbox: hidden and disabled until the views draw a floor (wireControls
 * shows it and says there when the floor is tilted). */
function floorToggle() {
  const floorBox = h("input", { type: "checkbox", id: "show-floor", checked: true, disabled: true });
  const floorText = h("span", { id: "floor-label" }, "floor");
  return { floorBox, floorText, floorToggle: h("label", { id: "floor-toggle", hidden: true }, floorBox, " ", floorText) };
}

/**
 * The views and the player, appended to `main` after the run picker. Keypoints are filtered, not
 * corrected: the right-hand view says which it shows (`outcome`).
 *
 * @returns the elements the view wires: the controls' (playerControls, viewControls), the two
 *   views' containers (rawDiv, corrDiv), their titles, the raw panel, the row and the player
 */
export function viewsLayout(main, picker, { nFrames, oriented, markersRan, outcome }) {
  const ui = { ...playerControls(nFrames), ...viewControls(oriented) };
  ui.rawDiv = h("div", { id: "view-raw", class: "view3d" });
  ui.corrDiv = h("div", { id: "view-corrected", class: "view3d" });
  ui.rawTitle = h("h3", { class: "view-title" }, "raw");
  ui.corrTitle = h("h3", { class: "view-title" }, outcome);
  ui.rawPanel = h("div", { class: "col panel", id: "panel-raw" }, ui.rawTitle, ui.rawDiv);
  ui.viewsRow = h("div", { class: "row view-row", id: "views" }, ui.rawPanel, h("div", { class: "col panel" }, ui.corrTitle, ui.corrDiv));
  ui.player = h("div", { class: "panel player", id: "player" },
    h("div", { class: "controls" }, ui.playButton, "speed ", ui.speed, ui.frameLabel, ui.jointLabel, ui.scrubber),
    h("div", { class: "controls" }, ui.loopButton, ui.loopFindingButton, ui.clearLoopButton, ui.loopLabel));
  main.append(
    picker,
    h("div", { class: "controls view-options" }, "camera ", ui.presets, ui.closeButton, ui.followButton,
      h("label", {}, ui.triadsBox, " joint axes"), h("label", {}, ui.overlayBox, " overlay (raw as ghost)"), ui.floorToggle,
      h("span", { class: "muted", id: "view-legend" }, viewLegend(oriented, markersRan))),
    ui.viewsRow,
    ui.player,
  );
  ui.help = h("p", { class: "muted", id: "keys-help" }, KEYS_HELP);
  return ui;
}

/** A take no check could read is said above its (empty) findings, not only under Steps. */
export function uncheckedNote(steps) {
  const unchecked = uncheckedSteps(steps);
  if (!unchecked.length) return null;
  return h("p", { class: "notice", id: "not-checked" }, h("b", {}, "Not checked: "),
    unchecked.map(([name, st]) => `${name}: ${st.message}`).join(" · "),
    unchecked.some(([, st]) => st.state === "no_roles") ? " — name the rig's joints in \u201cRig roles (mapping)\u201d below and re-run." : "");
}

// The run chosen in the run picker, until the view it opens has the picker again.
let pickedRun = null;

/** The run list, each run labelled by what differs from the defaults of `described` (GET
 * /run-options); another run opens at the frame shown now (`frameNow()`), as a reviewer
 * comparing runs expects, rather than at frame 0. A choice draws the view again: the new
 * picker takes the focus back (a keyboard user goes on choosing, ↑/↓ stepping through the runs). */
export function runPicker(take, run, frameNow, described) {
  const select = h("select", { id: "run-pick", "aria-label": "run", onchange: (e) => {
    pickedRun = e.target.value;
    location.hash = `${api.takeLink(take.id, e.target.value)}&frame=${frameNow()}`;
  } },
  take.runs.map((r, i) => h("option", { value: r.id, selected: r.id === run.id },
    `run ${i + 1} · ${r.status} · ${runOptionsLabel(r, described)}`)));
  if (pickedRun === run.id) {
    // A run still going draws the view again when it ends: the focus comes back then too.
    if (run.status === "done") pickedRun = null;
    refocus(select);
  }
  return h("div", { class: "controls" }, "Run ", select,
    run.server_time_s != null ? h("span", { class: "muted" }, `server time ${fmt(run.server_time_s, 2)} s`) : null,
    h("a", { href: `#/compare?a=${run.id}` }, "compare…"));
}

/**
 * Give `control` the focus once it is on the page (the caller appends it in the same task),
 * unless the focus went on to another control meanwhile: a control drawn again in place of the
 * one that had the focus.
 */
export function refocus(control) {
  queueMicrotask(() => {
    const now = document.activeElement;
    if (control.isConnected && (!now || now === document.body)) control.focus();
  });
}

export function downloadsPanel(run, result) {
  const labels = {
    bvh: "corrected BVH (the run's choice, before review)", csv: "filtered keypoints (CSV)", trc: "filtered keypoints (TRC)",
    c3d: "corrected C3D (swaps repaired, gaps filled; residual 0 on filled samples)", report: "JSON report", "report.html": "HTML report",
  };
  const kinds = [...(result.downloads || ["report"]), "report.html"];
  return h("div", { class: "panel" }, h("h2", {}, "Downloads"),
    kinds.map((k) => h("a", { href: api.downloadUrl(run.id, k), download: "", id: `download-${k.replace(".", "-")}`, class: "download" }, labels[k] || k)));
}

export function stepsPanel(result) {
  return h("div", { class: "panel" }, h("h2", {}, "Steps"),
    h("ul", { class: "steps" }, Object.entries(result.steps).map(([name, s]) => h("li", {}, h("b", {}, name), " ", badge(s.state, s.state === "done" ? "done" : ""), " ", s.message))));
}
