// The front page: the job list (polled), and the submit form whose field view shows the
// validator's errors at the fields they name (JSON pointers).
"use strict";

const { api, problemText, seconds, el } = fb;

// ---- the job list ----

function jobRow(j) {
  const link = el("a", { href: "/jobs/" + j.id }, j.name || j.id);
  const id = el("div", { class: "note mono" }, j.id);
  const status = el("span", { class: "status " + j.status }, j.status);
  const bar = el("progress", { max: 1, value: j.progress || 0 });
  const pct = el("span", { class: "note" }, " " + ((j.progress || 0) * 100).toFixed(1) + " %");
  const sim = (j.time_s || 0).toFixed(3) + " / " + (j.end_time_s || 0).toFixed(3) + " s";
  const eta = j.status === "running" ? seconds(j.eta_s) : "–";
  const created = (j.created_at || "").replace("T", " ").replace(/\.\d+Z$|Z$/, "");
  return el("tr", { "data-job": j.id },
    el("td", {}, link, id),
    el("td", {}, status, j.message ? el("div", { class: "note" }, j.message) : ""),
    el("td", {}, bar, pct),
    el("td", {}, sim),
    el("td", {}, eta),
    el("td", { class: "note" }, created));
}

async function refreshJobs() {
  const status = document.getElementById("status-filter").value;
  const note = document.getElementById("jobs-note");
  try {
    const r = await api("/v1/jobs?limit=100" + (status ? "&status=" + status : ""));
    if (!r.ok) {
      note.textContent = await problemText(r);
      return;
    }
    const body = await r.json();
    const tbody = document.querySelector("#jobs tbody");
    const rows = body.jobs.map(jobRow);
    if (!rows.length) rows.push(el("tr", {}, el("td", { colSpan: 6, class: "note" }, "no jobs yet")));
    tbody.replaceChildren(...rows);
    note.textContent = body.total + " job" + (body.total === 1 ? "" : "s");
  } catch (e) {
    note.textContent = "cannot reach the server (" + e.message + ")";
  }
}

// ---- the field view of the case ----

function pointerOf(parent, key) {
  return parent + "/" + String(key).replace(/~/g, "~0").replace(/\//g, "~1");
}

// Render `value` at `pointer`; editing a leaf writes into `root` and the text.
function fieldView(value, pointer, key, onEdit) {
  const node = el("div", { class: "field", "data-pointer": pointer });
  const name = el("span", { class: "key" }, key === null ? "case" : String(key));
  if (value !== null && typeof value === "object") {
    const entries = Array.isArray(value) ? value.map((v, i) => [i, v]) : Object.entries(value);
    if (Array.isArray(value) && value.length > 12) {
      node.append(name, el("span", { class: "note" }, ` [${value.length} items]`));
      return node;
    }
    node.append(name);
    const kids = el("div", { class: "children" });
    for (const [k, v] of entries) kids.append(fieldView(v, pointerOf(pointer, k), k, onEdit));
    node.append(kids);
    return node;
  }
  const input = el("input", { value: value === null ? "null" : String(value), spellcheck: false });
  input.addEventListener("change", () => {
    let v = input.value;
    if (typeof value === "number" || typeof value === "boolean" || value === null) {
      try { v = JSON.parse(v); } catch (_) { /* kept as text: the validator will say */ }
    }
    onEdit(pointer, v);
  });
  node.append(el("label", {}, name, input));
  return node;
}

function setAt(root, pointer, v) {
  const keys = pointer.split("/").slice(1).map((k) => k.replace(/~1/g, "/").replace(/~0/g, "~"));
  let o = root;
  for (const k of keys.slice(0, -1)) o = o[k];
  o[keys[keys.length - 1]] = v;
}

function renderFields() {
  const box = document.getElementById("case-fields");
  const text = document.getElementById("case-text");
  const textError = document.getElementById("text-error");
  textError.hidden = true;
  if (!text.value.trim()) {
    box.replaceChildren(el("p", { class: "note" }, "the case's fields appear here; errors are shown at their field"));
    return null;
  }
  let root;
  try {
    root = JSON.parse(text.value);
  } catch (e) {
    textError.textContent = "not valid JSON: " + e.message;
    textError.hidden = false;
    return null;
  }
  const onEdit = (pointer, v) => {
    setAt(root, pointer, v);
    text.value = JSON.stringify(root, null, 2);
  };
  box.replaceChildren(fieldView(root, "", null, onEdit));
  return root;
}

// Each error under the field its pointer names, or under the nearest field that exists.
function showErrors(errors) {
  for (const p of errors) {
    let ptr = p.pointer || "";
    let host = null;
    for (;;) {
      host = document.querySelector(`#case-fields [data-pointer="${CSS.escape(ptr)}"]`);
      if (host || ptr === "") break;
      ptr = ptr.slice(0, ptr.lastIndexOf("/"));
    }
    host = host || document.getElementById("case-fields");
    const where = ptr === p.pointer ? "" : `${p.pointer}: `;
    const allowed = p.allowed ? ` (allowed: ${p.allowed})` : "";
    host.classList.add("has-error");
    host.append(el("div", { class: "field-error", "data-error-for": p.pointer }, where + p.message + allowed));
  }
  const first = document.querySelector("#case-fields .field-error");
  if (first) first.scrollIntoView({ block: "center" });
}

async function submit(e) {
  e.preventDefault();
  const result = document.getElementById("submit-result");
  if (renderFields() === null) {
    result.textContent = "nothing to submit";
    return;
  }
  result.textContent = "submitting…";
  const r = await api("/v1/jobs", {
    method: "POST",
    headers: { "content-type": "application/json" },
    body: document.getElementById("case-text").value,
  });
  const body = await r.json().catch(() => ({}));
  if (r.status === 201) {
    result.replaceChildren("submitted: ", el("a", { href: "/jobs/" + body.id }, body.name || body.id));
    refreshJobs();
    return;
  }
  result.textContent = body.detail || body.title || `${r.status} ${r.statusText}`;
  if (Array.isArray(body.errors)) showErrors(body.errors);
}

async function loadCases() {
  const pick = document.getElementById("case-pick");
  const r = await api("/ui/cases.json");
  if (!r.ok) return;
  const { cases } = await r.json();
  for (const c of cases) {
    let name = "";
    try { name = JSON.parse(c.text).name || ""; } catch (_) { /* listed by file name alone */ }
    pick.append(el("option", { value: c.file }, name ? `${c.file} — ${name}` : c.file));
  }
  pick.addEventListener("change", () => {
    const c = cases.find((x) => x.file === pick.value);
    document.getElementById("case-text").value = c ? c.text : "";
    renderFields();
  });
}

document.getElementById("status-filter").addEventListener("change", refreshJobs);
document.getElementById("submit-form").addEventListener("submit", submit);
let typing = null;
document.getElementById("case-text").addEventListener("input", () => {
  clearTimeout(typing);
  typing = setTimeout(renderFields, 400);
});
refreshJobs();
setInterval(refreshJobs, 2000);
loadCases();
