// Shared by the pages: API calls (with the bearer token when the server wants one), the event
// stream read over fetch (so that the token can travel in a header), and formatting.
"use strict";

const fb = (() => {
  const TOKEN_KEY = "fluidbed-token";

  function authHeaders(extra) {
    const h = Object.assign({}, extra || {});
    const t = localStorage.getItem(TOKEN_KEY);
    if (t) h["Authorization"] = "Bearer " + t;
    return h;
  }

  // Ask for the token once the API answers 401; the page reloads with it.
  function askToken() {
    const form = document.getElementById("token-form");
    if (!form || !form.hidden) return;
    form.hidden = false;
    form.addEventListener("submit", (e) => {
      e.preventDefault();
      localStorage.setItem(TOKEN_KEY, document.getElementById("token").value.trim());
      location.reload();
    });
  }

  async function api(path, opts) {
    const o = Object.assign({}, opts || {});
    o.headers = authHeaders(o.headers);
    const r = await fetch(path, o);
    if (r.status === 401) askToken();
    return r;
  }

  // The problem+json detail of a failed answer, or its status line.
  async function problemText(r) {
    try {
      const p = await r.json();
      return p.detail || p.title || `${r.status} ${r.statusText}`;
    } catch (_) {
      return `${r.status} ${r.statusText}`;
    }
  }

  // Parse one server-sent event block ("event:", "data:", "id:" lines).
  function parseEvent(block) {
    const ev = { event: "message", data: "", id: null };
    const data = [];
    for (const line of block.split("\n")) {
      if (line === "" || line.startsWith(":")) continue;
      const i = line.indexOf(":");
      const key = i < 0 ? line : line.slice(0, i);
      const value = i < 0 ? "" : line.slice(i + 1).replace(/^ /, "");
      if (key === "event") ev.event = value;
      else if (key === "data") data.push(value);
      else if (key === "id") ev.id = value;
    }
    ev.data = data.join("\n");
    return data.length ? ev : null;
  }

  // Follow a job's event stream until its `end` event, reconnecting with Last-Event-ID.
  async function follow(path, onEvent) {
    let last = null;
    for (;;) {
      let ended = false;
      try {
        const r = await api(path, { headers: last === null ? {} : { "Last-Event-ID": last } });
        if (!r.ok) {
          onEvent({ event: "error", data: await problemText(r) });
          return;
        }
        const reader = r.body.pipeThrough(new TextDecoderStream()).getReader();
        let buf = "";
        for (;;) {
          const { value, done } = await reader.read();
          if (done) break;
          buf += value.replace(/\r\n?/g, "\n");
          let cut;
          while ((cut = buf.indexOf("\n\n")) >= 0) {
            const ev = parseEvent(buf.slice(0, cut));
            buf = buf.slice(cut + 2);
            if (!ev) continue;
            if (ev.id !== null) last = ev.id;
            if (ev.event === "end") ended = true;
            onEvent(ev);
          }
        }
      } catch (e) {
        onEvent({ event: "disconnected", data: String(e) });
      }
      if (ended) return;
      await new Promise((ok) => setTimeout(ok, 1500));
    }
  }

  // A download link that carries the token when one is set (fetched, then saved).
  function downloadLink(href, text) {
    const a = document.createElement("a");
    a.href = href;
    a.textContent = text;
    a.className = "download";
    a.addEventListener("click", async (e) => {
      if (!localStorage.getItem(TOKEN_KEY)) return;
      e.preventDefault();
      const r = await api(href);
      if (!r.ok) return alert(await problemText(r));
      const url = URL.createObjectURL(await r.blob());
      const tmp = document.createElement("a");
      tmp.href = url;
      tmp.download = href.split("/").pop().replace(/\?.*/, "") + "-" + text;
      tmp.click();
      setTimeout(() => URL.revokeObjectURL(url), 10000);
    });
    return a;
  }

  function seconds(s) {
    if (s === null || s === undefined || !isFinite(s)) return "–";
    if (s < 60) return s.toFixed(s < 10 ? 1 : 0) + " s";
    if (s < 3600) return Math.floor(s / 60) + " min " + Math.round(s % 60) + " s";
    return Math.floor(s / 3600) + " h " + Math.round((s % 3600) / 60) + " min";
  }

  function el(tag, attrs, ...children) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "class") e.className = v;
      else if (k.startsWith("data-")) e.setAttribute(k, v);
      else e[k] = v;
    }
    for (const c of children) e.append(c);
    return e;
  }

  return { api, problemText, follow, downloadLink, seconds, el };
})();
