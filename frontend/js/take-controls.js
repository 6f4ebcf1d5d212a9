// The take view's behaviour, on its state `t` (take.js builds it): drawing the frame, the link
// kept in the address, jumps, playback, the camera's focus, the in/out loop and the keys.
import * as api from "./api.js";
import { nextFinding } from "./format.js";
import { findingAt, loopOfFinding } from "./findings.js";
import * as store from "./state.js";
import { floorLabel } from "./scene-data.js";
import { clampFrame, frameAt, frameText, keyCommand, LOOP_MARGIN_S, loopText, takeQuery } from "./take-format.js";
import { parseRange, withIn, withOut } from "./timebar.js";

/** The selected joint's twist chain is the one the twist chart shows (when it has one). */
export function focusCharts(t) {
  const chart = document.getElementById("chart-twist");
  const chains = t.result.series.twist ? t.result.series.twist.chains : [];
  if (!chart || !chains.some((c) => c.joint === store.state.joint)) return;
  // Every trace of a chain (its lines, its interval bands, its spins) follows its legend group.
  const visible = chart.data.map((trace) => (trace.legendgroup === store.state.joint ? true : "legendonly"));
  t.Plotly.restyle(chart, { visible });
}

/** Draw the state's frame: the views, the player's lines, the time bars and the charts' cursor. */
export function render(t) {
  const { ui } = t;
  const f = store.state.frame;
  const frame = frameAt(t.detail, t.overview, f, { oriented: t.oriented, intervals: t.intervals, jointIndex: t.jointIndex, colorOf: t.colorOf, selected: t.jointIndex.get(store.state.joint) });
  t.views.show(frame);
  ui.frameLabel.textContent = frameText(f, t.nFrames, t.fps, frame.flagged.size);
  ui.jointLabel.textContent = store.state.joint ? `selected: ${store.state.joint}` : "click a joint to select it";
  // A narrow bar cuts a long name: the whole of it on hover.
  ui.jointLabel.title = ui.jointLabel.textContent;
  ui.rawTitle.textContent = `raw — frame ${frame.shown}`;
  ui.corrTitle.textContent = store.state.overlay ? `${t.outcome} (solid) and raw (ghost) — frame ${frame.shown}` : `${t.outcome} — frame ${frame.shown}`;
  ui.scrubber.value = f;
  t.timebar.setFrame(f);
  if (t.gapTimeline) t.gapTimeline.setFrame(f);
  if (t.contactTimeline) t.contactTimeline.setFrame(f);
  if (t.timeline) t.timeline.setFrame(f);
  if (t.player && t.player.playing && linkDue(t.linkedAt, performance.now())) remember(t);
}

/** Milliseconds between two updates of the link while playing (a reload then opens close to
 * the frame shown; replacing the address, not adding to the history). */
export const LINK_INTERVAL_MS = 250;

/** Whether the link is due again `now` (ms) when it was last written at `last` (ms; undefined
 * when never). */
export function linkDue(last, now, interval = LINK_INTERVAL_MS) {
  return last === undefined || now - last >= interval;
}

/** Keep the view's state in the address (a reload or a shared link opens it again): frame,
 * joint, in/out, the findings filter and the view options. */
export function remember(t) {
  const query = takeQuery(t.run.id, store.state, t.filterQuery);
  for (const [name, value] of store.viewOptionParams(store.state)) query.set(name, value);
  history.replaceState(null, "", `#/take/${t.take.id}?${query}`);
  t.linkedAt = performance.now();
}

/** Frames: the overview (whole take, decimated) or, when paused, a full-rate window around. */
export async function loadDetail(t) {
  if (t.overview.step === 1) return;
  const f = store.state.frame;
  const part = await api.getFramesPacked(t.run.id, { start: Math.max(0, f - 200), stop: Math.min(t.nFrames, f + 200), maxFrames: 401 });
  t.detail = part;
  if (!t.player.playing) render(t);
}

export function jump(t, f) {
  store.set({ frame: clampFrame(f, t.nFrames) });
  render(t); remember(t); loadDetail(t);
}

export function togglePlay(t) {
  const { player, ui } = t;
  if (player.playing) { player.pause(); remember(t); loadDetail(t); } else { t.detail = null; player.play(); }
  ui.playButton.textContent = player.playing ? "❚❚ pause" : "▶ play";
  ui.playButton.setAttribute("aria-pressed", String(player.playing));
}

/** Pause (when playing) and show frame `f`: a click on a time bar. */
export function pauseAndJump(t, f) {
  if (t.player.playing) togglePlay(t);
  jump(t, f);
}

/** Select joint `name` (a click on a joint, the mapping editor) and show it. */
export function selectJoint(t, name) {
  store.set({ joint: name }); focusCharts(t); render(t); remember(t);
}

/** Camera focus: "body" (the body's centre over the floor), "joint" (close-in on the selected
 * joint) or "root" (follow: the root in the centre). */
export function setFocus(t, mode) {
  if (mode === "joint" && !store.state.joint) {
    const f = t.list.current || findingAt(t.list.shown, store.state.frame) || t.list.shown[0];
    if (f) store.set({ joint: f.joint });
  }
  store.set({ focus: mode });
  t.ui.closeButton.setAttribute("aria-pressed", String(mode === "joint"));
  t.ui.followButton.setAttribute("aria-pressed", String(mode === "root"));
  t.views.setFocus(mode);
  render(t);
}

/** Loop: an in/out range (I / O keys, or a drag on the time bar) and a toggle (L). */
function showLoop(t) {
  const r = store.state.loop;
  t.ui.loopLabel.textContent = loopText(r, store.state.looping);
  t.ui.loopButton.setAttribute("aria-pressed", String(store.state.looping));
  t.timebar.setRange(r, store.state.looping);
  t.player.setLoop(store.state.looping ? r : null);
}

export function setRange(t, r) { store.set({ loop: r }); showLoop(t); remember(t); }

function setLooping(t, on) { store.set({ looping: on }); showLoop(t); }

/** Loop the current finding (else the one at the frame) with a margin, and play. */
function loopFinding(t) {
  const f = t.list.current || findingAt(t.list.shown, store.state.frame);
  if (!f) { t.ui.loopLabel.textContent = "open a finding (click, Enter or N/P) to loop it"; return; }
  t.list.mark(f);
  store.set({ joint: f.joint, loop: loopOfFinding(f, Math.round(LOOP_MARGIN_S * t.fps), t.nFrames), looping: true });
  showLoop(t);
  jump(t, store.state.loop[0]);
  if (!t.player.playing) togglePlay(t);
}

/** The player's, camera's, loop's and view options' controls. A link may carry the in/out
 * range (&loop=A-B): shown, not yet looping; and the view options (viewOptionsOf). */
export function wireControls(t) {
  const { ui, player, views } = t;
  ui.playButton.addEventListener("click", () => togglePlay(t));
  ui.scrubber.addEventListener("input", () => { store.state.frame = Number(ui.scrubber.value); render(t); });
  ui.scrubber.addEventListener("change", () => { remember(t); loadDetail(t); });
  ui.speed.addEventListener("change", () => player.setSpeed(Number(ui.speed.value)));
  ui.presets.forEach((button) => button.addEventListener("click", () => views.setCamera(button.textContent)));
  ui.closeButton.addEventListener("click", () => setFocus(t, store.state.focus === "joint" ? "body" : "joint"));
  ui.followButton.addEventListener("click", () => setFocus(t, store.state.focus === "root" ? "body" : "root"));
  ui.loopButton.addEventListener("click", () => setLooping(t, !store.state.looping));
  ui.loopFindingButton.addEventListener("click", () => loopFinding(t));
  ui.clearLoopButton.addEventListener("click", () => { store.set({ loop: null, looping: false }); showLoop(t); remember(t); });
  const linked = parseRange(t.params.get("loop"), t.nFrames);
  if (linked) setRange(t, linked);
  wireViewOptions(t);
  trackPlayerHeight(t);
}

/** The joint axes' and overlay's checkboxes and the floor's, as the link left them. */
function wireViewOptions(t) {
  const { ui } = t;
  store.set(store.viewOptionsOf(t.params));
  if (store.state.triads && t.oriented) showTriads(t, true);
  if (store.state.overlay) showOverlay(t, true);
  ui.triadsBox.addEventListener("change", () => { showTriads(t, ui.triadsBox.checked); remember(t); });
  ui.overlayBox.addEventListener("change", () => { showOverlay(t, ui.overlayBox.checked); remember(t); });
  wireFloorToggle(t);
}

function showTriads(t, on) {
  store.set({ triads: on });
  t.ui.triadsBox.checked = on;
  t.views.setTriads(on);
}

function showOverlay(t, on) {
  const { ui, views } = t;
  store.set({ overlay: on });
  ui.overlayBox.checked = on;
  ui.rawPanel.hidden = on;
  views.setOverlay(on);
  render(t);
}

/** The floor plane's checkbox, shown when the views draw the feet step's floor; its label says
 * when the floor is tilted (the views then draw the plane fitted to the feet). */
function wireFloorToggle(t) {
  const { ui, views } = t;
  const floor = views.floorDrawn();
  ui.floorToggle.hidden = !floor;
  ui.floorBox.disabled = !floor;
  if (!floor) return;
  const feet = t.result.series.feet;
  const tilted = Boolean(feet.floor_check && feet.floor_check.tilted);
  if (!store.state.floor) views.setFloorShown(false);
  ui.floorBox.checked = floor.shown.some(Boolean) && store.state.floor;
  ui.floorText.textContent = floorLabel(feet);
  ui.floorToggle.classList.toggle("tilted", tilted);
  ui.floorToggle.title = tilted
    ? "show or hide the feet step's floor; the floor is tilted: the plane drawn is the one fitted to the feet at rest"
    : "show or hide the feet step's floor";
  ui.floorBox.addEventListener("change", () => {
    store.set({ floor: ui.floorBox.checked });
    views.setFloorShown(ui.floorBox.checked);
    remember(t);
  });
}

/** The player bar is pinned to the window's top while the page scrolls: what scrolls into sight
 * under it (a row N/P reached, a control Tab focused) stops below it (app.css reads the bar's
 * height, --player-height, for the scroll margin). */
function trackPlayerHeight(t) {
  const { player } = t.ui;
  const measure = () => t.main.style.setProperty("--player-height", `${player.offsetHeight}px`);
  measure();
  if (typeof ResizeObserver === "function") new ResizeObserver(measure).observe(player);
}

/** N/P walk the findings the list's filters keep, across its groups. */
function walkFindings(t, dir) {
  const reached = nextFinding(t.list.shown, t.list.current, store.state.frame, dir);
  if (!reached) return;
  if (t.player.playing) togglePlay(t);
  t.list.mark(reached);
  // The row reached in sight (the list may be far below the views).
  document.querySelector("#findings tr.finding.current")?.scrollIntoView({ block: "nearest" });
  // The finding reached is the one opened: its joint selected, Y/X act on it if twist.
  t.decided.opened(reached); store.set({ joint: reached.joint }); focusCharts(t);
  // Y/X then act on the finding reached, not on a row focused before.
  if (document.activeElement && document.activeElement.closest && document.activeElement.closest("tr.finding")) document.activeElement.blur();
  jump(t, reached.start_frame);
}

// Keys a range slider (the scrubber) keeps as its own: every other key is the view's command.
const SLIDER_KEYS = new Set(["ArrowLeft", "ArrowRight", "ArrowUp", "ArrowDown", "Home", "End", "PageUp", "PageDown"]);
// Inputs typed in by no key: their keys are the view's commands (Space still ticks a checkbox).
const KEYLESS_INPUTS = new Set(["checkbox", "radio", "range"]);

/**
 * Whether `key` pressed on `element` is the element's own (typed in a field, chosen in a list,
 * moving a slider), not a command of the view. A checkbox or a radio button is no field; a range
 * slider keeps its arrows, Home, End and the page keys, and leaves the rest (Space, N, P, I, O,
 * A, …) to the view.
 *
 * @param element {tagName, type, isContentEditable}: the key's target (an element)
 * @param key     the KeyboardEvent's key
 */
export function elementKeepsKey(element, key) {
  if (!element || !element.tagName) return false;
  if (element.isContentEditable) return true;
  const tag = element.tagName.toUpperCase();
  if (tag === "TEXTAREA" || tag === "SELECT") return true;
  if (tag !== "INPUT") return false;
  const type = String(element.type || "text").toLowerCase();
  if (type === "range") return SLIDER_KEYS.has(key);
  return !KEYLESS_INPUTS.has(type);
}

/** The keyboard's commands (keyCommand); keys typed in a field are text (elementKeepsKey). */
export function onKey(t, e) {
  const target = e.target;
  if (elementKeepsKey(target, e.key) || e.ctrlKey || e.metaKey || e.altKey) return;
  const command = keyCommand(e.key, e.shiftKey);
  const { state } = store;
  switch (command && command.name) {
    // Space plays or pauses on its key-down (a focused play button would wait for the key-up).
    // The time bar and the scrubber (sliders) play too: where a reviewer's focus rests between
    // findings, or after a drag.
    case "play":
      if (playsOnSpace(t, target)) { e.preventDefault(); if (!e.repeat) togglePlay(t); }
      break;
    case "step": e.preventDefault(); if (t.player.playing) togglePlay(t); jump(t, state.frame + command.by); break;
    case "walk": walkFindings(t, command.dir); break;
    case "in": setRange(t, withIn(state.loop, state.frame, t.nFrames)); break;
    case "out": setRange(t, withOut(state.loop, state.frame)); break;
    case "loop-finding": loopFinding(t); break;
    case "loop": setLooping(t, !state.looping); break;
    case "close": setFocus(t, state.focus === "joint" ? "body" : "joint"); break;
    case "item": if (t.decided.onKey(e)) e.preventDefault(); break;
    case "review": t.review.decide(command.decision); break;
    case "help": t.ui.help.hidden = !t.ui.help.hidden; break;
    default: break;
  }
}

/** Space plays or pauses on the page, the play button and the two sliders (the time bar, the
 * scrubber); on another control (a button, a link, a checkbox) it is that control's. */
function playsOnSpace(t, target) {
  if (target === t.ui.playButton || target === t.ui.scrubber || target.id === "timebar") return true;
  return !(target.matches && target.matches("button, a, input, [tabindex]"));
}
