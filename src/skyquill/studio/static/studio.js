// skyquill studio: record strokes, ask the API for a plan, show it, offer the files.
// A plain ES module with no dependencies and no build step (the page works offline).

const W = 560; // logical canvas size (CSS pixels of the drawing area)
const POLL_MS = 200;
const COLORS = ["#e8590c", "#2b8a3e", "#5f3dc4", "#0b7285", "#d6336c", "#795548", "#364fc7", "#e67700"];
const css = getComputedStyle(document.documentElement);
const color = (name) => css.getPropertyValue(name).trim();

const $ = (id) => document.getElementById(id);
const ui = {
  studio: $("studio"), ink: $("ink"), overlay: $("overlay"), plots: $("plots"),
  undo: $("undo"), clear: $("clear"), count: $("stroke-count"), text: $("text"),
  board: $("board"), size: $("size_m"), drones: $("drones"), vmax: $("vmax"), amax: $("amax"),
  jmax: $("jmax"), fly: $("fly"), plan: $("plan"), progressBox: $("progress-box"),
  progress: $("progress"), stage: $("stage"), error: $("error"), play: $("play"),
  time: $("time"), clock: $("clock"), speed: $("speed"), summary: $("summary"),
  files: $("files"), notes: $("notes"),
};

// ---------------------------------------------------------------- state

const state = {
  strokes: [], // {points: [[x, y], ...] canvas px, y down; times: [s, ...]}
  current: null, // the stroke being drawn
  t0: null, // time origin of the recording, ms
  result: null, // the API's PlanResult
  views: [], // per drone: (u, v) on its board -> canvas px
  playing: false,
  t: 0, // animation time, s
  lastFrame: null,
};

// ------------------------------------------------------ canvas helpers

function setupCanvas(canvas, width, height) {
  // Sharp lines on high-density screens: draw in logical px, store device px.
  const ratio = window.devicePixelRatio || 1;
  canvas.width = Math.round(width * ratio);
  canvas.height = Math.round(height * ratio);
  const ctx = canvas.getContext("2d");
  ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
  return ctx;
}

const inkCtx = setupCanvas(ui.ink, W, W);
const overCtx = setupCanvas(ui.overlay, W, W);
const plotCtx = setupCanvas(ui.plots, W, 420);

function polyline(ctx, points) {
  if (points.length < 2) return;
  ctx.beginPath();
  ctx.moveTo(points[0][0], points[0][1]);
  for (let i = 1; i < points.length; i += 1) ctx.lineTo(points[i][0], points[i][1]);
  ctx.stroke();
}

// -------------------------------------------------------------- drawing

function canvasPoint(event) {
  const rect = ui.ink.getBoundingClientRect();
  return [(event.clientX - rect.left) * (W / rect.width), (event.clientY - rect.top) * (W / rect.height)];
}

function addPoint(stroke, event) {
  const [x, y] = canvasPoint(event);
  if (state.t0 === null) state.t0 = event.timeStamp;
  // Timestamps must increase strictly (the API checks); coalesced events may share one.
  const last = stroke.times.length ? stroke.times[stroke.times.length - 1] : -Infinity;
  // 1 ms apart at least, so that rounding to 0.1 ms for the request keeps them increasing.
  const t = Math.max((event.timeStamp - state.t0) / 1000, last + 1e-3);
  const prev = stroke.points[stroke.points.length - 1];
  if (prev && Math.hypot(x - prev[0], y - prev[1]) < 0.5) return; // sub-pixel jitter
  stroke.points.push([x, y]);
  stroke.times.push(t);
}

function onPointerDown(event) {
  if (event.pointerType === "mouse" && event.button !== 0) return;
  event.preventDefault();
  ui.ink.setPointerCapture(event.pointerId);
  // Strokes after the last one: a new stroke starts later than the previous one ended.
  state.current = { points: [], times: [], pointerId: event.pointerId };
  addPoint(state.current, event);
  if (state.strokes.length) {
    const prev = state.strokes[state.strokes.length - 1];
    const end = prev.times[prev.times.length - 1];
    if (state.current.times[0] <= end) state.current.times[0] = end + 1e-2;
  }
}

function onPointerMove(event) {
  const stroke = state.current;
  if (!stroke || event.pointerId !== stroke.pointerId) return;
  const events = event.getCoalescedEvents ? event.getCoalescedEvents() : [event];
  for (const e of events.length ? events : [event]) addPoint(stroke, e);
  drawInk();
}

function onPointerUp(event) {
  const stroke = state.current;
  if (!stroke || event.pointerId !== stroke.pointerId) return;
  addPoint(stroke, event);
  state.current = null;
  if (stroke.points.length >= 2) {
    state.strokes.push({ points: stroke.points, times: stroke.times });
    forgetPlan();
  }
  drawInk();
}

function drawInk() {
  inkCtx.clearRect(0, 0, W, W);
  inkCtx.lineCap = "round";
  inkCtx.lineJoin = "round";
  inkCtx.lineWidth = 3;
  inkCtx.strokeStyle = color("--ink");
  for (const s of state.strokes) polyline(inkCtx, s.points);
  if (state.current) polyline(inkCtx, state.current.points);
  const n = state.strokes.length;
  ui.count.textContent = `${n} stroke${n === 1 ? "" : "s"}`;
}

function undo() {
  state.strokes.pop();
  forgetPlan();
  drawInk();
}

function clearAll() {
  state.strokes = [];
  state.t0 = null;
  forgetPlan();
  drawInk();
}

// ------------------------------------------------------------- planning

function number(input) {
  const value = input.valueAsNumber;
  return Number.isFinite(value) ? value : input.value; // let the API say what is wrong
}

function requestBody() {
  const body = {
    board: ui.board.value, size_m: number(ui.size), drones: number(ui.drones),
    vmax: number(ui.vmax), amax: number(ui.amax), jmax: number(ui.jmax), fly: ui.fly.checked,
  };
  const text = ui.text.value.trim();
  if (text) return { ...body, text };
  // The API takes y up; the canvas has y down.
  body.strokes = state.strokes.map((s) => s.points.map(([x, y]) => [round(x), round(W - y)]));
  body.t = state.strokes.map((s) => s.times.map((t) => Math.round(t * 1e4) / 1e4));
  return body;
}

const round = (x) => Math.round(x * 100) / 100;

async function plan() {
  showError("");
  const body = requestBody();
  if (!body.text && body.strokes.length === 0) {
    showError("Draw something first (or type text).");
    return;
  }
  setBusy(true, 0, "sending");
  try {
    const answer = await fetch("/api/plan", {
      method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
    });
    const data = await answer.json().catch(() => ({}));
    if (!answer.ok) throw new Error(data.detail || `the server answered ${answer.status}`);
    const job = await poll(data.url);
    if (job.state !== "done") throw new Error(job.message || "the plan failed");
    showResult(job.result);
  } catch (error) {
    showError(error.message);
    ui.studio.dataset.state = "error";
  } finally {
    setBusy(false);
  }
}

async function poll(url) {
  for (;;) {
    const answer = await fetch(url);
    const job = await answer.json();
    if (!answer.ok) throw new Error(job.detail || `the server answered ${answer.status}`);
    setBusy(true, job.progress, `${job.stage} (${job.elapsed_s.toFixed(1)} s)`);
    if (job.state === "done" || job.state === "error") return job;
    await new Promise((resolve) => setTimeout(resolve, POLL_MS));
  }
}

function setBusy(busy, progress = 0, stage = "") {
  ui.plan.disabled = busy;
  ui.progressBox.hidden = !busy;
  ui.progress.value = progress;
  ui.stage.textContent = stage;
  if (busy) ui.studio.dataset.state = "planning";
}

function showError(message) {
  ui.error.hidden = !message;
  ui.error.textContent = message;
}

function forgetPlan() {
  state.result = null;
  state.playing = false;
  overCtx.clearRect(0, 0, W, W);
  plotCtx.clearRect(0, 0, W, 420);
  ui.play.disabled = ui.time.disabled = true;
  ui.play.textContent = "Play";
  ui.summary.textContent = "";
  ui.files.replaceChildren(item("Plan first.", "muted"));
  ui.notes.replaceChildren();
  ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
}

// -------------------------------------------------------------- results

function showResult(result) {
  state.result = result;
  state.views = result.drones.map((d) => viewOf(result, d));
  state.t = 0;
  ui.time.max = String(result.duration_s);
  ui.time.step = String(Math.max(result.duration_s / 1000, 0.01));
  ui.play.disabled = ui.time.disabled = false;
  showSummary(result);
  showFiles(result);
  drawFrame();
  ui.overlay.dataset.pathPoints = String(result.drones.reduce((n, d) => n + d.path.length, 0));
  ui.studio.dataset.state = "planned";
  setPlaying(true);
}

function viewOf(result, drone) {
  // Drawn input: map each board back onto the ink it came from (source units are canvas px).
  if (result.source === "strokes") {
    const [lx, ly] = drone.source_lo;
    const k = 1 / drone.source_scale;
    return ([u, v]) => [lx + u * k, W - (ly + v * k)];
  }
  // Typed text: fit every board's writing, side by side, into the canvas.
  let lo = [Infinity, Infinity];
  let hi = [-Infinity, -Infinity];
  for (const d of result.drones) {
    for (const stroke of d.input) {
      for (const [u, v] of stroke) {
        lo = [Math.min(lo[0], u + d.board_u0), Math.min(lo[1], v)];
        hi = [Math.max(hi[0], u + d.board_u0), Math.max(hi[1], v)];
      }
    }
  }
  const margin = 40;
  const k = (W - 2 * margin) / Math.max(hi[0] - lo[0], hi[1] - lo[1], 1e-9);
  const ox = margin + ((W - 2 * margin) - k * (hi[0] - lo[0])) / 2;
  const oy = margin + ((W - 2 * margin) - k * (hi[1] - lo[1])) / 2;
  return ([u, v]) => [ox + (u + drone.board_u0 - lo[0]) * k, W - (oy + (v - lo[1]) * k)];
}

function sampleIndex(drone, t) {
  // Samples are uniform in time: the index is a division, clamped.
  const n = drone.t.length;
  if (n < 2) return 0;
  return Math.max(0, Math.min(n - 1, Math.round((t / drone.t[n - 1]) * (n - 1))));
}

function drawFrame() {
  const result = state.result;
  overCtx.clearRect(0, 0, W, W);
  if (!result) return;
  overCtx.lineCap = "round";
  overCtx.lineJoin = "round";
  result.drones.forEach((drone, i) => drawDrone(drone, state.views[i], result.source === "text"));
  ui.clock.textContent = `${state.t.toFixed(1)} / ${result.duration_s.toFixed(1)} s`;
  ui.time.value = String(state.t);
  drawPlots(result);
}

function drawDrone(drone, view, showInput) {
  const k = sampleIndex(drone, state.t);
  if (showInput) {
    overCtx.strokeStyle = "rgba(29, 29, 31, 0.35)";
    overCtx.lineWidth = 3;
    for (const stroke of drone.input) polyline(overCtx, stroke.map(view));
  }
  drawPath(drone, view);
  // What the simulated brush left on the board: wide and pale, under the trace.
  overCtx.strokeStyle = "rgba(28, 126, 214, 0.35)";
  overCtx.lineWidth = 6;
  for (const line of drone.ink) polyline(overCtx, line.map(view));
  drawTrace(drone, view, k);
  if (drone.flight.length) {
    // The simulated flight so far (the tip below the flown vehicle), thin and solid.
    overCtx.strokeStyle = color("--flight");
    overCtx.lineWidth = 1.2;
    polyline(overCtx, drone.flight.slice(0, k + 1).map(view));
  }
  drawMarker(view(drone.path[k]), drone.path[k][2] < 0.003);
}

function drawPath(drone, view) {
  // Pen-down runs solid, pen-up runs dashed: split the samples where the pen changes.
  let run = [view(drone.path[0])];
  for (let i = 1; i < drone.path.length; i += 1) {
    run.push(view(drone.path[i]));
    if (drone.pen[i] !== drone.pen[i - 1] || i === drone.path.length - 1) {
      const down = drone.pen[i - 1] === 1;
      overCtx.strokeStyle = down ? color("--path") : color("--transit");
      overCtx.lineWidth = down ? 2 : 1;
      overCtx.setLineDash(down ? [] : [5, 5]);
      polyline(overCtx, run);
      run = [run[run.length - 1]];
    }
  }
  overCtx.setLineDash([]);
}

function drawTrace(drone, view, k) {
  // The drone's ink so far: the pen-down samples up to now.
  overCtx.strokeStyle = color("--drone");
  overCtx.lineWidth = 4;
  let run = [];
  for (let i = 0; i <= k; i += 1) {
    if (drone.pen[i]) run.push(view(drone.path[i]));
    else if (run.length) {
      polyline(overCtx, run);
      run = [];
    }
  }
  polyline(overCtx, run);
}

function drawMarker([x, y], down) {
  // A quadrotor seen from above: four rotors around the brush.
  overCtx.strokeStyle = color("--drone");
  overCtx.fillStyle = down ? color("--drone") : "white";
  overCtx.lineWidth = 2;
  for (const [dx, dy] of [[-9, -9], [9, -9], [-9, 9], [9, 9]]) {
    overCtx.beginPath();
    overCtx.arc(x + dx, y + dy, 5, 0, 2 * Math.PI);
    overCtx.stroke();
  }
  overCtx.beginPath();
  overCtx.arc(x, y, 4, 0, 2 * Math.PI);
  overCtx.fill();
  overCtx.stroke();
}

// ---------------------------------------------------------------- plots

const PANELS = [
  { key: "speed", limit: "vmax", label: "speed: largest |v_i|", unit: "m/s" },
  { key: "acc", limit: "amax", label: "acceleration: largest |a_i|", unit: "m/s²" },
  { key: "jerk", limit: "jmax", label: "jerk: largest |j_i|", unit: "m/s³" },
];

function drawPlots(result) {
  const height = 420;
  plotCtx.clearRect(0, 0, W, height);
  const panelHeight = height / PANELS.length;
  PANELS.forEach((panel, i) => drawPanel(result, panel, i * panelHeight, panelHeight));
}

function drawPanel(result, panel, top, height) {
  const left = 48;
  const right = W - 10;
  const y0 = top + height - 22;
  const y1 = top + 18;
  const limit = result.limits[panel.limit];
  let peak = limit;
  for (const d of result.drones) for (const value of d[panel.key]) peak = Math.max(peak, value);
  const ymax = peak * 1.15;
  const xOf = (t) => left + (t / result.duration_s) * (right - left);
  const yOf = (v) => y0 - (v / ymax) * (y0 - y1);

  plotCtx.font = "12px system-ui, sans-serif";
  plotCtx.fillStyle = "#333";
  plotCtx.fillText(`${panel.label}, ${panel.unit}`, left, top + 12);
  // Axes and ticks.
  plotCtx.strokeStyle = "#999";
  plotCtx.lineWidth = 1;
  polyline(plotCtx, [[left, y1], [left, y0], [right, y0]]);
  plotCtx.fillStyle = "#666";
  plotCtx.font = "10px system-ui, sans-serif";
  for (const v of [0, limit]) plotCtx.fillText(formatTick(v), 4, yOf(v) + 3);
  for (const t of timeTicks(result.duration_s)) plotCtx.fillText(`${t} s`, xOf(t) - 8, y0 + 13);
  // The limit, dashed red.
  plotCtx.strokeStyle = "#c92a2a";
  plotCtx.setLineDash([6, 4]);
  polyline(plotCtx, [[left, yOf(limit)], [right, yOf(limit)]]);
  plotCtx.setLineDash([]);
  // One curve per drone.
  result.drones.forEach((d, i) => {
    plotCtx.strokeStyle = COLORS[i % COLORS.length];
    plotCtx.lineWidth = 1.5;
    polyline(plotCtx, d.t.map((t, k) => [xOf(t), yOf(d[panel.key][k])]));
  });
  // Where the animation is.
  plotCtx.strokeStyle = color("--drone");
  polyline(plotCtx, [[xOf(state.t), y1], [xOf(state.t), y0]]);
}

function formatTick(v) {
  return v === 0 ? "0" : v >= 10 ? v.toFixed(0) : v.toFixed(1);
}

function timeTicks(duration) {
  const step = [1, 2, 5, 10, 20, 50, 100].find((s) => duration / s <= 8) || 200;
  const ticks = [];
  for (let t = 0; t <= duration; t += step) ticks.push(t);
  return ticks;
}

// --------------------------------------------------------- summary, files

function showSummary(result) {
  const mm = (m) => `${(1000 * m).toFixed(1)} mm`;
  const worst = Math.max(...result.drones.map((d) => d.deviation_max_m));
  const excess = Math.max(...result.drones.flatMap((d) => d.checks.map((c) => c.relative_excess)));
  const parts = [
    `${result.duration_s.toFixed(1)} s of flight`,
    `planned in ${result.planning_time_s.toFixed(2)} s`,
    `pen-down deviation ${mm(worst)}`,
    excess > 0 ? `limits exceeded by ${(100 * excess).toFixed(2)} %` : "every limit met",
  ];
  const flown = result.drones.filter((d) => d.flight_rmse_m !== null);
  if (flown.length) parts.push(`simulated RMSE ${mm(Math.max(...flown.map((d) => d.flight_rmse_m)))}`);
  if (result.min_separation_m !== null) parts.push(`closest drones ${result.min_separation_m.toFixed(2)} m`);
  ui.summary.textContent = parts.join(" · ");
}

function item(text, className) {
  const li = document.createElement("li");
  li.textContent = text;
  if (className) li.className = className;
  return li;
}

function showFiles(result) {
  const links = result.files.map((file) => {
    const li = document.createElement("li");
    const a = document.createElement("a");
    a.href = file.url;
    a.download = file.name;
    a.textContent = file.name;
    a.dataset.file = file.name;
    li.append(a, ` — ${file.description} (${(file.size_bytes / 1024).toFixed(0)} KB)`);
    return li;
  });
  if (result.source === "strokes") links.push(drawingLink());
  ui.files.replaceChildren(...links);
  ui.notes.replaceChildren(...result.notes.map((n) => item(n)));
}

function drawingLink() {
  // The recording itself, in the format `skyquill write --strokes` reads.
  const body = requestBody();
  const json = JSON.stringify({ strokes: body.strokes, t: body.t });
  const li = document.createElement("li");
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([json], { type: "application/json" }));
  a.download = "drawing.json";
  a.textContent = "drawing.json";
  li.append(a, " — your strokes with their timestamps (skyquill write --strokes)");
  return li;
}

// -------------------------------------------------------------- playback

function setPlaying(playing) {
  state.playing = playing && state.result !== null;
  ui.play.textContent = state.playing ? "Pause" : "Play";
  state.lastFrame = null;
  if (state.playing) requestAnimationFrame(tick);
}

function tick(now) {
  if (!state.playing || !state.result) return;
  if (state.lastFrame !== null) {
    state.t += ((now - state.lastFrame) / 1000) * Number(ui.speed.value);
  }
  state.lastFrame = now;
  if (state.t >= state.result.duration_s) {
    state.t = state.result.duration_s;
    drawFrame();
    setPlaying(false);
    return;
  }
  drawFrame();
  requestAnimationFrame(tick);
}

// ---------------------------------------------------------------- wiring

ui.ink.addEventListener("pointerdown", onPointerDown);
ui.ink.addEventListener("pointermove", onPointerMove);
ui.ink.addEventListener("pointerup", onPointerUp);
ui.ink.addEventListener("pointercancel", onPointerUp);
ui.undo.addEventListener("click", undo);
ui.clear.addEventListener("click", clearAll);
ui.plan.addEventListener("click", plan);
ui.play.addEventListener("click", () => {
  if (state.result && state.t >= state.result.duration_s) state.t = 0;
  setPlaying(!state.playing);
});
ui.time.addEventListener("input", () => {
  state.t = Number(ui.time.value);
  setPlaying(false);
  drawFrame();
});
document.addEventListener("keydown", (event) => {
  if ((event.ctrlKey || event.metaKey) && event.key === "z" && event.target === document.body) {
    event.preventDefault();
    undo();
  }
});
drawInk();
ui.studio.dataset.ready = "true";
