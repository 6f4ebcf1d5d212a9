// The take view: two 3D views with one camera, the player, findings, charts, review, re-run.
import * as api from "./api.js";
import * as charts from "./charts.js";
import { badge, h } from "./dom.js";
import { fmt, nextFinding, runOptionsLabel, seconds } from "./format.js";
import { filterFromParams, filterParams, findingAt, jointsOf, kindsOf, loopOfFinding } from "./findings.js";
import { findingsList } from "./findings-list.js";
import { createTimebar, parseRange, withIn, withOut } from "./timebar.js";
import { createPlayer } from "./player.js";
import { loadPlotly } from "./plotly.js";
import * as store from "./state.js";
import { createTimeline } from "./timeline.js";
import { reviewPanel } from "./review.js";
import { rerunPanel } from "./rerun.js";
import { intervalDecisions } from "./decisions.js";
import { MARKER_COLORS, createGapTimeline, gapRows } from "./gaptimeline.js";
import { contactRows, createContactTimeline } from "./contacttimeline.js";

const OVERVIEW_FRAMES = 800; // frames of a take drawn before any window is loaded
const LIMITS_COLOR = "#e67e22";
const DECISIONS = { a: "approved", f: "needs_fix", r: "rejected" }; // review keys
const LOOP_MARGIN_S = 0.5; // "loop this finding": seconds shown before and after it

export async function takeView(main, takeId, params, onTeardown) {
  const runParam = params.get("run");
  const scene = import("./scene3d.js");
  const take = await api.getTake(takeId);
  performance.mark("take-fetched");
  const runs = take.runs;
  const run = runs.find((r) => r.id === runParam) || runs[runs.length - 1];
  const header = h("div", {}, h("h1", {}, take.name, " ", badge(run ? run.status : "none")),
    h("p", { class: "muted" }, `${take.format.toUpperCase()} · ${take.n_frames} frames at ${fmt(take.fps, 2)} fps · ${take.n_joints} ${take.kind === "motion" ? "joints" : "keypoints"} · sha256 ${take.sha256.slice(0, 12)}…`));
  main.replaceChildren(header);
  if (!run) return;
  if (run.status !== "done") {
    const bar = h("progress", { max: 100, value: run.progress }), text = h("span", {}, run.step);
    main.append(h("p", {}, bar, " ", text));
    const final = await api.waitForRun(run.id, (r) => { bar.value = r.progress; text.textContent = `${r.step} (${r.progress} %)`; });
    if (final.status === "failed") { main.append(h("p", { class: "error" }, final.error)); return; }
    window.dispatchEvent(new HashChangeEvent("hashchange")); return;
  }
  const [result, first] = await Promise.all([
    api.getResult(run.id).then((r) => { performance.mark("result-fetched"); return r; }),
    api.getFirstFrames(run.id).then((f) => { performance.mark("frames-fetched"); return f; })]);
  // The re-run form's lists wait for nothing on screen.
  const formLists = Promise.all([api.listFilters(), api.getRunOptions()]);
  let overview = first;
  const fuller = first.step > 1 ? api.getFramesPacked(run.id, { maxFrames: OVERVIEW_FRAMES }) : Promise.resolve(first);
  const fps = result.summary.fps;
  const nFrames = result.summary.n_frames;
  const names = result.points.names;
  const parents = result.points.parents;
  const jointIndex = new Map(names.map((n, i) => [n, i]));
  const oriented = Array.isArray(overview.raw_rotations);
  store.reset();
  store.set({ frame: Math.max(0, Math.min(nFrames - 1, Number(params.get("frame")) || 0)), joint: params.get("joint") });
  const chainColor = result.series.twist ? charts.chainColors(result.series.twist) : new Map();
  // Drawn and coloured in this order, so a twist interval shows over a spin over a long limits
  // run (on the time bar and on a joint flagged by several).
  const KIND_ORDER = { limits: 0, spin: 1, twist: 2 };
  const byKind = (a, b) => (KIND_ORDER[a.kind] ?? 0) - (KIND_ORDER[b.kind] ?? 0);
  const findingColor = (f) => (f.kind === "twist" ? chainColor.get(f.joint) || "#c0392b" : f.kind === "spin" ? charts.SPIN_COLOR : MARKER_COLORS[f.kind] || LIMITS_COLOR);
  // A marker take the markers step checked: its corrected view has the swaps repaired and the
  // confident gaps filled (then filtered), filled samples marked.
  const markersRan = Boolean(result.steps.markers && result.steps.markers.state === "done");
  let detail = null;

  // Layout
  const frameLabel = h("span", { id: "frame-label" });
  const jointLabel = h("span", { id: "joint-label", class: "muted" });
  const scrubber = h("input", { type: "range", id: "scrubber", min: 0, max: nFrames - 1, value: 0, step: 1, "aria-label": "frame" });
  const playButton = h("button", { id: "play", class: "primary", "aria-keyshortcuts": "Space" }, "▶ play");
  const speed = h("select", { id: "speed", "aria-label": "speed" }, [0.25, 0.5, 1, 2].map((s) => h("option", { value: s, selected: s === 1 }, `${s}×`)));
  const rawDiv = h("div", { id: "view-raw", class: "view3d" });
  const corrDiv = h("div", { id: "view-corrected", class: "view3d" });
  const rawTitle = h("h3", { class: "view-title" }, "raw");
  // Keypoints are filtered, not corrected: the right-hand view says which it shows.
  const outcome = result.kind === "keypoints" && !markersRan ? "filtered" : "corrected";
  const corrTitle = h("h3", { class: "view-title" }, outcome);
  const rawPanel = h("div", { class: "col panel", id: "panel-raw" }, rawTitle, rawDiv);
  const presets = ["front", "side", "top"].map((name) => h("button", { id: `camera-${name}`, class: "small" }, name));
  const closeButton = h("button", { id: "camera-close", class: "small", "aria-pressed": "false", title: "frame the selected joint (or the current finding's joint) close (C)" }, "close-in");
  const followButton = h("button", { id: "camera-follow", class: "small", "aria-pressed": "false", title: "keep the root in the centre while playing" }, "follow");
  const loopButton = h("button", { id: "loop", "aria-pressed": "false", "aria-keyshortcuts": "L", title: "loop playback over the in/out range (L)" }, "⟲ loop");
  const loopFindingButton = h("button", { id: "loop-finding", class: "small", "aria-keyshortcuts": "Shift+L", title: "loop the current finding with a margin (shift+L)" }, "loop finding");
  const clearLoopButton = h("button", { id: "loop-clear", class: "small", title: "clear the in/out range" }, "clear in/out");
  const loopLabel = h("span", { id: "loop-label", class: "muted" }, "in/out: none (I / O or drag on the bar)");
  const triadsBox = h("input", { type: "checkbox", id: "show-axes", disabled: !oriented });
  const overlayBox = h("input", { type: "checkbox", id: "overlay" });
  const viewsRow = h("div", { class: "row view-row", id: "views" }, rawPanel, h("div", { class: "col panel" }, corrTitle, corrDiv));
  main.append(
    runPicker(take, run, () => store.state.frame),
    h("div", { class: "controls view-options" }, "camera ", presets, closeButton, followButton,
      h("label", {}, triadsBox, " joint axes"), h("label", {}, overlayBox, " overlay (raw as ghost)"),
      h("span", { class: "muted", id: "view-legend" }, oriented ? "bones are drawn in their parent joint's frame; the orange side marks the roll"
        : markersRan ? "markers; sticks join the segments inferred from the take; hollow green: filled by a gap fill (outlined on the gap timeline); purple: bridged by the filter"
          : "keypoints fade with their detection confidence; purple: bridged by the filter (hatched on the time bar)")),
    viewsRow,
    h("div", { class: "panel player", id: "player" },
      h("div", { class: "controls" }, playButton, "speed ", speed, frameLabel, jointLabel, scrubber),
      h("div", { class: "controls" }, loopButton, loopFindingButton, clearLoopButton, loopLabel)),
  );
  const help = h("p", { class: "muted", id: "keys-help" },
    "Keys: space play/pause · ←/→ one frame (shift: 10) · N/P next/previous finding · I/O in/out point · L loop in/out · shift+L loop the finding · C close-in · A/F/R approve, needs fix, reject the take (saves) · Y/X accept, reject the focused or last opened twist interval or swap (saves) · Enter on a row opens it · ? shows or hides this line");
  const timelines = h("div", {});
  const review = reviewPanel(take);
  const decided = intervalDecisions(run, result, take);
  // The findings filter travels in the link too (kinds, only, atleast, q).
  const linkedFilter = filterFromParams(params, kindsOf(result.findings), jointsOf(result.findings));
  let filterQuery = filterParams(linkedFilter, kindsOf(result.findings));
  const list = findingsList(result.findings, decided, (f) => { decided.opened(f); store.set({ joint: f.joint }); focusCharts(); jump(f.start_frame); viewsRow.scrollIntoView({ block: "start" }); },
    linkedFilter, (query) => { filterQuery = query; remember(); timebar.setMarks(marksOf(list.shown)); });
  // The time bar marks the findings the list's filters keep.
  const marksOf = (findings) => [...findings].sort(byKind).map((f) => ({ start: f.start_frame, end: f.end_frame, color: findingColor(f), label: `${f.kind} · ${f.joint} · ${f.start_frame}–${f.end_frame}` }));
  const timebar = createTimebar({
    nFrames, marks: marksOf(list.shown),
    onJump: (f) => { if (player.playing) togglePlay(); jump(f); }, onRange: (r) => setRange(r),
  });
  document.getElementById("player").append(timebar.el);
  const bridgedRuns = result.series.filter && result.series.filter.bridged_runs;
  if (bridgedRuns) timebar.setGaps(bridgedRuns);
  const gapRowsShown = markersRan ? gapRows(result.findings, nFrames, names) : [];
  const gapTimeline = gapRowsShown.length ? createGapTimeline(gapRowsShown, nFrames, (f) => { if (player.playing) togglePlay(); jump(f); }) : null;
  if (gapTimeline) document.getElementById("player").append(gapTimeline.el);
  // The feet step's contacts (two rows: left and right foot), its findings marked on them.
  const feetSeries = result.series.feet;
  const contactTimeline = feetSeries ? createContactTimeline(contactRows(feetSeries.contacts, result.findings, nFrames), nFrames, (f) => { if (player.playing) togglePlay(); jump(f); }) : null;
  if (contactTimeline) document.getElementById("player").append(contactTimeline.el);
  const rerunSlot = h("div", {});
  // A take no check could read is said above its (empty) findings, not only under Steps.
  const unchecked = Object.entries(result.steps).filter(([, st]) => st.state === "no_roles" || st.state === "no_model");
  const uncheckedNote = unchecked.length
    ? h("p", { class: "notice", id: "not-checked" }, h("b", {}, "Not checked: "),
      unchecked.map(([name, st]) => `${name}: ${st.message}`).join(" · "),
      unchecked.some(([, st]) => st.state === "no_roles") ? " — name the rig's joints in \u201cRig roles (mapping)\u201d below and re-run." : "")
    : null;
  main.append(help, uncheckedNote ?? "", list.panel, timelines, review, stepsPanel(result), downloadsPanel(run, result), rerunSlot);
  // The mapping editor selects the joint it names in the 3D views, as a click on the joint does.
  const onJoint = (name) => { if (!jointIndex.has(name)) return; store.set({ joint: name }); focusCharts(); render(); remember(); };
  formLists.then(([filters, described]) => rerunSlot.replaceWith(rerunPanel(take, run, filters, described, { summary: result.summary, onJoint })));

  // Frames: the overview (whole take, decimated) or, when paused, a full-rate window around.
  const pick = (source, f) => {
    const k = Math.max(0, Math.min(source.frames.length - 1, Math.round((f - source.frames[0]) / source.step)));
    return k;
  };
  const intervals = result.findings.filter((f) => jointIndex.has(f.joint)).sort(byKind);
  const flaggedAt = (f) => {
    const flagged = new Map();
    for (const i of intervals) if (f >= i.start_frame && f <= i.end_frame) flagged.set(jointIndex.get(i.joint), findingColor(i));
    return flagged;
  };
  const frameAt = (f) => {
    const source = detail && f >= detail.frames[0] && f <= detail.frames[detail.frames.length - 1] ? detail : overview;
    const k = pick(source, f);
    return {
      shown: source.frames[k], raw: source.raw[k], corrected: source.corrected[k],
      rawRotations: oriented ? source.raw_rotations[k] : null, correctedRotations: oriented ? source.corrected_rotations[k] : null,
      flagged: flaggedAt(f), selected: jointIndex.get(store.state.joint),
      confidence: source.confidence ? source.confidence[k] : null, bridged: source.bridged ? source.bridged[k] : null,
      filled: source.filled ? source.filled[k] : null,
    };
  };

  const { createViews } = await scene;
  performance.mark("views-start");
  const views = createViews({ raw: rawDiv, corrected: corrDiv }, { names, parents, bones: result.points.bones, nJoints: result.points.n_joints, oriented }, overview,
    (j) => { store.set({ joint: names[j] }); focusCharts(); render(); remember(); });
  let Plotly = null;
  let timeline = null; // the charts come after the skeletons are on screen
  // The selected joint's twist chain is the one the twist chart shows (when it has one).
  const focusCharts = () => {
    const chart = document.getElementById("chart-twist");
    const chains = result.series.twist ? result.series.twist.chains : [];
    if (!chart || !chains.some((c) => c.joint === store.state.joint)) return;
    // Every trace of a chain (its lines, its interval bands, its spins) follows its legend group.
    const visible = chart.data.map((trace) => (trace.legendgroup === store.state.joint ? true : "legendonly"));
    Plotly.restyle(chart, { visible });
  };
  const render = () => {
    const f = store.state.frame;
    const frame = frameAt(f);
    views.show(frame);
    frameLabel.textContent = `frame ${f} / ${nFrames - 1} · ${seconds(f, fps)} · ${frame.flagged.size} flagged joint(s)`;
    jointLabel.textContent = store.state.joint ? `selected: ${store.state.joint}` : "click a joint to select it";
    rawTitle.textContent = `raw — frame ${frame.shown}`;
    corrTitle.textContent = store.state.overlay ? `${outcome} (solid) and raw (ghost) — frame ${frame.shown}` : `${outcome} — frame ${frame.shown}`;
    scrubber.value = f;
    timebar.setFrame(f);
    if (gapTimeline) gapTimeline.setFrame(f);
    if (contactTimeline) contactTimeline.setFrame(f);
    if (timeline) timeline.setFrame(f);
  };
  const remember = () => {
    const query = new URLSearchParams({ run: run.id, frame: store.state.frame });
    if (store.state.joint) query.set("joint", store.state.joint);
    if (store.state.loop) query.set("loop", store.state.loop.join("-"));
    for (const [name, value] of Object.entries(filterQuery)) query.set(name, value);
    history.replaceState(null, "", `#/take/${take.id}?${query}`);
  };
  const loadDetail = async () => {
    if (overview.step === 1) return;
    const f = store.state.frame;
    const part = await api.getFramesPacked(run.id, { start: Math.max(0, f - 200), stop: Math.min(nFrames, f + 200), maxFrames: 401 });
    detail = part;
    if (!player.playing) render();
  };
  const jump = (f) => {
    store.set({ frame: Math.max(0, Math.min(nFrames - 1, Math.round(f))) });
    render(); remember(); loadDetail();
  };
  // Playback draws in the animation frame that picked the frame (not one later): nothing is left
  // pending for the frame after a pause, which then shows "paused" at once.
  const player = createPlayer({ fps, nFrames, getFrame: () => store.state.frame, onFrame: (f) => { store.state.frame = f; render(); views.renderNow(); } });
  const togglePlay = () => {
    if (player.playing) { player.pause(); remember(); loadDetail(); } else { detail = null; player.play(); }
    playButton.textContent = player.playing ? "❚❚ pause" : "▶ play";
    playButton.setAttribute("aria-pressed", String(player.playing));
  };
  window.mocapqaPlayer = player; // read by the browser tests' timing figures
  window.mocapqaViews = views;
  playButton.addEventListener("click", togglePlay);
  scrubber.addEventListener("input", () => { store.state.frame = Number(scrubber.value); render(); });
  scrubber.addEventListener("change", () => { remember(); loadDetail(); });
  speed.addEventListener("change", () => player.setSpeed(Number(speed.value)));
  presets.forEach((button) => button.addEventListener("click", () => views.setCamera(button.textContent)));
  // Camera focus: "body" (the body's centre over the floor), "joint" (close-in on the selected
  // joint) or "root" (follow: the root in the centre).
  const setFocus = (mode) => {
    if (mode === "joint" && !store.state.joint) {
      const f = list.current || findingAt(list.shown, store.state.frame) || list.shown[0];
      if (f) store.set({ joint: f.joint });
    }
    store.set({ focus: mode });
    closeButton.setAttribute("aria-pressed", String(mode === "joint"));
    followButton.setAttribute("aria-pressed", String(mode === "root"));
    views.setFocus(mode);
    render();
  };
  closeButton.addEventListener("click", () => setFocus(store.state.focus === "joint" ? "body" : "joint"));
  followButton.addEventListener("click", () => setFocus(store.state.focus === "root" ? "body" : "root"));
  // Loop: an in/out range (I / O keys, or a drag on the time bar) and a toggle (L).
  const showLoop = () => {
    const r = store.state.loop;
    loopLabel.textContent = r ? `in ${r[0]} · out ${r[1]} (${r[1] - r[0] + 1} frames)${store.state.looping ? " · looping" : ""}` : "in/out: none (I / O or drag on the bar)";
    loopButton.setAttribute("aria-pressed", String(store.state.looping));
    timebar.setRange(r, store.state.looping);
    player.setLoop(store.state.looping ? r : null);
  };
  const setRange = (r) => { store.set({ loop: r }); showLoop(); remember(); };
  const setLooping = (on) => { store.set({ looping: on }); showLoop(); };
  const loopFinding = () => {
    const f = list.current || findingAt(list.shown, store.state.frame);
    if (!f) { loopLabel.textContent = "open a finding (click, Enter or N/P) to loop it"; return; }
    list.mark(f);
    store.set({ joint: f.joint, loop: loopOfFinding(f, Math.round(LOOP_MARGIN_S * fps), nFrames), looping: true });
    showLoop();
    jump(store.state.loop[0]);
    if (!player.playing) togglePlay();
  };
  loopButton.addEventListener("click", () => setLooping(!store.state.looping));
  loopFindingButton.addEventListener("click", loopFinding);
  clearLoopButton.addEventListener("click", () => { store.set({ loop: null, looping: false }); showLoop(); remember(); });
  // A link may carry the in/out range (&loop=A-B): shown, not yet looping.
  const linked = parseRange(params.get("loop"), nFrames);
  if (linked) setRange(linked);
  triadsBox.addEventListener("change", () => views.setTriads(triadsBox.checked));
  overlayBox.addEventListener("change", () => {
    store.set({ overlay: overlayBox.checked });
    rawPanel.hidden = overlayBox.checked;
    views.setOverlay(overlayBox.checked);
    render();
  });

  const onKey = (e) => {
    const target = e.target;
    const typing = target instanceof HTMLElement && (target.matches("input, textarea, select, [contenteditable]") || target.isContentEditable);
    if (typing || e.ctrlKey || e.metaKey || e.altKey) return;
    // Space plays or pauses on its key-down (a focused play button would wait for the key-up).
    // The time bar (a slider) plays too: it is where a reviewer's focus rests between findings.
    if (e.key === " " && (target === playButton || target.id === "timebar" || !target.matches("button, a, [tabindex]"))) { e.preventDefault(); if (!e.repeat) togglePlay(); }
    else if (e.key === "ArrowRight" || e.key === "ArrowLeft") {
      e.preventDefault();
      if (player.playing) togglePlay();
      jump(store.state.frame + (e.key === "ArrowRight" ? 1 : -1) * (e.shiftKey ? 10 : 1));
    } else if (e.key === "n" || e.key === "N" || e.key === "p" || e.key === "P") {
      // N/P walk the findings the list's filters keep, across its groups.
      const reached = nextFinding(list.shown, list.current, store.state.frame, e.key.toLowerCase() === "n" ? 1 : -1);
      if (reached) {
        if (player.playing) togglePlay();
        list.mark(reached);
        // The row reached in sight (the list may be far below the views).
        document.querySelector("#findings tr.finding.current")?.scrollIntoView({ block: "nearest" });
        // The finding reached is the one opened: its joint selected, Y/X act on it if twist.
        decided.opened(reached); store.set({ joint: reached.joint }); focusCharts();
        // Y/X then act on the finding reached, not on a row focused before.
        if (document.activeElement && document.activeElement.closest && document.activeElement.closest("tr.finding")) document.activeElement.blur();
        jump(reached.start_frame);
      }
    } else if (e.key === "i" || e.key === "I") {
      setRange(withIn(store.state.loop, store.state.frame, nFrames));
    } else if (e.key === "o" || e.key === "O") {
      setRange(withOut(store.state.loop, store.state.frame));
    } else if (e.key === "L" && e.shiftKey) {
      loopFinding();
    } else if (e.key === "l") {
      setLooping(!store.state.looping);
    } else if (e.key === "c" || e.key === "C") {
      setFocus(store.state.focus === "joint" ? "body" : "joint");
    } else if (decided.onKey(e)) {
      e.preventDefault();
    } else if (DECISIONS[e.key.toLowerCase()]) {
      review.decide(DECISIONS[e.key.toLowerCase()]);
    } else if (e.key === "?") {
      help.hidden = !help.hidden;
    }
  };
  document.addEventListener("keydown", onKey);
  onTeardown(() => { player.pause(); views.dispose(); document.removeEventListener("keydown", onKey); });

  render();
  views.renderNow();
  fuller.then((more) => { overview = more; if (!player.playing) render(); });
  // The charting library (a long script to evaluate) only once the skeletons are on screen.
  await new Promise((r) => requestAnimationFrame(() => setTimeout(r, 0)));
  Plotly = await loadPlotly();
  timeline = createTimeline(Plotly, timelines, (f) => jump(f));
  window.mocapqaCharts = timeline; // the browser tests compare the drawn charts with their full data
  // Each chart in a task of its own: a key press or a drag waits for one chart, not all.
  const breathe = () => new Promise((r) => setTimeout(r, 0));
  await breathe();

  const series = result.series;
  if (series.twist) {
    const spins = result.findings.filter((f) => f.kind === "spin");
    await timeline.add("chart-twist", `Twist θP and removed offset (${series.twist.intervals.length} flagged interval(s)${spins.length ? `, ${spins.length} limb spin(s)` : ""})`,
      charts.twistFigure(series.twist, spins), (p) => {
        if (p.customdata) return p.customdata[0];
        const inside = series.twist.intervals.find((i) => i.start_frame <= p.x && p.x <= i.end_frame + 1);
        return inside ? inside.start_frame : p.x;
      });
  }
  await breathe();
  if (series.limits) {
    // A heat-map cell selects its joint as well as its frame.
    await timeline.add("chart-limits", "Joint-limit violations (joint × frame, degrees outside the limits)", charts.limitsFigure(series.limits),
      (p) => { if (jointIndex.has(p.y)) { store.set({ joint: p.y }); focusCharts(); } return p.x; });
  } else if (result.steps.limits && result.steps.limits.state !== "skipped") {
    timelines.append(h("p", { class: "muted", id: "limits-note" }, `Joint limits: ${result.steps.limits.message}`));
  }
  if (result.kind === "keypoints") {
    const choice = h("select", { id: "keypoint-pick", "aria-label": "keypoint" }, names.map((n, i) => h("option", { value: i }, n)));
    timelines.append(h("div", { class: "controls" }, "keypoint ", choice));
    const k = () => Number(choice.value);
    overview = await fuller;
    const trajectory = () => charts.trajectoryFigure(overview.frames, overview.raw.map((p) => p[k()]), overview.corrected.map((p) => p[k()]), result.summary.length_unit);
    await breathe();
    await timeline.add("chart-trajectory", "Raw vs filtered trajectory (one panel per axis)", trajectory(), (p) => p.x);
    const weights = series.filter && Object.keys(series.filter.weights).length ? series.filter.weights : null;
    await breathe();
    if (weights) await timeline.add("chart-weights", "Filter weights (stacked: Kalman / One Euro / EMA)", charts.weightsFigure(series.frames, weights, k()), (p) => p.x);
    choice.addEventListener("change", () => {
      timeline.replace("chart-trajectory", trajectory());
      if (weights) timeline.replace("chart-weights", charts.weightsFigure(series.frames, weights, k()));
    });
  }
  timeline.setFrame(store.state.frame);
  focusCharts();
  if (store.state.frame) loadDetail();
  await formLists;
  await fuller; // "ready" once the full overview replaced the light one (tests compare pixels)
  main.dataset.ready = "1";
}

/** The first, light overview: the skeletons do not wait for the full one. */

/** The run list; another run opens at the frame shown now (`frameNow()`), as a reviewer
 * comparing runs expects, rather than at frame 0. */
function runPicker(take, run, frameNow) {
  const select = h("select", { id: "run-pick", "aria-label": "run", onchange: (e) => { location.hash = `${api.takeLink(take.id, e.target.value)}&frame=${frameNow()}`; } },
    take.runs.map((r, i) => h("option", { value: r.id, selected: r.id === run.id },
      `run ${i + 1} · ${r.status} · ${runOptionsLabel(r)}`)));
  return h("div", { class: "controls" }, "Run ", select,
    run.server_time_s != null ? h("span", { class: "muted" }, `server time ${fmt(run.server_time_s, 2)} s`) : null,
    h("a", { href: `#/compare?a=${run.id}` }, "compare…"));
}

function downloadsPanel(run, result) {
  const labels = {
    bvh: "corrected BVH (the run's choice, before review)", csv: "filtered keypoints (CSV)", trc: "filtered keypoints (TRC)",
    c3d: "corrected C3D (swaps repaired, gaps filled; residual 0 on filled samples)", report: "JSON report", "report.html": "HTML report",
  };
  const kinds = [...(result.downloads || ["report"]), "report.html"];
  return h("div", { class: "panel" }, h("h2", {}, "Downloads"),
    kinds.map((k) => h("a", { href: api.downloadUrl(run.id, k), download: "", id: `download-${k.replace(".", "-")}`, class: "download" }, labels[k] || k)));
}

function stepsPanel(result) {
  return h("div", { class: "panel" }, h("h2", {}, "Steps"),
    h("ul", { class: "steps" }, Object.entries(result.steps).map(([name, s]) => h("li", {}, h("b", {}, name), " ", badge(s.state, s.state === "done" ? "done" : ""), " ", s.message))));
}

