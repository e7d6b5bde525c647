// skyquill studio: record strokes, ask the API for a plan, show it, offer the files.
// A plain ES module with no dependencies and no build step (the page works offline).

const W = 560; // logical canvas size (CSS pixels of the drawing area)
const PLOT_H = 420; // logical height of the plots
const POLL_MS = 200;
// Where the page keeps the drawing and the settings across a reload.
const STORE_KEY = "skyquill-studio-v1";
// One colour per drone (its pen-down path, its marker, its plots). None is the legend's
// blue (flown in simulation), grey (pen up), black (your drawing) or ink: they never clash.
const COLORS = ["#c2410c", "#2b8a3e", "#7048e8", "#c2255c", "#8d5524", "#5c7f0d", "#d9480f", "#9c6f00"];
// The page's names of the API's fields, for messages made in the page.
const LABELS = {
  strokes: "Drawing", t: "Drawing", text: "Text", board: "Surface", size_m: "Size of the writing",
  drones: "Drones", vmax: "Speed", amax: "Acceleration", jmax: "Jerk", fly: "Fly it in simulation",
  limits: "Limits", target: "Vehicle",
};
// What the page checks before sending; replaced by the server's own (/api/limits).
const LIMITS = { max_strokes: 200, max_points: 20000, max_stroke_points: 5000, max_text: 40, max_drones: 8, targets: [] };
const css = getComputedStyle(document.documentElement);
const color = (name) => css.getPropertyValue(name).trim();

const $ = (id) => document.getElementById(id);
const ui = {
  studio: $("studio"), ink: $("ink"), overlay: $("overlay"), plots: $("plots"),
  undo: $("undo"), clear: $("clear"), count: $("stroke-count"), text: $("text"),
  textCount: $("text-count"), target: $("target"), targetHint: $("target-hint"),
  board: $("board"), size: $("size_m"), drones: $("drones"), vmax: $("vmax"), amax: $("amax"),
  jmax: $("jmax"), fly: $("fly"), plan: $("plan"), progressBox: $("progress-box"),
  progress: $("progress"), stage: $("stage"), status: $("status"), error: $("error"),
  play: $("play"), time: $("time"), clock: $("clock"), speed: $("speed"), phase: $("phase"),
  summary: $("summary"), files: $("files"), notes: $("notes"), form: $("form"),
  cancel: $("cancel"), estimate: $("estimate"), warning: $("warning"),
  warningText: $("warning-text"), planAnyway: $("plan-anyway"), dismiss: $("dismiss"),
  stale: $("stale"), legend: $("legend"), pathKey: $("path-key"), plotLegend: $("plot-legend"),
  notFlown: $("not-flown"), actions: $("actions"), stagePanel: document.querySelector(".stage"),
};
const SETTINGS = ["text", "target", "board", "size_m", "drones", "vmax", "amax", "jmax"];

// ---------------------------------------------------------------- state

const state = {
  strokes: [], // {points: [[x, y], ...] canvas px, y down; times: [s, ...]}
  current: null, // the stroke being drawn
  t0: null, // time origin of the recording, ms
  result: null, // the API's PlanResult
  planned: null, // the request body the result was planned from (drawing.json is made of it)
  job: null, // URL of the running job (for Cancel)
  busy: false, // a plan is being estimated or run: the canvas is locked
  cancelled: false, // Cancel was pressed for the running job
  version: 0, // bumped by every change of the inputs; a result of an older one is out of date
  views: [], // per drone: (u, v) on its board -> canvas px
  cells: [], // per drone (typed text): its cell of the canvas, [x, y, w, h]
  overview: null, // the whole-flight inset: {box, map}
  lastStage: "",
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
    const refused = strokeRefusal(stroke);
    if (refused) showError(refused, "strokes");
    else {
      state.strokes.push({ points: stroke.points, times: stroke.times });
      inputsChanged();
    }
  }
  drawInk();
}

function strokeRefusal(stroke) {
  // The studio's bounds, said before anything is sent (never a silent cut).
  const points = state.strokes.reduce((n, s) => n + s.points.length, 0) + stroke.points.length;
  if (state.strokes.length >= LIMITS.max_strokes) {
    return `Drawing: at most ${LIMITS.max_strokes} strokes can be planned, and this drawing has them; `
      + "that stroke was not added. Undo some strokes or press Clear";
  }
  if (stroke.points.length > LIMITS.max_stroke_points) {
    return `Drawing: that stroke has ${stroke.points.length.toLocaleString("en")} points, at most `
      + `${LIMITS.max_stroke_points.toLocaleString("en")} per stroke; it was not added. Draw it as several shorter strokes`;
  }
  if (points > LIMITS.max_points) {
    return `Drawing: at most ${LIMITS.max_points.toLocaleString("en")} points in all can be planned; `
      + "that stroke was not added. Undo some strokes or press Clear";
  }
  return "";
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
  ui.count.textContent = `${n} of ${LIMITS.max_strokes} strokes`;
  ui.ink.setAttribute("aria-label", `Drawing area, ${n} stroke${n === 1 ? "" : "s"}: draw strokes here with a mouse, finger or pen`);
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

// ------------------------------------------------------ text and limits up front

function textLength() {
  return [...ui.text.value].length; // characters, as the server counts them (not UTF-16 units)
}

function showTextCount() {
  const n = textLength();
  ui.textCount.textContent = `${n} of ${LIMITS.max_text} characters`;
  ui.textCount.classList.toggle("over", n > LIMITS.max_text);
  const typed = ui.text.value.trim() !== "";
  ui.studio.dataset.input = typed ? "text" : "drawing";
  ui.notFlown.hidden = !(typed && state.strokes.length);
}

function textRefusal() {
  const n = textLength();
  if (n <= LIMITS.max_text) return "";
  return `Text: ${n} characters, at most ${LIMITS.max_text}; shorten it (nothing is cut for you)`;
}

function showTargetHint() {
  const choice = LIMITS.targets.find((t) => t.name === ui.target.value);
  ui.targetHint.textContent = choice ? choice.help : "";
}

async function loadLimits() {
  try {
    const answer = await fetch("/api/limits");
    if (answer.ok) Object.assign(LIMITS, await answer.json());
  } catch {
    // Offline from the server: the page's own numbers above stay.
  }
  ui.drones.max = String(LIMITS.max_drones);
}

// ------------------------------------------------------------ keeping the work

function save() {
  // The drawing and every setting, so that a reload (even mid-plan) loses nothing.
  const settings = Object.fromEntries(SETTINGS.map((id) => [id, $(id).value]));
  settings.fly = ui.fly.checked;
  const strokes = state.strokes.map((s) => ({ points: s.points, times: s.times }));
  try {
    localStorage.setItem(STORE_KEY, JSON.stringify({ strokes, settings }));
  } catch {
    // Storage full or refused (private mode): the page works on without it.
  }
}

function restore() {
  let saved = null;
  try {
    saved = JSON.parse(localStorage.getItem(STORE_KEY) || "null");
  } catch {
    saved = null;
  }
  if (!saved || typeof saved !== "object") return;
  const okStroke = (s) => s && Array.isArray(s.points) && Array.isArray(s.times)
    && s.points.length === s.times.length && s.points.length >= 2;
  if (Array.isArray(saved.strokes) && saved.strokes.every(okStroke)) {
    state.strokes = saved.strokes.slice(0, LIMITS.max_strokes);
    const last = state.strokes[state.strokes.length - 1];
    // New strokes continue the recording's clock after the last one.
    if (last) state.t0 = performance.now() - 1000 * (last.times[last.times.length - 1] + 1);
  }
  const settings = saved.settings || {};
  for (const id of SETTINGS) if (typeof settings[id] === "string") $(id).value = settings[id];
  if (typeof settings.fly === "boolean") ui.fly.checked = settings.fly;
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
    target: ui.target.value,
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
  // The server's message in the page's words (user_message); its API line as a fallback.
  const error = new Error(data.user_message || data.detail || `The studio answered ${status}; try again`);
  error.field = data.field || null;
  return error;
}

async function plan(confirmed = false) {
  showError("");
  hideWarning();
  const body = requestBody();
  if (!body.text && body.strokes.length === 0) {
    showError("Drawing: draw something on the canvas first, or type text", "strokes");
    return;
  }
  const tooLong = textRefusal();
  if (tooLong) {
    showError(tooLong, "text");
    return;
  }
  const version = state.version;
  const clicked = performance.now(); // "planned in" is the wait the person had, click to result
  state.cancelled = false;
  setBusy(true);
  showProgress(0, "estimating the flight", true);
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
    if (job.state === "cancelled" || state.cancelled) {
      forgetPlan();
      announce("Cancelled: nothing was planned.");
      return;
    }
    if (job.state !== "done") {
      const message = job.user_message || job.message || "The plan failed; try again";
      throw apiError({ user_message: message, field: job.field }, 422);
    }
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
    if (job.state === "queued" || job.state === "running") {
      showProgress(job.progress, job.stage, job.progress_known, job.elapsed_s);
    }
    if (job.state !== "queued" && job.state !== "running") return job;
    await new Promise((resolve) => setTimeout(resolve, POLL_MS));
  }
}

async function cancel() {
  if (!state.job) return;
  state.cancelled = true;
  ui.cancel.disabled = true;
  await fetch(state.job, { method: "DELETE" }).catch(() => null); // the poll sees the end
}

function setBusy(busy) {
  state.busy = busy;
  ui.plan.disabled = busy;
  ui.plan.textContent = busy ? "Planning…" : "Plan";
  ui.undo.disabled = ui.clear.disabled = busy;
  ui.ink.dataset.locked = String(busy);
  ui.cancel.hidden = !busy;
  ui.cancel.disabled = !busy;
  ui.progressBox.hidden = !busy;
  if (busy) {
    ui.studio.dataset.state = "planning";
    announce("");
  } else {
    state.lastStage = "";
    ui.stage.textContent = "";
    ui.progress.value = 0;
  }
}

function showProgress(fraction, stage, known, elapsed = null) {
  // Known: the bar shows the share done. Not known (a drone's solves, whose number shows only
  // as they happen): the bar has no value, which browsers draw as "working, length unknown".
  if (known) ui.progress.value = fraction;
  else ui.progress.removeAttribute("value");
  ui.progress.setAttribute("aria-valuetext", known ? `${Math.round(100 * fraction)} %` : "length not known in advance");
  const clock = elapsed === null ? "" : ` · ${elapsed.toFixed(1)} s`;
  ui.stage.textContent = `${capital(stage)}${clock}`;
  $("unknown").hidden = known;
  if (stage !== state.lastStage) {
    state.lastStage = stage;
    $("announce").textContent = `Planning: ${stage}.`; // stage changes, not the clock's ticks
  }
}

function announce(text, done = false) {
  ui.status.textContent = text;
  ui.status.classList.toggle("done", done);
}

const capital = (s) => (s ? s[0].toUpperCase() + s.slice(1) : s);

function showEstimate(guess) {
  const kb = (bytes) => (bytes >= 1e6 ? `${(bytes / 1e6).toFixed(1)} MB` : `${Math.ceil(bytes / 1024)} KB`);
  const parts = [`about ${formatDuration(guess.flight_time_s)} of flight (${guess.path_length_m.toFixed(1)} m of route)`];
  if (guess.crazyflie_uploads !== null) {
    const n = guess.crazyflie_uploads;
    parts.push(n === 1 ? "one Crazyflie upload" : `1 to ${n} Crazyflie uploads`);
  }
  parts.push(`setpoint file ≈ ${kb(guess.setpoint_bytes)}`);
  ui.estimate.hidden = false;
  ui.estimate.dataset.seconds = String(guess.flight_time_s);
  ui.estimate.textContent = `Estimate: ${parts.join(", ")}.`;
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

function fieldBox(field) {
  const name = field === "t" ? "strokes" : field;
  return name ? document.querySelector(`[data-field="${name}"]`) : null;
}

function showError(message, field = null) {
  // The message sits at the field it is about (marked); the Plan panel says where to look.
  for (const el of document.querySelectorAll(".invalid")) el.classList.remove("invalid");
  for (const el of document.querySelectorAll("[aria-invalid]")) el.removeAttribute("aria-invalid");
  for (const el of document.querySelectorAll(".field-error")) {
    el.hidden = true;
    el.textContent = "";
  }
  const where = fieldBox(field);
  const text = message && field ? labelled(message, field) : capital(message);
  const slot = where && $(`${field === "t" ? "strokes" : field}-error`);
  if (!message) {
    ui.error.hidden = true;
    ui.error.textContent = "";
    return;
  }
  if (!where || !slot) {
    ui.error.hidden = false;
    ui.error.textContent = text;
    return;
  }
  slot.textContent = text;
  slot.hidden = false;
  where.classList.add("invalid");
  ui.error.hidden = false;
  ui.error.textContent = `Not planned: see ${LABELS[field] || field}, marked in red.`;
  const input = where.matches("input, select, canvas") ? where : where.querySelector("input, select, canvas");
  if (input) input.setAttribute("aria-invalid", "true");
  (field === "strokes" || field === "t" ? where : slot).scrollIntoView({ block: "nearest" });
  if (input && input.tagName !== "CANVAS") input.focus({ preventScroll: true });
}

function labelled(message, field) {
  // A message that starts with an API name ("vmax: ...") gets the page's label instead.
  if (Object.values(LABELS).some((label) => message.startsWith(`${label}:`))) return message;
  const label = LABELS[field];
  const name = message.match(/^[a-z_]+(?=[:[.])/);
  return label && name ? label + message.slice(name[0].length) : capital(message);
}

function forgetPlan() {
  state.result = null;
  state.planned = null;
  state.playing = false;
  state.t = 0;
  overCtx.clearRect(0, 0, W, W);
  plotCtx.clearRect(0, 0, PW, PLOT_H);
  ui.play.disabled = ui.time.disabled = true;
  ui.play.textContent = "Play";
  ui.time.value = "0";
  ui.clock.textContent = "0.0 s";
  ui.phase.textContent = "";
  ui.summary.textContent = "";
  ui.stale.hidden = true;
  ui.plotLegend.hidden = true;
  showPathKeys(null);
  ui.files.replaceChildren(item("Plan first.", "muted"));
  ui.notes.replaceChildren();
  ui.status.textContent = "";
  ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
  delete ui.studio.dataset.planId;
}

function inputsChanged() {
  // Any change of the drawing, the text or a setting: the result shown is no longer of these inputs.
  state.version += 1;
  hideWarning();
  ui.estimate.hidden = true; // it was of the inputs before the change
  if (!state.busy) showError("");
  showTextCount();
  showTargetHint();
  const tooLong = textRefusal();
  if (tooLong && !state.busy) showError(tooLong, "text");
  markStale();
  if (!state.result && !state.busy) ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
  save();
}

function markStale() {
  if (!state.result) return;
  ui.stale.hidden = false;
  ui.studio.dataset.state = "stale";
  announce("Out of date: plan again.");
  for (const a of ui.files.querySelectorAll("a")) {
    a.removeAttribute("href");
    a.setAttribute("aria-disabled", "true");
  }
}

// -------------------------------------------------------------- results

function verdict(result) {
  // The one place the page words its verdict on the limits: "every limit met" only when the
  // plan and every download as its vehicle plays it meet them (result.delivered, which is
  // summary.json's exports.<file>.as_played).
  const pct = (x) => `${(100 * x).toFixed(2)} %`;
  const excess = Math.max(...result.drones.flatMap((d) => d.checks.map((c) => c.relative_excess)));
  if (excess > 0) return `limits exceeded by ${pct(excess)}`;
  const delivered = result.delivered || [];
  const worded = (d) => Object.entries(d.relative_excess)
    .filter(([, e]) => e > 1e-6)
    .map(([name, e]) => `${name} ${pct(e)}`)
    .join(", ");
  const refused = delivered.filter((d) => d.verdict === "refused");
  if (refused.length) {
    return "limits met as planned, but " +
      refused.map((d) => `the ${d.kind} file would fly over them and was not made`).join("; ");
  }
  const over = delivered.filter((d) => d.verdict !== "every limit met");
  if (over.length) {
    return "limits met as planned, but as flown from the files over them: " +
      over.map((d) => `${d.kind} ${worded(d)}`).join("; ");
  }
  return "every limit met";
}

function showResult(result, waitedS) {
  state.result = result;
  layoutViews(result);
  state.t = 0;
  ui.time.max = String(result.duration_s);
  ui.time.step = String(Math.max(result.duration_s / 1000, 0.01));
  ui.play.disabled = ui.time.disabled = false;
  ui.stale.hidden = true;
  showSummary(result, waitedS);
  showFiles(result);
  showDroneLegends(result);
  ui.overlay.dataset.pathPoints = String(result.drones.reduce((n, d) => n + d.path.length, 0));
  ui.studio.dataset.state = "planned";
  ui.studio.dataset.planId = result.plan_id;
  ui.studio.dataset.duration = String(result.duration_s);
  announce(`Planned: ${result.duration_s.toFixed(1)} s of flight, ${verdict(result)}.`, true);
  drawFrame();
  setPlaying(true);
  // On a phone the canvas may be scrolled away while the person looked at the form.
  const box = ui.stagePanel.getBoundingClientRect();
  if (box.top < 0 || box.top > window.innerHeight * 0.5) ui.stagePanel.scrollIntoView({ block: "start" });
}

function showPathKeys(result) {
  // One drone: its path is "planned path"; several: one key per drone, in its colour.
  for (const key of ui.legend.querySelectorAll(".key.drone")) key.remove();
  const n = result ? result.drones.length : 1;
  ui.pathKey.hidden = n > 1;
  if (n < 2) return;
  const keys = result.drones.map((_, i) => {
    const key = document.createElement("span");
    key.className = "key drone";
    key.style.setProperty("--key-color", COLORS[i % COLORS.length]);
    key.textContent = `drone ${i + 1}'s path, pen down`;
    return key;
  });
  ui.pathKey.after(...keys);
}

function showDroneLegends(result) {
  showPathKeys(result);
  ui.plotLegend.replaceChildren(...result.drones.map((_, i) => {
    const key = document.createElement("span");
    key.className = "key";
    key.style.setProperty("--key-color", COLORS[i % COLORS.length]);
    key.textContent = `drone ${i + 1}`;
    return key;
  }));
  ui.plotLegend.hidden = false;
}

function layoutViews(result) {
  // Drawn input: each board mapped back onto the ink it came from (source units are canvas px).
  // Typed text: each drone's writing in a cell of its own, as large as the cells allow.
  state.cells = [];
  if (result.source === "strokes") {
    state.views = result.drones.map((d) => {
      const [lx, ly] = d.source_lo;
      const k = 1 / d.source_scale;
      return ([u, v]) => [lx + u * k, W - (ly + v * k)];
    });
  } else {
    state.views = textViews(result);
  }
  state.overview = overview(result);
}

function extent(drone) {
  // What a drone writes: its input and its pen-down path (the legs from home are not).
  let lo = [Infinity, Infinity];
  let hi = [-Infinity, -Infinity];
  const grow = ([u, v]) => {
    lo = [Math.min(lo[0], u), Math.min(lo[1], v)];
    hi = [Math.max(hi[0], u), Math.max(hi[1], v)];
  };
  for (const stroke of drone.input) stroke.forEach(grow);
  drone.path.forEach((p, i) => { if (drone.pen[i]) grow(p); });
  return [lo, hi];
}

function textViews(result) {
  const n = result.drones.length;
  const boxes = result.drones.map(extent);
  const wu = Math.max(...boxes.map(([lo, hi]) => hi[0] - lo[0]), 1e-9);
  const hv = Math.max(...boxes.map(([lo, hi]) => hi[1] - lo[1]), 1e-9);
  const margin = n > 1 ? 22 : 40;
  let best = null;
  for (let cols = 1; cols <= n; cols += 1) {
    const rows = Math.ceil(n / cols);
    const k = Math.min((W / cols - 2 * margin) / wu, (W / rows - 2 * margin) / hv);
    if (!best || k > best.k) best = { cols, rows, k };
  }
  const { cols, rows, k } = best;
  const cw = W / cols;
  const ch = W / rows;
  const top = (W - rows * ch) / 2;
  return result.drones.map((d, i) => {
    const [lo] = boxes[i];
    const x0 = (i % cols) * cw;
    const y0 = top + Math.floor(i / cols) * ch;
    state.cells[i] = n > 1 ? [x0, y0, cw, ch] : null;
    const ox = x0 + (cw - k * wu) / 2;
    const oy = y0 + (ch - k * hv) / 2;
    return ([u, v]) => [ox + (u - lo[0]) * k, oy + (hv - (v - lo[1])) * k];
  });
}

function overview(result) {
  // The whole flight, take-off and landing included, in a corner inset: boards side by side.
  let lo = [Infinity, Infinity];
  let hi = [-Infinity, -Infinity];
  for (const d of result.drones) {
    for (const [u, v] of d.path) {
      lo = [Math.min(lo[0], u + d.board_u0), Math.min(lo[1], v)];
      hi = [Math.max(hi[0], u + d.board_u0), Math.max(hi[1], v)];
    }
  }
  const size = Math.round(W * 0.3);
  const pad = 10;
  const k = (size - 2 * pad) / Math.max(hi[0] - lo[0], hi[1] - lo[1], 1e-9);
  const corners = [[W - size - 6, 6], [6, 6], [W - size - 6, W - size - 6], [6, W - size - 6]];
  // The corner that hides the least of the path drawn in the main view.
  const covered = ([x, y]) => result.drones.reduce((n, d, i) => n + d.path.filter((p) => {
    const [px, py] = state.views[i](p);
    return px >= x && px <= x + size && py >= y && py <= y + size;
  }).length, 0);
  const [x, y] = corners.reduce((a, b) => (covered(b) < covered(a) ? b : a));
  const ox = x + (size - k * (hi[0] - lo[0])) / 2;
  const oy = y + (size - k * (hi[1] - lo[1])) / 2;
  return {
    box: [x, y, size, size],
    map: (d) => ([u, v]) => [ox + (u + d.board_u0 - lo[0]) * k, oy + (hi[1] - v) * k],
  };
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
  result.drones.forEach((drone, i) => {
    overCtx.save();
    const cell = state.cells[i];
    overCtx.beginPath();
    if (cell) overCtx.rect(...cell);
    else overCtx.rect(0, 0, W, W);
    overCtx.clip();
    drawDrone(drone, state.views[i], result.source === "text", i, cell);
    overCtx.restore();
  });
  drawOverview(result);
  ui.clock.textContent = `${state.t.toFixed(1)} / ${result.duration_s.toFixed(1)} s`;
  ui.time.value = String(state.t);
  ui.phase.textContent = phases(result);
  drawPlots(result);
}

function drawDrone(drone, view, showInput, i, cell) {
  const k = sampleIndex(drone, state.t);
  const own = COLORS[i % COLORS.length];
  if (cell) {
    overCtx.fillStyle = own;
    overCtx.font = "600 13px system-ui, sans-serif";
    overCtx.fillText(`drone ${i + 1}`, cell[0] + 6, cell[1] + 16);
  }
  if (showInput) {
    overCtx.strokeStyle = "rgba(29, 29, 31, 0.35)";
    overCtx.lineWidth = 3;
    for (const stroke of drone.input) polyline(overCtx, stroke.map(view));
  }
  drawPath(drone, view, own);
  drawLaidInk(drone, view, k);
  if (drone.flight.length) {
    // The simulated flight so far (the tip below the flown vehicle), thin and solid.
    overCtx.strokeStyle = color("--flight");
    overCtx.lineWidth = 1.5;
    polyline(overCtx, drone.flight.slice(0, k + 1).map(view));
  }
  const last = drone.path.length - 1;
  drawHome(view(drone.path[0]), cell);
  drawHome(view(drone.path[last]), cell);
  drawMarker(view(drone.path[k]), drone.pen[k] === 1, own, cell);
}

function drawPath(drone, view, penDown) {
  // Pen-down runs solid in the drone's colour, pen-up runs dashed grey.
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

function drawLaidInk(drone, view, k) {
  // The ink laid up to now: the simulated brush's (as wide as its footprint) when flown,
  // else the planned pen-down path's.
  const [x0, y0] = view([0, 0]);
  const [x1, y1] = view([1, 0]);
  overCtx.strokeStyle = color("--sim-ink");
  overCtx.lineWidth = Math.max(2, drone.ink_width_m * Math.hypot(x1 - x0, y1 - y0));
  if (drone.ink.length) {
    drone.ink.forEach((line, r) => {
      const times = drone.ink_t[r] || [];
      let n = 0;
      while (n < times.length && times[n] <= state.t) n += 1;
      polyline(overCtx, line.slice(0, n).map(view));
    });
    return;
  }
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

function inside([x, y], cell) {
  const [cx, cy, cw, ch] = cell || [0, 0, W, W];
  return x >= cx && x <= cx + cw && y >= cy && y <= cy + ch;
}

function clampTo([x, y], cell, pad = 12) {
  const [cx, cy, cw, ch] = cell || [0, 0, W, W];
  return [Math.min(Math.max(x, cx + pad), cx + cw - pad), Math.min(Math.max(y, cy + pad), cy + ch - pad)];
}

function drawHome(p, cell) {
  // Where the drone takes off and lands: a diamond, at the edge (pointing out) when off view.
  const away = !inside(p, cell);
  const [x, y] = away ? clampTo(p, cell, 9) : p;
  overCtx.save();
  overCtx.strokeStyle = color("--home");
  overCtx.fillStyle = "rgba(255, 255, 255, 0.85)";
  overCtx.lineWidth = 2;
  overCtx.setLineDash(away ? [2, 2] : []);
  overCtx.beginPath();
  overCtx.moveTo(x, y - 7);
  overCtx.lineTo(x + 7, y);
  overCtx.lineTo(x, y + 7);
  overCtx.lineTo(x - 7, y);
  overCtx.closePath();
  overCtx.fill();
  overCtx.stroke();
  overCtx.restore();
}

function drawMarker(p, down, own, cell) {
  // A quadrotor seen from above: four rotors around the brush; at the edge when off view.
  const [x, y] = inside(p, cell) ? p : clampTo(p, cell);
  overCtx.strokeStyle = own;
  overCtx.fillStyle = down ? own : "white";
  overCtx.lineWidth = 2;
  for (const [dx, dy] of [[-8, -8], [8, -8], [-8, 8], [8, 8]]) {
    overCtx.beginPath();
    overCtx.arc(x + dx, y + dy, 4.5, 0, 2 * Math.PI);
    overCtx.stroke();
  }
  overCtx.beginPath();
  overCtx.arc(x, y, 4, 0, 2 * Math.PI);
  overCtx.fill();
  overCtx.stroke();
}

function drawOverview(result) {
  const { box, map } = state.overview;
  const [x, y, w, h] = box;
  overCtx.save();
  overCtx.fillStyle = "rgba(255, 255, 255, 0.92)";
  overCtx.strokeStyle = "#8a8a8a";
  overCtx.lineWidth = 1;
  overCtx.fillRect(x, y, w, h);
  overCtx.strokeRect(x + 0.5, y + 0.5, w - 1, h - 1);
  overCtx.fillStyle = "#3d3d3d";
  overCtx.font = "11px system-ui, sans-serif";
  overCtx.fillText("whole flight", x + 5, y + 12);
  overCtx.beginPath();
  overCtx.rect(x, y, w, h);
  overCtx.clip();
  result.drones.forEach((d, i) => {
    const view = map(d);
    overCtx.lineWidth = 1;
    let run = [view(d.path[0])];
    for (let s = 1; s < d.path.length; s += 1) {
      run.push(view(d.path[s]));
      if (d.pen[s] !== d.pen[s - 1] || s === d.path.length - 1) {
        overCtx.strokeStyle = d.pen[s - 1] ? COLORS[i % COLORS.length] : color("--transit");
        overCtx.setLineDash(d.pen[s - 1] ? [] : [3, 3]);
        polyline(overCtx, run);
        run = [run[run.length - 1]];
      }
    }
    overCtx.setLineDash([]);
    const [hx, hy] = view(d.path[0]);
    overCtx.strokeStyle = color("--home");
    overCtx.strokeRect(hx - 3, hy - 3, 6, 6);
    const [px, py] = view(d.path[sampleIndex(d, state.t)]);
    overCtx.fillStyle = COLORS[i % COLORS.length];
    overCtx.beginPath();
    overCtx.arc(px, py, 3.5, 0, 2 * Math.PI);
    overCtx.fill();
  });
  overCtx.restore();
}

function phases(result) {
  // What each drone does now, in words: taking off, writing stroke k, moving, landing.
  const words = result.drones.map((d, i) => {
    const k = sampleIndex(d, state.t);
    const starts = [];
    for (let s = 0; s < d.pen.length; s += 1) if (d.pen[s] && (s === 0 || !d.pen[s - 1])) starts.push(s);
    const lastDown = d.pen.lastIndexOf(1);
    let what;
    if (state.t >= d.t[d.t.length - 1] - 1e-9 && k === d.t.length - 1) what = "landed";
    else if (!starts.length || k < starts[0]) what = "taking off and flying to the first stroke";
    else if (k > lastDown) what = "flying back and landing";
    else {
      const stroke = starts.filter((s) => s <= k).length;
      what = d.pen[k] ? `writing stroke ${stroke} of ${starts.length}` : `moving to stroke ${stroke + 1}`;
    }
    return result.drones.length > 1 ? `drone ${i + 1}: ${what}` : capital(what);
  });
  return words.join(" · ");
}

// ---------------------------------------------------------------- plots

const PANELS = [
  { key: "speed", limit: "vmax", label: "speed", unit: "m/s" },
  { key: "acc", limit: "amax", label: "acceleration", unit: "m/s²" },
  { key: "jerk", limit: "jmax", label: "jerk", unit: "m/s³" },
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
  plotCtx.fillStyle = "#1d1d1f";
  plotCtx.fillText(`${panel.label}, ${panel.unit} (dashed: the limit)`, left, top + 12);
  // Axes and ticks.
  plotCtx.strokeStyle = "#767676";
  plotCtx.lineWidth = 1;
  polyline(plotCtx, [[left, y1], [left, y0], [right, y0]]);
  plotCtx.fillStyle = "#4a4a4a";
  plotCtx.font = "10px system-ui, sans-serif";
  for (const v of [0, limit]) plotCtx.fillText(formatTick(v), 4, yOf(v) + 3);
  for (const t of timeTicks(result.duration_s)) plotCtx.fillText(`${t} s`, xOf(t) - 8, y0 + 13);
  // The limit, dashed red.
  plotCtx.strokeStyle = "#b02525";
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
  plotCtx.strokeStyle = "#3d3d3d";
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
  const parts = [
    `${result.duration_s.toFixed(1)} s of flight`,
    `planned in ${waitedS.toFixed(1)} s`,
    `the pen stays within ${mm(worst)} of your strokes`,
    verdict(result),
  ];
  const flown = result.drones.filter((d) => d.flight_rmse_m !== null);
  if (flown.length) parts.push(`in simulation it flew on average ${mm(Math.max(...flown.map((d) => d.flight_rmse_m)))} from the plan`);
  const inked = result.drones.filter((d) => d.ink_max_deviation_m !== null);
  if (inked.length) parts.push(`its ink within ${mm(Math.max(...inked.map((d) => d.ink_max_deviation_m)))} of your strokes`);
  const overlaps = result.drones.filter((d) => d.ink_iou !== null);
  if (overlaps.length) parts.push(`${Math.round(100 * Math.min(...overlaps.map((d) => d.ink_iou)))} % of its ink overlaps yours`);
  if (result.min_separation_m !== null) parts.push(`drones at least ${result.min_separation_m.toFixed(2)} m apart`);
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
    li.append(a, ` — ${file.description} (${Math.max(1, Math.round(file.size_bytes / 1024))} KB)`);
    return li;
  });
  if (result.source === "strokes") links.push(drawingLink(result.plan_id));
  ui.files.replaceChildren(...links);
  ui.notes.replaceChildren(...result.notes.map((n) => item(n)));
}

function drawingLink(planId) {
  // The recording the plan was made of (not the canvas now), in skyquill's stroke format.
  const body = state.planned;
  const json = JSON.stringify({ strokes: body.strokes, t: body.t }); // the id is in its name
  const li = document.createElement("li");
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([json], { type: "application/json" }));
  a.download = `skyquill-${planId}-drawing.json`;
  a.textContent = a.download;
  a.dataset.file = "drawing.json";
  li.append(a, " — your strokes with their timestamps, to plan again later");
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

// ------------------------------------------------------- the phone's Plan bar

function fitBar() {
  // On a phone the Plan bar is fixed at the bottom: the page keeps room for it.
  const fixed = getComputedStyle(ui.actions).position === "fixed";
  const h = fixed ? Math.ceil(ui.actions.getBoundingClientRect().height) : 0;
  document.documentElement.style.setProperty("--bar-h", `${h}px`);
}

// ---------------------------------------------------------------- wiring

ui.ink.addEventListener("pointerdown", onPointerDown);
ui.ink.addEventListener("pointermove", onPointerMove);
ui.ink.addEventListener("pointerup", onPointerUp);
ui.ink.addEventListener("pointercancel", onPointerUp);
ui.undo.addEventListener("click", undo);
ui.clear.addEventListener("click", clearAll);
ui.form.addEventListener("submit", (event) => {
  // Plan (or Enter in a field).
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
window.addEventListener("resize", () => {
  fitPlots();
  fitBar();
});
window.addEventListener("beforeunload", (event) => {
  // Leaving mid-plan loses the plan (the drawing and settings are kept): ask first.
  if (!state.busy) return;
  event.preventDefault();
  event.returnValue = "";
});
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
if (window.ResizeObserver) new ResizeObserver(fitBar).observe(ui.actions);

await loadLimits();
restore();
drawInk();
showTextCount();
showTargetHint();
if (textRefusal()) showError(textRefusal(), "text");
ui.studio.dataset.state = state.strokes.length ? "drawn" : "empty";
fitPlots();
fitBar();
ui.studio.dataset.ready = "true";
