// One job's page: its status and progress, the voidage maps, the ΔP trace and the per-layer
// pressure gradient, live from the job's event stream, and the download links.
"use strict";

(() => {
  const { api, problemText, follow, downloadLink, seconds } = fb;
  const id = decodeURIComponent(location.pathname.split("/").filter(Boolean).pop() || "");
  const base = "/v1/jobs/" + encodeURIComponent(id);
  const $ = (x) => document.getElementById(x);
  const FINAL = ["succeeded", "failed", "cancelled"];
  const series = { t: [], dp: [], h: [], n: [] };
  let latest = null;

  function showStatus(status, message) {
    const s = $("status");
    s.textContent = status;
    s.className = "status " + status;
    const m = $("message");
    m.hidden = !message;
    m.textContent = message || "";
    $("cancel").hidden = FINAL.includes(status);
  }

  function showProgress(p) {
    $("progress").value = p.progress || 0;
    $("progress-text").textContent = ((p.progress || 0) * 100).toFixed(1) + " %";
    $("sim-time").textContent = `${(p.time_s || 0).toFixed(4)} of ${(p.end_time_s || 0).toFixed(4)} s, step ${p.steps || 0}`;
    $("wall-time").textContent = seconds(p.wall_time_s);
    $("eta").textContent = p.status === "running" ? seconds(p.eta_s) : "–";
  }

  function showJob(j) {
    document.title = "fluidbed: " + (j.name || j.id);
    $("job-name").textContent = (j.name || "job") + " · " + j.id;
    showStatus(j.status, j.message);
    showProgress(j);
  }

  function drawMaps() {
    if (!latest || !latest.voidage) return;
    const g = latest.grid;
    const k = Math.min(+$("slice-layer").value, g.nz - 1);
    draw.axial($("axial"), g, latest.voidage);
    draw.slice($("slice"), g, latest.voidage, k);
    $("axial").dataset.snapshot = latest.n;
    $("slice").dataset.snapshot = latest.n;
    $("axial-time").textContent = `t = ${latest.time_s.toFixed(4)} s (snapshot ${latest.n})`;
    $("slice-z").textContent = `${(1000 * (k + 0.5) * g.dz_m).toFixed(1)} mm (layer ${k})`;
  }

  function drawPlots() {
    const gas = series.dp.some((v) => v !== null);
    if (gas) {
      $("trace-title").textContent = "Bed pressure drop ΔP";
      draw.trace($("trace"), series.t, series.dp, "time t (s)", "ΔP (Pa)");
    } else {
      $("trace-title").textContent = "Mean particle height (no gas)";
      draw.trace($("trace"), series.t, series.h.map((h) => (h === null ? NaN : 1000 * h)), "time t (s)", "height (mm)");
    }
    $("trace").dataset.points = series.t.length;
    const layers = latest && latest.layer_pressure_drop_pa;
    if (layers && layers.length) {
      const dz = latest.grid.dz_m;
      const zs = layers.map((_, k) => 1000 * (k + 1) * dz);
      draw.profile($("layers"), zs, layers.map((v) => v / dz), "−dP/dz (Pa/m)", "z (mm)");
      $("layers-time").textContent = `t = ${latest.time_s.toFixed(4)} s`;
      $("layers").dataset.snapshot = latest.n;
    }
  }

  function snapLinks() {
    const n = $("snap-pick").value;
    if (n === "") return;
    const s = `${base}/snapshots/${n}`;
    const links = [
      [`${s}?format=npy&field=voidage`, "voidage.npy"],
      [`${s}?format=npy&field=pressure`, "pressure.npy"],
      [`${s}?format=npy&field=particles`, "particles.npy"],
      [`${s}?format=vtu`, "cells.vtu"],
      [`${s}?format=vtp&what=particles`, "particles.vtp"],
      [`${s}?format=png`, "voidage.png"],
      [`${s}?format=json`, "snapshot.json"],
    ];
    $("snap-links").replaceChildren(...links.flatMap(([h, t]) => [downloadLink(h, t), " "]));
  }

  function onSnapshot(s) {
    if (series.n.includes(s.n)) return;
    latest = s;
    series.n.push(s.n);
    series.t.push(s.time_s);
    series.dp.push(s.pressure_drop_pa);
    series.h.push(s.mean_particle_height_m);
    const slider = $("slice-layer");
    if (+slider.max !== s.grid.nz - 1) {
      slider.max = s.grid.nz - 1;
      slider.value = Math.floor((s.grid.nz - 1) / 4);
    }
    const pick = $("snap-pick");
    const tracking = pick.value === "" || +pick.value === series.n[series.n.length - 2];
    pick.append(new Option(`${s.n} (t = ${s.time_s.toFixed(4)} s)`, s.n));
    if (tracking) pick.value = s.n;
    drawMaps();
    drawPlots();
    snapLinks();
  }

  function onEvent(ev) {
    let d = {};
    try { d = ev.data ? JSON.parse(ev.data) : {}; } catch (_) { d = { message: ev.data }; }
    if (ev.event === "snapshot") onSnapshot(d);
    else if (ev.event === "progress") showProgress(d);
    else if (ev.event === "status" || ev.event === "end") showStatus(d.status, d.message);
    else if (ev.event === "error") showStatus("unavailable", ev.data);
    if (ev.event === "end") refresh();
  }

  async function refresh() {
    const r = await api(base);
    if (!r.ok) {
      showStatus("unavailable", await problemText(r));
      return false;
    }
    showJob(await r.json());
    return true;
  }

  $("cancel").addEventListener("click", async () => {
    const r = await api(base, { method: "DELETE" });
    if (!r.ok) alert(await problemText(r));
    refresh();
  });
  $("slice-layer").addEventListener("input", drawMaps);
  $("snap-pick").addEventListener("change", snapLinks);
  draw.colourBar($("colorbar"));
  $("series-links").replaceChildren(
    ...[["csv", "pressure_drop.csv"], ["json", "pressure_drop.json"], ["png", "pressure_drop.png"]].flatMap(
      ([f, t]) => [downloadLink(`${base}/pressure-drop?format=${f}`, t), " "]));
  refresh().then((ok) => ok && follow(base + "/events", onEvent));
})();
