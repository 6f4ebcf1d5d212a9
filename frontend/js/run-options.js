// Pure functions of the re-run form: the server's description of the run options
// (GET /run-options, from pipeline/options.py) and the filter registry (GET /filters) in, checked
// values and the options of a new run out. No DOM.

/**
 * One typed-in value checked against its field ({name, type, minimum?, maximum?,
 * minimum_excluded?, maximum_excluded?}; an excluded bound is not itself allowed, as GET
 * /filters serves a range "> 0"): {value} (undefined for an empty text: the default) or {error}
 * naming the field.
 */
export function checkValue(field, text) {
  const raw = String(text ?? "").trim();
  if (raw === "") return { value: undefined };
  if (field.type === "str") return { value: raw };
  if (field.type === "bool") {
    if (raw === "true" || raw === "false") return { value: raw === "true" };
    return { error: `${field.name}: expected true or false, got "${raw}"` };
  }
  const value = Number(raw);
  if (!Number.isFinite(value)) return { error: `${field.name}: expected a number, got "${raw}"` };
  if (field.type === "int" && !Number.isInteger(value)) return { error: `${field.name}: expected a whole number, got ${raw}` };
  if (field.minimum != null && field.minimum_excluded && value <= field.minimum) return { error: `${field.name}: expected more than ${field.minimum}, got ${raw}` };
  if (field.minimum != null && value < field.minimum) return { error: `${field.name}: expected at least ${field.minimum}, got ${raw}` };
  if (field.maximum != null && field.maximum_excluded && value >= field.maximum) return { error: `${field.name}: expected less than ${field.maximum}, got ${raw}` };
  if (field.maximum != null && value > field.maximum) return { error: `${field.name}: expected at most ${field.maximum}, got ${raw}` };
  return { value };
}

/** The presets a take can use: those with a check it can run, their checks cut to those. */
export function usablePresets(presets, available) {
  return Object.entries(presets)
    .map(([name, options]) => [name, { ...options, checks: options.checks.filter((c) => available.includes(c)) }])
    .filter(([, options]) => options.checks.length);
}

// How each type of run-option field served by GET /run-options reads its control's value into
// a run's options; "filter" and "filter_preset" fields go with the filter's parameters.
const FIELD_VALUES = {
  choice: (field, text) => ({ value: text || undefined }),
  int: checkValue,
  float: checkValue,
};

/**
 * The options of a new run from the form's values.
 *
 * @param values  {checks: [..], filter_method, filter_preset, params: [[field, text], ...],
 *                 mapping?: {role: joint}, and each other form field's text by its name, e.g.
 *                 twist_method, max_points} (params: the registry's field of each filter
 *                 parameter; mapping: the roles named by hand, BVH takes)
 * @param fields  the run-option fields of the form by name (GET /run-options): their types,
 *                choices and bounds
 * @returns {options} or {errors: [message, ...]}
 */
export function formOptions(values, fields) {
  const errors = [];
  const filterParams = {};
  for (const [field, text] of values.params) {
    const checked = checkValue(field, text);
    if (checked.error) errors.push(checked.error);
    else if (checked.value !== undefined) filterParams[field.name] = checked.value;
  }
  const options = {
    checks: values.checks,
    filter_method: values.filter_method || null, filter_preset: values.filter_preset || null, filter_params: filterParams,
  };
  if (values.mapping && Object.keys(values.mapping).length) options.mapping = { ...values.mapping };
  for (const field of Object.values(fields)) {
    const read = FIELD_VALUES[field.type];
    if (!read || values[field.name] === undefined) continue;
    const checked = read(field, values[field.name]);
    if (checked.error) errors.push(checked.error);
    else if (checked.value !== undefined) options[field.name] = checked.value;
  }
  if (!values.checks.length) errors.push("checks: tick at least one check");
  return errors.length ? { errors } : { options };
}

/** The served default of every run-option field, by name (the fields of GET /run-options'
 * `groups`), e.g. {twist_apply: ..., max_points: ...}. */
export const optionDefaults = (described) =>
  Object.fromEntries(described.groups.flatMap((g) => g.fields).map((f) => [f.name, f.default]));

/**
 * The filters of the registry (GET /filters) a take of `kind` (a key of GET /run-options
 * `take_checks`: "motion", "markers" or "keypoints") can run, and the name of the one its run
 * uses when none is chosen (null: no filter), as GET /run-options serves them in `take_filters`
 * ({target: what the filters must apply to, default}).
 */
export function takeFilters(kind, described, filters) {
  const { target, default: fallback } = described.take_filters[kind];
  return { usable: filters.filter((f) => f.applies_to.includes(target)), fallback };
}

/** A parameter's label: its dotted name made readable ("kalman.process_noise" → "kalman · process noise"). */
export const paramLabel = (name) => name.split(".").map((part) => part.replace(/_/g, " ")).join(" · ");
