// skyquill studio: record strokes, ask the API for a plan, show it, offer the files.
// A plain ES module with no dependencies and no build step (the page works offline).

const W = 560; // logical canvas size (CSS pixels of the drawing area)
const PLOT_H = 420; // logical height of the plots
const POLL_MS = 200;
// One colour per drone, on the canvas (its pen-down path) and in the plots; drone 1's is --path.
const COLORS = ["#e8590c", "#2b8a3e", "#5f3dc4", "#0b7285", "#d6336c", "#795548", "#364fc7", "#e67700"];
// The page's names of the API's fields (the labels), for messages a person reads.
const LABELS = {
  strokes: "Drawing", t: "Drawing", text: "Text", board: "Surface", size_m: "Size of the writing",
  drones: "Drones", vmax: "Speed", amax: "Acceleration", jmax: "Jerk", fly: "Fly it in simulation",
  limits: "Limits",
};
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
  files: $("files"), notes: $("notes"), form: $("form"), cancel: $("cancel"),
  estimate: $("estimate"), warning: $("warning"), warningText: $("warning-text"),
  planAnyway: $("plan-anyway"), dismiss: $("dismiss"), stale: $("stale"),
  droneLegend: $("drone-legend"), plotLegend: $("plot-legend"), stagePanel: document.querySelector(".stage"),
};

// ---------------------------------------------------------------- state

const state = {
  strokes: [], // {points: [[x, y], ...] canvas px, y down; times: [s, ...]}
  current: null, // the stroke being drawn
  t0: null, // time origin of the recording, ms
  result: null, // the API's PlanResult
  planned: null, // the request body the result was planned from (drawing.json is made of it)
  job: null, // URL of the running job (for Cancel)
  busy: false, // a plan is being estimated or run: the canvas is locked
  version: 0, // bumped by every change of the inputs; a result of an older one is out of date
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
// The plots are drawn at the width they are shown (a phone's ~360 px), so their text stays readable.
let PW = W;
let plotCtx = setupCanvas(ui.plots, W, PLOT_H);

function fitPlots() {
  const shown = Math.round(ui.plots.getBoundingClientRect().width) || W;
  PW = Math.max(280, Math.min(W, shown));
  plotCtx = setupCanvas(ui.plots, PW, PLOT_H);
  ui.plots.style.aspectRatio = `${PW} / ${PLOT_H}`;
  if (state.result) drawPlots(state.result);
}

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
  // While a plan runs the drawing is locked: the result and drawing.json must be of one drawing.
  if (state.busy) return;
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
    inputsChanged();
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
  if (state.busy || !state.strokes.length) return;
  state.strokes.pop();
  inputsChanged();
  drawInk();
}

function clearAll() {
  if (state.busy) return;
  state.strokes = [];
  state.t0 = null;
  inputsChanged();
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

async function postJSON(url, body) {
  const answer = await fetch(url, {
    method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
  });
  const data = await answer.json().catch(() => ({}));
  if (!answer.ok) throw apiError(data, answer.status);
  return data;
}

function apiError(data, status) {
  const error = new Error(data.detail || `the server answered ${status}`);
  error.field = data.field || null;
  return error;
}

async function plan(confirmed = false) {
  showError("");
  hideWarning();
  const body = requestBody();
  if (!body.text && body.strokes.length === 0) {
    showError("Draw something first (or type text).", "strokes");
    return;
  }
  const version = state.version;
  const clicked = performance.now(); // "planned in" is the wait the person had, click to result
  setBusy(true, 0, "estimating");
  let guess;
  try {
    guess = await postJSON("/api/estimate", body);
  } catch (error) {
    failed(error);
    setBusy(false);
    return;
  }
  showEstimate(guess);
  if (guess.warnings.length && !confirmed) {
    setBusy(false);
    showWarning(guess.warnings);
    return;
  }
  try {
    const accepted = await postJSON("/api/plan", body);
    state.job = accepted.url;
    const job = await poll(accepted.url);
    if (job.state === "cancelled") {
      forgetPlan();
      ui.stage.textContent = "";
      showError("");
      ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
      return;
    }
    if (job.state !== "done") throw apiError({ detail: job.message || "the plan failed", field: job.field }, 422);
    state.planned = body;
    showResult(job.result, (performance.now() - clicked) / 1000);
    if (state.version !== version) markStale(); // the inputs changed while it was planned
  } catch (error) {
    failed(error);
  } finally {
    state.job = null;
    setBusy(false);
  }
}

function failed(error) {
  forgetPlan(); // a failed plan leaves no result that looks current
  showError(error.message, error.field);
  ui.studio.dataset.state = "error";
}

async function poll(url) {
  for (;;) {
    const answer = await fetch(url);
    const job = await answer.json();
    if (!answer.ok) throw apiError(job, answer.status);
    setBusy(true, job.progress, `${job.stage} · ${job.elapsed_s.toFixed(1)} s`);
    if (job.state !== "queued" && job.state !== "running") return job;
    await new Promise((resolve) => setTimeout(resolve, POLL_MS));
  }
}

async function cancel() {
  if (!state.job) return;
  ui.cancel.disabled = true;
  await fetch(state.job, { method: "DELETE" }).catch(() => null); // the poll sees the end
}

function setBusy(busy, progress = 0, stage = "") {
  state.busy = busy;
  ui.plan.disabled = busy;
  ui.undo.disabled = ui.clear.disabled = busy;
  ui.ink.dataset.locked = String(busy);
  ui.cancel.hidden = !busy;
  ui.cancel.disabled = !busy || stage === "estimating";
  ui.progressBox.hidden = !busy;
  ui.progress.value = progress;
  ui.stage.textContent = stage;
  if (busy) ui.studio.dataset.state = "planning";
}

function showEstimate(guess) {
  const kb = (bytes) => (bytes >= 1e6 ? `${(bytes / 1e6).toFixed(1)} MB` : `${Math.ceil(bytes / 1024)} KB`);
  ui.estimate.hidden = false;
  ui.estimate.textContent = `Estimate: at least ${formatDuration(guess.flight_time_s)} of flight `
    + `(${guess.path_length_m.toFixed(1)} m of route), about ${guess.crazyflie_uploads} Crazyflie `
    + `upload${guess.crazyflie_uploads === 1 ? "" : "s"}, setpoints ≈ ${kb(guess.setpoint_bytes)}.`;
}

function formatDuration(s) {
  return s >= 90 ? `${(s / 60).toFixed(1)} min` : `${s.toFixed(0)} s`;
}

function showWarning(warnings) {
  ui.warningText.textContent = `Before planning: ${warnings.join("; ")}.`;
  ui.warning.hidden = false;
  ui.studio.dataset.state = "warned";
}

function hideWarning() {
  ui.warning.hidden = true;
}

function showError(message, field = null) {
  for (const el of document.querySelectorAll(".invalid")) el.classList.remove("invalid");
  for (const el of document.querySelectorAll("[aria-invalid]")) el.removeAttribute("aria-invalid");
  ui.error.hidden = !message;
  ui.error.textContent = field ? labelled(message, field) : message;
  const where = field && document.querySelector(`[data-field="${field === "t" ? "strokes" : field}"]`);
  if (!where) return;
  where.classList.add("invalid");
  const input = where.querySelector("input, select");
  if (input) {
    input.setAttribute("aria-invalid", "true");
    input.focus({ preventScroll: true });
  }
}

function labelled(message, field) {
  // "vmax: got -1, ..." -> "Speed: got -1, ..." (the page's words, not the API's).
  const label = LABELS[field];
  const name = message.match(/^(strokes from studio drawing|[a-z_]+)(?=[:[.])/);
  return label && name ? label + message.slice(name[0].length) : message;
}

function forgetPlan() {
  state.result = null;
  state.planned = null;
  state.playing = false;
  overCtx.clearRect(0, 0, W, W);
  plotCtx.clearRect(0, 0, PW, PLOT_H);
  ui.play.disabled = ui.time.disabled = true;
  ui.play.textContent = "Play";
  ui.summary.textContent = "";
  ui.stale.hidden = true;
  ui.droneLegend.hidden = ui.plotLegend.hidden = true;
  ui.files.replaceChildren(item("Plan first.", "muted"));
  ui.notes.replaceChildren();
  ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
}

function inputsChanged() {
  // Any change of the drawing, the text or a setting: the result shown is no longer of these inputs.
  state.version += 1;
  hideWarning();
  ui.estimate.hidden = true; // it was of the inputs before the change
  if (!state.busy) showError("");
  markStale();
  if (!state.result && !state.busy) ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
}

function markStale() {
  if (!state.result) return;
  ui.stale.hidden = false;
  ui.studio.dataset.state = "stale";
  for (const a of ui.files.querySelectorAll("a")) {
    a.removeAttribute("href");
    a.setAttribute("aria-disabled", "true");
  }
}

// -------------------------------------------------------------- results

function showResult(result, waitedS) {
  state.result = result;
  state.views = result.drones.map((d) => viewOf(result, d));
  state.t = 0;
  ui.time.max = String(result.duration_s);
  ui.time.step = String(Math.max(result.duration_s / 1000, 0.01));
  ui.play.disabled = ui.time.disabled = false;
  ui.stale.hidden = true;
  showSummary(result, waitedS);
  showFiles(result);
  showDroneLegends(result);
  drawFrame();
  ui.overlay.dataset.pathPoints = String(result.drones.reduce((n, d) => n + d.path.length, 0));
  ui.studio.dataset.state = "planned";
  ui.studio.dataset.planId = result.plan_id;
  setPlaying(true);
  // On a phone the canvas may be scrolled away while the person looked at the Plan button.
  const box = ui.stagePanel.getBoundingClientRect();
  if (box.top < 0 || box.top > window.innerHeight * 0.5) ui.stagePanel.scrollIntoView({ block: "start" });
}

function showDroneLegends(result) {
  const n = result.drones.length;
  for (const legend of [ui.droneLegend, ui.plotLegend]) {
    legend.replaceChildren(...result.drones.map((_, i) => {
      const key = document.createElement("span");
      key.className = "key";
      key.style.setProperty("--key-color", COLORS[i % COLORS.length]);
      key.textContent = n > 1 ? `drone ${i + 1}` : "drone 1";
      return key;
    }));
    legend.hidden = n < 2 && legend === ui.droneLegend;
  }
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
  result.drones.forEach((drone, i) => drawDrone(drone, state.views[i], result.source === "text", i));
  ui.clock.textContent = `${state.t.toFixed(1)} / ${result.duration_s.toFixed(1)} s`;
  ui.time.value = String(state.t);
  drawPlots(result);
}

function drawDrone(drone, view, showInput, i) {
  const k = sampleIndex(drone, state.t);
  if (showInput) {
    overCtx.strokeStyle = "rgba(29, 29, 31, 0.35)";
    overCtx.lineWidth = 3;
    for (const stroke of drone.input) polyline(overCtx, stroke.map(view));
  }
  // What the simulated brush left on the board, as ink: as wide as the brush's footprint
  // (ink_width_m, the tip pressed to its planned depth) at the canvas's scale.
  const [x0, y0] = view([0, 0]);
  const [x1, y1] = view([1, 0]);
  overCtx.strokeStyle = color("--sim-ink");
  overCtx.lineWidth = Math.max(1, drone.ink_width_m * Math.hypot(x1 - x0, y1 - y0));
  for (const line of drone.ink) polyline(overCtx, line.map(view));
  drawPath(drone, view, COLORS[i % COLORS.length]);
  drawTrace(drone, view, k);
  if (drone.flight.length) {
    // The simulated flight so far (the tip below the flown vehicle), thin and solid.
    overCtx.strokeStyle = color("--flight");
    overCtx.lineWidth = 1.2;
    polyline(overCtx, drone.flight.slice(0, k + 1).map(view));
  }
  drawMarker(view(drone.path[k]), drone.path[k][2] < 0.003);
}

function drawPath(drone, view, penDown) {
  // Pen-down runs solid, pen-up runs dashed: split the samples where the pen changes.
  let run = [view(drone.path[0])];
  for (let i = 1; i < drone.path.length; i += 1) {
    run.push(view(drone.path[i]));
    if (drone.pen[i] !== drone.pen[i - 1] || i === drone.path.length - 1) {
      const down = drone.pen[i - 1] === 1;
      overCtx.strokeStyle = down ? penDown : color("--transit");
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
  const height = PLOT_H;
  plotCtx.clearRect(0, 0, PW, height);
  const panelHeight = height / PANELS.length;
  PANELS.forEach((panel, i) => drawPanel(result, panel, i * panelHeight, panelHeight));
}

function drawPanel(result, panel, top, height) {
  const left = 48;
  const right = PW - 10;
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
  const most = PW < 400 ? 5 : 8; // fewer ticks on a narrow screen, so that they do not overlap
  const step = [1, 2, 5, 10, 20, 50, 100, 200, 500].find((s) => duration / s <= most) || 1000;
  const ticks = [];
  for (let t = 0; t <= duration; t += step) ticks.push(t);
  return ticks;
}

// --------------------------------------------------------- summary, files

function showSummary(result, waitedS) {
  const mm = (m) => `${(1000 * m).toFixed(1)} mm`;
  const worst = Math.max(...result.drones.map((d) => d.deviation_max_m));
  const excess = Math.max(...result.drones.flatMap((d) => d.checks.map((c) => c.relative_excess)));
  const parts = [
    `${result.duration_s.toFixed(1)} s of flight`,
    `planned in ${waitedS.toFixed(1)} s`,
    `pen-down deviation ${mm(worst)}`,
    excess > 0 ? `limits exceeded by ${(100 * excess).toFixed(2)} %` : "every limit met",
  ];
  const flown = result.drones.filter((d) => d.flight_rmse_m !== null);
  if (flown.length) parts.push(`simulated path RMSE ${mm(Math.max(...flown.map((d) => d.flight_rmse_m)))}`);
  const inked = result.drones.filter((d) => d.ink_max_deviation_m !== null);
  if (inked.length) parts.push(`ink deviation ${mm(Math.max(...inked.map((d) => d.ink_max_deviation_m)))}`);
  const overlaps = result.drones.filter((d) => d.ink_iou !== null);
  if (overlaps.length) parts.push(`ink IoU ${Math.min(...overlaps.map((d) => d.ink_iou)).toFixed(2)}`);
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
    a.dataset.file = file.kind;
    li.append(a, ` — ${file.description} (${(file.size_bytes / 1024).toFixed(0)} KB)`);
    return li;
  });
  if (result.source === "strokes") links.push(drawingLink(result.plan_id));
  ui.files.replaceChildren(...links);
  ui.notes.replaceChildren(...result.notes.map((n) => item(n)));
}

function drawingLink(planId) {
  // The recording the plan was made of (not the canvas now), as `skyquill write --strokes` reads it.
  const body = state.planned;
  const json = JSON.stringify({ strokes: body.strokes, t: body.t }); // the id is in its name
  const li = document.createElement("li");
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([json], { type: "application/json" }));
  a.download = `skyquill-${planId}-drawing.json`;
  a.textContent = a.download;
  a.dataset.file = "drawing.json";
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
ui.form.addEventListener("submit", (event) => {
  // Plan (or Enter in a field): the browser has checked the fields' ranges first.
  event.preventDefault();
  if (!state.busy) plan();
});
ui.form.addEventListener("input", inputsChanged);
ui.form.addEventListener("change", inputsChanged);
ui.planAnyway.addEventListener("click", () => plan(true));
ui.dismiss.addEventListener("click", () => {
  hideWarning();
  ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
});
ui.cancel.addEventListener("click", cancel);
window.addEventListener("resize", fitPlots);
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
fitPlots();
ui.studio.dataset.ready = "true";
