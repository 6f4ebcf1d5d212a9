// The take view: two 3D views with one camera, the player, findings, charts, review, re-run.
// Its state `t` is built here in steps; take-controls.js holds its behaviour, take-layout.js its
// page parts, take-charts.js its charts and take-format.js its pure functions.
import * as api from "./api.js";
import * as charts from "./charts.js";
import { h } from "./dom.js";
import { filterFromParams, filterParams, jointsOf, kindsOf } from "./findings.js";
import { findingsList } from "./findings-list.js";
import { createTimebar } from "./timebar.js";
import { createPlayer } from "./player.js";
import * as store from "./state.js";
import { reviewPanel } from "./review.js";
import { rerunPanel } from "./rerun.js";
import { intervalDecisions } from "./decisions.js";
import { createGapTimeline, gapRows } from "./gaptimeline.js";
import { contactRows, createContactTimeline } from "./contacttimeline.js";
import { drawCharts } from "./take-charts.js";
import { floorPlane } from "./scene-data.js";
import {
  focusCharts, jump, loadDetail, onKey, pauseAndJump, remember, render, selectJoint, setRange, wireControls,
} from "./take-controls.js";
import { byKind, findingColors, OVERVIEW_FRAMES, timeMarks } from "./take-format.js";
import { downloadsPanel, runPicker, stepsPanel, takeHeader, uncheckedNote, viewsLayout, waitForRun } from "./take-layout.js";

export async function takeView(main, takeId, params, onTeardown) {
  const runParam = params.get("run");
  const scene = import("./scene3d.js");
  const take = await api.getTake(takeId);
  performance.mark("take-fetched");
  const runs = take.runs;
  const run = runs.find((r) => r.id === runParam) || runs[runs.length - 1];
  main.replaceChildren(takeHeader(take, run));
  if (!run) return;
  // A run not finished shows its progress; the take's other runs stay one choice away (a
  // failed run says why, and the picker opens a finished one).
  if (run.status !== "done") {
    if (runs.length > 1) main.append(runPicker(take, run, () => 0, await api.getRunOptions()));
    await waitForRun(main, run);
    return;
  }
  const t = await openRun(main, take, run, params);
  layOut(t);
  const { createViews } = await scene;
  startViews(t, createViews);
  wireControls(t);
  const keys = (e) => onKey(t, e);
  document.addEventListener("keydown", keys);
  onTeardown(() => { t.player.pause(); t.views.dispose(); document.removeEventListener("keydown", keys); });

  render(t);
  t.views.renderNow();
  t.fuller.then((more) => { t.overview = more; if (!t.player.playing) render(t); });
  await drawCharts(t);
  if (store.state.frame) loadDetail(t);
  await t.formLists;
  await t.fuller; // "ready" once the full overview replaced the light one (tests compare pixels)
  main.dataset.ready = "1";
}

/** The run's result and first frames, and the view's state `t` made from them: the first, light
 * overview is drawn at once (the skeletons do not wait for the full one, `t.fuller`). */
async function openRun(main, take, run, params) {
  // The run options' description labels the run list; the filter list waits for nothing on screen.
  const [result, first, described] = await Promise.all([
    api.getResult(run.id).then((r) => { performance.mark("result-fetched"); return r; }),
    api.getFirstFrames(run.id).then((f) => { performance.mark("frames-fetched"); return f; }),
    api.getRunOptions()]);
  const formLists = Promise.all([api.listFilters(), described]);
  const fuller = first.step > 1 ? api.getFramesPacked(run.id, { maxFrames: OVERVIEW_FRAMES }) : Promise.resolve(first);
  const nFrames = result.summary.n_frames;
  const names = result.points.names;
  const jointIndex = new Map(names.map((n, i) => [n, i]));
  store.reset();
  store.set({ frame: Math.max(0, Math.min(nFrames - 1, Number(params.get("frame")) || 0)), joint: params.get("joint") });
  const colorOf = findingColors(result.series.twist ? charts.chainColors(result.series.twist) : new Map());
  // A marker take the markers step checked: its corrected view has the swaps repaired and the
  // confident gaps filled (then filtered), filled samples marked.
  const markersRan = Boolean(result.steps.markers && result.steps.markers.state === "done");
  return {
    main, take, run, result, params, described, formLists, fuller, overview: first, detail: null,
    fps: result.summary.fps, nFrames, names, jointIndex, oriented: Array.isArray(first.raw_rotations), markersRan,
    // Keypoints are filtered, not corrected: the right-hand view says which it shows.
    outcome: result.kind === "keypoints" && !markersRan ? "filtered" : "corrected",
    colorOf, intervals: result.findings.filter((f) => jointIndex.has(f.joint)).sort(byKind),
    filterQuery: {}, Plotly: null, timeline: null,
  };
}

/** The page: views and player, the findings list, the time bars, the charts' place, review,
 * steps, downloads and the re-run form (once its lists arrive). */
function layOut(t) {
  const { main, take, run, result } = t;
  t.ui = viewsLayout(main, runPicker(take, run, () => store.state.frame, t.described), t);
  t.timelines = h("div", {});
  t.review = reviewPanel(take);
  t.decided = intervalDecisions(run, result, take);
  t.list = findingsPart(t);
  timeBars(t);
  const rerunSlot = h("div", {});
  main.append(t.ui.help, uncheckedNote(result.steps) ?? "", t.list.panel, t.timelines, t.review, stepsPanel(result), downloadsPanel(run, result), rerunSlot);
  // The mapping editor selects the joint it names in the 3D views, as a click on the joint does.
  const onJoint = (name) => { if (t.jointIndex.has(name)) selectJoint(t, name); };
  t.formLists.then(([filters, described]) => rerunSlot.replaceWith(rerunPanel(take, run, filters, described, { summary: result.summary, onJoint })));
}

/** The findings list; its filter travels in the link too (kinds, only, atleast, q). */
function findingsPart(t) {
  const { findings } = t.result;
  const linkedFilter = filterFromParams(t.params, kindsOf(findings), jointsOf(findings));
  t.filterQuery = filterParams(linkedFilter, kindsOf(findings));
  const open = (f) => { t.decided.opened(f); store.set({ joint: f.joint }); focusCharts(t); jump(t, f.start_frame); t.ui.viewsRow.scrollIntoView({ block: "start" }); };
  const refiltered = (query) => { t.filterQuery = query; remember(t); t.timebar.setMarks(timeMarks(t.list.shown, t.colorOf)); };
  return findingsList(findings, t.decided, open, linkedFilter, refiltered, t.result.series.twist);
}

/** Under the player: the time bar (the findings the list's filters keep, the filter's bridged
 * gaps), a marker take's gap timeline and the feet step's contacts (two rows: left and right
 * foot), its findings marked on them. */
function timeBars(t) {
  const { result, nFrames, ui } = t;
  t.timebar = createTimebar({
    nFrames, marks: timeMarks(t.list.shown, t.colorOf),
    onJump: (f) => pauseAndJump(t, f), onRange: (r) => setRange(t, r),
  });
  ui.player.append(t.timebar.el);
  const bridgedRuns = result.series.filter && result.series.filter.bridged_runs;
  if (bridgedRuns) t.timebar.setGaps(bridgedRuns);
  const gapRowsShown = t.markersRan ? gapRows(result.findings, nFrames, t.names) : [];
  t.gapTimeline = gapRowsShown.length ? createGapTimeline(gapRowsShown, nFrames, (f) => pauseAndJump(t, f)) : null;
  if (t.gapTimeline) ui.player.append(t.gapTimeline.el);
  const feetSeries = result.series.feet;
  t.contactTimeline = feetSeries ? createContactTimeline(contactRows(feetSeries.contacts, result.findings, nFrames), nFrames, (f) => pauseAndJump(t, f)) : null;
  if (t.contactTimeline) ui.player.append(t.contactTimeline.el);
}

/** The two 3D views (a click on a joint selects it) and the player. */
function startViews(t, createViews) {
  const { ui, result, names } = t;
  performance.mark("views-start");
  t.views = createViews({ raw: ui.rawDiv, corrected: ui.corrDiv },
    { names, parents: result.points.parents, bones: result.points.bones, nJoints: result.points.n_joints, oriented: t.oriented }, t.overview,
    (j) => selectJoint(t, names[j]));
  // The feet step's floor, under both skeletons (none when the step did not run).
  t.views.setFloor(floorPlane(result.series.feet, [t.overview.raw, t.overview.corrected]));
  // Playback draws in the animation frame that picked the frame (not one later): nothing is left
  // pending for the frame after a pause, which then shows "paused" at once.
  t.player = createPlayer({ fps: t.fps, nFrames: t.nFrames, getFrame: () => store.state.frame, onFrame: (f) => { store.state.frame = f; render(t); t.views.renderNow(); } });
  window.mocapqaPlayer = t.player; // read by the browser tests' timing figures
  window.mocapqaViews = t.views;
}
