// Drawing on canvases: the voidage on the axial plane and on a horizontal slice of the
// cylindrical grid, a colour bar, a time trace and a per-layer profile.
//
// The grid (docs/API.md): nz layers of dz; annulus i (width dr) holds n0·(2i+1) cells, starting
// at n0·i² in its layer, θ increasing from the x axis; cell c of layer k is k·cells_per_layer + c.
"use strict";

const draw = (() => {
  // The voidage scale of the server's PNGs (0.3–1) and its colour map (5 stops of viridis).
  const LO = 0.3, HI = 1.0;
  const STOPS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
  const FONT = "12px system-ui, sans-serif";

  function colour(v) {
    let t = (v - LO) / (HI - LO);
    t = isFinite(t) ? Math.min(1, Math.max(0, t)) : 0;
    const x = t * (STOPS.length - 1);
    const i = Math.min(Math.floor(x), STOPS.length - 2);
    const f = x - i;
    const c = STOPS[i].map((s, n) => Math.round(s * (1 - f) + STOPS[i + 1][n] * f));
    return `rgb(${c[0]},${c[1]},${c[2]})`;
  }

  function clear(cv) {
    const ctx = cv.getContext("2d");
    ctx.clearRect(0, 0, cv.width, cv.height);
    ctx.font = FONT;
    return ctx;
  }

  const cellsIn = (g, i) => g.n0 * (2 * i + 1);
  const firstOf = (g, i) => g.n0 * i * i;
  const perLayer = (g) => g.n0 * g.nr * g.nr;

  // The plane y = 0: x from −R to R (θ = π on the left, θ = 0 on the right), z upward.
  function axial(cv, g, field) {
    const ctx = clear(cv);
    const pad = 28;
    const s = Math.min((cv.width - 2 * pad) / (2 * g.radius_m), (cv.height - 2 * pad) / g.height_m);
    const x0 = cv.width / 2, y0 = cv.height - pad;
    const cpl = perLayer(g);
    for (let k = 0; k < g.nz; k++) {
      for (let i = 0; i < g.nr; i++) {
        const n = cellsIn(g, i);
        const w = g.dr_m * s, h = g.dz_m * s + 0.5;
        const top = y0 - (k + 1) * g.dz_m * s;
        ctx.fillStyle = colour(field[k * cpl + firstOf(g, i)]);
        ctx.fillRect(x0 + i * g.dr_m * s, top, w + 0.5, h);
        ctx.fillStyle = colour(field[k * cpl + firstOf(g, i) + Math.floor(n / 2)]);
        ctx.fillRect(x0 - (i + 1) * g.dr_m * s - 0.5, top, w + 0.5, h);
      }
    }
    ctx.strokeStyle = "#444";
    ctx.strokeRect(x0 - g.radius_m * s, y0 - g.height_m * s, 2 * g.radius_m * s, g.height_m * s);
    ctx.fillStyle = "#222";
    ctx.textAlign = "center";
    ctx.fillText(`x (mm), D = ${(2000 * g.radius_m).toFixed(1)}`, x0, cv.height - 8);
    ctx.save();
    ctx.translate(12, y0 - (g.height_m * s) / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.fillText(`z (mm), H = ${(1000 * g.height_m).toFixed(1)}`, 0, 0);
    ctx.restore();
  }

  // Layer k seen from above: x to the right, y upward, annular sectors.
  function slice(cv, g, field, k) {
    const ctx = clear(cv);
    const cx = cv.width / 2, cy = cv.height / 2;
    const s = (Math.min(cv.width, cv.height) / 2 - 10) / g.radius_m;
    const base = k * perLayer(g);
    for (let i = 0; i < g.nr; i++) {
      const n = cellsIn(g, i);
      const r0 = i * g.dr_m * s, r1 = (i + 1) * g.dr_m * s;
      for (let j = 0; j < n; j++) {
        const a0 = (2 * Math.PI * j) / n, a1 = (2 * Math.PI * (j + 1)) / n;
        ctx.beginPath();
        ctx.arc(cx, cy, r1 + 0.5, -a0, -a1, true);
        ctx.arc(cx, cy, r0, -a1, -a0, false);
        ctx.closePath();
        ctx.fillStyle = ctx.strokeStyle = colour(field[base + firstOf(g, i) + j]);
        ctx.fill();
        ctx.stroke(); // covers the anti-aliased seams between sectors
      }
    }
    ctx.strokeStyle = "#444";
    ctx.beginPath();
    ctx.arc(cx, cy, g.radius_m * s, 0, 2 * Math.PI);
    ctx.stroke();
  }

  function colourBar(cv) {
    const ctx = clear(cv);
    const top = 10, bottom = cv.height - 10, x = 10, w = 18;
    for (let y = top; y <= bottom; y++) {
      ctx.fillStyle = colour(HI - ((y - top) / (bottom - top)) * (HI - LO));
      ctx.fillRect(x, y, w, 1.5);
    }
    ctx.strokeStyle = "#444";
    ctx.strokeRect(x, top, w, bottom - top);
    ctx.fillStyle = "#222";
    ctx.textAlign = "left";
    ctx.textBaseline = "middle";
    for (let v = LO; v <= HI + 1e-9; v += 0.1) {
      const y = bottom - ((v - LO) / (HI - LO)) * (bottom - top);
      ctx.fillRect(x + w, y, 4, 1);
      ctx.fillText(v.toFixed(1), x + w + 7, y);
    }
    ctx.save();
    ctx.translate(cv.width - 8, cv.height / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textAlign = "center";
    ctx.fillText("voidage ε", 0, 0);
    ctx.restore();
  }

  // About five round tick values covering [lo, hi].
  function ticks(lo, hi) {
    if (!(hi > lo)) hi = lo + 1;
    const raw = (hi - lo) / 5;
    const mag = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 5, 10].map((m) => m * mag).find((st) => st >= raw);
    const out = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(+v.toPrecision(12));
    return out;
  }

  // Axes for [x0, x1] × [y0, y1] in the canvas' plot area; the data → pixel maps.
  function axes(ctx, cv, [x0, x1], [y0, y1], xlabel, ylabel) {
    const L = 62, R = 12, T = 10, B = 40;
    const px = (x) => L + ((x - x0) / (x1 - x0 || 1)) * (cv.width - L - R);
    const py = (y) => cv.height - B - ((y - y0) / (y1 - y0 || 1)) * (cv.height - T - B);
    ctx.strokeStyle = "#ccc";
    ctx.fillStyle = "#222";
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    for (const t of ticks(x0, x1)) {
      ctx.beginPath(); ctx.moveTo(px(t), T); ctx.lineTo(px(t), cv.height - B); ctx.stroke();
      ctx.fillText(String(t), px(t), cv.height - B + 4);
    }
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    for (const t of ticks(y0, y1)) {
      ctx.beginPath(); ctx.moveTo(L, py(t)); ctx.lineTo(cv.width - R, py(t)); ctx.stroke();
      ctx.fillText(String(t), L - 5, py(t));
    }
    ctx.strokeStyle = "#444";
    ctx.strokeRect(L, T, cv.width - L - R, cv.height - T - B);
    ctx.textAlign = "center";
    ctx.textBaseline = "bottom";
    ctx.fillText(xlabel, L + (cv.width - L - R) / 2, cv.height - 2);
    ctx.save();
    ctx.translate(12, T + (cv.height - T - B) / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textBaseline = "middle";
    ctx.fillText(ylabel, 0, 0);
    ctx.restore();
    return [px, py];
  }

  function range(vs) {
    const f = vs.filter((v) => isFinite(v));
    if (!f.length) return [0, 1];
    let lo = Math.min(...f), hi = Math.max(...f);
    if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { lo -= 0.5 * Math.abs(lo || 1); hi += 0.5 * Math.abs(hi || 1); }
    return [lo, hi];
  }

  // y(x) as a line with its points.
  function trace(cv, xs, ys, xlabel, ylabel) {
    const ctx = clear(cv);
    const [ylo, yhi] = range(ys);
    const [px, py] = axes(ctx, cv, [0, Math.max(...xs, 1e-9)], [Math.min(0, ylo), yhi * 1.05], xlabel, ylabel);
    ctx.strokeStyle = "#1f77b4";
    ctx.fillStyle = "#1f77b4";
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    xs.forEach((x, i) => (i ? ctx.lineTo(px(x), py(ys[i])) : ctx.moveTo(px(x), py(ys[i]))));
    ctx.stroke();
    xs.forEach((x, i) => ctx.fillRect(px(x) - 2, py(ys[i]) - 2, 4, 4));
    ctx.lineWidth = 1;
  }

  // One bar per layer interface: value (x) against height z (y).
  function profile(cv, zs, vs, xlabel, ylabel) {
    const ctx = clear(cv);
    const [lo, hi] = range(vs);
    const [px, py] = axes(ctx, cv, [Math.min(0, lo), hi * 1.05], [0, Math.max(...zs) * 1.04], xlabel, ylabel);
    const h = Math.max(2, Math.abs(py(zs[0]) - py(zs[1] ?? 0)) * 0.7);
    ctx.fillStyle = "#d62728";
    zs.forEach((z, i) => {
      const a = px(Math.min(0, vs[i])), b = px(Math.max(0, vs[i]));
      ctx.fillRect(a, py(z) - h / 2, Math.max(1, b - a), h);
    });
  }

  return { axial, slice, colourBar, trace, profile };
})();
