// Min–max decimation of the charts' series: Plotly is never handed more points than the plot
// has pixel columns, so plotting a 10,000-frame take is one short task. Pure functions, no DOM.
//
// The samples are cut into buckets, one per pixel column of the shown x-range (and, outside it,
// one per pixel column of the whole take, so panning and a reset still draw every peak). A line
// keeps, per bucket, its first, lowest, highest and last sample (in time order) and its first
// missing one, so the drawn line has the same extremes — the same autoranged y-range — and a
// gap in the data stays a gap. A heat map keeps, per bucket and row, the largest value.

const missing = (v) => v == null || Number.isNaN(v);

/**
 * The bucket of each sample: one per pixel column of `range` inside it, one per pixel column of
 * the whole x-range outside it. `x` is ascending; returns an Int32Array of bucket numbers that
 * never decrease (a new number starts a new bucket).
 */
export function buckets(x, columns, range = null) {
  const n = x.length;
  const out = new Int32Array(n);
  if (n === 0) return out;
  const lo = x[0], span = x[n - 1] - x[0];
  const [a, b] = range ? [Math.min(...range), Math.max(...range)] : [lo, x[n - 1]];
  const wide = b - a;
  for (let i = 0; i < n; i++) {
    const v = x[i];
    const whole = span > 0 ? Math.min(columns - 1, Math.floor(((v - lo) / span) * columns)) : 0;
    if (v < a) out[i] = 3 * whole;
    else if (v > b) out[i] = 3 * whole + 2;
    else {
      // Inside the range: the whole take's column before it, then the range's own columns.
      const own = wide > 0 ? Math.min(columns - 1, Math.floor(((v - a) / wide) * columns)) : 0;
      out[i] = 3 * columns + own;
    }
  }
  // Renumber so the numbers follow the samples' order (the range's sit between the others).
  let k = 0;
  const ids = new Int32Array(n);
  for (let i = 1; i < n; i++) { if (out[i] !== out[i - 1]) k++; ids[i] = k; }
  return ids;
}

/**
 * The indices of the samples a line keeps: per bucket its first, lowest, highest, last and
 * first missing (null or NaN) sample, ascending. `y` is (n,), `bucket` from `buckets`.
 */
export function keptIndices(y, bucket) {
  const kept = [];
  const n = y.length;
  let start = 0;
  while (start < n) {
    let end = start, min = -1, max = -1, gap = -1;
    while (end < n && bucket[end] === bucket[start]) {
      const v = y[end];
      if (missing(v)) { if (gap < 0) gap = end; }
      else {
        if (min < 0 || v < y[min]) min = end;
        if (max < 0 || v > y[max]) max = end;
      }
      end++;
    }
    const own = [start, min, max, end - 1, gap].filter((i) => i >= 0).sort((p, q) => p - q);
    for (let j = 0; j < own.length; j++) if (j === 0 || own[j] !== own[j - 1]) kept.push(own[j]);
    start = end;
  }
  return kept;
}

/** A line's (x, y) decimated to `columns` pixel columns (of `range`, if given). */
export function decimateLine(x, y, columns, range = null) {
  if (x.length <= 4 * columns && !range) return { x, y };
  const kept = keptIndices(y, buckets(x, columns, range));
  if (kept.length >= x.length) return { x, y };
  return { x: kept.map((i) => x[i]), y: kept.map((i) => y[i]) };
}

/**
 * A heat map's columns merged per bucket: `x` (n,) ascending column centres, `z` rows of (n,).
 * Returns `x` as the n' + 1 cell edges (each bucket spans its columns' cells) and `z` as rows of
 * (n',), each the largest value of its bucket (null when all are missing).
 */
export function decimateHeatmap(x, z, columns, range = null) {
  const n = x.length;
  if (n <= columns && !range) return { x, z };
  const bucket = buckets(x, columns, range);
  const starts = [0];
  for (let i = 1; i < n; i++) if (bucket[i] !== bucket[i - 1]) starts.push(i);
  if (starts.length >= n) return { x, z };
  const half = n > 1 ? (x[1] - x[0]) / 2 : 0.5;
  const edge = (i) => (i === 0 ? x[0] - half : i === n ? x[n - 1] + half : (x[i - 1] + x[i]) / 2);
  const edges = [...starts.map(edge), edge(n)];
  const rows = z.map((row) => starts.map((s, k) => {
    const end = k + 1 < starts.length ? starts[k + 1] : n;
    let top = null;
    for (let i = s; i < end; i++) if (!missing(row[i]) && (top === null || row[i] > top)) top = row[i];
    return top;
  }));
  return { x: edges, z: rows };
}

/** Does this trace get decimated (lines and heat maps; stacked areas and bars do not)? */
export const decimated = (trace) =>
  (trace.type === "scatter" && !trace.stackgroup && Array.isArray(trace.x)) || trace.type === "heatmap";

/** One trace's decimated {x, y} or {x, z} for `columns` pixel columns of `range` (or all). */
export function decimateTrace(trace, columns, range = null) {
  return trace.type === "heatmap"
    ? decimateHeatmap(trace.x, trace.z, columns, range)
    : decimateLine(trace.x, trace.y, columns, range);
}

/** A figure with its lines and heat maps decimated; everything else (bands, layout) as given. */
export function decimateFigure(figure, columns, range = null) {
  const data = figure.data.map((trace) => (decimated(trace) ? { ...trace, ...decimateTrace(trace, columns, range) } : trace));
  return { data, layout: figure.layout };
}
