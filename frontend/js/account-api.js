// The account routes: who am I, sign-in/out, users, tokens, audit log.
import { request } from "./api.js";

export const me = () => request("GET", "/me");
export const signIn = (name, password) => request("POST", "/auth/sign-in", { name, password });
export const signOut = () => request("POST", "/auth/sign-out");
export const listUsers = () => request("GET", "/users");
export const addUser = (user) => request("POST", "/users", user);
export const changeUser = (name, changes) => request("PATCH", `/users/${encodeURIComponent(name)}`, changes);
export const listTokens = (everyone = false) => request("GET", `/tokens?everyone=${everyone}`);
export const createToken = (name, expiresDays) => request("POST", "/tokens", { name, expires_days: expiresDays });
export const revokeToken = (id) => request("DELETE", `/tokens/${id}`);
export const listAudit = (limit, offset) => request("GET", `/audit?limit=${limit}&offset=${offset}`);

export { h } from "./dom.js";
export const when = (iso) => (iso ? new Date(iso).toLocaleString() : "–");
