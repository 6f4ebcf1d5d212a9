// The dashboard's address: the part after "#" names the view and its parameters. Pure
// (unit-tested with node --test).

/**
 * Split a location's hash into the view's path parts and its query.
 *
 * @param {string} hash e.g. "#/take/ID?run=RID&frame=F"
 * @returns {{parts: string[], params: URLSearchParams}} e.g. ["take", "ID"] and run=RID&frame=F;
 *   "" or "#/" give no parts.
 */
export function parseRoute(hash) {
  const [path, query] = hash.replace(/^#/, "").split("?");
  return { parts: (path || "/").split("/").filter(Boolean), params: new URLSearchParams(query || "") };
}
