// monitor.js: the live monitor page (index.html) polls the master's API
// once a second: /api/status (progress, tiles, warnings, log),
// /api/workers (the table) and, when tiles came in, /api/image.png of the
// frame shown; a serving master's (--serve) /api/jobs, the queue. A token in the page's address (?token=...) goes with every
// API request. No libraries, no build step.
"use strict";

const token = new URLSearchParams(location.search).get("token");
const $ = (id) => document.getElementById(id);
let frame = 0;           // index of the frame shown
let shownDone = -1;      // its tiles done when its image was last loaded
let imageBusy = false;
let workers = [];        // by slot
let lastStatus = null;
let stopped = false;
let serving = false;     // /api/jobs answers: a master with a job queue

function apiUrl(path) {
  if (!token) return path;
  return path + (path.includes("?") ? "&" : "?") + "token=" + encodeURIComponent(token);
}

async function getJson(path) {
  const r = await fetch(apiUrl(path), { cache: "no-store" });
  if (!r.ok) {
    let why = r.status + " " + r.statusText;
    try { why = (await r.json()).error || why; } catch (e) { /* not JSON */ }
    throw new Error(why);
  }
  return r.json();
}

function colour(slot) {
  return "hsl(" + ((slot * 67) % 360) + ", 75%, 55%)";
}

function seconds(s) {
  if (s === null || s === undefined) return "-";
  if (s < 60) return s.toFixed(s < 10 ? 1 : 0) + " s";
  const m = Math.floor(s / 60);
  if (m < 60) return m + " min " + Math.round(s - 60 * m) + " s";
  return Math.floor(m / 60) + " h " + (m % 60) + " min";
}

function td(text, cls) {
  const e = document.createElement("td");
  e.textContent = text;
  if (cls) e.className = cls;
  return e;
}

function showWorkers(list) {
  workers = [];
  const body = $("workers").tBodies[0];
  body.textContent = "";
  for (const w of list) {
    workers[w.slot] = w;
    const tr = document.createElement("tr");
    tr.className = w.alive ? "alive" : "gone";
    tr.dataset.worker = w.name;
    const name = td("");
    const sw = document.createElement("span");
    sw.className = "swatch";
    sw.style.background = colour(w.slot);
    name.append(sw, w.name);
    tr.append(name, td(w.host), td(w.threads, "num"), td(w.tiles, "num"),
              td(w.rate_tiles_per_s.toFixed(2), "num"), td(w.cpu_seconds.toFixed(1), "num"),
              td(w.leases, "num"), td(w.state), td(w.last_error || ""));
    body.append(tr);
  }
  if (!list.length) {
    const tr = document.createElement("tr");
    const cell = td("no worker has joined yet");
    cell.colSpan = 9;
    cell.className = "muted";
    tr.append(cell);
    body.append(tr);
  }
}

function showFrames(st) {
  const box = $("frames");
  box.hidden = st.frames.length < 2;
  if (box.hidden) return;
  if (box.children.length !== st.frames.length) {
    box.textContent = "";
    st.frames.forEach((f, i) => {
      const b = document.createElement("button");
      b.addEventListener("click", () => { frame = i; shownDone = -1; refresh(); });
      box.append(b);
    });
  }
  st.frames.forEach((f, i) => {
    const b = box.children[i];
    b.textContent = "frame " + f.number + " (" + f.done + "/" + f.tiles + ")";
    b.className = i === frame ? "on" : "";
  });
}

function drawOverlay() {
  const st = lastStatus;
  const img = $("image"), cv = $("overlay");
  if (!st || !img.naturalWidth) return;
  const f = st.frames[frame];
  cv.width = img.clientWidth;
  cv.height = img.clientHeight;
  const ctx = cv.getContext("2d");
  const sx = cv.width / f.width, sy = cv.height / f.height;
  ctx.clearRect(0, 0, cv.width, cv.height);
  for (let t = 0; t < f.tiles; t++) {
    const s = f.tile_state[t];
    if (s === "d") continue;
    const x = (t % f.tiles_x) * f.tile_size * sx, y = Math.floor(t / f.tiles_x) * f.tile_size * sy;
    const w = Math.min(f.tile_size, f.width - (t % f.tiles_x) * f.tile_size) * sx;
    const h = Math.min(f.tile_size, f.height - Math.floor(t / f.tiles_x) * f.tile_size) * sy;
    if (s === "q") {
      ctx.fillStyle = "rgba(40, 40, 48, 0.85)";
      ctx.fillRect(x, y, w, h);
    } else {
      ctx.strokeStyle = colour(f.tile_worker[t]);
      ctx.lineWidth = 2;
      ctx.strokeRect(x + 1, y + 1, w - 2, h - 2);
    }
  }
}

function tileAt(ev) {
  const st = lastStatus, cv = $("overlay");
  if (!st) return;
  const f = st.frames[frame];
  const r = cv.getBoundingClientRect();
  const px = (ev.clientX - r.left) * f.width / r.width, py = (ev.clientY - r.top) * f.height / r.height;
  const t = Math.floor(py / f.tile_size) * f.tiles_x + Math.floor(px / f.tile_size);
  if (t < 0 || t >= f.tiles) return;
  const state = { d: "done", l: "being rendered", q: "queued" }[f.tile_state[t]];
  const w = workers[f.tile_worker[t]];
  $("tile-info").textContent = "tile " + t + ": " + state + (w ? " by " + w.name : "");
}

// Loads the frame's image when tiles came in; counts its lit pixels
// (data-lit-pixels) once it is decoded, for tests and for the curious.
function loadImage(done) {
  const index = lastStatus.frames[frame].index;   // the monitor's: every job's frames
  done = index + ":" + done;
  if (imageBusy || done === shownDone) return;
  imageBusy = true;
  const next = new Image();
  next.onload = () => {
    const img = $("image");
    img.src = next.src;
    img.dataset.loaded = next.naturalWidth + "x" + next.naturalHeight;
    const c = document.createElement("canvas");
    c.width = next.naturalWidth;
    c.height = next.naturalHeight;
    const ctx = c.getContext("2d");
    ctx.drawImage(next, 0, 0);
    const px = ctx.getImageData(0, 0, c.width, c.height).data;
    let lit = 0;
    for (let i = 0; i < px.length; i += 4) if (px[i] || px[i + 1] || px[i + 2]) lit++;
    img.dataset.litPixels = lit;
    shownDone = done;
    imageBusy = false;
    requestAnimationFrame(drawOverlay);
    const now = lastStatus && lastStatus.frames[frame];
    if (now && now.index + ":" + now.done !== done) loadImage(now.done);   // tiles came meanwhile
  };
  next.onerror = () => { imageBusy = false; };
  next.src = apiUrl("/api/image.png?frame=" + index + "&done=" + done);
}

function showStatus(st) {
  lastStatus = st;
  const job = st.job, tiles = st.tiles;
  $("scene").textContent = job.scene + (job.frames > 1 ? " (" + job.frames + " frames)" : "");
  const state = $("state");
  state.textContent = job.state;
  state.className = "state " + job.state;
  const pct = tiles.total ? (100 * tiles.done / tiles.total) : 100;
  $("bar").style.width = pct.toFixed(1) + "%";
  $("progress").textContent = tiles.done + "/" + tiles.total + " tiles (" + Math.floor(pct) +
    "%), " + st.rate_tiles_per_s.toFixed(1) + " tiles/s, ETA " + seconds(st.eta_s) + ", " +
    st.workers_alive + " worker" + (st.workers_alive === 1 ? "" : "s") + " alive, " +
    tiles.leased + " tiles being rendered, " + seconds(job.elapsed_s) + " elapsed" +
    (job.error ? " - " + job.error : "");
  document.title = Math.floor(pct) + "% " + job.scene + " - aafarm";
  if (frame >= st.frames.length) frame = 0;
  showFrames(st);
  const warn = $("warnings");
  warn.textContent = "";
  for (const w of st.warnings) {
    const li = document.createElement("li");
    li.textContent = w.count + " " + w.text;
    warn.append(li);
  }
  if (!st.warnings.length) {
    const li = document.createElement("li");
    li.className = "muted";
    li.textContent = "none";
    warn.append(li);
  }
  const log = $("log");
  const atEnd = log.scrollTop + log.clientHeight >= log.scrollHeight - 4;
  log.textContent = st.log.join("\n");
  if (atEnd) log.scrollTop = log.scrollHeight;
  $("image-section").hidden = !st.frames.length;   // a serving master between jobs
  if (!st.frames.length) return;
  loadImage(st.frames[frame].done);
  drawOverlay();
}

function showJobs(list) {
  $("jobs-box").hidden = false;
  const body = $("jobs").tBodies[0];
  body.textContent = "";
  for (const j of list.slice().reverse()) {   // the newest first
    const tr = document.createElement("tr");
    tr.className = j.state;
    tr.dataset.job = j.id;
    const pct = j.tiles ? Math.floor(100 * j.tiles_done / j.tiles) + "%" : "-";
    tr.append(td(String(j.id)), td(j.state, "state " + j.state), td(String(j.priority)),
              td(pct), td(j.scene), td(j.outputs[0] + (j.outputs.length > 1 ? " ..." : "")),
              td(j.error || ""));
    body.append(tr);
  }
}

async function refresh() {
  if (stopped) return;
  try {
    const [st, wk, jobs] = await Promise.all([getJson("/api/status"), getJson("/api/workers"),
      getJson("/api/jobs").catch(() => null)]);
    $("problem").hidden = true;
    serving = jobs !== null;
    showWorkers(wk.workers);
    showStatus(st);
    if (serving) showJobs(jobs.jobs);
    // the end of a one-shot render: nothing more will change
    if (!serving && st.job.state !== "running") stopped = true;
  } catch (e) {
    $("problem").hidden = false;
    $("problem").textContent = "The master did not answer: " + e.message +
      (String(e.message).includes("token") ? "" : " (the render may have ended)");
    if (lastStatus) {
      $("state").textContent = "unreachable";
      $("state").className = "state unreachable";
    }
  }
}

$("overlay").addEventListener("mousemove", tileAt);
window.addEventListener("resize", drawOverlay);
refresh();
setInterval(refresh, 1000);
