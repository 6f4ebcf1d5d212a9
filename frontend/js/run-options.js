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

/**
 * The options of a new run from the form's values.
 *
 * @param values  {checks: [..], twist_method?, twist_apply?, filter_method, filter_preset,
 *                 max_points?: text, params: [[field, text], ...], mapping?: {role: joint}}
 *                 (field as the registry's; mapping: the roles named by hand, BVH takes)
 * @param fields  the run-option fields by name (for max_points' bounds)
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
  if (values.twist_method) options.twist_method = values.twist_method;
  if (values.twist_apply) options.twist_apply = values.twist_apply;
  if (fields.max_points) {
    const checked = checkValue(fields.max_points, values.max_points);
    if (checked.error) errors.push(checked.error);
    else if (checked.value !== undefined) options.max_points = checked.value;
  }
  if (!values.checks.length) errors.push("checks: tick at least one check");
  return errors.length ? { errors } : { options };
}

/** A parameter's label: its dotted name made readable ("kalman.process_noise" → "kalman · process noise"). */
export const paramLabel = (name) => name.split(".").map((part) => part.replace(/_/g, " ")).join(" · ");
