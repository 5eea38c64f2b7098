// robodamp dashboard page: the fleet's tiles and one cell's live view from the server's event stream
// (docs/dashboard.md). Plots are Debian's dygraphs; nothing here draws a chart by hand.
'use strict';

const $ = (id) => document.getElementById(id);
const fmt = (v, digits) => (v === null || v === undefined || Number.isNaN(v)) ? '–' : Number(v).toFixed(digits);
const esc = (s) => String(s === undefined || s === null ? '' : s).replace(/[&<>"']/g,
  (c) => ({'&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;'}[c]));

// What the browser tests read: state changes seen (with their delay from the cell), and what each plot holds.
window.robodamp = { latencies: [], plotted: {}, updates: { time: 0, spectrum: 0, lobes: 0, timing: 0 }, events: 0, handlerMs: [] };

// How long the page works on each event (the last 2000): the load script reads it to show the page keeps up.
function timed(fn) {
  return (ev) => {
    const t0 = performance.now();
    window.robodamp.events++;
    fn(ev);
    const h = window.robodamp.handlerMs;
    h.push(performance.now() - t0);
    if (h.length > 2000) h.shift();
  };
}

let token = sessionStorage.getItem('robodamp-token') || '';
let role = 'observer';
let source = null;
let currentCell = null;
const shown = {};  // cell -> "state/trip" last rendered
const plots = {};
let timeRows = [];

function message(text, ok) {
  const m = $('message');
  m.textContent = text;
  m.className = ok === undefined ? '' : (ok ? 'ok' : 'bad');
}

async function api(path, body) {
  const headers = { 'Content-Type': 'application/json' };
  if (token) headers.Authorization = 'Bearer ' + token;
  const res = await fetch(path, body === undefined ? { headers } : { method: 'POST', headers, body: JSON.stringify(body) });
  let data = {};
  try { data = await res.json(); } catch (e) { data = { error: res.statusText }; }
  return { status: res.status, data };
}

function showWho(user) {
  $('login').hidden = !!user;
  $('who').hidden = !user;
  $('who-name').textContent = user ? user + ' (' + role + ')' : '';
  document.body.dataset.role = role;
  $('actions-note').textContent = role === 'operator' ? '' : 'log in as an operator to act';
}

async function whoami() {
  const r = await api('/api/whoami');
  role = r.data.role || 'observer';
  if (!r.data.user) { token = ''; sessionStorage.removeItem('robodamp-token'); }
  showWho(r.data.user);
}

$('login').addEventListener('submit', async (ev) => {
  ev.preventDefault();
  const r = await api('/api/login', { user: $('user').value, password: $('password').value });
  $('password').value = '';
  if (r.status === 200) {
    token = r.data.token; role = r.data.role;
    sessionStorage.setItem('robodamp-token', token);
    showWho(r.data.user);
    message('logged in as ' + r.data.user + ' (' + r.data.role + ')', true);
  } else {
    message('login refused: ' + (r.data.error || r.status), false);
  }
});

$('logout').addEventListener('click', async () => {
  await api('/api/logout', {});
  token = ''; role = 'observer'; sessionStorage.removeItem('robodamp-token');
  showWho(null);
  message('logged out', true);
});

// The operator's typed values. The boxes are text, not <input type="number">: that one hands the page '' for
// anything it cannot parse, and Number('') is 0, so an empty gain box once sent K = 0 and the cell took it.
// Here the text is parsed strictly and checked against what the cell publishes (its gain limit, its sets,
// its spindle's range) before anything leaves the page; the cell checks again when it executes.
const kTyped = {
  gain: { box: 'gain-value', what: 'the gain K', unit: 'N s/m', integer: false },
  set: { box: 'set-value', what: 'the parameter set', unit: '', integer: true },
  spindle: { box: 'spindle-value', what: 'the spindle speed', unit: 'rpm', integer: false },
};
const kNumberText = /^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$/;
let cellStatus = null;     // the current cell's last status (its limits) and machining sample
let cellMachining = null;
let cellLobes = null;      // its last lobes (they come with the spectrum, about once a second)
let lobesDrawn = '';       // what the lobes panel was last drawn for

function typedValue(action, text, status) {
  const spec = kTyped[action];
  const t = String(text).trim();
  const unit = spec.unit ? ' ' + spec.unit : '';
  const said = '"' + t.slice(0, 24) + (t.length > 24 ? '…' : '') + '"';
  if (t === '') return { error: spec.what + ' is empty: type a value' + (spec.unit ? ' in ' + spec.unit : '') + ' (nothing was sent)' };
  if (t.includes(',')) return { error: spec.what + ' ' + said + ': write the decimal mark as a point (1.5, not 1,5) and no thousands separator (nothing was sent)' };
  if (!kNumberText.test(t)) return { error: spec.what + ' ' + said + ' is not a number (nothing was sent)' };
  const v = Number(t);
  if (!Number.isFinite(v)) return { error: spec.what + ' ' + said + ' is too large to be a number (nothing was sent)' };
  if (v < 0) return { error: spec.what + ' = ' + t + unit + ' is negative: allowed from 0 (nothing was sent)' };
  if (spec.integer && v !== Math.floor(v)) return { error: spec.what + ' = ' + t + ' is not a whole number (nothing was sent)' };
  if (!status) return { error: 'the cell\'s limits are not known yet (no status heard): nothing was sent' };
  const max = { gain: status.max_gain_ns_per_m, set: status.parameter_sets - 1, spindle: status.spindle_rpm_max }[action];
  const name = { gain: 'the cell\'s gain limit', set: 'the last configured set', spindle: 'the spindle\'s spindle.rpm_max' }[action];
  if (!(max >= 0)) return { error: 'the cell does not publish ' + name + ': nothing was sent' };
  if (v > max) return { error: spec.what + ' = ' + t + unit + ' is above ' + name + ' (' + fmt(max, spec.integer ? 0 : 1) + unit + '): nothing was sent' };
  return { value: v };
}

// What an action does, in words, and whether it reduces or removes damping or changes the spindle (those
// wait for the operator's confirmation).
function effect(action, value, status, machining) {
  const k = status ? status.gain_ns_per_m : undefined;
  switch (action) {
    case 'gain':
      if (value === 0) return { text: 'K ' + fmt(k, 0) + ' → 0 N s/m: removes the damping', confirm: true };
      if (k !== undefined && value < k) return { text: 'K ' + fmt(k, 0) + ' → ' + fmt(value, 0) + ' N s/m: less damping', confirm: true };
      return { text: 'K ' + fmt(k, 0) + ' → ' + fmt(value, 0) + ' N s/m', confirm: false };
    case 'disarm': return { text: 'disarm: the command fades out and the damper stops damping', confirm: true };
    case 'set': return { text: 'parameter set ' + (status ? status.parameter_set : '?') + ' → ' + value +
      ': another controller (fade out, swap, fade in)', confirm: true };
    case 'spindle': return { text: 'spindle ' + fmt(machining ? machining.spindle_rpm : undefined, 0) + ' → ' + fmt(value, 0) +
      ' rpm: the notches and the limits follow the new speed', confirm: true };
    default: return { text: action, confirm: false };
  }
}

let pending = null;  // the action waiting for its confirmation
function ask(body, text) {
  pending = { body, cell: currentCell, until: Date.now() + 20000 };
  $('confirm-text').textContent = text + ' on ' + currentCell + '?';
  $('confirm').hidden = false;
}
function cancelPending(why) {
  if (!pending) return;
  pending = null;
  $('confirm').hidden = true;
  if (why) message(why + ': nothing was sent', false);
}

async function send(body) {
  message(body.action + ' sent to ' + currentCell + '…');
  const r = await api('/api/cells/' + encodeURIComponent(currentCell) + '/action', body);
  const d = r.data;
  if (r.status === 200) message((d.accepted ? 'accepted: ' : 'refused by the cell: ') + d.reason, d.accepted);
  else message(body.action + ' refused (' + r.status + '): ' + (d.error || d.reason), false);
  loadActions();
}

document.querySelectorAll('#actions button[data-action]').forEach((b) => b.addEventListener('click', async () => {
  const action = b.dataset.action;
  cancelPending();
  const body = { action };
  if (kTyped[action]) {
    const t = typedValue(action, $(kTyped[action].box).value, cellStatus);
    if (t.error) return message(t.error, false);
    body.value = t.value;
  }
  const e = effect(action, body.value, cellStatus, cellMachining);
  if (e.confirm && role === 'operator') return ask(body, e.text);
  send(body);
}));
$('confirm-yes').addEventListener('click', () => {
  const p = pending;
  pending = null;
  $('confirm').hidden = true;
  if (!p || p.cell !== currentCell) return message('nothing to confirm', false);
  if (Date.now() > p.until) return message('the confirmation came after 20 s: nothing was sent; ask again', false);
  send(p.body);
});
$('confirm-no').addEventListener('click', () => cancelPending('cancelled'));

// A pose as the cell's log writes it: "[-100, 10, 90] deg".
function poseText(q) { return '[' + q.map((v) => fmt(v, 1)).join(', ') + '] deg'; }

// A tile's class, data attributes (what the browser tests read) and inner HTML.
function tile(c) {
  const m = c.machining || {};
  const state = c.state || 'unknown';
  const fault = state === 'fault';
  const limit = m.limit_mm;
  const pct = (limit && m.depth_mm !== undefined) ? Math.min(100, 100 * m.depth_mm / limit) : 0;
  // Not cutting (the spindle stopped, the robot's depth 0, no tooth-passing lines): neither "quiet" nor a
  // depth above the limit describes the cut; the limit stays, as the plan's.
  const idle = m.cutting === 'not cutting';
  const chatter = idle ? '<span class="note" data-field="not-cutting">not cutting (' + esc(m.cutting_reason || '') + ')</span>'
    : m.indicator_valid ? (m.chatter ? '<span class="chatter">CHATTER ' + fmt(m.chatter_hz, 1) + ' Hz</span>' : 'quiet')
    : (m.spindle_rpm > 0 ? 'listening…' : '–');
  return {
    className: 'tile ' + state + (c.live ? '' : ' quiet'),
    data: { cell: c.cell, state, trip: c.trip, live: String(c.live) },
    html: '<h2><span>' + esc(c.cell) + '</span><span class="badge ' + esc(state) + '">' + esc(state) + '</span></h2>' +
      (c.live ? '' : '<p class="trip">no contact for ' + fmt(c.quiet_s, 0) + ' s</p>') +
      (c.publishers > 1 ? '<p class="trip">' + c.publishers + ' publishers call themselves ' + esc(c.cell) + '</p>' : '') +
      (fault || (c.trip && c.trip !== 'none') ? '<p class="trip" data-field="trip">trip: ' + esc(c.trip) + ' – ' + esc(c.trip_description) + '</p>' : '') +
      '<dl>' +
      '<dt>damping</dt><dd>' + fmt(c.active_s, 1) + ' s active, ' + fmt(c.availability_pct, 1) + ' % of the time asked' +
      (c.derated_pct > 0 ? ' (' + fmt(c.derated_pct, 1) + ' % derated)' : '') + '; ' + (c.trips || 0) + ' trips' +
      (c.derated ? ' <span class="derated" data-field="derated" title="the cut grew or saturated the actuator: the gain is lowered until it is quiet (docs/realtime_loop.md)">DERATED</span>' : '') + '</dd>' +
      '<dt>vibration</dt><dd>' + fmt(c.accel_rms_mps2, 4) + ' m/s² RMS</dd>' +
      '<dt>spindle</dt><dd>' + (m.spindle_rpm !== undefined ? fmt(m.spindle_rpm, 0) + ' rpm' : '–') + '</dd>' +
      '<dt>depth</dt><dd>' + (m.depth_mm !== undefined ? fmt(m.depth_mm, 2) + ' mm of ' +
        (m.limits_ready ? fmt(limit, 2) + ' mm' + (m.loop_active ? ' (damped)' : ' (open loop: the damper is off)') : '…') +
        (m.depth_warning ? (m.depth_measured ? ' <span class="chatter">above the limit</span>'
          : idle ? ' <span class="note" data-field="plan-above">the job\'s planned depth is above the limit here (not cutting now)</span>'
          : ' <span class="chatter" data-field="plan-above">the job\'s planned depth is above the limit here</span>') : '') +
        (m.depth_measured ? '' : ' <span class="note" data-field="depth-source">(the job\'s plan: the robot reports no depth)</span>') +
        '<div class="bar' + (m.depth_warning && !idle ? ' warn' : '') + '"><span style="width:' + pct.toFixed(0) + '%"></span></div>' : '–') + '</dd>' +
      (m.limits_pose_deg && m.limits_pose_deg.length ? '<dt>pose</dt><dd data-field="pose">' + poseText(m.limits_pose_deg) +
        (m.limits_ready ? ': the limit is for this pose' : ' <span class="note">(recomputing: the robot moved)</span>') +
        (m.mode_spread_pct >= 0 ? '<br><span class="note" data-field="mode-spread">its modes ±' + fmt(m.mode_spread_pct, 1) +
          ' % (one sigma), ' + fmt(m.nearest_measured_deg, 0) + '° from the nearest measured pose</span>' : '') + '</dd>' : '') +
      '<dt>chatter</dt><dd>' + chatter + '</dd>' +
      (c.advice ? '<dt>advice</dt><dd data-field="advice" data-status="' + adviceState(c.advice, m) + '">' +
        (adviceState(c.advice, m) === 'expired' ? 'expired: ' + esc(c.advice.status_reason)
        : !c.advice.found ? 'no stable speed in range'
        : adviceState(c.advice, m) === 'followed' ? 'at the advised ' + fmt(c.advice.advised_rpm, 1) + ' rpm'
        : 'go to ' + fmt(c.advice.advised_rpm, 1) + ' rpm') + ' (#' + c.advice.seq + ')</dd>' : '') +
      '</dl>',
  };
}

// One element per cell, kept across updates (a click never lands on a node being replaced); only what
// changed is written.
const tiles = {};
function placeTiles(cells) {
  const grid = $('fleet');
  cells.forEach((c, i) => {
    let el = tiles[c.cell];
    if (!el) {
      el = tiles[c.cell] = document.createElement('div');
      el.addEventListener('click', () => { location.hash = '#/cell/' + encodeURIComponent(el.dataset.cell); });
    }
    const t = tile(c);
    if (el.className !== t.className) el.className = t.className;
    for (const [k, v] of Object.entries(t.data)) if (el.dataset[k] !== v) el.dataset[k] = v;
    if (el.innerHTML !== t.html) el.innerHTML = t.html;
    if (grid.children[i] !== el) grid.insertBefore(el, grid.children[i] || null);
  });
}

function renderFleet(cells) {
  const changed = [];
  for (const c of cells) {
    const key = c.state + '/' + c.trip;
    if (shown[c.cell] !== undefined && shown[c.cell] !== key && c.state_source_ms > 0) changed.push(c);
    shown[c.cell] = key;
  }
  // The delay from the cell's sample to the screen: measured at the next frame, after the tiles are painted.
  if (changed.length > 0) requestAnimationFrame(() => setTimeout(() => {
    const now = Date.now();
    changed.forEach((c) => window.robodamp.latencies.push({ cell: c.cell, state: c.state, trip: c.trip, ms: now - c.state_source_ms }));
  }, 0));
  placeTiles(cells);
  $('empty').hidden = cells.length > 0;
  if (currentCell) {
    const c = cells.find((x) => x.cell === currentCell);
    if (c) {
      $('cell-state').textContent = c.state + (c.live ? '' : ' (no contact)');
      $('cell-state').className = 'badge ' + c.state;
      $('cell-state').dataset.state = c.state;
      $('cell-trip').innerHTML = c.trip && c.trip !== 'none' ? '<span class="trip">' + esc(c.trip) + ': ' + esc(c.trip_description) + '</span>' : '';
    }
  }
}

// A dygraphs chart made with its first data (an empty placeholder upsets a log scale), then updated.
function draw(id, labels, rows, options) {
  if (!plots[id]) plots[id] = new Dygraph($(id), rows, Object.assign({ labels, legend: 'always', labelsSeparateLines: false }, options));
  else plots[id].updateOptions(Object.assign({ file: rows }, options.underlayCallback ? { underlayCallback: options.underlayCallback } : {}));
}

function plotTime(t) {
  for (let i = 0; i < t.time_s.length; i++) timeRows.push([t.time_s[i], t.accel_mps2[i], t.accel_rms_mps2[i], t.command_v[i]]);
  if (timeRows.length === 0) return;
  const last = timeRows[timeRows.length - 1][0];
  timeRows = timeRows.filter((r) => r[0] >= last - 20 && r[0] <= last);
  draw('plot-time', ['t', 'acceleration', 'acceleration RMS', 'command'], timeRows, {
    xlabel: 'loop time (s)', ylabel: 'm/s²', y2label: 'V', series: { command: { axis: 'y2' } },
    axes: { y2: { independentTicks: true } }, colors: ['#3367d6', '#9bb5ec', '#d0342c'],
  });
  window.robodamp.plotted.time = { points: timeRows.length, last_s: last };
  window.robodamp.updates.time++;
}

function plotSpectrum(s) {
  if (!s || !s.accel_asd) return;
  const rows = [];
  const fmax = Math.min(s.bin_hz * (s.accel_asd.length - 1), 250);
  for (let k = 1; k < s.accel_asd.length && k * s.bin_hz <= fmax; k++) rows.push([k * s.bin_hz, s.accel_asd[k] > 0 ? s.accel_asd[k] : null]);
  const harmonics = [];
  for (let k = 1; s.tooth_passing_hz > 0 && k * s.tooth_passing_hz <= fmax; k++) harmonics.push(k * s.tooth_passing_hz);
  const marks = (ctx, area, g) => {  // dygraphs' underlay hook: vertical markers at known frequencies
    const line = (hz, color) => { const x = g.toDomXCoord(hz); ctx.fillStyle = color; ctx.fillRect(x - 1, area.y, 2, area.h); };
    (s.mode_hz || []).forEach((hz) => line(hz, 'rgba(51,103,214,0.55)'));
    harmonics.forEach((hz) => line(hz, 'rgba(230,124,0,0.55)'));
  };
  if (rows.length === 0) return;
  draw('plot-spectrum', ['Hz', 'ASD'], rows, { logscale: true, xlabel: 'frequency (Hz)', ylabel: '(m/s²)/√Hz', colors: ['#1d2430'],
    axes: { y: { axisLabelWidth: 70 } }, underlayCallback: marks });
  $('spectrum-note').textContent = 'Welch, ' + fmt(s.record_s, 1) + ' s, ' + fmt(s.bin_hz, 2) + ' Hz bins; modes ' +
    (s.mode_hz || []).map((h) => fmt(h, 1)).join(', ') + ' Hz' + (s.tooth_passing_hz > 0 ? '; tooth passing ' + fmt(s.tooth_passing_hz, 1) + ' Hz' : '');
  window.robodamp.plotted.spectrum = { bins: rows.length, modes: (s.mode_hz || []).length, harmonics: harmonics.length, peak_hz: rows.reduce((a, r) => (r[1] > a[1] ? r : a), [0, 0])[0] };
  window.robodamp.updates.spectrum++;
}

// The advice as the cell says it stands (runtime/speed_advisor.hpp: current, followed, expired); a spindle
// already at the advised speed (SpeedAdvisor::same_speed_rpm: 0.2 %, 0.5 rpm at least) reads as followed at
// once, before the cell's next look (0.2 s).
function adviceState(a, m) {
  if (!a) return 'none';
  if (a.status === 'expired' || a.status === 'followed') return a.status;
  const near = Math.max(0.5, 0.002 * a.advised_rpm);
  return a.found && m && Math.abs((m.spindle_rpm || 0) - a.advised_rpm) <= near ? 'followed' : 'current';
}

function plotLobes(l, m, a) {
  if (!l || !l.rpm || l.rpm.length === 0) return;
  const rows = l.rpm.map((r, i) => [r, l.open_limit_mm[i], l.damped_limit_mm[i], l.depth_mm, null, null]);
  if (m && m.spindle_rpm > 0) rows.push([m.spindle_rpm, null, null, null, m.depth_mm, null]);
  const options = a && a.found && adviceState(a, m) !== 'expired' ? a.options : [];
  options.forEach((o) => rows.push([o.rpm, null, null, null, null, a.depth_mm]));
  rows.sort((x, y) => x[0] - y[0]);
  // The operating point says whether the tool is in the cut (the cell's cutting state).
  const now = !m || m.cutting === 'cutting' ? 'cutting now' : m.cutting === 'not cutting' ? 'speed now (not cutting)' : 'speed now';
  const series = { 'job depth': { strokePattern: [6, 4] }, advised: { strokeWidth: 0, drawPoints: true, pointSize: 5 } };
  series[now] = { strokeWidth: 0, drawPoints: true, pointSize: 6 };
  draw('plot-lobes', ['rpm', 'open loop', l.speed_scheduled ? 'damped (schedule)' : 'damped', 'job depth', now, 'advised'], rows, {
    xlabel: 'spindle speed (rpm)', ylabel: 'limiting depth (mm)', connectSeparatedPoints: true,
    valueRange: [0, Math.max(3, 6 * l.depth_mm)],  // the lobes near the job's depth (zoom with the mouse)
    colors: ['#7a8494', '#2e9e4f', '#1d2430', '#d0342c', '#e67c00'],
    series,
  });
  // The curve is about the state it was computed for: while the cell runs another set or K (a request, a ramp)
  // the note says so until the new sweep arrives; with the damper off the open loop is what applies.
  const s = cellStatus;
  const moved = m && l.pose_deg && l.pose_deg.length && JSON.stringify(m.limits_pose_deg || []) !== JSON.stringify(l.pose_deg);
  const other = s && !l.speed_scheduled && (s.parameter_set !== l.parameter_set || Math.abs(s.gain_ns_per_m - l.gain_ns_per_m) > 0.5);
  const off = s && s.state !== 'active';
  $('lobes-note').textContent = (other ? 'recomputing for set ' + s.parameter_set + ', K = ' + fmt(s.gain_ns_per_m, 0) + ' N s/m; shown: ' : '') +
    l.method + (l.speed_scheduled ? ' (each speed with its band\'s controller and K; K = 0 where the damper is worse than none)'
    : ', parameter set ' + l.parameter_set + ', K = ' + fmt(l.gain_ns_per_m, 0) + ' N s/m') + ', ' + l.rpm.length + ' speeds' +
    (l.pose_deg && l.pose_deg.length ? ', the robot at ' + poseText(l.pose_deg) + (moved ? ' (it has moved: recomputing)' : '') : '') +
    (off ? '; the damper is ' + s.state + ': the open loop applies' : '');
  window.robodamp.plotted.lobes = { speeds: l.rpm.length, operating_rpm: m ? m.spindle_rpm : 0, operating_label: now, advised: options.length,
    gain_ns_per_m: l.gain_ns_per_m, recomputing: !!other, damper_off: !!off, pose_deg: l.pose_deg || [], pose_moved: !!moved,
    scheduled: !!l.speed_scheduled, damped_below_open: l.rpm.filter((r, i) => l.damped_limit_mm[i] !== null && l.open_limit_mm[i] !== null &&
      l.damped_limit_mm[i] < 0.995 * l.open_limit_mm[i]).length };
  window.robodamp.updates.lobes++;
}

// The advice line, drawn whether or not the cell's lobes have come: a restarted cell advises before its first
// sweep of live lobes is done (under load that took longer than the operator's 30 s, and the page showed
// the old line; CI saw it once).
function renderAdvice(a, m) {
  const state = adviceState(a, m), followed = state === 'followed';
  // An advice the spindle has followed is not an instruction any more: said as done (the tile does the same);
  // one the cell has expired (the state it was for is gone) says why, and its speeds are not drawn.
  $('advice').innerHTML = a ? ('advice #' + a.seq + ' (' + esc(a.trigger) + ' at ' + fmt(a.spindle_rpm, 0) + ' rpm): ' +
    (state === 'expired' ? 'expired: ' + esc(a.status_reason) + ' (it was ' + (a.found ? fmt(a.advised_rpm, 1) + ' rpm' : 'none in range') + ')'
    : !a.found ? esc(a.reason) : (followed ? 'followed: at the advised ' : 'go to ') + fmt(a.advised_rpm, 1) + ' rpm, limit ' +
      fmt(a.advised_limit_mm, 2) + ' mm (margin ' + fmt(a.margin, 2) + ')') + ' – ' + esc(a.method) +
    (a.poses_ahead > 0 ? '; checked at the pose now and ' + a.poses_ahead + ' of the path ahead' +
      (a.limiting_pose_deg && a.limiting_pose_deg.length ? ', lowest at ' + poseText(a.limiting_pose_deg) : '') : '')) : 'no advice asked for';
  $('advice').dataset.followed = followed ? 'true' : 'false';
  $('advice').dataset.posesAhead = a ? String(a.poses_ahead || 0) : '0';
  $('advice').dataset.status = state;
}

function plotTiming(s) {
  if (!s || !s.wake_histogram || s.wake_histogram.length === 0) return;
  const edges = s.histogram_edges_us;
  const rows = s.wake_histogram.map((n, i) => [i, n > 0 ? n : null, s.compute_histogram[i] > 0 ? s.compute_histogram[i] : null]);
  const label = (i) => (i >= edges.length ? '' : (i === edges.length - 1 ? '≥' : '') + edges[i] + ' µs');
  if (!rows.some((r) => r[1] !== null || r[2] !== null)) return;  // nothing timed yet (a virtual clock times nothing)
  draw('plot-timing', ['bin', 'wake-up latency', 'compute'], rows, {
    stepPlot: true, fillGraph: true, logscale: true, xlabel: 'microseconds (bin from)', ylabel: 'ticks', colors: ['#3367d6', '#e67c00'],
    axes: { x: { axisLabelFormatter: (i) => label(Math.round(i)), valueFormatter: (i) => label(Math.round(i)) } },
  });
  window.robodamp.plotted.timing = { ticks: s.wake_histogram.reduce((a, b) => a + b, 0) };
  window.robodamp.updates.timing++;
}

function renderCounters(d) {
  const s = d.status || {};
  const rows = [['backend', s.backend], ['ticks', s.ticks], ['missed ticks', s.missed_ticks], ['overruns', s.overruns],
    ['stale sensor ticks', s.stale_ticks], ['invalid samples', s.invalid_samples], ['saturated ticks', s.saturated_ticks],
    ['telemetry ring drops', s.ring_drops], ['trips', s.trips], ['back at full gain', s.back_at_full_gain],
    ['wake-up p50 / p99 / max', fmt(s.wake_p50_us, 0) + ' / ' + fmt(s.wake_p99_us, 0) + ' / ' + fmt(s.wake_max_us, 1) + ' µs'],
    ['compute mean / max', fmt(s.compute_mean_us, 2) + ' / ' + fmt(s.compute_max_us, 1) + ' µs'],
    ['availability', fmt(s.availability_pct, 2) + ' %'], ['derated now / share', (s.derated ? 'yes' : 'no') + ' / ' + fmt(s.derated_pct, 2) + ' %'],
    ['parameter set', s.parameter_set],
    ['gain K / limit', fmt(s.gain_ns_per_m, 0) + ' / ' + fmt(s.max_gain_ns_per_m, 0) + ' N s/m'],
    ['parameter writes', s.parameter_writes ? 'on' : 'off (the cell refuses actions)']];
  const html = rows.map((r) => '<tr><td>' + esc(r[0]) + '</td><td data-counter="' + esc(r[0]) + '">' + esc(r[1] === undefined ? '–' : r[1]) + '</td></tr>').join('');
  if (html !== countersShown) countersShown = html, $('counters').innerHTML = html;  // rewritten only when it changes
}
let countersShown = '';

async function loadActions() {
  const r = await api('/api/actions');
  if (r.status !== 200) return;
  $('action-log').innerHTML = r.data.filter((a) => !currentCell || a.cell === currentCell).reverse().map((a) =>
    '<li class="' + (a.accepted ? '' : 'refused') + '">' + esc(a.time) + ' ' + esc(a.user) + ': ' + esc(a.action) +
    (['gain', 'set', 'spindle'].includes(a.action) ? ' ' + a.value : '') + ' – ' + (a.accepted ? 'accepted' : 'refused') + ': ' + esc(a.reason) + '</li>').join('');
}

function connect() {
  if (source) source.close();
  source = new EventSource('/api/events' + (currentCell ? '?cell=' + encodeURIComponent(currentCell) : ''));
  source.onopen = () => { $('link').textContent = 'live'; };
  source.onerror = () => { $('link').textContent = 'reconnecting…'; };
  source.addEventListener('fleet', timed((ev) => renderFleet(JSON.parse(ev.data).cells)));
  source.addEventListener('cell', timed((ev) => {
    const d = JSON.parse(ev.data);
    if (d.cell !== currentCell) return;
    // Drawn once the events already queued are taken: a page behind the stream (a busy machine, an event each
    // 100 ms) merges them and draws the newest once instead of drawing each in turn.
    // (A timer, not an animation frame: a page in a background tab gets no frames, and would only merge.)
    if (pendingCell) pendingCell = mergeCell(pendingCell, d);
    else pendingCell = d, setTimeout(renderCell, 0);
  }));
}

let pendingCell = null;

function mergeCell(a, b) {
  const t = a.telemetry;
  for (const k of Object.keys(b.telemetry)) if (Array.isArray(t[k])) t[k] = t[k].concat(b.telemetry[k]);
  t.last_seq = b.telemetry.last_seq;
  const merged = Object.assign({}, a, b, { telemetry: t });
  if (b.spectrum === undefined && a.spectrum !== undefined) merged.spectrum = a.spectrum, merged.lobes = a.lobes;
  return merged;
}

function renderCell() {
  const d = pendingCell;
  pendingCell = null;
  if (!d || d.cell !== currentCell) return;
  {
    if (d.status && d.status.state !== undefined) cellStatus = d.status;
    if (d.machining && d.machining.spindle_rpm !== undefined) cellMachining = d.machining;
    plotTime(d.telemetry);
    if (d.spectrum !== undefined) { plotSpectrum(d.spectrum); cellLobes = d.lobes; }
    // The lobes panel (the operating point, the advice and whether it is followed, the note on the state) is
    // redrawn when what it shows changes, not only when new lobes come: a followed advice says so at once.
    const m = d.machining || {}, s = cellStatus || {};
    const drawn = JSON.stringify([cellLobes && cellLobes.rpm ? cellLobes.rpm.length : 0, cellLobes && cellLobes.gain_ns_per_m,
      m.spindle_rpm, m.depth_mm, m.cutting, d.advice && d.advice.seq, d.advice && d.advice.status, s.state, s.parameter_set, s.gain_ns_per_m,
      m.limits_pose_deg, cellLobes && cellLobes.pose_deg]);
    if (d.spectrum !== undefined || drawn !== lobesDrawn) { lobesDrawn = drawn; plotLobes(cellLobes, d.machining, d.advice); renderAdvice(d.advice, d.machining); }
    plotTiming(d.status);
    renderCounters(d);
  }
}

function route() {
  const m = location.hash.match(/^#\/cell\/(.+)$/);
  currentCell = m ? decodeURIComponent(m[1]) : null;
  cancelPending();
  cellStatus = null;
  cellMachining = null;
  cellLobes = null;
  lobesDrawn = '';
  $('fleet-view').hidden = !!currentCell;
  $('cell-view').hidden = !currentCell;
  $('where').textContent = currentCell ? 'cell ' + currentCell : 'fleet';
  if (currentCell) {
    $('cell-name').textContent = currentCell;
    timeRows = [];
    for (const id of Object.keys(plots)) { plots[id].destroy(); delete plots[id]; }
    window.robodamp.plotted = {};
    loadActions();
  }
  connect();
}

window.addEventListener('hashchange', route);
whoami();
route();
