import { test } from "node:test";
import assert from "node:assert/strict";
import {
  decisionForKey, deleteConfirmed, exportQuery, formatCell, HEATMAP_COLORSCALE, HEATMAP_COLUMN_PX, HEATMAP_LABEL_CHARS, HEATMAP_MAX_TAKES, heatmapChanged,
  heatmapFigure, heatmapKeyGradient, heatmapPage, heatmapPager, heatmapQuery, heatmapRows, hoverLines, importLines, isFiltered, middleEllipsis, nextSort, pageInfo,
  progressSummary, scoreColor, scoreRangeProblem, shootControls, tableState, takesQuery, viewQuery, TABLE_DEFAULTS,
} from "../../frontend/js/shoot-format.js";

test("tableState parses numbers, clamps the page size and rejects unknown orders", () => {
  const s = tableState(new URLSearchParams("limit=9000&offset=-4&order=sideways&sort=rig&status=done&junk=1"));
  assert.equal(s.limit, 500);
  assert.equal(s.offset, 0);
  assert.equal(s.order, "asc");
  assert.equal(s.sort, "rig");
  assert.equal(s.status, "done");
  assert.equal("junk" in s, false);
  assert.equal(tableState(new URLSearchParams("")).limit, TABLE_DEFAULTS.limit);
});

test("takesQuery leaves out empty filters, keeps zero and trims search", () => {
  const q = new URLSearchParams(takesQuery({ ...TABLE_DEFAULTS, min_score: 0, search: "  walk ", has_findings: "true" }));
  assert.equal(q.get("min_score"), "0");
  assert.equal(q.get("search"), "walk");
  assert.equal(q.get("has_findings"), "true");
  assert.equal(q.get("sort"), "score");
  assert.equal(q.get("limit"), "25");
  assert.equal(q.has("status"), false);
  assert.equal(q.has("rig"), false);
});

test("viewQuery keeps only what differs from the defaults", () => {
  assert.equal(viewQuery({ ...TABLE_DEFAULTS }), "");
  assert.equal(viewQuery({ ...TABLE_DEFAULTS, order: "desc", offset: 25 }), "order=desc&offset=25");
  // A round trip through the URL gives the same state.
  const state = { ...TABLE_DEFAULTS, sort: "n_findings", status: "failed", max_score: "40" };
  const back = tableState(new URLSearchParams(viewQuery(state)));
  assert.equal(takesQuery(back), takesQuery(state));
});

test("nextSort flips the same column and starts a new one ascending, on the first page", () => {
  const s = { ...TABLE_DEFAULTS, offset: 50 };
  assert.deepEqual([nextSort(s, "score").order, nextSort(s, "score").offset], ["desc", 0]);
  assert.equal(nextSort({ ...s, order: "desc" }, "score").order, "asc");
  const other = nextSort({ ...s, order: "desc" }, "name");
  assert.deepEqual([other.sort, other.order], ["name", "asc"]);
});

test("pageInfo names the rows shown and the neighbouring pages", () => {
  assert.deepEqual(pageInfo(0, 25, 60), { text: "1–25 of 60", previous: null, next: 25 });
  assert.deepEqual(pageInfo(50, 25, 60), { text: "51–60 of 60", previous: 25, next: null });
  assert.deepEqual(pageInfo(10, 25, 60).previous, 0);
  assert.deepEqual(pageInfo(0, 25, 0), { text: "0–0 of 0", previous: null, next: null });
});

test("formatCell formats shares as percent, missing values as a dash", () => {
  const row = { violation_share: 0.1234, missing_share: null, duration_s: 2.5, score: 87.25, status: null, review_status: "needs_fix", n_findings: 0 };
  assert.equal(formatCell("violation_share", row), "12.3 %");
  assert.equal(formatCell("missing_share", row), "–");
  assert.equal(formatCell("duration_s", row), "2.5 s");
  assert.equal(formatCell("score", row), "87.3");
  assert.equal(formatCell("status", row), "none");
  assert.equal(formatCell("review_status", row), "needs fix");
  assert.equal(formatCell("n_findings", row), "0");
});

test("scoreColor runs from red through amber to green, grey without a score", () => {
  assert.equal(scoreColor(0), "hsl(0, 65%, 40%)");
  assert.equal(scoreColor(50), "hsl(60, 65%, 40%)");
  assert.equal(scoreColor(100), "hsl(120, 65%, 40%)");
  assert.equal(scoreColor(140), "hsl(120, 65%, 40%)");
  assert.equal(scoreColor(null), "#9aa3ad");
  assert.equal(scoreColor(undefined), "#9aa3ad");
});

test("progressSummary counts done and failed takes as finished", () => {
  const p = progressSummary({ n_takes: 4, status_counts: { done: 2, failed: 1, running: 1 }, frames_done: 900 });
  assert.equal(p.finished, 3);
  assert.equal(p.share, 0.75);
  assert.equal(p.text, "3 of 4 takes analysed (1 running, 2 done, 1 failed) · 900 frames");
  assert.equal(progressSummary({ n_takes: 0, status_counts: {}, frames_done: 0 }).share, 1);
});

test("importLines lists kept names, skip reasons and errors", () => {
  const lines = importLines({
    created: [{ name: "a.bvh", take_id: "1", run_id: "2" }],
    skipped: [{ name: "x.zip:notes.txt", reason: "not a motion file" }],
    failed: [{ name: "b.bvh", error: "line 3: bad" }],
  });
  assert.deepEqual(lines, { kept: ["a.bvh"], skipped: ["x.zip:notes.txt: not a motion file"], failed: ["b.bvh: line 3: bad"] });
});

test("importLines says when a kept take has the content of one already in the shoot", () => {
  const lines = importLines({ created: [{ name: "copy.bvh", take_id: "3", run_id: "4", duplicate_of: "walk.bvh" }] });
  assert.deepEqual(lines.kept, ["copy.bvh (same content as walk.bvh, already in the shoot)"]);
});

test("decisionForKey maps A/F/R in either case and nothing else", () => {
  assert.equal(decisionForKey("a"), "approved");
  assert.equal(decisionForKey("F"), "needs_fix");
  assert.equal(decisionForKey("r"), "rejected");
  assert.equal(decisionForKey("x"), null);
  assert.equal(decisionForKey(" "), null);
});

test("heatmapRows turns joints × takes shares into takes × joints percent", () => {
  const data = { joints: ["knee", "elbow"], takes: [{ name: "a" }, { name: "b" }, { name: "c" }], values: [[0.5, 0, null], [0.25, 0.1, null]] };
  assert.deepEqual(heatmapRows(data), [[50, 25], [0, 10], [null, null]]);
  assert.deepEqual(heatmapRows({ joints: [], takes: [{ name: "a" }], values: [] }), [[]]);
});

test("shootControls: viewers get neither, reviewers rename and delete only shoots they own", () => {
  const viewer = { user_id: 3, can: ["read", "own_tokens"] };
  const reviewer = { user_id: 2, can: ["read", "upload", "run", "review", "delete_own", "own_tokens"] };
  const admin = { user_id: 1, can: [...reviewer.can, "delete_any", "manage_users", "read_audit"] };
  const unowned = { id: "s", name: "Day 1" };
  assert.deepEqual(shootControls(viewer, unowned), { rename: false, delete: false });
  assert.deepEqual(shootControls(reviewer, unowned), { rename: false, delete: false });
  assert.deepEqual(shootControls(reviewer, { ...unowned, owner_id: 2 }), { rename: true, delete: true });
  assert.deepEqual(shootControls(reviewer, { ...unowned, owner_id: 7 }), { rename: false, delete: false });
  assert.deepEqual(shootControls(viewer, { ...unowned, owner_id: 3 }), { rename: false, delete: false });
  assert.deepEqual(shootControls(admin, unowned), { rename: true, delete: true });
  assert.deepEqual(shootControls(admin, { ...unowned, owner_id: 7 }), { rename: true, delete: true });
  assert.deepEqual(shootControls(null, unowned), { rename: false, delete: false });
  // A caller without a user id (no users on the server) never "owns" an unowned shoot.
  assert.deepEqual(shootControls({ user_id: null, can: ["delete_own"] }, { ...unowned, owner_id: null }).delete, false);
});

test("deleteConfirmed wants the exact name", () => {
  assert.equal(deleteConfirmed("Day 1", "Day 1"), true);
  assert.equal(deleteConfirmed("day 1", "Day 1"), false);
  assert.equal(deleteConfirmed("Day 1 ", "Day 1"), false);
  assert.equal(deleteConfirmed("", ""), false);
  assert.equal(deleteConfirmed(undefined, "Day 1"), false);
});

test("heatmapPage keeps the page size within the API's bounds and the offset on a page start", () => {
  assert.deepEqual(heatmapPage(0, 200), { offset: 0, limit: 200 });
  assert.deepEqual(heatmapPage(250, 200), { offset: 200, limit: 200 });
  assert.deepEqual(heatmapPage(-5, 200), { offset: 0, limit: 200 });
  assert.deepEqual(heatmapPage(0, 5000), { offset: 0, limit: HEATMAP_MAX_TAKES });
  assert.deepEqual(heatmapPage(0, 0), { offset: 0, limit: 200 });
  assert.deepEqual(heatmapPage(0, "junk"), { offset: 0, limit: 200 });
  assert.deepEqual(heatmapPage(400, "100"), { offset: 400, limit: 100 });
  // Past the end (the shoot shrank): the last page.
  assert.deepEqual(heatmapPage(1000, 200, 230), { offset: 200, limit: 200 });
  assert.deepEqual(heatmapPage(200, 200, 200), { offset: 0, limit: 200 });
  assert.deepEqual(heatmapPage(600, 200, 0), { offset: 0, limit: 200 });
});

test("heatmapQuery asks the API for one bounded page in the table's order", () => {
  const q = new URLSearchParams(heatmapQuery({ offset: 450, limit: 200 }));
  assert.equal(q.get("limit"), "200");
  assert.equal(q.get("offset"), "400");
  assert.equal(q.get("sort"), "score");
  assert.equal(q.get("order"), "asc");
  assert.equal(new URLSearchParams(heatmapQuery({ offset: 0, limit: 99999 })).get("limit"), String(HEATMAP_MAX_TAKES));
  const sorted = new URLSearchParams(heatmapQuery({ offset: 0, limit: 100 }, { ...TABLE_DEFAULTS, sort: "name", order: "desc" }));
  assert.equal(sorted.get("sort"), "name");
  assert.equal(sorted.get("order"), "desc");
});

test("heatmapQuery carries the table's filters, with the heat map's own page", () => {
  const state = tableState(new URLSearchParams("sort=rig&order=desc&limit=25&offset=75&status=done&rig=cmu&min_score=40&max_score=90&has_findings=true&search=walk&review_status=approved"));
  const q = new URLSearchParams(heatmapQuery({ offset: 200, limit: 200 }, state));
  assert.deepEqual(Object.fromEntries(q), {
    sort: "rig", order: "desc", limit: "200", offset: "200", status: "done", review_status: "approved", rig: "cmu",
    min_score: "40", max_score: "90", has_findings: "true", search: "walk",
  });
  // Empty filters are left out, as for the table.
  assert.equal(heatmapQuery({ offset: 0, limit: 200 }, TABLE_DEFAULTS), "sort=score&order=asc&limit=200&offset=0");
  assert.equal(isFiltered(TABLE_DEFAULTS), false);
  assert.equal(isFiltered(state), true);
  assert.equal(isFiltered({ ...TABLE_DEFAULTS, has_findings: "false" }), true);
});

test("heatmapChanged: filters, sort and order move the heat map; the table's page does not", () => {
  const base = tableState(new URLSearchParams(""));
  assert.equal(heatmapChanged(base, { ...base, offset: 25 }), false);
  assert.equal(heatmapChanged(base, { ...base, limit: 100 }), false);
  assert.equal(heatmapChanged(base, { ...base, sort: "name" }), true);
  assert.equal(heatmapChanged(base, { ...base, order: "desc" }), true);
  assert.equal(heatmapChanged(base, { ...base, search: "walk" }), true);
  assert.equal(heatmapChanged({ ...base, min_score: 40 }, { ...base, min_score: "40" }), false);
});

test("heatmapPager pages through more than 200 takes", () => {
  const first = heatmapPager({ offset: 0, limit: 200 }, 1234);
  assert.equal(first.text, "takes 1–200 of 1234");
  assert.equal(first.previous, null);
  assert.equal(first.next, 200);
  const last = heatmapPager({ offset: 1200, limit: 200 }, 1234);
  assert.equal(last.text, "takes 1201–1234 of 1234");
  assert.equal(last.previous, 1000);
  assert.equal(last.next, null);
  // Walking "next" from the first page visits every take once.
  const seen = [];
  for (let page = { offset: 0, limit: 200 }; page.offset != null; page = { offset: heatmapPager(page, 1234).next, limit: 200 }) {
    seen.push(page.offset);
  }
  assert.deepEqual(seen, [0, 200, 400, 600, 800, 1000, 1200]);
});

test("heatmapFigure labels rows by rank (same names stay apart) and sizes rows evenly", () => {
  const data = {
    joints: ["LeftKnee", "RightElbow"],
    takes: [{ name: "walk.bvh" }, { name: "walk.bvh" }, { name: "run.bvh" }],
    values: [[0.5, 0, null], [0.25, 0.1, null]],
  };
  const figure = heatmapFigure(data, 200);
  assert.deepEqual(figure.y, ["201. walk.bvh", "202. walk.bvh", "203. run.bvh"]);
  assert.equal(new Set(figure.y).size, 3);
  assert.deepEqual(figure.x, data.joints);
  assert.deepEqual(figure.z, [[50, 25], [0, 10], [null, null]]);
  assert.equal(figure.zmax, 50); // the colour key's end: the page's largest share, in percent
  assert.equal(figure.height, 260); // small pages keep a readable minimum
  const big = heatmapFigure({ joints: ["A"], takes: Array.from({ length: 500 }, (_, k) => ({ name: `t${k}` })), values: [Array(500).fill(0)] }, 0);
  assert.equal(big.height, big.margin.t + big.margin.b + 22 * 500);
  assert.equal(big.y[499], "500. t499");
  assert.equal(big.zmax, 1); // nothing outside: a scale that still goes up
});

test("middleEllipsis keeps a long name's start and end within the limit", () => {
  assert.equal(middleEllipsis("walk.bvh", 40), "walk.bvh");
  const exact = "x".repeat(40);
  assert.equal(middleEllipsis(exact, 40), exact);
  const long = `take_${"very_long_name_".repeat(15)}end.bvh`; // 237 characters, as in the browser review
  const short = middleEllipsis(long, 40);
  assert.equal(short.length, 40);
  assert.equal(short, "take_very_long_name_…y_long_name_end.bvh"); // 20 + 1 + 19
  assert.ok(long.startsWith(short.split("…")[0]));
  assert.ok(long.endsWith(short.split("…")[1]));
  assert.equal([...short].filter((c) => c === "…").length, 1);
  assert.equal(middleEllipsis("abcdefghij", 5), "ab…ij");
  assert.equal(middleEllipsis("abcdefghij", 4), "ab…j");
  assert.equal(middleEllipsis("abcdefghij", 1), "…");
  // Characters, not UTF-16 units: an emoji is never cut in half.
  const emoji = middleEllipsis("😀".repeat(30), 9);
  assert.equal([...emoji].length, 9);
  assert.equal(emoji, `${"😀".repeat(4)}…${"😀".repeat(4)}`);
});

test("heatmapFigure shortens long row labels, keeps the full name for the hover, labels every joint", () => {
  const long = `take_${"very_long_name_".repeat(15)}end.bvh`;
  const joints = ["CC_Base_L_Thigh", "CC_Base_L_Calf", "CC_Base_L_Foot", "CC_Base_R_Thigh", "CC_Base_R_Calf", "CC_Base_R_Foot",
    "CC_Base_L_Upperarm", "CC_Base_L_Forearm", "CC_Base_R_Upperarm", "CC_Base_R_Forearm", "UpperLeg_R"];
  const data = { joints, takes: [{ name: long }, { name: "walk.bvh" }, { name: long }], values: joints.map(() => [0.1, 0, 0.2]) };
  const figure = heatmapFigure(data, 0);
  for (const label of figure.y) assert.ok([...label].length <= HEATMAP_LABEL_CHARS, label);
  assert.ok(figure.y[0].startsWith("1. take_very_long"));
  assert.ok(figure.y[0].endsWith("_end.bvh"));
  assert.equal(figure.y[1], "2. walk.bvh");
  assert.notEqual(figure.y[0], figure.y[2]); // the rank keeps equal long names apart
  // The hover names the take in full: one text per cell.
  assert.equal(figure.text.length, 3);
  assert.equal(figure.text[0].length, joints.length);
  assert.equal(figure.text[0][5].replaceAll("<br>", ""), `1. ${long}`);
  assert.equal(figure.text[2][0], hoverLines(`3. ${long}`));
  assert.equal(figure.text[1][0], "2. walk.bvh");
  // Every joint column and every row is labelled (Plotly's automatic ticks skip some).
  assert.deepEqual(figure.xaxis, { tickmode: "array", tickvals: joints, ticktext: joints, range: [-0.5, 10.5] });
  // The first take on top; fixed ranges (no automatic padding around the cells).
  assert.deepEqual(figure.yaxis, { tickmode: "array", tickvals: figure.y, ticktext: figure.y, range: [2.5, -0.5] });
  // The labels' margin is bounded by the label limit, and each joint column has its minimum.
  assert.ok(figure.margin.l <= 12 + 7 * HEATMAP_LABEL_CHARS);
  assert.equal(figure.minWidth, figure.margin.l + figure.margin.r + HEATMAP_COLUMN_PX * joints.length);
  assert.ok(figure.margin.t > 0 && figure.margin.t === figure.margin.b); // joints above and below
  const many = heatmapFigure({ joints: Array.from({ length: 60 }, (_, k) => `J${k}`), takes: [{ name: "a" }], values: Array(60).fill([0]) }, 0);
  assert.equal(many.xaxis.tickvals.length, 60);
  assert.ok(many.minWidth >= 60 * HEATMAP_COLUMN_PX);
});

test("hoverLines breaks a long name into lines and never lets it read as markup", () => {
  assert.equal(hoverLines("walk.bvh"), "walk.bvh");
  const long = "x".repeat(130);
  assert.equal(hoverLines(long, 60), `${"x".repeat(60)}<br>${"x".repeat(60)}<br>${"x".repeat(10)}`);
  assert.equal(hoverLines("a<b>&c.bvh"), "a&lt;b&gt;&amp;c.bvh");
  assert.equal(hoverLines("😀".repeat(3), 2), "😀😀<br>😀");
  assert.equal(hoverLines(""), "");
});

test("heatmapKeyGradient draws the chart's colour scale from 0 % to the largest share", () => {
  const gradient = heatmapKeyGradient();
  assert.ok(gradient.startsWith("linear-gradient(to right, rgb(255,255,204) 0%"));
  assert.ok(gradient.endsWith("rgb(128,0,38) 100%)"));
  assert.equal(gradient.match(/rgb\(/g).length, HEATMAP_COLORSCALE.length);
  assert.equal(heatmapKeyGradient([[0, "red"], [1, "blue"]]), "linear-gradient(to right, red 0%, blue 100%)");
});

test("scoreRangeProblem: a min score above the max score, or a bound outside 0–100", () => {
  assert.equal(scoreRangeProblem(TABLE_DEFAULTS), null);
  assert.equal(scoreRangeProblem({ min_score: "40", max_score: "" }), null);
  assert.equal(scoreRangeProblem({ min_score: "50", max_score: "50" }), null);
  assert.equal(scoreRangeProblem({ min_score: 0, max_score: 100 }), null);
  assert.deepEqual(scoreRangeProblem({ min_score: "95", max_score: "50" }), {
    fields: ["min_score", "max_score"], text: "min score (95) is above max score (50): no take can match",
  });
  assert.deepEqual(scoreRangeProblem({ min_score: " 9.5 ", max_score: "9" }).fields, ["min_score", "max_score"]);
  assert.deepEqual(scoreRangeProblem({ min_score: "", max_score: "140" }), { fields: ["max_score"], text: 'max score must be a number from 0 to 100 (got "140")' });
  assert.deepEqual(scoreRangeProblem({ min_score: "abc" }).fields, ["min_score"]);
  assert.deepEqual(scoreRangeProblem(tableState(new URLSearchParams("min_score=80&max_score=20"))).fields, ["min_score", "max_score"]);
});

test("exportQuery sends the table's filters, sort and order, never its page", () => {
  const state = { ...TABLE_DEFAULTS, sort: "name", order: "desc", offset: 50, limit: 25, rig: " cmu ", has_findings: "true" };
  assert.equal(exportQuery(state), "sort=name&order=desc&rig=cmu&has_findings=true");
  assert.equal(exportQuery(TABLE_DEFAULTS), "sort=score&order=asc");
});

test("an analysed take without a score reads 'not checked', a queued one a dash", () => {
  assert.equal(formatCell("score", { status: "done", score: null }), "not checked");
  assert.equal(formatCell("score", { status: "queued", score: null }), "–");
  assert.equal(formatCell("score", { status: "done", score: 97.25 }), "97.3");
});
